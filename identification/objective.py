"""The calibration objective of docs/model.md.

    e1 = sum_i (F_exp_i - F_sim_i)^2      (N^2)

evaluated at the simulation's displacement points, with the experimental curve linearly
interpolated onto them (test machine and model are never sampled alike).
"""

from __future__ import annotations

import numpy as np

from colonsim.identification.specimen import ClampedStripModel, FEConvergenceError
from colonsim.identification.testdata import TensileCurve
from colonsim.identification.uniaxial import HomogeneousStripModel


def make_model(curve: TensileCurve, law="mooney_rivlin_3", analytic=False, **mesh):
    """The force model of one specimen: clamped FE strip, or the closed form with ``analytic``."""
    if analytic:
        return HomogeneousStripModel(curve.length, curve.width, curve.thickness, law)
    return ClampedStripModel(curve.length, curve.width, curve.thickness, law, **mesh)


class CurveObjective:
    """Sum of squared force differences between a test curve and a force model.

    Parameters
    ----------
    curve : TensileCurve
    model : object with ``solve(params, displacements) -> forces``
    n_points : int
        Simulation displacement points, evenly spaced up to the last measured displacement.
    failure_value : float
        Objective returned when the model cannot be solved for a parameter set (recorded as
        failed, never NaN), default 1e6 N^2.
    """

    def __init__(self, curve: TensileCurve, model, n_points=20, failure_value=1e6):
        self.curve = curve
        self.model = model
        start = max(curve.displacement[0], curve.max_displacement / n_points)
        self.displacement = np.linspace(start, curve.max_displacement, n_points)
        self.force_exp = curve.force_at(self.displacement)
        self.failure_value = float(failure_value)

    def simulate(self, params):
        """Model forces at the simulation points, N."""
        return self.model.solve(np.asarray(params, dtype=float), self.displacement)

    def residuals(self, params):
        return self.force_exp - self.simulate(params)

    def __call__(self, params) -> float:
        try:
            r = self.residuals(params)
        except FEConvergenceError:
            return self.failure_value
        value = float(r @ r)
        return value if np.isfinite(value) else self.failure_value
