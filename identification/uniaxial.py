"""Homogeneous uniaxial tension of an incompressible strip in closed form."""

from __future__ import annotations

import numpy as np

from colonsim.laws import Law, get_law


def homogeneous_force(displacement, length, width, thickness, law: Law, params):
    """Axial force (N) of a strip (m) stretched homogeneously by ``displacement`` (m)."""
    stretch = 1.0 + np.asarray(displacement, dtype=float) / length
    return law.uniaxial_nominal_stress(stretch, params) * width * thickness


def tangent_modulus(stretch, law: Law, params, h=1e-6):
    """Tangent modulus dP/dl of the uniaxial curve, Pa (central difference)."""
    l = np.asarray(stretch, dtype=float)
    return (law.uniaxial_nominal_stress(l + h, params) - law.uniaxial_nominal_stress(l - h, params)) / (2 * h)


class HomogeneousStripModel:
    """Closed-form stand-in for :class:`colonsim.identification.specimen.ClampedStripModel`.

    Same ``solve(params, displacements)`` interface; ignores the grips, so it is softer than the
    clamped FE model by a few percent (the reason the source used inverse FE).
    """

    grips = "none (homogeneous)"

    def __init__(self, length, width, thickness, law="mooney_rivlin_3"):
        self.length, self.width, self.thickness = float(length), float(width), float(thickness)
        self.law = get_law(law) if isinstance(law, str) else law

    def solve(self, params, displacements):
        """Axial force, N, at each displacement, m."""
        return homogeneous_force(displacements, self.length, self.width, self.thickness, self.law, params)

    def describe(self) -> dict:
        return {"model": "homogeneous uniaxial (closed form)", "law": self.law.name}
