"""The validation report's checks that need no sweep: the solver against analytic solutions, and
the calibration's recovery of the synthetic ground truth.

Each verification row is a dict (group, quantity, analytic, measured, relative error, tolerance,
why, passed); the figures are written to ``OUT/figures``.
"""

from __future__ import annotations

import math
import time

import numpy as np
from matplotlib.figure import Figure

from colonsim.files import save_figure
from colonsim.markdown import num
from colonsim.insertion.study import verification as iv


# --- verification ------------------------------------------------------------------------------

def check(group, comparison, rel_tol, why):
    """A verification row judged on the relative error."""
    rel = comparison.relative_error
    return {"group": group, **comparison.to_dict(), "tolerance": f"|rel. error| <= {num(rel_tol, 2)}", "why": why,
            "passed": bool(abs(rel) <= rel_tol)}


def bound(group, quantity, measured, passed, tolerance, why, analytic=None, unit=""):
    """A verification row judged on a bound (an analytic value of zero, or a range)."""
    rel = (measured - analytic) / abs(analytic) if analytic not in (None, 0.0) else math.nan
    return {"group": group, "quantity": quantity, "analytic": analytic, "measured": measured, "unit": unit,
            "relative_error": rel, "tolerance": tolerance, "why": why, "passed": bool(passed)}


def verify_rod(full, figures, out):
    rows = []
    spacings = (0.01, 0.005) if full else (0.01,)
    for h in spacings:
        rows.append(check("rod", iv.cantilever_tip_deflection(0.3, h), 0.01,
                          f"30 cm cantilever, {h * 1e3:g} mm segments, delta/L = 0.5 %: midpoint moment-area sum "
                          "(h/L)^2/4 ~ 3e-4, relaxation residual < 1e-4 after 16 time constants, geometric "
                          "nonlinearity ~1e-5"))
    for h in spacings:
        rows.append(check("rod", iv.euler_buckling_load(0.3, h), 0.02,
                          f"tangent stiffness of the compressed straight rod, {h * 1e3:g} mm segments: the discrete "
                          "Euler problem converges as (h/L)^2, ~0.1 %"))
    speed, force = iv.axial_wave()
    why = ("velocity step on a 1 m rod, 5 mm segments, front timed at 0.5 m: the lattice front spreads over "
           "~(c t)^(1/3) h^(2/3) ~ 2 cm, its half-height point travels at c")
    rows += [check("rod", speed, 0.02, why), check("rod", force, 0.02, why)]

    length, spacing = (0.3, 0.01) if full else (0.15, 0.0075)
    ratios = (0.5, 0.8, 0.9, 0.95, 1.05, 1.1, 1.2, 1.5)
    measured = {r: iv.buckling_tip_deflection(r, length, spacing) for r in ratios}
    why_below = ("dynamic relaxation under P = 0.95 P_E with a lateral imperfection 1e-3 P; the bound of the test: "
                 "linear theory amplifies the imperfection ~20x to ~0.015 L, the straight rod must stay stable")
    rows.append(bound("rod", f"tip deflection / L at P = 0.95 P_E (L = {length * 100:g} cm), beam-column theory",
                      measured[0.95], 0.0 < measured[0.95] < 0.03, "0 < measured < 0.03", why_below,
                      analytic=iv.beam_column_tip_deflection(0.95)))
    rows.append(bound("rod", f"tip deflection / L at P = 1.05 P_E (L = {length * 100:g} cm), elastica",
                      measured[1.05], measured[1.05] > 0.15, "measured > 0.15",
                      "5 % above the Euler load the rod must buckle: the perfect elastica gives 0.38 L",
                      analytic=iv.elastica_tip_deflection(1.05)))

    fig = Figure(figsize=(6.5, 4.2))
    ax = fig.subplots()
    below = np.linspace(0.02, 0.985, 200)
    above = np.linspace(1.0, 1.6, 200)
    ax.plot(below, [iv.beam_column_tip_deflection(r) for r in below], "k-", lw=1,
            label="beam-column theory, imperfection 1e-3 P")
    ax.plot(above, [iv.elastica_tip_deflection(r) for r in above], "k--", lw=1, label="elastica (perfect rod)")
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
    return rows


def verify_shell(full, figures, out):
    rows = []
    stretches = (1.05, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6) if full else (1.05, 1.2, 1.4, 1.6)
    measured = []
    for s in stretches:
        c, spread = iv.inflate_section(s)
        measured.append(c.measured)
        rows.append(check("shell", c, 1e-3,
                          "static solve of a 2 cm periodic tube section (3 mm triangles) at the closed-form "
                          "pressure with the exact inscribed-polygon correction 1/cos(pi/m); the remainder is the "
                          f"ring-to-ring triangles tilting out of the hoop plane (nodal spread {spread:.1e})"))
    clamped = iv.inflate_clamped_tube((1.1, 1.2, 1.3) if full else (1.2,), 10.0 if full else 6.0)
    for c in clamped:
        rows.append(check("shell", c, 1e-3, "clamped end rings hold the wall back over a boundary layer of a few "
                          "radii; the middle ring is beyond it"))
    for radius in (0.03, 0.3):
        for angle in ((0, 15, 30, 45, 60, 90) if full else (0, 30, 60, 90)):
            rows.append(check("shell", iv.cylinder_bending(radius, angle), 0.01,
                              "6 cm sheet of 3 mm near-equilateral triangles: rows 0.4 % off equilateral, "
                              "O((h/R)^2) = 1 % at R = 3 cm (far smaller on the angle-squared sum)"))
    rows.append(check("shell", iv.sphere_bending(0.3), 0.01,
                      "discrete hinges have an intrinsic Poisson ratio -1/3 (documented in insertion/shell.py): "
                      "the sphere checks that documented value"))

    material = iv.reference_material()
    fig = Figure(figsize=(6.5, 4.2))
    ax = fig.subplots()
    line = np.linspace(1.0, 1.65, 200)
    ax.plot(line, iv.thin_wall_pressure(line, material) / 1e3, "k-", lw=1, label="thin-wall theory (plane strain)")
    ax.plot(measured, iv.thin_wall_pressure(np.array(stretches), material) / 1e3, "o", c="tab:red",
            label="shell model: stretch reached at that pressure")
    if clamped:
        ax.plot([c.measured for c in clamped], iv.thin_wall_pressure(np.array([c.analytic for c in clamped])) / 1e3,
                "s", mfc="none", c="tab:blue", label="clamped tube, middle ring")
    ax.set_xlabel("hoop stretch")
    ax.set_ylabel("inflation pressure [kPa]")
    ax.legend(fontsize=8)
    ax.set_title(f"Mooney-Rivlin tube, R = {iv.TUBE_RADIUS * 1e3:g} mm, t = {iv.WALL_T * 1e3:g} mm "
                 "(reference material)", fontsize=10)
    save_figure(fig, out / "figures" / "inflation.png")
    figures["inflation"] = {"file": "figures/inflation.png", "stretch_target": list(stretches),
                            "stretch_measured": measured}
    return rows


def verify_energy_contact():
    rows = []
    for name, body in iv.free_vibration_energy_drift().items():
        rows.append(bound("energy", f"free vibration, {name}: max |E(t) - E(0)| / E(0) over 5 periods",
                          body["drift"], body["drift"] < 0.01 and body["external_work"] == 0.0, "< 0.01 (and no external work)",
                          "undamped central differences conserve a shadow energy; the measured energy oscillates "
                          "by O((omega dt)^2) of the excited modes", analytic=0.0))
    residual, work, _, _, _ = iv.damped_push_energy_balance()
    rows.append(bound("energy", "damped pushed rod: max |kinetic + strain + dissipated - work| / work",
                      residual / work, residual < 0.01 * work, "< 0.01",
                      "exact accounting of kinetic energy; the residual is the O(dt^2) quadrature of the strain "
                      "energy (trapezoid)", analytic=0.0))
    rest = iv.rod_resting_on_wall(1.0)
    rows.append(check("contact", rest.penetration, 0.005, "vertical force balance of 11 parallel contact springs is "
                      "exact at rest; the residual is the relaxation after 30 time constants"))
    rows.append(bound("contact", "resting rod: normal force / applied load", rest.normal_force, abs(rest.normal_force - 1.0) <= 0.005,
                      "|rel. error| <= 0.005", "force balance at rest", analytic=1.0, unit="N"))
    rows.append(bound("contact", "resting rod: max |energy balance| / work", rest.energy_residual / rest.work,
                      rest.energy_residual < 0.02 * rest.work, "< 0.02",
                      "the contact damping power is evaluated at the half-step velocity", analytic=0.0))
    tip, active = iv.tip_on_node(0.2)
    rows.append(check("contact", tip, 0.005, f"one node under the hemispherical tip ({active} active); relaxation residual"))
    rows.append(check("contact", iv.friction_stick(), 0.01,
                      "steady creep of the regularised Coulomb law; only the O(mu f_n dt / m) lag of the explicit "
                      "viscous update deviates"))
    for c in iv.friction_sliding():
        rows.append(check("contact", c, 0.01, "friction saturated once |v| > v_reg (before the 2 ms measuring start); "
                          "the normal force stays N to 1e-4"))
    return rows


def verify_specimen(full):
    from colonsim.identification import verification as idv

    rows = []
    axial, closed, lateral = idv.membrane_uniaxial_stress(np.linspace(1.05, 1.6, 8))
    k = int(np.argmax(np.abs(axial / closed - 1.0)))
    rows.append(bound("specimen", "membrane law, F = diag(l, l^-1/2): nominal stress at the worst of l = 1.05..1.6",
                      float(axial[k]), bool(np.allclose(axial, closed, rtol=1e-12)) and float(np.abs(lateral).max()) <= 1e-9 * axial.max(),
                      "|rel. error| <= 1e-12, lateral stress ~0", "the same closed form evaluated through the "
                      "plane-stress membrane: round-off only", analytic=float(closed[k]), unit="Pa"))
    sliding = idv.specimen_against_closed_form("sliding")
    k = int(np.argmax(np.abs(sliding.relative_difference)))
    rows.append(bound("specimen", f"sliding grips: force at {sliding.displacement[k] * 1e3:g} mm (worst of 3..60 mm) vs "
                      "homogeneous uniaxial tension", float(sliding.model[k]),
                      bool(np.all(np.abs(sliding.relative_difference) <= 5e-3)), "|rel. error| <= 5e-3 at every point",
                      "without the clamp the strip is homogeneous and constant F is in the P2 space: exact up to "
                      "the Newton tolerance", analytic=float(sliding.closed_form[k]), unit="N"))
    clamped = idv.specimen_against_closed_form("clamped")
    ex = clamped.relative_difference
    rows.append(bound("specimen", "clamped grips: force excess over the closed form, min..max over 3..60 mm",
                      float(ex.max()), bool(np.all((ex > 0.01) & (ex < 0.05))), "every point in (0.01, 0.05)",
                      f"the clamp holds the strip's ends from contracting, which stiffens this strip by 2-3 %; measured "
                      f"{ex.min():.2%}..{ex.max():.2%}",
                      analytic=None))
    fine = (32, 12) if full else (24, 9)
    coarse, finer = idv.mesh_convergence(fine=fine)
    rows.append(bound("specimen", f"mesh convergence: force at 60 mm, default 8 x 3 P2 vs {fine[0]} x {fine[1]}",
                      coarse, abs(coarse / finer - 1.0) <= 5e-3, "|rel. error| <= 5e-3",
                      "the calibration default must be converged well below the 0.05 N data noise (~0.3 %)",
                      analytic=finer, unit="N"))
    return rows


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
