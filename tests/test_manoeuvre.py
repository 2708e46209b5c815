"""Push profiles: speeds, depths and phase timing against closed-form kinematics."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.manoeuvre import HELD_PUSH, RELAX, SETTLE, continuous_push, straighten_relax_push


def test_continuous_push_reaches_the_depth_smoothly():
    p = continuous_push(0.20, speed=0.6, ramp=0.05)
    assert p.duration == pytest.approx(0.025 + 0.20 / 0.6)
    assert p.depth(p.duration) == pytest.approx(0.20, rel=1e-12)
    assert p.speed(0.0) == 0.0 and p.speed(0.025) == pytest.approx(0.3) and p.speed(0.1) == pytest.approx(0.6)
    # depth is the integral of speed (trapezoid on a fine grid)
    t = np.linspace(0, p.duration, 20001)
    v = np.array([p.speed(x) for x in t])
    assert np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(t)) == pytest.approx(p.depth(p.duration), rel=1e-6)


def test_straighten_relax_push_phases():
    p = straighten_relax_push(0.15, 0.40, speed=0.6, ramp=0.05, relax=0.1)
    names = [ph.name for ph in p.phases]
    assert names == ["straighten", "stop", "relax", "push"]
    straighten, stop, relax, push = p.phases
    # the mobile part is held until the scope has come to rest at the straightening depth
    assert straighten.lateral_constraint and stop.lateral_constraint
    assert not relax.lateral_constraint and not push.lateral_constraint
    assert p.lateral_constraint_end == stop.end == relax.start
    assert p.speed(stop.end) == pytest.approx(0.0, abs=1e-12)
    assert p.depth(stop.end) == pytest.approx(0.15, rel=1e-12)
    # it rests there for the relax time, released, then the push goes on to the total depth
    assert relax.end - relax.start == pytest.approx(0.1)
    assert p.depth(relax.end) == pytest.approx(0.15, rel=1e-12)
    assert p.depth(p.duration) == pytest.approx(0.40, rel=1e-12)
    assert p.phase_at(relax.start + 0.01).name == "relax"
    assert continuous_push(0.2).lateral_constraint_end is None


@pytest.mark.parametrize("straighten,depth", [(0.239, 0.68), (0.05, 0.08), (0.02, 0.021)])
def test_pushes_too_short_to_finish_their_ramp_still_stop_at_their_depths(straighten, depth):
    """At 0.6 m/s a 0.4 s ramp covers 12 cm speeding up and as much slowing down: a straightening
    push shorter than 24 cm (the RSF sigmoid's 23.9 cm among them) slows down before reaching its
    plateau, and a final push under 12 cm ends still speeding up. Each phase is timed so that the
    profile's own depth, the integral of its speed, is the asked one."""
    p = straighten_relax_push(straighten, depth, speed=0.6, ramp=0.4, relax=0.1)
    straighten_phase, stop, _, push = p.phases
    assert straighten_phase.end < 0.4  # the ramp is not finished
    assert p.speed(stop.end) == pytest.approx(0.0, abs=1e-12)
    assert p.depth(stop.end) == pytest.approx(straighten, rel=1e-12)
    assert p.depth(p.duration) == pytest.approx(depth, rel=1e-12)
    assert _integrated_depth(p, p.duration) == pytest.approx(depth, rel=1e-6)
    short = continuous_push(0.05, speed=0.6, ramp=0.4)
    assert short.duration < 0.4 and short.depth(short.duration) == pytest.approx(0.05, rel=1e-12)


@pytest.mark.parametrize("depth,stop_mm", [(0.05, 10.0), (0.10, 50.0), (0.40, 5.0)])
def test_a_stop_distance_on_a_push_still_speeding_up_comes_to_rest_at_the_depth(depth, stop_mm):
    """A push shorter than its speed ramp (0.6 m/s, 0.4 s: 12 cm) slows to rest over the stop
    distance from the speed it has reached, not from the plateau it never reaches; one long enough
    to reach its plateau before slowing keeps the closed form (0.40 m: the plateau ends
    5 mm / 0.6 m/s before the planned end)."""
    p = continuous_push(depth, speed=0.6, ramp=0.4, stop_distance=stop_mm * 1e-3, settle=0.5)
    push, settle = p.phases
    assert p.depth(p.hold_start) == pytest.approx(depth, rel=1e-12)
    assert p.depth(settle.start) == pytest.approx(depth - stop_mm * 1e-3, rel=1e-12)
    assert p.speed(p.hold_start + 1e-9) == 0.0 and settle.end - p.hold_start == pytest.approx(0.5)
    assert _integrated_depth(p, p.duration) == pytest.approx(depth, rel=1e-6)
    if depth > 0.12 + stop_mm * 1e-3:
        assert push.end == continuous_push(depth, speed=0.6, ramp=0.4).duration - stop_mm * 1e-3 / 0.6
    r = straighten_relax_push(0.02, 0.021 + stop_mm * 1e-3, speed=0.6, ramp=0.4, relax=0.1,
                              stop_distance=stop_mm * 1e-3, settle=0.5)
    assert r.depth(r.hold_start) == pytest.approx(0.021 + stop_mm * 1e-3, rel=1e-12)
    assert p.slow(0.5 * push.end, 0.5)  # a held push keeps the stop distance it slows to rest over
    assert p.depth(p.settle_start) == pytest.approx(depth - stop_mm * 1e-3, rel=1e-12)
    assert p.depth(p.hold_start) == pytest.approx(depth, rel=1e-12)


@pytest.mark.parametrize("args,message", [((-0.1,), "must be positive"), ((0.2, 0.0), "push speed"),
                                          ((0.2, 0.6, -1.0), "ramp")])
def test_bad_profiles(args, message):
    with pytest.raises(ColonsimError, match=message):
        continuous_push(*args)
    with pytest.raises(ColonsimError, match="must lie between 0 and the total depth"):
        straighten_relax_push(0.5, 0.4)


def _integrated_depth(p, t_end):
    t = np.linspace(0.0, t_end, 40001)
    v = np.array([p.speed(x) for x in t])
    return np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(t))


@pytest.mark.parametrize("stop_mm", [0.0, 5.0])
def test_the_held_push_goes_on_at_its_share_to_the_same_depth(stop_mm):
    p = straighten_relax_push(0.20, 0.68, speed=0.3, ramp=0.4, relax=0.1, stop_distance=stop_mm * 1e-3, settle=1.0)
    planned, hold = p.duration, p.phases[-1].end - p.phases[-1].start - p.phases[-1].ramp
    t = p.phases[3].start + 0.8  # in the last push, at its plateau
    assert p.slow(t, 0.5)
    names = [ph.name for ph in p.phases]
    assert names == ["straighten", "stop", "relax", "push", HELD_PUSH, SETTLE]
    held, settle = p.phases[-2], p.phases[-1]
    assert held.start == t and held.speed == pytest.approx(0.15)
    assert p.speed(t) == pytest.approx(0.3) and p.speed(t + 0.4 + 1e-9) == pytest.approx(0.15, rel=1e-9)
    # the closed form: the remaining push at 0.15 m/s after a (1 - cos) ramp from 0.3 (covering 0.09 m)
    remaining = 0.68 - p.depth(t)
    assert settle.start - t == pytest.approx(0.4 + (remaining - stop_mm * 1e-3 - 0.09) / 0.15, rel=1e-9)
    assert p.depth(p.duration) == pytest.approx(0.68, rel=1e-12)
    # depth is the speed's integral (the trapezoids miss up to v dt / 2 = 7.5e-6 m at the stop to rest)
    assert _integrated_depth(p, p.duration) == pytest.approx(0.68, abs=1e-5)
    assert settle.end - settle.start - settle.ramp == pytest.approx(hold)  # the hold at rest is kept
    assert p.speed(settle.end - 1e-9) == 0.0 and p.duration > planned
    assert p.slowed_at == t and not p.slow(t + 0.1, 0.5)  # once only


def test_a_push_that_ends_while_slowing_ends_at_its_depth_and_rests():
    p = continuous_push(0.28, speed=0.3, ramp=0.4, settle=1.0)
    t = p.phases[0].end - 0.1  # 3 cm before the end: shorter than the 9 cm the slowing takes
    assert p.slow(t, 0.5)
    end = p.settle_start
    assert 0.15 < p.speed(end - 1e-9) < 0.3  # still slowing when the depth is reached
    assert p.depth(end) == pytest.approx(0.28, rel=1e-12) and p.speed(end + 1e-9) == 0.0


def test_a_stop_during_a_speed_change_stops_from_the_speed_reached():
    p = continuous_push(0.28, speed=0.3, ramp=0.4, settle=1.0)
    p.slow(0.5, 0.5)
    v = p.speed(0.6)
    assert 0.15 < v < 0.3
    p.stop(0.6, 0.005, 0.5)
    assert p.depth(p.hold_start) == pytest.approx(p.depth(0.6) + 0.005, rel=1e-12)  # slows to rest over 5 mm
    assert p.speed(p.hold_start + 1e-9) == 0.0


@pytest.mark.parametrize("when, share", [("before", 0.5), ("push", 1.0), ("push", 0.0), ("settle", 0.5)])
def test_no_slow_down_outside_the_last_push_or_without_a_share(when, share):
    p = straighten_relax_push(0.20, 0.68, speed=0.3, ramp=0.4, relax=0.1, settle=1.0)
    t = {"before": p.phases[0].start + 0.5, "push": p.phases[3].start + 0.8, "settle": p.phases[-1].start + 0.1}[when]
    phases = list(p.phases)
    assert not p.slow(t, share) and p.phases == phases and p.slowed_at is None


@pytest.mark.parametrize("longer", [0.35, -0.05])
def test_a_relax_retimed_moves_every_later_phase_and_keeps_depths_and_speeds(longer):
    p = straighten_relax_push(0.15, 0.40, speed=0.6, ramp=0.05, relax=0.1, settle=0.2)
    before = [(ph.name, ph.start, ph.end) for ph in p.phases]
    relax = p.phases[2]
    assert p.retime(RELAX, relax.end + longer)
    for (name, start, end), ph in zip(before, p.phases):
        shift = 0.0 if name in ("straighten", "stop") else longer
        assert ph.name == name and ph.end == pytest.approx(end + shift, abs=1e-12)
        assert ph.start == pytest.approx(start + (0.0 if name == "relax" else shift), abs=1e-12)
    # the push after the relax is the same push, later: the same speed and depth at the same time into it
    q = straighten_relax_push(0.15, 0.40, speed=0.6, ramp=0.05, relax=0.1, settle=0.2)
    for tau in (0.0, 0.01, 0.03, 0.2, 0.4):
        t = q.phases[3].start + tau
        assert p.depth(t + longer) == pytest.approx(q.depth(t), rel=1e-12, abs=1e-15)
        assert p.speed(t + longer) == pytest.approx(q.speed(t), rel=1e-12, abs=1e-15)
    assert p.depth(p.duration) == pytest.approx(0.40, rel=1e-12)
    assert p.speed(relax.start + 0.5 * (relax.end - relax.start)) == 0.0


def test_only_a_pause_is_retimed():
    p = straighten_relax_push(0.15, 0.40, speed=0.6, ramp=0.05, relax=0.1)
    assert not p.retime("push", p.duration + 1.0)  # a moving phase
    assert not p.retime(RELAX, p.phases[2].start - 0.01)  # before its own start
    assert not continuous_push(0.2).retime(RELAX, 1.0)  # no relax


def test_a_faster_straightening_reaches_the_same_depths_sooner_and_the_final_push_keeps_its_speed():
    """``straighten_speed``: only the straightening push changes; it still comes to rest at the
    straightening depth, the final push runs at ``speed`` to the same total depth."""
    slow = straighten_relax_push(0.239, 0.68, speed=0.15, ramp=0.4, relax=0.1)
    fast = straighten_relax_push(0.239, 0.68, speed=0.15, ramp=0.4, relax=0.1, straighten_speed=0.3)
    assert fast.phases[0].speed == 0.3 and fast.phases[-1].speed == slow.phases[-1].speed == 0.15
    # 3 cm of speed ramp each way at 0.15 m/s, 6 cm at 0.3 m/s: the plateaus take 1.195 s and 0.397 s
    assert slow.phases[0].end - fast.phases[0].end == pytest.approx(0.179 / 0.15 - 0.119 / 0.3, rel=1e-9)
    for p in (slow, fast):
        assert p.depth(p.lateral_constraint_end) == pytest.approx(0.239, rel=1e-12)
        assert p.depth(p.duration) == pytest.approx(0.68, rel=1e-12)
        assert _integrated_depth(p, p.duration) == pytest.approx(0.68, rel=1e-6)
    assert fast.duration == pytest.approx(slow.duration - (slow.phases[0].end - fast.phases[0].end), rel=1e-12)
    with pytest.raises(ColonsimError, match="push speed"):
        straighten_relax_push(0.239, 0.68, speed=0.15, straighten_speed=0.0)


def test_the_straightening_speed_is_a_setting_of_the_models_that_straighten_only():
    from colonsim.insertion.case.insertion_case import InsertionCase

    # at 1, the default and the runs of before, it stays out of the key
    assert InsertionCase(segment="rsf", straighten_speed_factor=1.0).key() == InsertionCase(segment="rsf").key()
    assert InsertionCase(segment="thf", straighten_speed_factor=2.0).key() != InsertionCase(segment="thf").key()
    assert InsertionCase(segment="rsj", straighten_speed_factor=2.0).key() == InsertionCase(segment="rsj").key()
    with pytest.raises(ColonsimError, match="straighten_speed_factor"):
        InsertionCase(segment="rsf", straighten_speed_factor=0.5).validate()
