"""The identification pipeline of docs/model.md on one strip curve: sensitivity study -> CMA-ES -> Nelder-Mead.

The search itself (Latin hypercube, CMA-ES seeded with the 10 best designs, Nelder-Mead polish,
every evaluation recorded, seeded) is :mod:`colonsim.identification.search`; here it minimises
e1 = sum (F_exp - F_sim)^2 of one specimen, whose sensitivity probes are the simulated force at
50 % and 100 % of the displacement range. Around it: the default bounds, the magnitude check of
the curve, the fit's quality, uncertainty and the clamped-FE / closed-form model comparison.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize

from colonsim.errors import ColonsimError
from colonsim.identification.diagnostics import fit_against_noise, shear_modulus_weights
from colonsim.identification.objective import CurveObjective, make_model
from colonsim.identification.specimen import FEConvergenceError
from colonsim.identification.testdata import TensileCurve
from colonsim.identification.search import Budget, SearchProblem, search
from colonsim.identification.uniaxial import HomogeneousStripModel
from colonsim.identification.uncertainty import FitUncertainty, fit_uncertainty

# docs/model.md: bounds and initial guess for the 3-parameter Mooney-Rivlin law, Pa.
DEFAULT_BOUNDS = {"C10": (0.0, 0.06e6), "C01": (0.0, 0.06e6), "C11": (0.0, 2.5e6)}
DEFAULT_INITIAL = {"C10": 0.03e6, "C01": 0.03e6, "C11": 1.25e6}
# Bounds of the comparison laws (not in the source): wide enough to reach the tangent moduli of
# docs/model.md (0.36 MPa at 10 %, 2.5 MPa at 60 % strain); initial guess at their centre.
LAW_BOUNDS = {
    "mooney_rivlin_3": DEFAULT_BOUNDS,
    # C10 up to the neo-Hookean's bound: a law that contains another must contain its box too,
    # or a comparison of the two (--compare-laws) finds the larger law fitting worse.
    "mooney_rivlin_2": {"C10": (0.0, 0.3e6), "C01": (0.0, 0.1e6)},
    "neo_hookean": {"C10": (0.0, 0.3e6)},
    "yeoh": {"C10": (0.0, 0.06e6), "C20": (0.0, 1.0e6), "C30": (0.0, 1.0e6)},
}


def default_start(law_name):
    """Bounds and initial guess (Pa) of a law: docs/model.md for Mooney-Rivlin 3, centres otherwise."""
    bounds = LAW_BOUNDS[law_name]
    if law_name == "mooney_rivlin_3":
        return bounds, DEFAULT_INITIAL
    return bounds, {n: 0.5 * (lo + hi) for n, (lo, hi) in bounds.items()}


# Bounded Gauss-Newton steps of the local refit of the other model (compare_models): the force is
# nearly linear in the parameters and the two models differ by a few %, so the second step moves
# mu0 by ~1e-5 relative (measured on specimen_01 and on a noise-free closed-form curve).
REFIT_STEPS = 2


# A curve whose force exceeds this multiple of the most the law can carry within its bounds is a
# unit slip (kN read as N, a thickness in m typed as mm), not a stiff tissue; and no soft tissue
# has a peak nominal stress below MIN_PEAK_STRESS (Pa): forces in the wrong unit again.
MAGNITUDE_LIMIT = 10.0
MIN_PEAK_STRESS = 1.0


def check_force_magnitude(objective: CurveObjective, upper):
    """Refuse, before optimizing, a curve whose forces no parameters within the bounds can reach."""
    c = objective.curve
    size = f"{c.width * 1e3:g} x {c.thickness * 1e3:g} mm strip {c.length * 1e3:g} mm long"
    peak = float(np.max(c.force))
    stress = peak / (c.width * c.thickness)
    if stress < MIN_PEAK_STRESS:
        raise ColonsimError(f"{c.name}: the peak nominal stress is {stress:.3g} Pa ({peak:.3g} N on a {size}), far below "
                            "any soft tissue; check the force unit and the specimen geometry (in mm)")
    reach = HomogeneousStripModel(c.length, c.width, c.thickness, objective.model.law).solve(
        np.asarray(upper, dtype=float), objective.displacement)
    if peak > MAGNITUDE_LIMIT * np.max(reach):
        raise ColonsimError(
            f"{c.name}: the measured force reaches {peak:.3g} N, {peak / np.max(reach):.3g} times the most a {size} of "
            f"{objective.model.law.name} can carry within its parameter bounds ({np.max(reach):.3g} N); check the force "
            "unit and the specimen geometry (in mm) before fitting")


@dataclass
class CalibrationResult:
    """Outcome of :func:`calibrate` (parameters in Pa, forces in N)."""

    names: tuple
    parameters: np.ndarray
    history: pd.DataFrame
    stages: dict
    sensitivity: pd.DataFrame
    uncertainty: FitUncertainty
    fit: dict
    fitted: pd.DataFrame
    curve: TensileCurve = field(repr=False)
    model: dict = field(default_factory=dict)
    model_comparison: dict = field(default_factory=dict)
    settings: dict = field(default_factory=dict)

    @property
    def parameter_dict(self):
        return dict(zip(self.names, self.parameters.tolist()))


def calibrate(objective: CurveObjective, bounds=None, initial=None, budget: Budget | None = None,
              seed=1, progress=None) -> CalibrationResult:
    """Identify the law parameters that minimise ``objective`` (docs/model.md).

    Parameters
    ----------
    objective : CurveObjective
    bounds, initial : dict, optional
        Parameter bounds and initial guess in Pa; default :func:`default_start` of the model's law
        (docs/model.md for the 3-parameter Mooney-Rivlin).
    budget : Budget, optional
    seed : int
        Seeds the Latin hypercube and CMA-ES: the same seed gives the same result.
    progress : callable(stage, n_evaluations, e1), optional
    """
    law_bounds, law_initial = default_start(objective.model.law.name)
    bounds = bounds or law_bounds
    initial = initial or law_initial
    budget = budget or Budget()
    names = tuple(bounds)
    lower = np.array([bounds[n][0] for n in names], dtype=float)
    upper = np.array([bounds[n][1] for n in names], dtype=float)
    check_force_magnitude(objective, upper)
    problem = SearchProblem(objective.simulate, objective.force_exp, objective.failure_value, (FEConvergenceError,))
    outcome = search(problem, names, bounds, initial, budget, seed, progress)
    theta, wall = outcome.theta, outcome.wall_time_s
    unc = fit_uncertainty(objective.simulate, objective.force_exp, theta, names, upper - lower)
    f_fit = objective.simulate(theta)
    resid = objective.force_exp - f_fit
    ss_tot = float(((objective.force_exp - objective.force_exp.mean()) ** 2).sum())
    fit = {"e1_N2": float(resid @ resid), "rms_N": float(np.sqrt(np.mean(resid**2))),
           "max_abs_N": float(np.abs(resid).max()), "r2": 1.0 - float(resid @ resid) / ss_tot if ss_tot > 0 else None,
           "n_points": int(resid.size), "n_parameters": len(names), "wall_time_s": wall, "evaluations": outcome.evaluations,
           **fit_against_noise(objective.curve, objective.displacement, resid, len(names))}
    fitted = pd.DataFrame({"displacement_mm": objective.displacement * 1e3, "force_exp_N": objective.force_exp,
                           "force_fit_N": f_fit})
    settings = {"seed": seed, "budget": budget.__dict__.copy(), "bounds_Pa": {n: list(bounds[n]) for n in names},
                "initial_Pa": dict(initial)}
    return CalibrationResult(names, theta, outcome.history, outcome.stages, outcome.sensitivity, unc, fit,
                             fitted, objective.curve, objective.model.describe(),
                             compare_models(objective, theta, lower, upper), settings)


def compare_models(objective: CurveObjective, params, lower, upper) -> dict:
    """The clamped FE strip against the closed form: forces at the same parameters, and the
    small-strain modulus each model identifies from the same curve.

    Whichever model was fitted, the other is evaluated at the identified parameters on the same
    displacements (how much the homogeneous assumption misreads the clamped test, docs/model.md),
    then refitted locally from them (:func:`refit_locally`): the two mu0 differ by the
    model-form share of the uncertainty, which the noise-only sd of the fit does not contain.
    """
    fitted_is_fe = not isinstance(objective.model, HomogeneousStripModel)
    law = objective.model.law
    other = CurveObjective(objective.curve, make_model(objective.curve, law, analytic=fitted_is_fe),
                           n_points=objective.displacement.size)
    theta = np.asarray(params, dtype=float)
    f_self = objective.simulate(theta)
    try:
        f_other = other.simulate(theta)
    except FEConvergenceError as exc:  # e.g. mu0 = 0 at a bound: the fit stands, the comparison does not
        return {"unavailable": f"the clamped FE strip cannot be solved at the identified parameters ({exc})"}
    f_fe, f_cf = (f_self, f_other) if fitted_is_fe else (f_other, f_self)
    rel = (f_fe - f_cf) / np.maximum(np.abs(f_cf), 1e-12)
    try:
        theta_other, refit_note = refit_locally(other, theta, lower, upper), f"{REFIT_STEPS} bounded Gauss-Newton steps"
    except FEConvergenceError as exc:
        theta_other, refit_note = None, f"refit failed: {exc}"
    w = shear_modulus_weights(law, theta.size)
    mu0_self = float(w @ theta)
    mu0_other = float(w @ theta_other) if theta_other is not None else None
    mu0_fe, mu0_cf = (mu0_self, mu0_other) if fitted_is_fe else (mu0_other, mu0_self)
    return {"fe_over_closed_form_minus_1_at_end": float(rel[-1]),
            "fe_over_closed_form_minus_1_max": float(rel.max()),
            "fe_over_closed_form_minus_1_min": float(rel.min()),
            "force_end_fe_N": float(f_fe[-1]), "force_end_closed_form_N": float(f_cf[-1]),
            "mu0_clamped_fe_Pa": mu0_fe, "mu0_closed_form_Pa": mu0_cf,
            "mu0_refit": f"{'closed form' if fitted_is_fe else 'clamped FE'} refitted from the identified "
                         f"parameters ({refit_note})"}


def refit_locally(objective: CurveObjective, theta, lower, upper, steps=REFIT_STEPS):
    """Parameters minimising ``objective`` near ``theta``: bounded Gauss-Newton steps, each with a
    forward-difference Jacobian and a bounded linear least-squares step (in bound-scaled units)."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    scale = upper - lower
    theta = np.clip(np.asarray(theta, dtype=float), lower, upper)
    forces = objective.simulate(theta)
    for _ in range(steps):
        h = 1e-4 * scale
        J = np.stack([(objective.simulate(theta + h[i] * e) - forces) / h[i] for i, e in enumerate(np.eye(theta.size))],
                     axis=1)
        step = optimize.lsq_linear(J * scale, objective.force_exp - forces,
                                   bounds=((lower - theta) / scale, (upper - theta) / scale)).x
        theta = np.clip(theta + step * scale, lower, upper)
        forces = objective.simulate(theta)
    return theta
