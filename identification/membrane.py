"""Plane-stress incompressible membrane kinematics: stress and tangent from a law.

A thin incompressible sheet deformed in its plane by the 2x2 deformation gradient ``F`` has the
thickness stretch ``1 / det F`` (J = 1), so

    C = diag(F^T F, det(F)^-2),  I1 = |F|^2 + det(F)^-2,  I2 = |F|^2 / det(F)^2 + det(F)^2.

Using this reduced energy W(F) enforces zero through-thickness stress exactly, without a
pressure field. Tensors are flattened as ``[F11, F12, F21, F22]`` on the last axis.

Ogden's law (:class:`colonsim.laws.OgdenLaw`) is a function of the singular values of F, the
in-plane stretches: with F = U diag(l1, l2) V^T, P = U diag(W_1, W_2) V^T, and the tangent has the
eigen-decomposition of an isotropic energy of the stretches: the block W_ij on the stretch
directions U e_i e_i^T V^T, and two shear directions, U [[0, -1], [1, 0]] V^T / sqrt 2 with
(W_1 + W_2) / (l1 + l2) and U [[0, 1], [1, 0]] V^T / sqrt 2 with (W_1 - W_2) / (l1 - l2), which
becomes W_11 - W_12 as the stretches meet (below a relative difference of 1e-6).
"""

from __future__ import annotations

import numpy as np

from colonsim.laws import Law, OgdenLaw

# d(cof F)/dF for 2x2 F: cof F = [F22, -F21, -F12, F11] is linear in F.
_DCOF = np.zeros((4, 4))
_DCOF[0, 3] = _DCOF[3, 0] = 1.0
_DCOF[1, 2] = _DCOF[2, 1] = -1.0
_EYE4 = np.eye(4)


def _cofactor(F):
    return np.stack([F[..., 3], -F[..., 2], -F[..., 1], F[..., 0]], axis=-1)


_TWIST = np.array([[0.0, -1.0], [1.0, 0.0]]) / np.sqrt(2.0)
_FLIP = np.array([[0.0, 1.0], [1.0, 0.0]]) / np.sqrt(2.0)
EQUAL_STRETCHES = 1e-6  # relative difference below which the flip stiffness takes its limit


def _ogden_stress(F, law: OgdenLaw, params, tangent):
    """:func:`membrane_stress` of Ogden's law, through the singular values of F (see the module)."""
    M = F.reshape(*F.shape[:-1], 2, 2)
    C = np.swapaxes(M, -1, -2) @ M
    theta = 0.5 * np.arctan2(2.0 * C[..., 0, 1], C[..., 0, 0] - C[..., 1, 1])  # first eigenvector of C
    c, s_ = np.cos(theta), np.sin(theta)
    V = np.stack([np.stack([c, -s_], axis=-1), np.stack([s_, c], axis=-1)], axis=-2)  # columns v_a, v_b
    MV = M @ V
    l1, l2 = np.linalg.norm(MV[..., 0], axis=-1), np.linalg.norm(MV[..., 1], axis=-1)
    U = MV / np.stack([l1, l2], axis=-1)[..., None, :]
    _, t1, t2 = law.principal(l1, l2, params)
    w1, w2 = t1 / l1, t2 / l2

    def outer(D):  # U D V^T flattened, for a 2x2 D (broadcast)
        return (U @ D @ np.swapaxes(V, -1, -2)).reshape(*F.shape)

    e1, e2 = np.diag([1.0, 0.0]), np.diag([0.0, 1.0])
    d1, d2 = outer(e1), outer(e2)
    P = w1[..., None] * d1 + w2[..., None] * d2
    if not tangent:
        return P
    w11, w12, w22 = law.hessian(l1, l2, params)
    near = l1 - l2 <= EQUAL_STRETCHES * l1
    flip = np.where(near, w11 - w12, (w1 - w2) / np.where(near, 1.0, l1 - l2))
    twist = (w1 + w2) / (l1 + l2)
    t, f = outer(_TWIST), outer(_FLIP)

    def dyad(a, b):
        return a[..., :, None] * b[..., None, :]

    A = (w11[..., None, None] * dyad(d1, d1) + w22[..., None, None] * dyad(d2, d2)
         + w12[..., None, None] * (dyad(d1, d2) + dyad(d2, d1))
         + twist[..., None, None] * dyad(t, t) + flip[..., None, None] * dyad(f, f))
    return P, A


def membrane_stress(F, law: Law | OgdenLaw, params, tangent=True):
    """Nominal stress P = dW/dF (..., 4), Pa, and optionally the tangent dP/dF (..., 4, 4)."""
    if isinstance(law, OgdenLaw):
        return _ogden_stress(F, law, params, tangent)
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
