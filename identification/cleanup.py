"""Cleaning a test curve before the fit: slack or preload, and decimation, recorded in provenance.

**Where the load starts.** A strip mounted slack carries no force until its grips have taken up
the slack ``d0``; one mounted under preload already carries force at zero displacement. Either way
the specimen's unloaded state is not the recorded zero. With the load start ``d0`` (found from the
data or given) the curve is re-referenced: ``d' = d - d0``, free length ``L' = L + d0``, the
points before ``d0`` dropped (slack) or the origin ``(0, 0)`` added (preload, ``d0 < 0``).

- A **slack region** is found when the curve starts with at least :data:`MIN_FLAT_SAMPLES`
  samples, over at least :data:`MIN_FLAT_SHARE` of the displacement range, whose force stays
  within 3 noise sd of zero and shows no trend (the means of its two halves differ by less than
  three standard errors); ``d0`` is where the straight line through the rise that follows (force
  from 3 to 10 noise sd) reaches zero force. A rising toe, however small its force, has a trend
  and is not slack. A slack region found is corrected, and said so.
- A **preload** is found (never corrected unless asked) when the first force exceeds 5 noise sd:
  ``d0`` is where the straight line through the first 5 % of the displacement range reaches zero
  force. The line misses the stiffening before the record starts: on the reference wall
  (strips of 100 mm, noise 0.05 N) it lands 0.3 mm short of a 4 mm preload and 2 mm short of an
  8 mm one (measured, tests/test_calibration_cleanup.py); give ``--load-start MM`` when the load
  start is known.

**Decimation** resamples a curve at evenly spaced stretches (or displacements) by linear
interpolation, for dense records whose points would otherwise weigh by sampling density.

Nothing is cleaned unless asked, except a slack region found; every step goes into the curve's
``meta["cleaning"]`` and so into ``material.json``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.identification.diagnostics import noise_sd
from colonsim.identification.testdata import TensileCurve

MIN_FLAT_SAMPLES = 10
MIN_FLAT_SHARE = 0.02
PRELOAD_SD = 5.0
FLAT_SD = 3.0


def find_slack(displacement, force):
    """The load start d0 (m) of a slack region at the start of the curve, or None."""
    d, f = np.asarray(displacement, dtype=float), np.asarray(force, dtype=float)
    sd = noise_sd(d, f)
    above = np.flatnonzero(np.abs(f) > FLAT_SD * sd)
    end = int(above[0]) if above.size else d.size
    if end < MIN_FLAT_SAMPLES or d[end - 1] - d[0] < MIN_FLAT_SHARE * (d[-1] - d[0]):
        return None
    half = end // 2
    trend = abs(np.mean(f[half:end]) - np.mean(f[:half]))
    if trend > 3.0 * sd * np.sqrt(1.0 / half + 1.0 / (end - half)):
        return None
    # the rise through 3-10 noise sd, extended back to zero force: where the load starts
    rise = np.flatnonzero((np.arange(d.size) >= end) & (f <= 10.0 * sd))
    rise = rise[rise < (rise[0] + np.argmax(np.diff(rise) > 1) + 1 if np.any(np.diff(rise) > 1) else d.size)]
    if rise.size >= 3:
        slope, intercept = np.polyfit(d[rise], f[rise], 1)
        if slope > 0:
            return float(np.clip(-intercept / slope, d[0], d[end]))
    return float(d[end - 1])


def find_preload(displacement, force):
    """The load start d0 (m, below the first displacement) of a preloaded curve, or None."""
    d, f = np.asarray(displacement, dtype=float), np.asarray(force, dtype=float)
    if f[0] <= PRELOAD_SD * noise_sd(d, f):
        return None
    early = d <= d[0] + 0.05 * (d[-1] - d[0])
    if early.sum() < 3:
        early = np.arange(d.size) < 3
    slope, intercept = np.polyfit(d[early], f[early], 1)
    if slope <= 0:
        return None
    return float(-intercept / slope)


def shift_load_start(curve: TensileCurve, d0, how) -> TensileCurve:
    """``curve`` re-referenced to the load start ``d0`` (m; see the module)."""
    d0 = float(d0)
    if not np.isfinite(d0) or d0 >= curve.max_displacement or curve.length + d0 <= 0:
        raise ColonsimError(f"{curve.name}: load start {d0 * 1e3:g} mm is outside the curve "
                            f"({curve.displacement[0] * 1e3:g}-{curve.max_displacement * 1e3:g} mm); give one inside it")
    keep = curve.displacement > d0
    d, f = curve.displacement[keep] - d0, curve.force[keep]
    if d0 < curve.displacement[0]:  # preload: the unloaded state lies before the record
        d, f = np.concatenate([[0.0], d]), np.concatenate([[0.0], f])
    step = {"step": "load start", "how": how, "load_start_mm": d0 * 1e3, "length_mm_before": curve.length * 1e3,
            "length_mm_after": (curve.length + d0) * 1e3, "points_dropped": int((~keep).sum())}
    return replace(curve, displacement=d, force=f, length=curve.length + d0,
                   meta={**curve.meta, "cleaning": [*curve.meta.get("cleaning", []), step]})


def check_decimation(name, n, points):
    """Refuse resampling a curve of ``points`` points at ``n``: fewer than 5, or more than it holds
    (the extra points would be invented by interpolation)."""
    if n < 5:
        raise ColonsimError(f"--decimate {n}: keep at least 5 points")
    if n > points:
        raise ColonsimError(f"--decimate {n} is more than the {points} points of {name}: the extra points would be "
                            f"invented by interpolation; give at most {points}")


def decimate(curve: TensileCurve, n) -> TensileCurve:
    """``curve`` resampled at ``n`` evenly spaced displacements over its range."""
    check_decimation(curve.name, n, curve.displacement.size)
    grid = np.linspace(curve.displacement[0], curve.max_displacement, int(n))
    step = {"step": "decimation", "points_before": int(curve.displacement.size), "points_after": int(n),
            "how": "linear interpolation at evenly spaced displacements"}
    return replace(curve, displacement=grid, force=np.interp(grid, curve.displacement, curve.force),
                   meta={**curve.meta, "cleaning": [*curve.meta.get("cleaning", []), step]})


def clean(curve: TensileCurve, load_start=None, decimate_to=None) -> tuple[TensileCurve, list[str]]:
    """Apply the asked cleaning to ``curve``; return it and one note per step taken or found.

    ``load_start``: None (correct a slack region if one is found, report a preload), ``"detect"``
    (correct slack or preload found), ``"off"`` (nothing) or a displacement in m.
    """
    notes = []
    if isinstance(load_start, (int, float)) and not isinstance(load_start, bool):
        curve = shift_load_start(curve, load_start, "given")
        notes.append(f"{curve.name}: load start {load_start * 1e3:g} mm given: displacement re-referenced, free length "
                     f"{curve.length * 1e3:g} mm")
    elif load_start != "off":
        slack = find_slack(curve.displacement, curve.force)
        preload = find_preload(curve.displacement, curve.force) if slack is None else None
        if slack is not None:
            curve = shift_load_start(curve, slack, "slack region found in the data")
            notes.append(f"{curve.name}: slack region found: the load starts at {slack * 1e3:.3g} mm; displacement "
                         f"re-referenced there, free length {curve.length * 1e3:.4g} mm (--load-start off keeps the raw curve)")
        elif preload is not None and load_start == "detect":
            curve = shift_load_start(curve, preload, "preload found in the data")
            notes.append(f"{curve.name}: preload found: the load starts at {preload * 1e3:.3g} mm; curve re-referenced, "
                         f"free length {curve.length * 1e3:.4g} mm")
        elif preload is not None:
            notes.append(f"{curve.name}: the curve starts under load ({curve.force[0]:.3g} N, the unloaded state lies near "
                         f"{preload * 1e3:.3g} mm); not corrected: --load-start detect corrects it")
    if decimate_to is not None:
        curve = decimate(curve, decimate_to)
        notes.append(f"{curve.name}: decimated to {decimate_to} evenly spaced points")
    return curve, notes


def figure(pairs):
    """Raw and cleaned force-displacement curves in one figure; ``pairs`` = [(raw, cleaned), ...]."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(6.5, 4.2))
    ax = fig.subplots()
    for raw, cleaned in pairs:
        line, = ax.plot(raw.displacement * 1e3, raw.force, "-", lw=0.8, alpha=0.5, label=f"{raw.name} raw")
        ax.plot(cleaned.displacement * 1e3, cleaned.force, "-", lw=1.4, c=line.get_color(), label=f"{raw.name} cleaned")
    ax.set_xlabel("grip displacement [mm] (cleaned: from the load start)")
    ax.set_ylabel("force [N]")
    ax.legend(fontsize=7)
    ax.set_title("test curves before and after cleaning", fontsize=9)
    return fig


def clean_curves(curves, load_start=None, decimate_to=None):
    """:func:`clean` over several curves: (cleaned curves, notes, [(raw, cleaned)] of those changed)."""
    out, notes, changed = [], [], []
    for c in curves:
        cleaned, n = clean(c, load_start, decimate_to)
        out.append(cleaned)
        notes += n
        if cleaned is not c:
            changed.append((c, cleaned))
    return out, notes, changed
