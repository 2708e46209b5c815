"""Plane-stress incompressible membrane kinematics: stress and tangent from a law.

A thin incompressible sheet deformed in its plane by the 2x2 deformation gradient ``F`` has the
thickness stretch ``1 / det F`` (J = 1), so

    C = diag(F^T F, det(F)^-2),  I1 = |F|^2 + det(F)^-2,  I2 = |F|^2 / det(F)^2 + det(F)^2.

Using this reduced energy W(F) enforces zero through-thickness stress exactly, without a
pressure field. Tensors are flattened as ``[F11, F12, F21, F22]`` on the last axis.
"""

from __future__ import annotations

import numpy as np

from colonsim.laws import Law

# d(cof F)/dF for 2x2 F: cof F = [F22, -F21, -F12, F11] is linear in F.
_DCOF = np.zeros((4, 4))
_DCOF[0, 3] = _DCOF[3, 0] = 1.0
_DCOF[1, 2] = _DCOF[2, 1] = -1.0
_EYE4 = np.eye(4)


def _cofactor(F):
    return np.stack([F[..., 3], -F[..., 2], -F[..., 1], F[..., 0]], axis=-1)


def membrane_stress(F, law: Law, params, tangent=True):
    """Nominal stress P = dW/dF (..., 4), Pa, and optionally the tangent dP/dF (..., 4, 4)."""
    s = np.einsum("...i,...i->...", F, F)
    J = F[..., 0] * F[..., 3] - F[..., 1] * F[..., 2]
    G = _cofactor(F)
    d = law(s + J**-2, s / J**2 + J**2, params)
    Ji2, Ji3, Ji4 = J**-2, J**-3, J**-4
    dI1 = 2.0 * F - 2.0 * Ji3[..., None] * G
    dI2 = 2.0 * Ji2[..., None] * F + (2.0 * J - 2.0 * s * Ji3)[..., None] * G
    P = d.W1[..., None] * dI1 + d.W2[..., None] * dI2
    if not tangent:
        return P
    GG = G[..., :, None] * G[..., None, :]
    FG = F[..., :, None] * G[..., None, :]
    d2I1 = 2.0 * _EYE4 + (6.0 * Ji4)[..., None, None] * GG - (2.0 * Ji3)[..., None, None] * _DCOF
    d2I2 = (
        (2.0 * Ji2)[..., None, None] * _EYE4
        - (4.0 * Ji3)[..., None, None] * (FG + np.swapaxes(FG, -1, -2))
        + (6.0 * s * Ji4 + 2.0)[..., None, None] * GG
        + (2.0 * J - 2.0 * s * Ji3)[..., None, None] * _DCOF
    )
    A = (
        d.W11[..., None, None] * dI1[..., :, None] * dI1[..., None, :]
        + d.W12[..., None, None] * (dI1[..., :, None] * dI2[..., None, :] + dI2[..., :, None] * dI1[..., None, :])
        + d.W22[..., None, None] * dI2[..., :, None] * dI2[..., None, :]
        + d.W1[..., None, None] * d2I1
        + d.W2[..., None, None] * d2I2
    )
    return P, A
