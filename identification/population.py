"""Fitting every specimen separately: per-specimen parameters and their population statistics.

The source fitted the mean curve of its 8 specimens. Fitting each specimen separately keeps the
specimen-to-specimen scatter, which is what an uncertainty study of the insertion needs. The
specimens are independent, so they run in a process pool; each worker builds its own model from
the curve (plain arrays), and returns its :class:`CalibrationResult`.
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from colonsim.files import save_figure, write_csv, write_json
from colonsim.laws import get_law
from colonsim.identification.objective import CurveObjective, make_model
from colonsim.identification.pipeline import Budget, CalibrationResult, calibrate
from colonsim.identification.report import MATERIAL_FORMAT, write_calibration


def calibrate_curve(curve, law="mooney_rivlin_3", analytic=False, budget=None, seed=1, bounds=None,
                    initial=None, n_points=20, progress=None, **mesh) -> CalibrationResult:
    """Run the whole pipeline of docs/model.md on one test curve."""
    objective = CurveObjective(curve, make_model(curve, law, analytic, **mesh), n_points=n_points)
    return calibrate(objective, bounds, initial, budget, seed, progress)


def calibrate_specimens(curves, workers=1, progress=None, **options) -> list[CalibrationResult]:
    """Calibrate each curve separately (same seed and settings for all), in input order.

    Parameters
    ----------
    curves : sequence of TensileCurve
    workers : int
        Processes; 1 runs in this process (and reports ``progress`` per evaluation).
    progress : callable(name, stage, n_evaluations, e1) or callable(name, None, None, None)
        Called per evaluation with ``workers=1``, per finished specimen otherwise.
    options
        Passed to :func:`calibrate_curve`.
    """
    if workers <= 1 or len(curves) <= 1:
        results = []
        for c in curves:
            cb = None if progress is None else (lambda stage, n, e1, name=c.name: progress(name, stage, n, e1))
            results.append(calibrate_curve(c, progress=cb, **options))
        return results
    results = [None] * len(curves)
    with ProcessPoolExecutor(max_workers=min(workers, len(curves))) as pool:
        futures = {pool.submit(calibrate_curve, c, **options): i for i, c in enumerate(curves)}
        for fut in as_completed(futures):
            i = futures[fut]
            results[i] = fut.result()
            if progress is not None:
                progress(curves[i].name, None, None, None)
    return results


def population_table(results) -> pd.DataFrame:
    """One row per specimen: thickness, parameters and their standard deviations, fit quality."""
    rows = []
    for r in results:
        row = {"specimen": r.curve.name, "thickness_mm": r.curve.thickness * 1e3}
        for name, value, sd in zip(r.names, r.parameters, r.uncertainty.std):
            row[f"{name}_Pa"] = value
            row[f"{name}_sd_Pa"] = sd
        row["mu0_Pa"] = get_law(r.model["law"]).initial_shear_modulus(r.parameters)
        row.update({"rms_N": r.fit["rms_N"], "r2": r.fit["r2"], "e1_N2": r.fit["e1_N2"],
                    "evaluations": r.fit["evaluations"], "wall_time_s": r.fit["wall_time_s"]})
        rows.append(row)
    return pd.DataFrame(rows)


def population_summary(table: pd.DataFrame, names) -> dict:
    """Population mean, standard deviation and coefficient of variation of each parameter."""
    summary = {}
    for name in (*names, "mu0"):
        v = table[f"{name}_Pa"].to_numpy()
        sd = float(v.std(ddof=1)) if v.size > 1 else 0.0
        summary[name] = {"mean_Pa": float(v.mean()), "sd_Pa": sd,
                         "cv": sd / abs(float(v.mean())) if v.mean() != 0 else None, "n": int(v.size)}
    return summary


def population_figure(results) -> Figure:
    """Every specimen's curve with its fit, and the per-specimen parameters with error bars."""
    names = results[0].names
    fig = Figure(figsize=(4 * (len(names) + 1), 4))
    axes = fig.subplots(1, len(names) + 1)
    for r in results:
        line, = axes[0].plot(r.curve.displacement * 1e3, r.curve.force, "-", lw=0.6, alpha=0.5)
        axes[0].plot(r.fitted["displacement_mm"], r.fitted["force_fit_N"], "--", c=line.get_color(), lw=1.2)
    axes[0].set_xlabel("grip displacement [mm]")
    axes[0].set_ylabel("force [N]")
    axes[0].set_title("specimens (solid) and fits (dashed)", fontsize=9)
    idx = np.arange(len(results))
    for ax, (k, name) in zip(axes[1:], enumerate(names)):
        est = np.array([r.parameters[k] for r in results]) / 1e3
        sd = np.array([r.uncertainty.std[k] for r in results]) / 1e3
        sd = np.where(np.isfinite(sd), sd, np.nan)  # no bar where the data do not identify the parameter
        ax.errorbar(idx, est, yerr=1.96 * sd, fmt="o", capsize=3)
        ax.axhline(est.mean(), c="tab:red", lw=1, label="population mean")
        ax.set_xticks(idx, [r.curve.name for r in results], rotation=60, fontsize=7)
        ax.set_ylabel(f"{name} [kPa] (bars: 95 % linearised)")
    axes[1].legend(fontsize=8)
    return fig


def write_population(results, out_dir) -> dict:
    """Per-specimen folders plus ``population.csv``, ``population.json`` and ``population.png``.

    ``population.json`` follows the material format with the population means as parameters
    and the between-specimen standard deviations as uncertainty, so the insertion solver can
    read it like any material file.
    """
    out = Path(out_dir)
    for r in results:
        write_calibration(r, out / r.curve.name)
    table = population_table(results)
    names = results[0].names
    summary = population_summary(table, names)
    law = results[0].model["law"]
    doc = {"format": MATERIAL_FORMAT, "law": law,
           "description": f"Population mean of {len(results)} specimens fitted separately by colonsim calibrate.",
           "units": "Pa",
           "parameters": {n: summary[n]["mean_Pa"] for n in names},
           "uncertainty": {"method": "between-specimen standard deviation (ddof=1)",
                           "std": {n: summary[n]["sd_Pa"] for n in names}},
           "correlation": {"names": list(names),
                           "matrix": np.corrcoef(table[[f"{n}_Pa" for n in names]].to_numpy().T).tolist()
                           if len(results) > 2 else None},
           "population": summary,
           "specimens": table.to_dict(orient="records")}
    paths = {"table": out / "population.csv", "material": out / "population.json", "plot": out / "population.png"}
    write_csv(paths["table"], table)
    write_json(paths["material"], doc)
    save_figure(population_figure(results), paths["plot"])
    return paths


__all__ = ["Budget", "calibrate_curve", "calibrate_specimens", "population_table", "population_summary",
           "write_population"]
