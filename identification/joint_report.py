"""Result files of a multi-mode (joint) calibration, and the comparison of laws on it.

Layout of the output folder::

    material.json    law, parameters (Pa; Ogden exponents dimensionless), uncertainty, per-curve fit
                     quality, the Drucker stability check, and the warnings: curves the law does
                     not follow, with the likely cause, and Drucker instability (colonsim-material/1)
    fit.csv          every curve's measured and fitted nominal stress at its stretches
    curves.csv       one row per curve: mode, weight, points, R^2, RMS (Pa), the RMS against the curve's
                     own noise and whether the law follows it (colonsim.identification.curve_checks)
    history.csv      every objective evaluation (stage, parameters, e1)
    modes.png        every mode's data and fit, residuals below
    laws.csv, laws.png, laws/<law>/   with --compare-laws: one row per law (stability included)

Every law's material file, Ogden's included, runs in the insertion solver (``colonsim insert
--material``) and exports to other solvers' cards.
"""

from __future__ import annotations

import datetime as _dt
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from colonsim.files import save_figure, write_csv, write_json
from colonsim.identification.hyperelastic import MODES, calibration_law
from colonsim.identification.joint import JointResult
from colonsim.identification.law_comparison import evidence, information_criteria
from colonsim.identification.report import MATERIAL_FORMAT
from colonsim.identification.uncertainty import sd_for_json
from colonsim.provenance import code_version

_MODE_COLOURS = {"uniaxial": "tab:blue", "equibiaxial": "tab:orange", "planar": "tab:green"}


def material_document(result: JointResult, selection=None, level=0.95) -> dict:
    """The ``material.json`` of a joint calibration."""
    law = calibration_law(result.law)
    unc = result.uncertainty.to_dict(level)
    unc["residual_sd"] = unc.pop("residual_sd_N")
    mu0, mu0_sd = result.mu0
    warning = result.stability.warning()
    doc = {
        "format": MATERIAL_FORMAT, "law": law.name,
        "description": f"Identified by colonsim calibrate from {len(result.curves)} curve(s) in mode(s) "
                       f"{', '.join(dict.fromkeys(c.mode for c in result.curves))} (joint fit).",
        "units": "Pa", "parameter_units": dict(zip(law.parameter_names, law.units)),
        "parameters": result.parameter_dict,
        "small_strain": {"mu0_Pa": mu0, "mu0_sd_Pa": sd_for_json(mu0_sd), "E0_Pa": 3.0 * mu0},  # null: not identified
        "warnings": [*result.warnings, *([warning] if warning else [])],
        "stability": result.stability.to_dict(),
        "uncertainty": {k: v for k, v in unc.items() if k not in ("correlation", "covariance")},
        "correlation": {"names": list(result.names), "matrix": unc["correlation"]},
        "fit": {**result.fit, "curves": result.per_curve.to_dict(orient="records")},
        "stages": result.stages,
        "test_data": [{"curve": c.name, "mode": c.mode, "weight": c.weight,
                       **{k: v for k, v in c.meta.items() if v is not None}} for c in result.curves],
        "provenance": {"tool": "colonsim calibrate (joint)", **code_version(),
                       "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"), **result.settings},
    }
    if selection is not None:
        doc["law_selection"] = selection
    return doc


def modes_figure(results, title=None) -> Figure:
    """Every mode's data (markers) and each result's fit (lines), residuals below."""
    results = list(results)
    modes = [m for m in MODES if any(m == c.mode for c in results[0].curves)]
    fig = Figure(figsize=(4.2 * len(modes), 5.8))
    axes = fig.subplots(2, len(modes), squeeze=False, gridspec_kw={"height_ratios": [3, 1.3]})
    for j, mode in enumerate(modes):
        ax, ax_r = axes[0, j], axes[1, j]
        ax_r.axhline(0.0, c="0.6", lw=0.8)
        for k, r in enumerate(results):
            f = r.fitted[r.fitted["mode"] == mode]
            if k == 0:
                ax.plot(f["stretch"], f["stress_exp_Pa"] / 1e6, "o", mfc="none", c="k", label="test")
            q = r.per_curve[r.per_curve["mode"] == mode]
            label = f"{r.law}: R$^2$ {', '.join(f'{v:.4f}' for v in q['r2'])}"
            if r.fit.get("strip_model") == "fe":  # the clamped FE strip at its points, not the closed form
                x, y = f["stretch"], f["stress_fit_Pa"] / 1e6
                label += " (clamped FE)"
            else:
                x = np.linspace(1.0, f["stretch"].max(), 200)
                y = calibration_law(r.law).nominal_stress(mode, x, r.parameters) / 1e6
            line, = ax.plot(x, y, "-", label=label, c=None if len(results) > 1 else _MODE_COLOURS[mode])
            ax_r.plot(f["stretch"], (f["stress_exp_Pa"] - f["stress_fit_Pa"]) / 1e6, ".-", c=line.get_color())
        ax.set_title(mode, fontsize=10)
        ax.legend(fontsize=7)
        ax_r.set_xlabel("stretch")
    axes[0, 0].set_ylabel("nominal stress [MPa]")
    axes[1, 0].set_ylabel("residual [MPa]")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def write_joint(result: JointResult, out_dir, selection=None) -> dict:
    """Write one joint calibration into ``out_dir``; return the paths."""
    out = Path(out_dir)
    paths = {"material": out / "material.json", "fit": out / "fit.csv", "curves": out / "curves.csv",
             "history": out / "history.csv", "modes_plot": out / "modes.png"}
    write_json(paths["material"], material_document(result, selection))
    write_csv(paths["fit"], result.fitted)
    write_csv(paths["curves"], result.per_curve)
    write_csv(paths["history"], result.history)
    save_figure(modes_figure([result], f"{result.law} fitted jointly"), paths["modes_plot"])
    return paths


def compare_joint(results: dict) -> tuple[pd.DataFrame, str, str]:
    """Rank joint fits: BIC on the weighted residuals, stable laws first. (table, chosen, reason)."""
    rows = []
    for law, r in results.items():
        n, k = r.fit["n_points"], len(r.names)
        aic, bic = information_criteria(r.fit["e1"], n, k)
        mu0, mu0_sd = r.mu0
        first = r.stability.first()
        rows.append({"law": law, "n_parameters": k, "drucker_stable": r.stability.is_stable,
                     "first_unstable": "" if first is None else f"{first[0]} {first[1]} from {first[2]:.3g}",
                     **{f"r2_{row['curve']}": row["r2"] for _, row in r.per_curve.iterrows()},
                     "e1": r.fit["e1"], "aic": aic, "bic": bic, "mu0_Pa": mu0, "mu0_sd_Pa": mu0_sd,
                     "parameters": "; ".join(f"{p}={v:.6g}" for p, v in r.parameter_dict.items())})
    table = pd.DataFrame(rows)
    table["delta_bic"] = table["bic"] - table["bic"].min()
    order = table.sort_values(["drucker_stable", "bic", "n_parameters"], ascending=[False, True, True]).reset_index(drop=True)
    chosen = order.loc[0, "law"]
    unstable = order.loc[~order["drucker_stable"], "law"].tolist()
    if order.loc[0, "drucker_stable"]:
        reason = f"lowest BIC ({order.loc[0, 'bic']:.1f}) among the Drucker-stable laws"
        if unstable:
            reason += f"; unstable within the checked range and passed over: {', '.join(unstable)}"
        stable_rest = order[order["drucker_stable"]].iloc[1:]
        if len(stable_rest):
            d = stable_rest.iloc[0]["bic"] - order.loc[0, "bic"]
            reason += f"; next stable {stable_rest.iloc[0]['law']} at delta BIC {d:.1f} ({evidence(d)} evidence for {chosen})"
    else:
        reason = f"no law is Drucker stable over the checked range; lowest BIC ({order.loc[0, 'bic']:.1f})"
    table["chosen"] = table["law"] == chosen
    return order.assign(chosen=order["law"] == chosen), chosen, reason


def write_comparison(results: dict, out_dir) -> dict:
    """``laws.csv``, ``laws.png``, one folder per law, and the chosen law's files in ``out_dir``."""
    out = Path(out_dir)
    table, chosen, reason = compare_joint(results)
    for law, r in results.items():
        write_joint(r, out / "laws" / law)
    selection = {"criterion": "Drucker-stable laws first, then BIC (lowest wins) on the weighted residuals",
                 "chosen": chosen, "reason": reason, "table": "laws.csv"}
    paths = write_joint(results[chosen], out, selection)
    paths.update({"laws_table": out / "laws.csv", "laws_plot": out / "laws.png"})
    write_csv(paths["laws_table"], table)
    save_figure(modes_figure(results.values(), f"every law fitted jointly; chosen: {chosen}"), paths["laws_plot"])
    return {**paths, "chosen": chosen, "reason": reason, "table": table}
