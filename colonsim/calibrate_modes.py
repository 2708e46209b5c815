"""The console workflow of a multi-mode calibration: ``colonsim calibrate`` with a mode manifest
(a ``mode`` column) or ``--curve FILE --mode MODE``. Reads the curves, fits one law or every law
(``--compare-laws``) jointly, prints per-curve R^2 and RMS, the parameters with their uncertainty
and the Drucker check, and writes the folder of :mod:`colonsim.identification.joint_report`.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

from colonsim.errors import ColonsimError


@dataclass(frozen=True)
class ModeRequest:
    """What to fit (the ``calibrate`` options a multi-mode fit uses)."""

    manifest: Path | None = None
    curve: Path | None = None
    mode: str | None = None
    stress_measure: str | None = None
    law: str | None = None
    compare_laws: bool = False
    residuals: str = "relative"
    stability_range: tuple | None = None
    analytic: bool = False
    mesh: tuple = (8, 3)
    quick: bool = False
    budget: object = None  # a search Budget for every fit; None: quick's or the model's default
    modes: tuple | None = None  # fit only the curves of these test modes; None: every curve
    seed: int = 1
    displacement_unit: str | None = None
    force_unit: str | None = None
    load_start: object = None
    decimate: int | None = None


def wants_modes(manifest, curve, mode) -> bool:
    """Whether the calibrate options ask for the multi-mode workflow."""
    if mode is not None:
        return True
    if manifest is None or not Path(manifest).is_file():
        return False
    from colonsim.identification.export_layout import read_text

    text, _ = read_text(manifest)
    header = next((r for r in text.splitlines() if r.strip() and not r.lstrip().startswith("#")), "")
    return "mode" in [c.strip() for c in header.split(",")]


def _curves(request: ModeRequest):
    from colonsim.identification.stress_curves import read_mode_manifest, read_stress_curve

    if request.curve and request.manifest:
        raise ColonsimError("give either --curve or --manifest, not both")
    if request.curve:
        if request.mode is None:
            raise ColonsimError(f"{request.curve}: give its test mode with --mode (uniaxial, equibiaxial, planar)")
        return [read_stress_curve(request.curve, request.mode, stress_measure=request.stress_measure)]
    if request.mode is not None:
        raise ColonsimError("--mode goes with --curve; a mode manifest has its own mode column")
    curves = read_mode_manifest(request.manifest, request.stress_measure, request.displacement_unit, request.force_unit)
    if request.modes is None:
        return curves
    chosen = [c for c in curves if c.mode in request.modes]
    if not chosen:
        raise ColonsimError(f"{request.manifest} has no curve in mode {', '.join(request.modes)}; "
                            f"its modes: {', '.join(sorted({c.mode for c in curves}))}")
    return chosen


def _clean(curves, request, out):
    """Strips cleaned as :func:`colonsim.identification.cleanup.clean` says (the load start is a
    displacement: strips only); stress-stretch curves decimated at evenly spaced stretches."""
    from dataclasses import replace

    import numpy as np

    from colonsim.files import save_figure
    from colonsim.identification.cleanup import check_decimation, clean_curves, figure
    from colonsim.identification.stress_curves import from_strip

    load_start = request.load_start * 1e-3 if isinstance(request.load_start, (int, float)) else request.load_start
    strips = [c.strip for c in curves if c.strip is not None]
    cleaned, notes, changed = clean_curves(strips, load_start, request.decimate)
    by_name = {c.name: c for c in cleaned}
    out_curves = []
    for c in curves:
        if c.strip is not None:
            out_curves.append(from_strip(by_name[c.name], c.weight))
        elif request.decimate is not None:
            check_decimation(c.name, request.decimate, c.stretch.size)
            grid = np.linspace(c.stretch[0], c.max_stretch, request.decimate)
            step = {"step": "decimation", "points_before": int(c.stretch.size), "points_after": request.decimate,
                    "how": "linear interpolation at evenly spaced stretches"}
            out_curves.append(replace(c, stretch=grid, stress=np.interp(grid, c.stretch, c.stress),
                                      meta={**c.meta, "cleaning": [step]}))
            notes.append(f"{c.name}: decimated to {request.decimate} evenly spaced stretches")
        else:
            out_curves.append(c)
    for note in notes:
        print(note, flush=True)
    if changed:
        save_figure(figure(changed), Path(out) / "cleaning.png")
    return out_curves


def _describe(r) -> str:
    from colonsim.identification.hyperelastic import calibration_law

    law = calibration_law(r.law)
    sd, ci = r.uncertainty.std, r.uncertainty.interval()
    lines = [f"{r.law}: joint fit of {len(r.curves)} curve(s), {r.fit['residuals']} residuals, "
             f"{r.fit['evaluations']} evaluations in {r.fit['wall_time_s']:.1f} s"]
    for i, (n, unit) in enumerate(zip(law.parameter_names, law.units)):
        shown = "-" if unit == "1" else unit  # Ogden's exponents are dimensionless
        lines.append(f"  {n:>6} = {r.parameters[i]:14.6g} {shown:<2}  sd {sd[i]:.3g}   95% [{ci[i, 0]:.6g}, {ci[i, 1]:.6g}]")
    if r.uncertainty.unidentified_words():
        lines.append(f"  {r.uncertainty.unidentified_words()}")
    mu0, mu0_sd = r.mu0
    unidentified = "" if math.isfinite(mu0_sd) else " (not identified: it has a share in the combination above)"
    lines.append(f"  mu0 = {mu0:.6g} Pa, sd {mu0_sd:.3g}{unidentified}")
    for _, row in r.per_curve.iterrows():
        r2 = "-" if row["r2"] is None else f"{row['r2']:.4f}"
        lines.append(f"  {row['curve']:<24} {row['mode']:<11} weight {row['weight']:g}: R^2 {r2}, RMS {row['rms_Pa'] / 1e3:.4g} kPa "
                     f"= {row['rms_over_noise']:.1f} x noise ({row['n_points']} points, to stretch {row['max_stretch']:.3g})")
    lo, hi = r.stability.stretch_range
    lines.append(f"  Drucker stability over stretch {lo:.3g}-{hi:.3g} in {', '.join(r.stability.onsets)}: "
                 f"{'stable' if r.stability.is_stable else 'UNSTABLE'}")
    return "\n".join(lines)


def calibrate_modes(request: ModeRequest, out: Path) -> list:
    """Fit, print, write; return the results (the chosen law's first with --compare-laws)."""
    from colonsim.files import check_output_folder
    from colonsim.identification.hyperelastic import CALIBRATION_LAWS, calibration_law
    from colonsim.identification.joint import UnsolvableNearFit, calibrate_joint
    from colonsim.identification.joint_report import write_comparison, write_joint
    from colonsim.identification.search import Budget
    from colonsim.laws import DEFAULT_LAW

    check_output_folder(out)
    if request.compare_laws and request.law is not None:
        raise ColonsimError(f"--compare-laws fits every law; drop --law {request.law}")
    law = request.law or DEFAULT_LAW
    calibration_law(law)
    if request.stability_range is not None and not (0 < request.stability_range[0] < 1 < request.stability_range[1]):
        lo, hi = request.stability_range
        raise ColonsimError(f"--stability-range {lo:g} {hi:g}: it must run from below 1 to above 1 (e.g. 0.5 4)")
    curves = _clean(_curves(request), request, out)
    strip_model = "fe" if (not request.analytic and any(c.strip is not None for c in curves)) else "closed-form"
    budget = request.budget or ((Budget.quick() if request.quick else Budget()) if strip_model == "fe" else None)
    options = dict(residuals=request.residuals, budget=budget, seed=request.seed,
                   stability_range=request.stability_range, strip_model=strip_model, mesh=request.mesh)
    print(f"fitting {len(curves)} curve(s) jointly: " + ", ".join(f"{c.name} ({c.mode})" for c in curves), flush=True)
    if request.compare_laws:
        results = {}
        for name in CALIBRATION_LAWS:
            try:
                results[name] = calibrate_joint(curves, name, **options)
            except UnsolvableNearFit as exc:
                print(f"{name} left out: {exc}", flush=True)
        written = write_comparison(results, out)
        modes = {f"r2_{c.name}": f"R2 {c.mode}" for c in curves}
        shown = written["table"].set_index("law")[["drucker_stable", "first_unstable", *modes, "bic", "delta_bic"]]
        if len(set(modes.values())) == len(modes):
            shown = shown.rename(columns=modes)
        print(shown.to_string(float_format=lambda v: f"{v:.4g}"))
        print(f"chosen: {written['chosen']}, {written['reason']}")
        chosen = results[written["chosen"]]
        ordered = [chosen] + [r for n, r in results.items() if n != written["chosen"]]
    else:
        chosen = calibrate_joint(curves, law, **options)
        written = write_joint(chosen, out)
        ordered = [chosen]
    print(_describe(chosen))
    for r in ordered:
        for warning in [*r.warnings, r.stability.warning()]:
            if warning:
                print(f"colonsim: warning: {warning}", file=sys.stderr, flush=True)
    print(f"results: {written['material']} (+ fit.csv, curves.csv, history.csv, modes.png"
          f"{', laws.csv, laws.png, laws/' if request.compare_laws else ''} in {out}/)")
    return ordered
