"""The quasi-static check of one run: how much the push force rings about its trend, and the
snap-throughs it leaves out (docs/quasi_static.md).

Plain functions of recorded arrays, so they apply equally to a fresh run and to a time series
read back from an older run's folder.
"""

from __future__ import annotations

import numpy as np

from colonsim.insertion.anatomy.manoeuvre import SETTLE
from colonsim.insertion.case.outcomes import depth_trend, depth_weights

RINGING_WINDOW = 0.01  # m of push: the moving average the push force rings about
RINGING_LIMIT = 0.1  # a run whose ringing ratio is below this is quasi-static
# The ringing is measured against max(mean push force, this) (assumption): a tenth of the 1 kg
# (9.8 N) above which endoscopists push only 5 % of the time. A ringing of 0.1 N RMS on the
# 0.2-1.5 N that a run with nothing holding its tip needs is physically nothing.
RINGING_FORCE_FLOOR_N = 1.0
# A snap-through is the push force falling by more than SNAP_DROP_N and by more than
# SNAP_DROP_SHARE of the force before it, within SNAP_DROP_PUSH of push. A ringing whose ratio is
# under the limit cannot make such a drop: a sinusoid of ratio 0.1 falls by at most 0.28 of its
# mean over half a period, and by less within 2 mm unless its period is under 4 mm.
SNAP_DROP_N = 1.0
SNAP_DROP_SHARE = 0.25
SNAP_DROP_PUSH = 2e-3  # m
SNAP_LEFT_OUT_PUSH = 6e-3  # m of push after a snap-through that the ratio leaves out (real dynamics)
# A run that leaves out more than this share of its push is not a run with a few snap-throughs but
# one whose force falls everywhere: it fails the check whatever its ratio.
SNAP_LEFT_OUT_LIMIT = 0.25
GRID_STEP = 2e-4  # m of push: the resampling on which drops and periods are found


def _from_first_contact(depth, push_force, in_contact):
    """Depth and push force from the first sample in contact on (empty arrays without contact)."""
    contact = np.asarray(in_contact, dtype=bool)
    first = int(np.argmax(contact)) if contact.any() else contact.size
    return np.asarray(depth, dtype=float)[first:], np.asarray(push_force, dtype=float)[first:]


def _advancing(z):
    """Samples that advance the push (a pause has one depth: its first sample is kept)."""
    return np.concatenate(([True], np.diff(z) > 0.0))


def snap_throughs(depth, push_force, in_contact, drop_N=SNAP_DROP_N, drop_share=SNAP_DROP_SHARE,
                  drop_push=SNAP_DROP_PUSH, step=GRID_STEP) -> list:
    """The snap-throughs of a run: where the push force, once contact has begun, falls by more than
    ``drop_N`` and more than ``drop_share`` of the force before it within ``drop_push`` of push.

    The force is resampled every ``step`` of push (pauses left out, so a relax at a standing depth
    is no drop); falls closer than ``drop_push`` to each other are one snap-through.

    Returns
    -------
    list of (start, end) push depths, m: where the force began to fall (its largest value within
    ``drop_push`` before the fall was detected) and where it stopped falling steeply.
    """
    z, f = _from_first_contact(depth, push_force, in_contact)
    if z.size < 3 or z[-1] - z[0] <= drop_push:
        return []
    keep = _advancing(z)
    grid = np.arange(z[0], z[-1], step)
    force = np.interp(grid, z[keep], f[keep])
    lag = max(int(round(drop_push / step)), 1)
    if grid.size <= lag:
        return []
    before = force[:-lag]
    fall = before - force[lag:]
    at = np.flatnonzero((fall > drop_N) & (fall > drop_share * np.maximum(before, 0.0))) + lag
    events = []
    for group in np.split(at, np.flatnonzero(np.diff(at) > lag) + 1) if at.size else []:
        first, last = int(group[0]), int(group[-1])
        top = first - lag + int(np.argmax(force[first - lag:first + 1]))
        events.append((float(grid[top]), float(grid[last])))
    return events


def ringing_ratio(depth, push_force, in_contact, window=RINGING_WINDOW, floor_N=RINGING_FORCE_FLOOR_N,
                  snaps=None):
    """How much the push force rings about its trend, once contact has begun (docs/quasi_static.md).

    The push force is a function of the pushed depth in a quasi-static run. Every sample is
    weighted by the depth it stands for (:func:`depth_weights`), so the measure is an integral over
    the push: a pause, when the scope is not advancing (the stop and relax of RSF/THF), weighs
    nothing, and a run sampled at another push speed measures the same thing. The trend is the
    force's depth-weighted mean over ``window`` of push (:func:`depth_trend`), taken separately on
    either side of each snap-through (a moving average across a step would ring where nothing
    does), and the :data:`SNAP_LEFT_OUT_PUSH` after each snap-through is left out.

    Parameters
    ----------
    depth, push_force : (n,) arrays
        Pushed depth (m, non-decreasing) and push force (N) per sample.
    in_contact : (n,) bool array
        Samples with scope-wall contact; the measure starts at the first.
    window : float
        Push distance of the moving average, m (1 cm).
    floor_N : float
        The ratio's denominator is max(mean push force, ``floor_N``), N.
    snaps : list of (start, end) or None
        Snap-throughs (:func:`snap_throughs`, found here when None; ``[]`` leaves nothing out).

    Returns
    -------
    dict with ``ratio`` (RMS about the trend over max(mean, floor); NaN when the push after first
    contact is shorter than the window), ``rms_N``, ``mean_N``, ``push_cm`` (the push distance
    measured), ``snap_throughs`` (their start depths, cm) and ``left_out_share`` (the share of the
    push left out after them).
    """
    z, f = _from_first_contact(depth, push_force, in_contact)
    empty = {"ratio": float("nan"), "rms_N": float("nan"), "mean_N": float("nan"), "push_cm": 0.0,
             "snap_throughs": [], "left_out_share": 0.0}
    if z.size < 3 or z[-1] - z[0] < window:
        return {**empty, "push_cm": float((z[-1] - z[0]) * 100) if z.size else 0.0}
    snaps = snap_throughs(z, f, np.ones(z.size, dtype=bool)) if snaps is None else snaps
    w = depth_weights(z)
    trend = np.empty_like(f)
    cuts = np.searchsorted(z, [start for start, _ in snaps], side="left")
    for part in np.split(np.arange(z.size), cuts):
        if part.size:
            trend[part] = depth_trend(z[part], f[part], window)[0]
    counted = np.ones(z.size, dtype=bool)
    for start, end in snaps:  # from where the force began to fall to 6 mm after it stopped
        counted &= ~((z >= start) & (z <= end + SNAP_LEFT_OUT_PUSH))
    pushed = float(w.sum())
    total = float(w[counted].sum())
    if total <= 0.0:
        return {**empty, "push_cm": 0.0, "snap_throughs": [s * 100 for s, _ in snaps], "left_out_share": 1.0}
    mean = float(np.sum(w[counted] * f[counted]) / total)
    rms = float(np.sqrt(np.sum(w[counted] * (f[counted] - trend[counted]) ** 2) / total))
    return {"ratio": rms / max(mean, floor_N), "rms_N": rms, "mean_N": mean, "push_cm": total * 100,
            "snap_throughs": [s * 100 for s, _ in snaps], "left_out_share": 1.0 - total / pushed}


def push_ringing(phase, depth, push_force, contact_nodes):
    """:func:`ringing_ratio` of a run's recorded samples over its push: the closing settle phase
    (``phase`` :data:`SETTLE`, the scope held still) left out. ``depth`` in m, ``push_force`` in N,
    ``contact_nodes`` the scope-wall contacts per sample."""
    pushing = np.asarray(phase) != SETTLE
    return ringing_ratio(np.asarray(depth, dtype=float)[pushing], np.asarray(push_force, dtype=float)[pushing],
                         np.asarray(contact_nodes)[pushing] > 0)


def ringing_holds(ring) -> bool:
    """The verdict of :func:`ringing_ratio`'s result: the ratio below :data:`RINGING_LIMIT` with no
    more than :data:`SNAP_LEFT_OUT_LIMIT` of the push left out (NaN ratio: does not hold)."""
    return bool(ring["ratio"] < RINGING_LIMIT and ring["left_out_share"] <= SNAP_LEFT_OUT_LIMIT)


def ringing_cause(ring) -> str:
    """Why a ringing verdict fails, in words (empty when it holds)."""
    if ringing_holds(ring):
        return ""
    if not ring["ratio"] == ring["ratio"]:
        return f"too little push after the first contact ({ring['push_cm']:.1f} cm) to measure"
    if ring["left_out_share"] > SNAP_LEFT_OUT_LIMIT:
        return (f"{len(ring['snap_throughs'])} drops of the push force leave out {ring['left_out_share']:.0%} of the "
                f"push (more than {SNAP_LEFT_OUT_LIMIT:.0%}): the force falls everywhere, not at a few snap-throughs")
    return (f"the push force rings {ring['rms_N']:.2f} N RMS about its trend on a mean of {ring['mean_N']:.2f} N "
            f"(ratio {ring['ratio']:.3f} over max(mean, {RINGING_FORCE_FLOOR_N:g} N))")


def ringing_wavelength(depth, push_force, in_contact, window=RINGING_WINDOW, step=GRID_STEP):
    """The push distance over which the push force's ringing repeats most strongly (m).

    The ringing (:func:`ringing_ratio`: the force about its trend over ``window`` of push, from
    the first contact) resampled every ``step`` of push, pauses left out, and the peak of its
    periodogram (Hann-windowed) among periods shorter than ``window``. A remainder tied to the
    discretisation shows here as a fixed push distance whatever the push speed: the scope passing
    over the wall's nodes repeats every one or two rings of the wall mesh (docs/model.md, "Time
    integration and damping").

    Returns NaN when under two windows of push were measured after the first contact.
    """
    measured = _on_push_grid(depth, push_force, in_contact, window, step)
    if measured is None:
        return float("nan")
    grid, _, residual = measured
    residual = (residual - residual.mean()) * np.hanning(grid.size)
    power = np.abs(np.fft.rfft(residual)) ** 2
    frequency = np.fft.rfftfreq(grid.size, step)  # cycles per m of push
    shorter = frequency > 1.0 / window
    if not shorter.any():
        return float("nan")
    return float(1.0 / frequency[shorter][np.argmax(power[shorter])])


def _on_push_grid(depth, push_force, in_contact, window, step):
    """The push force after the first contact and its ringing about the trend over ``window``
    (:func:`ringing_ratio`) resampled every ``step`` of push, pauses left out: the grid (m), the
    force and the ringing (N); None when under two windows of push were measured."""
    z, f = _from_first_contact(depth, push_force, in_contact)
    if z.size < 3 or z[-1] - z[0] < 2.0 * window:
        return None
    trend, _ = depth_trend(z, f, window)
    advancing = _advancing(z)
    grid = np.arange(z[0], z[-1], step)
    return grid, np.interp(grid, z[advancing], f[advancing]), np.interp(grid, z[advancing], (f - trend)[advancing])


def ringing_at_drops(depth, push_force, in_contact, window=RINGING_WINDOW, drop_N=1.0, drop_push=2e-3,
                     near=6e-3, step=GRID_STEP):
    """How much of the ringing (:func:`ringing_ratio`) sits at sudden drops of the push force.

    A loop that snaps through drops the push force by newtons within a millimetre or two of push:
    a step in a force that is otherwise a function of the depth, which the moving average turns
    into RMS on either side of it without anything oscillating. Here a drop is the force falling
    by more than ``drop_N`` over ``drop_push`` of push (on the force resampled every ``step``,
    pauses left out); ``share`` is the fraction of the squared ringing within ``near`` of push of
    a drop, ``push_share`` the fraction of the push that lies there, ``drops`` the number of
    separate drops (closer than ``drop_push`` counts as one). An oscillation of the push force
    about its trend gives a share near ``push_share``; ringing made of steps, a share near 1.

    Returns NaN values (``drops`` 0) when under two windows of push were measured after the
    first contact.
    """
    measured = _on_push_grid(depth, push_force, in_contact, window, step)
    if measured is None:
        return {"share": float("nan"), "push_share": float("nan"), "drops": 0}
    grid, force, residual = measured
    lag = max(int(round(drop_push / step)), 1)
    dropping = np.zeros(grid.size, dtype=bool)
    dropping[lag:] = force[:-lag] - force[lag:] > drop_N
    reach = int(round(near / step))
    around = np.convolve(dropping, np.ones(2 * reach + 1), mode="same") > 0.0
    at = np.flatnonzero(dropping)
    drops = int(at.size > 0) + int(np.sum(np.diff(at) > lag))
    total = float(np.sum(residual**2))
    share = float(np.sum(residual[around] ** 2) / total) if total > 0.0 else float("nan")
    return {"share": share, "push_share": float(np.mean(around)), "drops": drops}


