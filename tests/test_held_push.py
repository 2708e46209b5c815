"""The loading-following held push (insertion/case/held_push.py, PushProfile.change_speed): the
tip's pace read from the samples, the speed it asks for with its hysteresis, and the profile's
changes of speed that keep the final depth and the closing hold; off by default (the keys of
every run of before unchanged)."""

import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.manoeuvre import HELD_PUSH, SETTLE, straighten_relax_push
from colonsim.insertion.case.held_push import PACE_HYSTERESIS, PACE_WINDOW, paced_speed, tip_pace
from colonsim.insertion.case.insertion_case import InsertionCase


def samples(pace, pushed=0.03, start_arc=0.40):
    """Samples every 0.1 mm of push, the tip advancing ``pace`` of it from ``start_arc`` (m)."""
    n = int(round(pushed / 1e-4)) + 1
    return [{"depth_m": 0.30 + k * 1e-4, "tip_arc_m": start_arc + pace * k * 1e-4} for k in range(n)]


@pytest.mark.parametrize("pace", [1.0, 0.95, 0.5, 0.0])
def test_the_pace_is_the_tips_advance_over_the_last_centimetre_of_push(pace):
    assert tip_pace(samples(pace)) == pytest.approx(pace, abs=1e-9)


def test_no_pace_before_a_centimetre_of_push_or_before_the_tip_is_wholly_resisted():
    assert tip_pace(samples(1.0, pushed=0.005)) is None and tip_pace([]) is None
    rows = samples(1.0, pushed=0.03, start_arc=0.40)  # the last centimetre's tip runs from 0.42 to 0.43 m
    assert tip_pace(rows, resisted_from=0.42 + 0.5 * PACE_WINDOW) is None  # the window began short of it
    assert tip_pace(rows, resisted_from=0.42 - 0.5 * PACE_WINDOW) == pytest.approx(1.0)


def test_the_speed_follows_the_pace_with_a_hysteresis():
    full, held = 0.15, 0.075
    assert paced_speed(0.95, 0.9, held, full, held) == full
    assert paced_speed(0.8, 0.9, full, full, held) == full  # inside the band: unchanged either way
    assert paced_speed(0.8, 0.9, held, full, held) == held
    assert paced_speed(0.9 - PACE_HYSTERESIS - 0.01, 0.9, full, full, held) == held
    assert paced_speed(None, 0.9, held, full, held) == held


def test_speed_changes_keep_the_final_depth_and_the_closing_hold():
    p = straighten_relax_push(0.20, 0.68, speed=0.3, ramp=0.4, relax=0.1, settle=1.0)
    hold = p.phases[-1].end - p.phases[-1].start - p.phases[-1].ramp
    t = p.phases[3].start + 0.8
    assert not p.change_speed(t, 0.3)  # not before the push is held
    assert p.slow(t, 0.5)
    slowed_end = p.settle_start
    t2 = t + 0.6
    assert not p.change_speed(t2, 0.15)  # the speed it has: nothing to change
    assert p.change_speed(t2, 0.3)
    assert [ph.name for ph in p.phases][-3:] == [HELD_PUSH, HELD_PUSH, SETTLE]
    assert p.depth(p.duration) == pytest.approx(0.68, rel=1e-12) and p.settle_start < slowed_end
    assert p.speed(t2) == pytest.approx(0.15, rel=1e-9) and p.speed(t2 + 0.4 + 1e-9) == pytest.approx(0.3, rel=1e-9)
    t3 = t2 + 0.5
    assert p.change_speed(t3, 0.15)
    assert p.depth(p.duration) == pytest.approx(0.68, rel=1e-12)
    settle = p.phases[-1]
    assert settle.end - settle.start - settle.ramp == pytest.approx(hold)
    assert not p.change_speed(settle.start + 0.1, 0.3)  # not once the push has ended


def test_off_by_default_and_out_of_the_key_there():
    assert InsertionCase().held_push_pace == 0.0
    assert InsertionCase(held_push_pace=0.0).key() == InsertionCase().key()
    assert InsertionCase(held_push_pace=0.9).key() != InsertionCase().key()
    # nothing holds the tip: no held push, so no pace either
    assert (InsertionCase(distal_resistance_N=0.0, held_push_pace=0.9).key()
            == InsertionCase(distal_resistance_N=0.0).key())
    with pytest.raises(ColonsimError, match=r"held_push_pace = 1.5 is outside \[0, 1\]"):
        InsertionCase(held_push_pace=1.5).validate()


def test_the_paced_benchmark_judges_departures_by_the_rate_bounds_and_their_floors():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    from bench_paced import departures

    old = {"point_A_cm": 2.0, "point_C_cm": 1.5, "final_deformation_cm": 0.05, "max_deformation_cm": 2.0,
           "max_lag_cm": 6.0, "peak_contact_force_N": 20.0, "peak_push_force_N": 0.2}
    new = {**old, "point_A_cm": 2.09, "point_C_cm": 1.6, "final_deformation_cm": 0.09, "peak_contact_force_N": 21.9,
           "peak_push_force_N": 0.4}
    found = {name: ok for name, _, ok in departures(new, old)}
    assert found["A"] and not found["C"]  # +4.5 % within, +6.7 % beyond
    assert found["peak contact"] and "peak push" not in found and "final" not in found  # below their floors: not judged
