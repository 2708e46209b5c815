"""Fitting one law to several test modes at once (uniaxial, equibiaxial, planar).

Every curve contributes its residuals ``P_exp - P_fit`` (nominal stress, Pa) at its own
stretches, scaled so that each curve weighs the same whatever its stress level and sampling, then
multiplied by the curve's weight ``w`` (default 1):

- ``relative`` (default): ``r_i = w (P_exp,i - P_fit,i) / (max(|P_exp,i|, S/10) sqrt(n))``: every
  point's relative error counts alike, the start of a curve as much as its end, except that
  stresses below a tenth of the peak count as that tenth (near the origin a small error in a
  read-off stress is a large relative one).
- ``absolute``: ``r_i = w (P_exp,i - P_fit,i) / (S sqrt(n))``, S the curve's largest stress, n
  its points: the mean squared error in units of the peak. Small stresses count little, as in a
  plot of the curve.

On Treloar's three modes the relative default lets both Ogden (3 terms) and Yeoh follow the
uniaxial and planar curves to R^2 >= 0.99; with absolute residuals Yeoh's uniaxial R^2 drops to
0.989 (docs/calibration.md has the numbers).

Before the fit, a curve whose values cannot be what its header says (a stretch beyond any tissue
or rubber test, tension as negative stress, no load) is refused; after it, every curve gets the
single-curve path's diagnostics (its residual against its own noise, R^2) and a curve the law
does not follow is named in a warning with the likely cause
(:mod:`colonsim.identification.curve_checks`).

The search is the project's (:mod:`colonsim.identification.search`: Latin hypercube, CMA-ES,
Nelder-Mead) with :meth:`Budget.closed_form`, followed by a bounded trust-region least-squares
polish (scipy ``least_squares``) from the Nelder-Mead optimum and from the 10 best hypercube
designs (the optimum only with the FE strip), the best of which wins: Ogden's landscape has local minima (terms pressed against their
exponent bounds) where CMA-ES can settle, and the polish, cheap in closed form, leaves them. Its
evaluations are recorded as stage ``least-squares``. The uncertainty the linearised one of
:mod:`colonsim.identification.uncertainty`. A uniaxial strip given as force and displacement is
read through its geometry (:func:`colonsim.identification.stress_curves.from_strip`); with
``strip_model="fe"`` its prediction is the clamped FE strip's force over the section instead of
the closed form (every law, Ogden's included).

Parameter bounds come from the data: with G the largest secant modulus of the curves read as a
neo-Hookean solid (:func:`characteristic_modulus`) and a the largest ``I1 - 3`` the tests reach,
the invariant constants lie in +-5 G / a^(k-1) for a term of order k in (I1 - 3), (I2 - 3);
Ogden's mu_p in +-5 G and the exponents in disjoint ranges (one term: 0.1..30; two: 0.1..4 and
4..30; three: those and -30..-0.1), which removes the relabelling symmetry of the terms. The
bounds are symmetric about zero, so the optimum lies inside the box, not pressed against a bound
(where the clipped objective is flat and CMA-ES stalls); a negative constant is allowed (rubber
fits have them) and the Drucker check says what it does.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import optimize

from colonsim.errors import ColonsimError
from colonsim.identification.curve_checks import check_plausible, curve_misfit, misfit_warnings
from colonsim.identification.hyperelastic import CalibrationLaw, calibration_law, mode_stretches
from colonsim.identification.search import Budget, SearchProblem, search
from colonsim.identification.specimen import ClampedStripModel, FEConvergenceError
from colonsim.identification.stability import StabilityCheck, check_stability, default_range
from colonsim.identification.stress_curves import ModeCurve
from colonsim.identification.uncertainty import FitUncertainty, fit_uncertainty

RESIDUALS = ("relative", "absolute")


class UnsolvableNearFit(ColonsimError):
    """The clamped FE strip cannot be solved next to the fitted parameters (so no uncertainty):
    a law that fits only at the edge of what the strip can carry (Ogden terms of opposite sign
    cancelling each other)."""
RELATIVE_FLOOR = 0.1  # of the curve's peak stress
POLISH_STARTS = 10
STRIP_POINTS = 20  # stretches at which a force-displacement strip is compared (as the strip fit's --points)
_BOUND = 5.0
_ORDERS = {"C10": 1, "C01": 1, "C11": 2, "C20": 2, "C30": 3}
_ALPHA = {1: ((0.1, 30.0),), 2: ((0.1, 4.0), (4.0, 30.0)), 3: ((0.1, 4.0), (4.0, 30.0), (-30.0, -0.1))}


def characteristic_modulus(curves) -> float:
    """G, Pa: the largest secant modulus of the data read as a neo-Hookean solid, P / g(l) with g
    the neo-Hookean nominal stress of unit modulus in the curve's mode (l - l^-2, l - l^-5, l - l^-3)."""
    unit = calibration_law("neo_hookean")
    return max(float(np.max(np.abs(c.stress) / unit.nominal_stress(c.mode, c.stretch, [0.5]).clip(min=1e-12)))
               for c in curves if np.any(c.stretch > 1.0))


def data_bounds(law: CalibrationLaw, curves) -> dict:
    """Parameter bounds scaled by the data (see the module), ``{name: (low, high)}``."""
    G = characteristic_modulus(curves)
    a = max(1.0, max(float(np.sum(np.square(mode_stretches(c.mode, c.max_stretch)))) - 3.0 for c in curves))
    if law.terms:
        bounds = {}
        for i, (lo, hi) in enumerate(_ALPHA[law.terms], start=1):
            bounds[f"mu{i}"], bounds[f"alpha{i}"] = (-_BOUND * G, _BOUND * G), (lo, hi)
        return bounds
    return {n: (-_BOUND * G / a ** (_ORDERS[n] - 1), _BOUND * G / a ** (_ORDERS[n] - 1)) for n in law.parameter_names}


@dataclass
class _Piece:
    """One curve's points in the objective: stretches, measured stress, residual scale, prediction."""

    curve: ModeCurve
    stretch: np.ndarray
    stress: np.ndarray
    scale: np.ndarray
    model: object = None  # ClampedStripModel for an FE strip

    def predict(self, law, params):
        if self.model is not None:
            c = self.curve.strip
            return self.model.solve(params, (self.stretch - 1.0) * c.length) / (c.width * c.thickness)
        return law.nominal_stress(self.curve.mode, self.stretch, params)


class JointObjective:
    """Weighted stress residuals of one law over several curves (see the module)."""

    def __init__(self, curves, law, residuals="relative", strip_model="closed-form", mesh=(8, 3)):
        self.law = calibration_law(law) if isinstance(law, str) else law
        if residuals not in RESIDUALS:
            raise ColonsimError(f"--residuals {residuals!r}: use absolute or relative")
        if strip_model not in ("closed-form", "fe"):
            raise ColonsimError(f"strip model {strip_model!r}: use closed-form or fe")
        self.curves, self.residuals, self.strip_model = list(curves), residuals, strip_model
        if not self.curves:
            raise ColonsimError("no curves to fit")
        for c in self.curves:  # before any fitting: values that cannot be what the header says
            check_plausible(c)
        self.pieces = []
        for c in self.curves:
            if c.strip is not None:
                stretch = np.linspace(max(c.stretch[0], 1.0 + (c.max_stretch - 1.0) / STRIP_POINTS), c.max_stretch,
                                      STRIP_POINTS)
                stress = np.interp(stretch, c.stretch, c.stress)
            else:
                stretch, stress = np.asarray(c.stretch, float), np.asarray(c.stress, float)
            peak = float(np.max(np.abs(stress)))
            base = np.full(stress.size, peak) if residuals == "absolute" else np.maximum(np.abs(stress), RELATIVE_FLOOR * peak)
            model = None
            if strip_model == "fe" and c.strip is not None:
                s = c.strip
                model = ClampedStripModel(s.length, s.width, s.thickness, self.law.invariant or self.law.ogden,
                                          n_length=mesh[0], n_width=mesh[1])
            self.pieces.append(_Piece(c, stretch, stress, c.weight / (base * np.sqrt(stress.size)), model))
        self.target = np.concatenate([p.scale * p.stress for p in self.pieces])

    def predictions(self, params):
        """Nominal stress of every piece, Pa (list of arrays)."""
        return [p.predict(self.law, np.asarray(params, dtype=float)) for p in self.pieces]

    def simulate(self, params):
        return np.concatenate([p.scale * s for p, s in zip(self.pieces, self.predictions(params))])

    @property
    def max_stretch(self) -> float:
        return max(float(p.stretch[-1]) for p in self.pieces)


@dataclass
class JointResult:
    """A law fitted to several modes: parameters, per-curve fit quality, uncertainty, stability."""

    law: str
    names: tuple
    parameters: np.ndarray
    history: pd.DataFrame
    stages: dict
    sensitivity: pd.DataFrame
    uncertainty: FitUncertainty
    per_curve: pd.DataFrame
    fitted: pd.DataFrame
    stability: StabilityCheck
    fit: dict
    settings: dict = field(default_factory=dict)
    curves: list = field(default_factory=list, repr=False)
    warnings: list = field(default_factory=list)  # curves the law does not follow (curve_checks.misfit_warnings)

    @property
    def parameter_dict(self):
        return dict(zip(self.names, self.parameters.tolist()))

    @property
    def mu0(self) -> tuple[float, float]:
        """Small-strain shear modulus and its sd from the fit, Pa."""
        law = calibration_law(self.law)
        return law.initial_shear_modulus(self.parameters), self.uncertainty.linear_combination_std(
            law.shear_modulus_gradient(self.parameters))


def polish(objective: JointObjective, outcome, bounds, names):
    """Bounded least squares from the Nelder-Mead optimum and the best hypercube designs (see the
    module): (parameters, history with the polish's evaluations appended, stages)."""
    lo = np.array([bounds[n][0] for n in names])
    hi = np.array([bounds[n][1] for n in names])
    h = outcome.history
    designs = h[(h["stage"] == "sensitivity") & h["ok"]].nsmallest(POLISH_STARTS, "e1")
    starts = [outcome.theta] + [row.to_numpy(float) for _, row in designs[list(names)].iterrows()]
    if objective.strip_model == "fe":  # an FE evaluation costs 0.1 s, not microseconds: polish the optimum only
        starts = starts[:1]
    rows = []

    def residual(x):
        params = lo + x * (hi - lo)
        try:
            with np.errstate(over="ignore", invalid="ignore"):
                r = objective.target - objective.simulate(params)
        except FEConvergenceError:
            r = np.full(objective.target.size, np.nan)
        e1 = float(r @ r)
        ok = bool(np.isfinite(e1))
        rows.append({"evaluation": len(h) + len(rows), "stage": "least-squares", **dict(zip(names, params)),
                     "e1": e1 if ok else 1e6, "ok": ok})
        return r if ok else np.full(r.size, 1e3)

    best = None
    for start in starts:
        x0 = np.clip((np.asarray(start) - lo) / (hi - lo), 1e-9, 1 - 1e-9)
        sol = optimize.least_squares(residual, x0, bounds=(0.0, 1.0), x_scale="jac")
        if best is None or sol.cost < best.cost:
            best = sol
    history = pd.concat([h, pd.DataFrame(rows)], ignore_index=True)
    theta = lo + best.x * (hi - lo)
    e1 = float(2.0 * best.cost)
    if e1 > outcome.stages["nelder-mead"]["e1"]:  # never worse than the search found
        theta, e1 = outcome.theta, outcome.stages["nelder-mead"]["e1"]
    stages = {**outcome.stages, "least-squares": {"e1": e1, "evaluations": len(rows), "starts": len(starts),
                                                   "message": str(best.message)}}
    return theta, history, stages


def calibrate_joint(curves, law, residuals="relative", budget: Budget | None = None, seed=1, progress=None,
                    stability_range=None, strip_model="closed-form", mesh=(8, 3)) -> JointResult:
    """Fit ``law`` to all ``curves`` jointly (see the module); Drucker-check the result over
    ``stability_range`` (default: 0.5 to twice the largest tested stretch)."""
    t0 = time.perf_counter()
    objective = JointObjective(curves, law, residuals, strip_model, mesh)
    model = objective.law
    budget = budget or (Budget.closed_form() if strip_model == "closed-form" else Budget())
    bounds = data_bounds(model, objective.curves)
    names = model.parameter_names
    initial = {n: 0.5 * (lo + hi) for n, (lo, hi) in bounds.items()}
    problem = SearchProblem(objective.simulate, objective.target, failures=(FEConvergenceError,),
                            probes=("y_mid", "y_end"))
    with np.errstate(over="ignore", invalid="ignore"):
        outcome = search(problem, names, bounds, initial, budget, seed, progress)
    theta, history, stages = polish(objective, outcome, bounds, names)
    scales = np.array([hi - lo for lo, hi in bounds.values()])
    try:
        unc = fit_uncertainty(objective.simulate, objective.target, theta, names, scales)
    except FEConvergenceError as exc:
        raise UnsolvableNearFit(f"{model.name}: the clamped FE strip cannot be solved next to the fitted parameters "
                                f"({exc}), so their uncertainty is unknown; fit {model.name} in closed form "
                                "(--analytic) or choose another law") from None
    rows, fitted = [], []
    n_total = sum(p.stretch.size for p in objective.pieces)
    for piece, pred in zip(objective.pieces, objective.predictions(theta)):
        c = piece.curve
        share = len(names) * piece.stretch.size / n_total  # the parameters a curve's points absorb
        rows.append({"curve": c.name, "mode": c.mode, "weight": c.weight, "n_points": int(piece.stretch.size),
                     "max_stretch": float(piece.stretch[-1]), "max_stress_Pa": float(np.max(piece.stress)),
                     **curve_misfit(c, piece.stretch, piece.stress, pred, share)})
        fitted.append(pd.DataFrame({"curve": c.name, "mode": c.mode, "stretch": piece.stretch,
                                    "stress_exp_Pa": piece.stress, "stress_fit_Pa": pred}))
    r = objective.target - objective.simulate(theta)
    stability_range = stability_range or default_range(objective.max_stretch)
    fit = {"e1": float(r @ r), "n_points": int(r.size), "n_parameters": len(names), "residuals": residuals,
           "wall_time_s": time.perf_counter() - t0, "evaluations": len(history),
           "strip_model": strip_model if any(c.strip is not None for c in objective.curves) else None}
    settings = {"seed": seed, "budget": budget.__dict__.copy(), "bounds": {n: list(bounds[n]) for n in names},
                "bounds_rule": "from the data (colonsim.identification.joint)", "initial": initial}
    warnings = misfit_warnings(model.name, rows, objective.curves, model.initial_shear_modulus(theta))
    return JointResult(model.name, names, theta, history, stages, outcome.sensitivity, unc,
                       pd.DataFrame(rows), pd.concat(fitted, ignore_index=True),
                       check_stability(model, theta, stability_range), fit, settings, objective.curves, warnings)
