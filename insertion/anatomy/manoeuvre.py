"""The insertion manoeuvre (docs/model.md, "Loading"): a smooth push-speed profile and its phases.

The proximal end of the scope is driven at a prescribed speed along the sheath axis. The speed
profile is piecewise constant with (1 - cos) transitions of duration ``ramp`` between levels, so
the scope is never jerked (a step in speed launches an axial wave of amplitude rho c A dv).

- RSJ: one continuous push.
- RSF, THF (**assumption** on the exact profile): push with the mobile part's lateral motion
  constrained until the pushed depth reaches the end of the mobile part ("straighten", "stop"),
  let the system relax at rest with the constraint released ("birth and death"), then push on
  through the flexure.
- Behind a held tip ("held push"): once the colon beyond the model holds the tip back, the push
  goes on at a share of its speed (:meth:`PushProfile.slow`) to the same depth: the scope bowing
  into a loop behind a held tip is the slowest part of an insertion.
- Every run ends at rest ("settle"): the push slows to a stop over a given push distance and the
  scope is held still for a settling time, so the final state is an equilibrium at the final
  depth, not a snapshot of the motion. A run that ends before its planned depth because the tip
  passed the end stops so from where it is (:meth:`PushProfile.stop`); a jam ends at once, under
  its load.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from colonsim.errors import ColonsimError


@dataclass(frozen=True)
class Phase:
    """One phase of the manoeuvre: a time window, s, and the push speed at its plateau, m/s."""

    name: str
    start: float
    end: float
    speed: float
    lateral_constraint: bool = False
    ramp: float | None = None  # s: this phase's speed change (None: the profile's ramp)


def _transition(tau, ramp):
    """Smooth 0 -> 1 over [0, ramp] ((1 - cos) / 2) and its integral."""
    if tau <= 0.0:
        return 0.0, 0.0
    if tau >= ramp:
        return 1.0, tau - 0.5 * ramp
    w = math.pi / ramp
    return 0.5 * (1.0 - math.cos(w * tau)), 0.5 * (tau - math.sin(w * tau) / w)


@dataclass
class PushProfile:
    """Push speed against time built from phases; speed changes take ``ramp`` seconds.

    Each phase starts from the speed and depth the previous one ended at and changes its speed to
    its own over ``ramp`` (or its own ``Phase.ramp``) from its start; a phase that ends before
    its change is complete hands on the speed it has reached.
    """

    phases: list
    ramp: float
    _starts: list = field(init=False, repr=False)
    slowed_at: float | None = field(default=None, init=False)  # s: when :meth:`slow` took effect

    def __post_init__(self):
        if self.ramp < 0:
            raise ColonsimError(f"ramp = {self.ramp} s must be >= 0")
        self._starts = []  # per phase: start time, speed and depth at the start, plateau speed, ramp
        v = d = 0.0
        for p in self.phases:
            ramp = self.ramp_of(p)
            self._starts.append((p.start, v, d, p.speed, ramp))
            s, integral = _transition(p.end - p.start, ramp)
            v, d = v + (p.speed - v) * s, d + v * (p.end - p.start) + (p.speed - v) * integral

    @property
    def duration(self):
        return self.phases[-1].end

    def _at(self, t):
        k = 0
        while k + 1 < len(self._starts) and self._starts[k + 1][0] <= t:
            k += 1
        return self._starts[k]

    def speed(self, t):
        """Push speed at time ``t``, m/s."""
        t0, v0, _, speed, ramp = self._at(t)
        return v0 + (speed - v0) * _transition(t - t0, ramp)[0]

    def depth(self, t):
        """Insertion depth (distance pushed) at time ``t``, m."""
        t0, v0, d0, speed, ramp = self._at(t)
        return d0 + v0 * max(t - t0, 0.0) + (speed - v0) * _transition(t - t0, ramp)[1]

    @property
    def settle_start(self):
        """Start of the closing ``settle`` phase, s (None: the profile does not end at rest)."""
        last = self.phases[-1]
        return last.start if last.name == SETTLE else None

    @property
    def last_push(self):
        """The last phase before the closing ``settle`` (it moves later if a pause is retimed)."""
        return [p for p in self.phases if p.name != SETTLE][-1]

    def ramp_of(self, phase):
        """The speed ramp into ``phase``, s (the profile's own unless the phase sets one)."""
        return self.ramp if phase.ramp is None else phase.ramp

    @property
    def hold_start(self):
        """Time the push has come to rest and the closing hold begins, s (None: no settle phase)."""
        start = self.settle_start
        return None if start is None else start + self.ramp_of(self.phases[-1])

    def stop(self, t, distance, hold):
        """End the push from time ``t``: slow to rest over ``distance`` (m) of push and hold still
        for ``hold`` seconds (the ``settle`` phase); later phases are dropped."""
        if self.settle_start is not None and self.settle_start <= t:
            return
        kept = [p for p in self.phases if p.start <= t]
        kept[-1] = Phase(kept[-1].name, kept[-1].start, t, kept[-1].speed, kept[-1].lateral_constraint, kept[-1].ramp)
        v = self.speed(t)
        ramp = 2.0 * distance / v if v > 0.0 else 0.0
        self.phases = kept + [Phase(SETTLE, t, t + ramp + hold, 0.0, ramp=ramp)]
        self.__post_init__()

    def slow(self, t, share) -> bool:
        """From time ``t``, push at ``share`` of the current plateau speed to the same final depth
        (the ``held push`` phase, its speed reached over the profile's ramp; a push that ends
        sooner ends still slowing). A closing ``settle`` phase keeps its stop distance and hold.
        Only once and only during the last push; returns whether the profile changed."""
        last = self.last_push
        if (self.slowed_at is not None or not 0.0 < share < 1.0 or not last.start <= t < last.end
                or last.speed <= 0.0):
            return False
        if not self._push_on_at(t, share * last.speed):
            return False
        self.slowed_at = t
        return True

    def change_speed(self, t, speed) -> bool:
        """From time ``t`` within the held push, push at ``speed`` (m/s) to the same final depth: a
        new ``held push`` plateau, reached over the profile's ramp (the loading-following held push,
        ``held_push_pace``; docs/model.md, "Distal resistance"). A closing ``settle`` phase keeps
        its stop distance and hold. Only after :meth:`slow`; returns whether the profile changed."""
        last = self.last_push
        if (self.slowed_at is None or last.name != HELD_PUSH or not last.start <= t < last.end
                or not speed > 0.0 or speed == last.speed):
            return False
        return self._push_on_at(t, speed)

    def _push_on_at(self, t, speed) -> bool:
        """Replace the last push from time ``t`` by a ``held push`` at ``speed`` to the same final
        depth (:meth:`slow`, :meth:`change_speed`); False when it has no depth left to push."""
        last = self.last_push
        settle = self.phases[-1] if self.phases[-1].name == SETTLE else None
        # the slowing to rest covers half its ramp times the speed it starts from
        stop_distance = 0.5 * settle.ramp * self.speed(settle.start) if settle is not None else 0.0
        hold = settle.end - settle.start - settle.ramp if settle is not None else 0.0
        goal = self.depth(self.duration) - stop_distance  # where the slowing to rest begins
        before = self.phases[:-1] if settle is not None else list(self.phases)
        before[-1] = Phase(last.name, last.start, t, last.speed, last.lateral_constraint, last.ramp)
        trial = PushProfile(before + [Phase(HELD_PUSH, t, math.inf, speed)], self.ramp)
        if goal <= trial.depth(t):
            return False
        # depth rises monotonically; slowing from the plateau the speed stays above the new one, so
        # the bracket holds at once; a push speeding up (or still ramping) may need a wider one
        hi = t + (goal - trial.depth(t)) / speed
        while trial.depth(hi) < goal:
            hi = t + 2.0 * (hi - t)
        end = _solve_time(trial.depth, goal, t, hi)
        phases = before + [Phase(HELD_PUSH, t, end, speed)]
        if settle is not None:
            v = trial.speed(end)
            ramp = 2.0 * stop_distance / v
            phases.append(Phase(SETTLE, end, end + ramp + hold, 0.0, ramp=ramp))
        self.phases = phases
        self.__post_init__()
        return True

    def retime(self, name, end) -> bool:
        """Let the pause ``name`` (a phase at rest: the ``relax``) end at ``end`` (s), later or
        sooner than planned; every later phase moves by as much, at the same depths and speeds.
        Returns whether the profile changed (not for a phase that moves)."""
        k = next((i for i, p in enumerate(self.phases) if p.name == name), None)
        if k is None or self.phases[k].speed != 0.0 or self._starts[k][1] != 0.0 or end < self.phases[k].start:
            return False
        shift = end - self.phases[k].end
        self.phases = (self.phases[:k] + [replace(self.phases[k], end=end)]
                       + [replace(p, start=p.start + shift, end=p.end + shift) for p in self.phases[k + 1:]])
        self.__post_init__()
        return True

    @property
    def lateral_constraint_end(self):
        """End of the last phase that holds the mobile part laterally, s (None: no such phase)."""
        ends = [p.end for p in self.phases if p.lateral_constraint]
        return ends[-1] if ends else None

    def phase_at(self, t):
        for p in self.phases:
            if p.start <= t < p.end:
                return p
        return self.phases[-1]


SETTLE = "settle"
HELD_PUSH = "held push"
RELAX = "relax"


def _settle(phases, speed, ramp, stop_distance, settle):
    """``phases`` of a push ending at speed, plus a ``settle`` phase slowing to rest over
    ``stop_distance`` (m) and holding for ``settle`` s; unchanged when both are 0.

    The last push ends where its own depth is ``stop_distance`` short of its planned end, and the
    slow-down starts from the speed reached there: on the plateau that is ``stop_distance / speed``
    before its planned end; a push still speeding up is timed on the profile's depth (bisection)."""
    if settle <= 0.0 and stop_distance <= 0.0:
        return phases
    if not (np.isfinite(settle) and settle >= 0.0 and np.isfinite(stop_distance) and stop_distance >= 0.0):
        raise ColonsimError(f"settle time {settle!r} s and stop distance {stop_distance!r} m must be >= 0")
    last = phases[-1]
    planned = PushProfile(phases, ramp)
    end = last.end - stop_distance / speed  # where slowing down from the plateau covers the stop distance
    reached = speed
    if stop_distance > 0.0 and end < last.start + planned.ramp_of(last):
        goal = planned.depth(last.end) - stop_distance
        if goal <= planned.depth(last.start):
            end = last.start
        else:
            end = _solve_time(planned.depth, goal, last.start, last.end)
            reached = planned.speed(end)
    if end <= last.start:
        raise ColonsimError(f"the stop distance {stop_distance:g} m is longer than the last push; shorten it")
    slow_down = 2.0 * stop_distance / reached
    return phases[:-1] + [Phase(last.name, last.start, end, last.speed, last.lateral_constraint, last.ramp),
                          Phase(SETTLE, end, end + slow_down + settle, 0.0, ramp=slow_down)]


def _solve_time(covered, distance, lo, hi):
    """The time in [lo, hi] at which ``covered(t)`` (increasing) reaches ``distance``: bisection
    to the last bit (the held push's end, and the pushes too short to finish their speed ramp)."""
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if covered(mid) < distance else (lo, mid)
    return hi


def _time_to_push(distance, speed, ramp):
    """Time for a push from rest to cover ``distance``: the ramp covers speed * ramp / 2, then the
    plateau the rest; a shorter push ends still speeding up, where the ramp's integral reaches it."""
    if distance >= 0.5 * speed * ramp:
        return 0.5 * ramp + distance / speed
    return _solve_time(lambda t: speed * _transition(t, ramp)[1], distance, 0.0, ramp)


def _time_to_stop_at(distance, speed, ramp):
    """End of a push from rest that, slowed to rest over the next ``ramp`` seconds, comes to rest
    at ``distance``: speeding up and slowing down each cover speed * ramp / 2 after a full ramp; a
    push too short to finish its ramp slows down from the speed it has reached."""
    if distance >= speed * ramp:
        return _time_to_push(distance, speed, ramp) - 0.5 * ramp

    def at_rest(t):
        reached, integral = _transition(t, ramp)
        return speed * (integral + 0.5 * reached * ramp)

    return _solve_time(at_rest, distance, 0.0, ramp)


def continuous_push(depth, speed=0.6, ramp=0.05, stop_distance=0.0, settle=0.0) -> PushProfile:
    """RSJ: push from rest to ``depth`` (m) at ``speed`` (m/s), starting with a ramp (s); with a
    ``stop_distance`` (m) or ``settle`` time (s), the push comes to rest at ``depth`` and holds."""
    _check(depth, speed, ramp)
    phases = [Phase("push", 0.0, _time_to_push(depth, speed, ramp), speed)]
    return PushProfile(_settle(phases, speed, ramp, stop_distance, settle), ramp)


def straighten_relax_push(straighten_depth, depth, speed=0.6, ramp=0.05, relax=0.1, stop_distance=0.0,
                          settle=0.0, straighten_speed=None) -> PushProfile:
    """RSF/THF: push to ``straighten_depth`` with the lateral constraint (at ``straighten_speed``,
    m/s; None: ``speed``), slow to a stop there with it still on, relax for ``relax`` seconds with
    it released, then push on to ``depth`` (m) at ``speed`` (coming to rest there and holding, as
    :func:`continuous_push`).

    Phases: ``straighten`` (at speed) and ``stop`` (the slow-down ramp, ending at rest at
    ``straighten_depth``) hold the mobile part (``lateral_constraint``); ``relax`` and ``push`` do not.
    """
    _check(depth, speed, ramp)
    straighten_speed = speed if straighten_speed is None else straighten_speed
    _check(depth, straighten_speed, ramp)
    if not 0.0 < straighten_depth < depth:
        raise ColonsimError(f"straightening depth {straighten_depth:.3g} m must lie between 0 and the total depth {depth:.3g} m")
    if not (np.isfinite(relax) and relax > 0.0):
        raise ColonsimError(f"relax time {relax!r} s must be positive (the scope must come to rest)")
    t1 = _time_to_stop_at(straighten_depth, straighten_speed, ramp)
    t2 = t1 + ramp
    t3 = t2 + relax
    t4 = t3 + _time_to_push(depth - straighten_depth, speed, ramp)
    phases = [Phase("straighten", 0.0, t1, straighten_speed, lateral_constraint=True),
              Phase("stop", t1, t2, 0.0, lateral_constraint=True),
              Phase(RELAX, t2, t3, 0.0),
              Phase("push", t3, t4, speed)]
    return PushProfile(_settle(phases, speed, ramp, stop_distance, settle), ramp)


def _check(depth, speed, ramp):
    if not (np.isfinite(depth) and depth > 0):
        raise ColonsimError(f"insertion depth {depth!r} m must be positive")
    if not (np.isfinite(speed) and 0 < speed <= 5.0):
        raise ColonsimError(f"push speed {speed!r} m/s must lie in (0, 5] (the source pushed at 0.6 m/s)")
    if not (np.isfinite(ramp) and ramp >= 0):
        raise ColonsimError(f"ramp {ramp!r} s must be >= 0")
