"""Homogeneous uniaxial tension of an incompressible strip in closed form."""

from __future__ import annotations

import numpy as np

from colonsim.identification.laws import Law


def uniaxial_invariants(stretch):
    """I1 and I2 of incompressible uniaxial stretch ``l``: I1 = l^2 + 2/l, I2 = 2 l + 1/l^2."""
    l = np.asarray(stretch, dtype=float)
    return l**2 + 2.0 / l, 2.0 * l + 1.0 / l**2


def nominal_stress(stretch, law: Law, params):
    """First Piola-Kirchhoff (nominal) stress of homogeneous uniaxial tension, Pa.

    P = 2 (l - l^-2) (W1 + W2 / l); for the three-parameter Mooney-Rivlin law this is
    docs/model.md's P = 2 (l - l^-2) [C10 + C11 (I2-3) + (C01 + C11 (I1-3)) / l].
    """
    l = np.asarray(stretch, dtype=float)
    I1, I2 = uniaxial_invariants(l)
    d = law(I1, I2, params)
    return 2.0 * (l - l**-2) * (d.W1 + d.W2 / l)


def homogeneous_force(displacement, length, width, thickness, law: Law, params):
    """Axial force (N) of a strip (m) stretched homogeneously by ``displacement`` (m)."""
    stretch = 1.0 + np.asarray(displacement, dtype=float) / length
    return nominal_stress(stretch, law, params) * width * thickness


def tangent_modulus(stretch, law: Law, params, h=1e-6):
    """Tangent modulus dP/dl of the uniaxial curve, Pa (central difference)."""
    l = np.asarray(stretch, dtype=float)
    return (nominal_stress(l + h, law, params) - nominal_stress(l - h, law, params)) / (2 * h)


class HomogeneousStripModel:
    """Closed-form stand-in for :class:`colonsim.identification.specimen.ClampedStripModel`.

    Same ``solve(params, displacements)`` interface; ignores the grips, so it is softer than the
    clamped FE model by a few percent (the reason the source used inverse FE).
    """

    grips = "none (homogeneous)"

    def __init__(self, length, width, thickness, law="mooney_rivlin_3"):
        from colonsim.identification.laws import get_law

        self.length, self.width, self.thickness = float(length), float(width), float(thickness)
        self.law = get_law(law) if isinstance(law, str) else law

    def solve(self, params, displacements):
        """Axial force, N, at each displacement, m."""
        return homogeneous_force(displacements, self.length, self.width, self.thickness, self.law, params)

    def describe(self) -> dict:
        return {"model": "homogeneous uniaxial (closed form)", "law": self.law.name}
