"""The rules of a run's quasi-static check and of its end (docs/quasi_static.md), each shown to
come out both ways: the ringing ratio's force floor, the snap-throughs it leaves out, and the
folded tip that ends a run."""

import numpy as np
import pytest

from colonsim.catalog import SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM, TIP_FOLDED
from colonsim.insertion.case.ringing import (RINGING_FORCE_FLOOR_N, RINGING_LIMIT, SNAP_LEFT_OUT_LIMIT,
                                             SNAP_DROP_PUSH, SNAP_LEFT_OUT_PUSH, ringing_cause, ringing_holds, ringing_ratio,
                                             snap_throughs)

Z = np.linspace(0.0, 0.3, 30001)  # m of push, sampled every 10 um


def ring(force, **kw):
    return ringing_ratio(Z, force, np.ones(Z.size, dtype=bool), **kw)


def test_a_small_ring_on_a_small_push_passes_only_through_the_floor():
    """0.05 N RMS on a 0.3 N push: 0.17 of its mean, but 0.05 of the 1 N floor."""
    force = 0.3 + 0.05 * np.sqrt(2.0) * np.sin(2 * np.pi * Z / 2e-3)
    r = ring(force)
    assert r["rms_N"] == pytest.approx(0.05, rel=0.02)
    assert r["ratio"] == pytest.approx(0.05 / RINGING_FORCE_FLOOR_N, rel=0.02) and ringing_holds(r)
    unfloored = ring(force, floor_N=0.0)
    assert unfloored["ratio"] > RINGING_LIMIT and not ringing_holds(unfloored)


def test_the_floor_does_not_excuse_ringing_on_a_real_push():
    """The same relative ringing on a 3 N push fails: the floor acts below 1 N only."""
    r = ring(3.0 + 0.5 * np.sqrt(2.0) * np.sin(2 * np.pi * Z / 2e-3))
    assert r["ratio"] == pytest.approx(0.5 / 3.0, rel=0.02) and not ringing_holds(r)
    assert "rings" in ringing_cause(r)


def rising_with_drops(drop_N, depths=(0.08, 0.15, 0.22)):
    """A force rising with the push that falls by ``drop_N`` within 0.5 mm at each depth."""
    force = 2.0 + 30.0 * Z
    for d in depths:
        force = force - drop_N * np.clip((Z - d) / 5e-4, 0.0, 1.0)
    return force


def test_snap_throughs_are_found_and_left_out():
    force = rising_with_drops(3.0)
    snaps = snap_throughs(Z, force, np.ones(Z.size, dtype=bool))
    assert [round(s, 3) for s, _ in snaps] == [0.08, 0.15, 0.22]
    r = ring(force)
    assert r["snap_throughs"] == pytest.approx([8.0, 15.0, 22.0], abs=0.05)
    # from where the force begins to fall to 6 mm after the fall is no longer detected (within 2 mm)
    assert 3 * SNAP_LEFT_OUT_PUSH / 0.3 < r["left_out_share"] < 3 * (SNAP_LEFT_OUT_PUSH + SNAP_DROP_PUSH + 5e-4) / 0.3
    assert r["ratio"] < 0.01 and ringing_holds(r)
    # without the rule the moving average straddles the steps and the run fails
    assert not ringing_holds(ring(force, snaps=[]))


@pytest.mark.parametrize("drop_N,base", [(0.8, 0.0), (2.0, 8.0)])
def test_a_fall_too_small_is_not_a_snap_through(drop_N, base):
    """Under 1 N, or under a quarter of the force before it: no snap-through, nothing left out."""
    force = rising_with_drops(drop_N) + base
    assert snap_throughs(Z, force, np.ones(Z.size, dtype=bool)) == []
    r = ring(force)
    assert r["snap_throughs"] == [] and r["left_out_share"] == 0.0


def test_a_force_that_falls_everywhere_fails_however_much_is_left_out():
    """Ringing of ratio 0.35 on 10 N with a 5 mm period falls by more than a quarter within 2 mm
    every period: such drops are not a few snap-throughs, and the run fails."""
    r = ring(10.0 + 3.5 * np.sqrt(2.0) * np.sin(2 * np.pi * Z / 5e-3))
    assert len(r["snap_throughs"]) > 20 and r["left_out_share"] > SNAP_LEFT_OUT_LIMIT
    assert not ringing_holds(r) and "falls everywhere" in ringing_cause(r)


def test_a_pause_is_not_a_snap_through():
    """The relax of RSF/THF stands at one depth while the force relaxes: no push, no drop."""
    z = np.concatenate((Z[:15000], np.full(3000, Z[15000]), Z[15000:]))
    force = np.concatenate((2.0 + 30.0 * Z[:15000], np.linspace(6.5, 1.0, 3000), 1.0 + 30.0 * (Z[15000:] - Z[15000])))
    assert len(snap_throughs(z, force, np.ones(z.size, dtype=bool))) == 1  # the force is lower after the pause
    assert snap_throughs(z, np.concatenate((force[:15000], np.full(3000, 6.5), 6.5 + 30 * (Z[15000:] - Z[15000]))),
                         np.ones(z.size, dtype=bool)) == []


# --- a folded tip ends the run -----------------------------------------------------------------------

@pytest.fixture(scope="module")
def folded_run():
    """The straight sanity tube with the fold angle lowered below any heading: the rule fires at
    its first check, so the run shows the ending's wiring in a second (the physics of a fold is
    the tip heading, tested in tests/test_outcomes.py)."""
    import colonsim.insertion.case.scenario as scenario
    from colonsim.insertion.case.scenario import InsertionCase, run_insertion

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(scenario, "TURNED_BACK_DEG", -1.0)
        return run_insertion(InsertionCase(segment="straight", scope="utc", element_size_mm=5.0,
                                           push_speed=SMOKE_PUSH_SPEED, scope_spacing_mm=SMOKE_SCOPE_SPACING_MM))


def test_a_folded_tip_ends_the_run_where_it_folds(folded_run):
    s = folded_run.summary
    assert s["ended_by"] == TIP_FOLDED and "folded" in s["end"]["reason"]
    assert s["end"]["depth_cm"] < 0.5  # the first check, a millimetre or so of push
    assert s["final_deformation_cm"] == pytest.approx(folded_run.timeseries["deformation_m"].iloc[-1] * 100)


def test_a_tight_bend_is_not_a_fold():
    """80 deg from the lumen is a tight bend, 100 deg a fold (the heading: tests/test_outcomes.py)."""
    from colonsim.insertion.case.outcomes import TURNED_BACK_DEG, tip_heading

    arc = np.linspace(0.0, 0.2, 201)
    tangents = np.tile([1.0, 0.0, 0.0], (arc.size, 1))
    for turn, folded in ((80.0, False), (100.0, True)):
        t = np.radians(turn)
        scope = np.array([[0.0, 0.0, 0.0], [0.05, 0.0, 0.0], [0.05 + 0.01 * np.cos(t), 0.01 * np.sin(t), 0.0]])
        assert (tip_heading(scope, 2, arc, tangents, 0.05) > TURNED_BACK_DEG) is folded
