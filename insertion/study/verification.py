"""What the verification problems share: the comparison they return and the standard bodies.

Each problem builds a small model with a closed-form answer, solves it and returns a
:class:`Comparison` of the analytic and the measured number: the rod's in
:mod:`~colonsim.insertion.study.verification_rod`, the wall's in
:mod:`~colonsim.insertion.study.verification_shell`, the integrator's energy accounting, contact and
friction in :mod:`~colonsim.insertion.study.verification_contact`. Which of them is checked, against
what rule and why, is listed once in :mod:`~colonsim.insertion.study.verification_table`, which the
test-suite parametrizes over and the validation report renders. SI units throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material

# The standard scope (catalogue diameter).
SCOPE_E = 16e6  # Pa
SCOPE_RHO = 2944.0  # kg/m^3
SCOPE_D = 12.8e-3  # m
WALL_T = 2e-3  # m, wall thickness (an assumption, docs/model.md)


@dataclass(frozen=True)
class Comparison:
    """An analytic value and what the model gives for it.

    ``extra`` holds further measured numbers of the same run that an acceptance rule may judge
    (e.g. the number of active contacts), by name.
    """

    quantity: str
    analytic: float
    measured: float
    unit: str = ""
    extra: dict[str, float] = field(default_factory=dict)

    @property
    def relative_error(self) -> float:
        """(measured - analytic) / |analytic|; NaN when the analytic value is zero."""
        return (self.measured - self.analytic) / abs(self.analytic) if self.analytic != 0.0 else math.nan


def reference_material():
    return load_material(REFERENCE_MATERIAL_PATH)
