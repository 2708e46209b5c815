"""Result files of a calibration: material JSON, CSV tables and the figures of the source.

Layout of one calibration folder::

    material.json       parameters, uncertainty, correlation, fit quality (colonsim-material/1)
    history.csv         every objective evaluation (stage, parameters in Pa, e1 in N^2, seconds)
    sensitivity.csv     Spearman sensitivity of each parameter (docs/model.md, "The fit", step 1)
    top10_designs.csv   the 10 best designs of the sensitivity study (CMA-ES start population)
    fit.csv             experimental and fitted force at the simulation displacements (mm, N)
    sensitivity.png, objective.png, fit.png

Figures use :class:`matplotlib.figure.Figure` directly so no GUI backend is touched.
"""

from __future__ import annotations

import datetime as _dt
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from colonsim.files import save_figure, write_csv, write_json
from colonsim.provenance import code_version
from colonsim.identification.diagnostics import identification_words, misfit_warning, shear_modulus
from colonsim.identification.hyperelastic import calibration_law
from colonsim.identification.stability import StabilityCheck, check_stability, default_range
from colonsim.laws import get_law
from colonsim.identification.pipeline import CalibrationResult
from colonsim.identification.testdata import source_records
from colonsim.identification.uncertainty import sd_for_json

MATERIAL_FORMAT = "colonsim-material/1"
_STAGE_COLOURS = {"initial": "k", "sensitivity": "tab:gray", "cma-es": "tab:blue", "nelder-mead": "tab:red"}


def small_strain(result: CalibrationResult) -> dict:
    """mu0 with its noise-only sd, how well that identifies it, and the model-form share beside it:
    mu0 as the clamped FE strip and as the closed form identify it from the same curve."""
    mu0, mu0_sd = shear_modulus(result)
    mc = result.model_comparison
    fe, cf = mc.get("mu0_clamped_fe_Pa"), mc.get("mu0_closed_form_Pa")
    model_form = None
    if fe is not None and cf is not None:
        model_form = {"mu0_clamped_fe_Pa": fe, "mu0_closed_form_Pa": cf, "difference_Pa": fe - cf,
                      "difference_in_noise_sd": (fe - cf) / mu0_sd if 0 < mu0_sd < np.inf else None,
                      "how": mc["mu0_refit"]}
    return {"mu0_Pa": mu0, "mu0_sd_Pa": sd_for_json(mu0_sd), "E0_Pa": 3.0 * mu0, "mu0_sd_covers": "measurement noise only",
            "identification": identification_words(mu0, mu0_sd, result.fit["follows_curve"]),
            "model_form": model_form}


def strip_stability(result: CalibrationResult) -> StabilityCheck:
    """Drucker stability of a strip fit along the three modes, from 0.5 to twice the strip's largest stretch."""
    c = result.curve
    return check_stability(calibration_law(result.model["law"]), result.parameters,
                           default_range(1.0 + c.max_displacement / c.length))


def material_document(result: CalibrationResult, level=0.95, selection=None) -> dict:
    """The ``material.json`` document of one calibration (read by :mod:`colonsim.insertion.engine.material`);
    ``selection`` records why this law was chosen when several were compared."""
    law = get_law(result.model["law"])
    unc = result.uncertainty.to_dict(level)
    warning = misfit_warning(result)
    stability = strip_stability(result)
    document = {
        "format": MATERIAL_FORMAT,
        "law": law.name,
        "description": f"Identified by colonsim calibrate from {result.curve.name} "
                       f"({result.model['model']}).",
        "units": "Pa",
        "parameters": result.parameter_dict,
        "small_strain": small_strain(result),
        "warnings": [w for w in (warning, stability.warning()) if w],
        "stability": stability.to_dict(),
        "uncertainty": {k: unc[k] for k in unc if k not in ("correlation", "covariance")},
        "correlation": {"names": list(result.names), "matrix": unc["correlation"]},
        "covariance_Pa2": unc["covariance"],
        "fit": result.fit,
        "stages": result.stages,
        "model": result.model,
        "model_comparison": result.model_comparison,
        "specimen": {"name": result.curve.name, "length_mm": result.curve.length * 1e3,
                     "width_mm": result.curve.width * 1e3, "thickness_mm": result.curve.thickness * 1e3,
                     **{k: v for k, v in result.curve.meta.items() if k in ("path", "averaged_specimens", "cleaning")}},
        "provenance": {"tool": "colonsim calibrate", **code_version(),
                       "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
                       **result.settings, "source_files": source_records(result.curve)},
    }
    if selection is not None:
        document["law_selection"] = selection
    return document


def top_designs(result: CalibrationResult, n=10) -> pd.DataFrame:
    """The ``n`` best designs of the sensitivity study (parameters in Pa, e1 in N^2)."""
    designs = result.history[result.history["stage"] == "sensitivity"]
    return designs.nsmallest(n, "e1")[["evaluation", *result.names, "e1"]]


def sensitivity_figure(result: CalibrationResult) -> Figure:
    """Objective of every design against each parameter, the 10 best highlighted."""
    designs = result.history[(result.history["stage"] == "sensitivity") & result.history["ok"]]
    top = top_designs(result)
    fig = Figure(figsize=(4 * len(result.names), 3.6))
    axes = fig.subplots(1, len(result.names), sharey=True)
    for ax, name in zip(np.atleast_1d(axes), result.names):
        rho = result.sensitivity.loc[name, "spearman_log_e1"]
        ax.scatter(designs[name] / 1e3, designs["e1"], s=12, c="tab:gray", label="designs")
        ax.scatter(top[name] / 1e3, top["e1"], s=30, c="tab:red", label="10 best (CMA-ES start)")
        ax.set_yscale("log")
        ax.set_xlabel(f"{name} [kPa]")
        ax.set_title(f"Spearman(log e1) = {rho:+.2f}", fontsize=9)
    np.atleast_1d(axes)[0].set_ylabel("objective e1 [N$^2$]")
    np.atleast_1d(axes)[0].legend(fontsize=8)
    fig.suptitle(f"Sensitivity study ({len(designs)} Latin-hypercube designs)")
    return fig


def objective_figure(result: CalibrationResult) -> Figure:
    """Objective of every evaluation, coloured by stage, with the running best."""
    h = result.history
    fig = Figure(figsize=(7, 4))
    ax = fig.subplots()
    for stage, rows in h.groupby("stage", sort=False):
        ax.scatter(rows["evaluation"], rows["e1"], s=8, c=_STAGE_COLOURS.get(stage, "tab:green"), label=stage)
    ax.plot(h["evaluation"], h["e1"].cummin(), "k-", lw=1.2, label="best so far")
    ax.set_yscale("log")
    ax.set_xlabel("evaluation")
    ax.set_ylabel("objective e1 [N$^2$]")
    ax.legend(fontsize=8)
    ax.set_title(f"e1: {result.stages['initial']['e1']:.3g} (initial) -> {result.stages['cma-es']['e1']:.3g} "
                 f"(CMA-ES) -> {result.stages['nelder-mead']['e1']:.3g} N$^2$ (Nelder-Mead)", fontsize=9)
    return fig


def fit_figure(result: CalibrationResult) -> Figure:
    """Experimental curve against the fitted model, with the residuals below."""
    fig = Figure(figsize=(6.5, 5.5))
    ax, ax_r = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1]})
    c, f = result.curve, result.fitted
    ax.plot(c.displacement * 1e3, c.force, "-", c="0.6", lw=0.8, label=f"experiment ({c.name})")
    ax.plot(f["displacement_mm"], f["force_exp_N"], "o", ms=4, mfc="none", c="k", label="experiment, interpolated")
    ax.plot(f["displacement_mm"], f["force_fit_N"], "-", c="tab:red", label="fitted model")
    ax.set_ylabel("force [N]")
    ax.legend(fontsize=8)
    ax.set_title(f"R$^2$ = {result.fit['r2']:.6f}, RMS error = {result.fit['rms_N']:.3g} N", fontsize=9)
    ax_r.axhline(0.0, c="0.6", lw=0.8)
    ax_r.plot(f["displacement_mm"], f["force_exp_N"] - f["force_fit_N"], "o-", ms=3, c="tab:red")
    ax_r.set_xlabel("grip displacement [mm]")
    ax_r.set_ylabel("residual [N]")
    return fig


def write_calibration(result: CalibrationResult, out_dir, selection=None) -> dict:
    """Write the files of one calibration into ``out_dir``; return their paths (``selection``: see
    :func:`material_document`)."""
    out = Path(out_dir)
    paths = {"material": out / "material.json", "history": out / "history.csv",
             "sensitivity": out / "sensitivity.csv", "top10": out / "top10_designs.csv", "fit": out / "fit.csv",
             "sensitivity_plot": out / "sensitivity.png", "objective_plot": out / "objective.png",
             "fit_plot": out / "fit.png"}
    write_json(paths["material"], material_document(result, selection=selection))
    write_csv(paths["history"], result.history)
    write_csv(paths["sensitivity"], result.sensitivity.rename_axis("parameter").reset_index())
    write_csv(paths["top10"], top_designs(result))
    write_csv(paths["fit"], result.fitted)
    save_figure(sensitivity_figure(result), paths["sensitivity_plot"])
    save_figure(objective_figure(result), paths["objective_plot"])
    save_figure(fit_figure(result), paths["fit_plot"])
    return paths
