"""The validation report's checks that need no sweep: the verification table (the solver and the
specimen model against analytic solutions) with its figures, and the calibration's recovery of the
synthetic ground truth. The figures are written to ``OUT/figures``.
"""

from __future__ import annotations

import time

import numpy as np
from matplotlib.figure import Figure

from colonsim.files import save_figure
from colonsim.insertion.study.verification import WALL_T, reference_material
from colonsim.insertion.study.verification_rod import (beam_column_tip_deflection, buckling_check,
                                                       elastica_tip_deflection)
from colonsim.insertion.study.verification_rules import Run
from colonsim.insertion.study.verification_shell import TUBE_RADIUS, thin_wall_pressure
from colonsim.insertion.study.verification_table import BUCKLING_ROD, evaluate

BUCKLING_RATIOS = (0.5, 0.8, 0.9, 0.95, 1.05, 1.1, 1.2, 1.5)


def verify(full, figures, out):
    """The rows of the verification table at full or CI size (dicts: id, group, quantity, analytic,
    measured, unit, relative error, rule, details, why, passed), and the buckling and inflation
    figures."""
    verdicts = evaluate(full)
    buckling_figure(full, figures, out)
    inflation_figure(verdicts, figures, out)
    return [v.row() for v in verdicts]


def buckling_figure(full, figures, out):
    """Tip deflection of the dynamic buckling runs against beam-column theory and the elastica; the
    runs at 0.95 and 1.05 P_E are those of the table's rows."""
    length, spacing = BUCKLING_ROD["full" if full else "reduced"]
    measured = {r: Run(buckling_check, (r, length, spacing))().measured for r in BUCKLING_RATIOS}
    fig = Figure(figsize=(6.5, 4.2))
    ax = fig.subplots()
    below = np.linspace(0.02, 0.985, 200)
    above = np.linspace(1.0, 1.6, 200)
    ax.plot(below, [beam_column_tip_deflection(r) for r in below], "k-", lw=1,
            label="beam-column theory, imperfection 1e-3 P")
    ax.plot(above, [elastica_tip_deflection(r) for r in above], "k--", lw=1, label="elastica (perfect rod)")
    ax.plot(list(measured), list(measured.values()), "o", c="tab:red", label=f"rod model, L = {length * 100:g} cm")
    ax.axvline(1.0, c="0.7", lw=0.8)
    ax.set_xlabel("axial load / Euler load $\\pi^2 EI / (4 L^2)$")
    ax.set_ylabel("lateral tip deflection / L")
    ax.set_ylim(0.0, 0.8)
    ax.legend(fontsize=8)
    ax.set_title("Clamped-free rod under a dead axial load", fontsize=10)
    save_figure(fig, out / "figures" / "buckling.png")
    figures["buckling"] = {"file": "figures/buckling.png", "load_ratio": list(measured),
                           "tip_deflection_over_L": list(measured.values())}


def inflation_figure(verdicts, figures, out):
    """The stretches the table's inflated sections and clamped tube reached, on the thin-wall curve."""
    def reached(prefix):
        return [v.comparison for v in verdicts if v.check.id.startswith(prefix)]

    sections, clamped = reached("shell.section_"), reached("shell.clamped_tube_")
    material = reference_material()
    fig = Figure(figsize=(6.5, 4.2))
    ax = fig.subplots()
    line = np.linspace(1.0, 1.65, 200)
    ax.plot(line, thin_wall_pressure(line, material) / 1e3, "k-", lw=1, label="thin-wall theory (plane strain)")
    targets = np.array([c.analytic for c in sections])
    ax.plot([c.measured for c in sections], thin_wall_pressure(targets, material) / 1e3, "o", c="tab:red",
            label="shell model: stretch reached at that pressure")
    if clamped:
        ax.plot([c.measured for c in clamped], thin_wall_pressure(np.array([c.analytic for c in clamped])) / 1e3,
                "s", mfc="none", c="tab:blue", label="clamped tube, middle ring")
    ax.set_xlabel("hoop stretch")
    ax.set_ylabel("inflation pressure [kPa]")
    ax.legend(fontsize=8)
    ax.set_title(f"Mooney-Rivlin tube, R = {TUBE_RADIUS * 1e3:g} mm, t = {WALL_T * 1e3:g} mm "
                 "(reference material)", fontsize=10)
    save_figure(fig, out / "figures" / "inflation.png")
    figures["inflation"] = {"file": "figures/inflation.png", "stretch_target": [c.analytic for c in sections],
                            "stretch_measured": [c.measured for c in sections]}


# --- calibration recovery -------------------------------------------------------------------------

def calibration_recovery(full, out):
    from colonsim.identification.pipeline import Budget
    from colonsim.identification.report import fit_figure
    from colonsim.identification.verification import specimen_recovery

    budget = Budget() if full else Budget.quick()
    t0 = time.perf_counter()
    rec = specimen_recovery("specimen_01", budget=budget, seed=1)
    wall = time.perf_counter() - t0
    save_figure(fit_figure(rec.result), out / "figures" / "calibration_fit.png")
    r = rec.result
    return {"specimen": rec.curve.name, "thickness_mm": rec.curve.thickness * 1e3,
            "budget": "default" if full else "quick", "budget_settings": budget.__dict__.copy(), "seed": 1,
            "parameters": rec.table(), "truth_in_95_region": bool(rec.truth_in_region),
            "mahalanobis2": r.uncertainty.mahalanobis2(rec.truth), "region_threshold": r.uncertainty.region_threshold(),
            "correlation_C10_C01": float(r.uncertainty.correlation[0, 1]), "rms_N": r.fit["rms_N"],
            "noise_sd_N": rec.noise_sd, "r2": r.fit["r2"], "evaluations": r.fit["evaluations"],
            "stages_e1": {k: r.stages[k]["e1"] for k in ("initial", "sensitivity", "cma-es", "nelder-mead")},
            "fe_over_closed_form_minus_1_at_end": r.model_comparison["fe_over_closed_form_minus_1_at_end"],
            "wall_time_s": wall, "figure": "figures/calibration_fit.png"}
