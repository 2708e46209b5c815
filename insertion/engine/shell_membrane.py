"""Membrane of the wall shell: constant-strain triangles of an incompressible hyperelastic law.

With the in-plane right Cauchy-Green tensor C (2x2) of a triangle, incompressibility gives the
thickness stretch lambda_3^2 = 1/det C, so I1 = tr C + 1/det C and I2 = tr C/det C + det C; the
reduced energy W(C) already contains the zero through-thickness stress, and S = 2 dW/dC
(docs/model.md).

The law is any of :data:`colonsim.laws.WALL_LAWS`, passed to the kernels as its index and a
float64 parameter array: :func:`law_derivatives` compiles the invariant laws' own energy functions
and dispatches on the index (a jitted function as a kernel argument would be recompiled in every
process). Adding an invariant law: its function and entry in :mod:`colonsim.laws`, and its branch
here. Numba's cache only watches each kernel's own file: after editing a law in colonsim/laws.py,
delete this folder's ``__pycache__`` (tests/test_wall_laws.py fails on a stale compiled law).

Ogden's law (:func:`colonsim.laws.ogden`) is a function of the principal stretches, not of the
invariants, and has its own branch (:func:`_ogden_membrane_stress`): the eigenvalues c_a >= c_b of
C give the in-plane stretches l_i = sqrt(c_i), the law the differences t_i = sigma_i - sigma_3, and
the principal second Piola-Kirchhoff stresses are S_i = t_i / l_i^2 along C's eigenvectors. The
projector on the first eigenvector, N = (C - c_b I) / (c_a - c_b), has entries bounded by 1 however
close c_a and c_b come, so S = S_b I + (S_a - S_b) N never divides by a vanishing difference; at
c_a = c_b exactly S is isotropic, S_a I.
"""

import math

import numba
import numpy as np

from colonsim import laws
from colonsim.errors import ColonsimError

_jit_law = numba.njit(cache=True, inline="always")
_mooney_rivlin_3 = _jit_law(laws.mooney_rivlin_3)
_mooney_rivlin_2 = _jit_law(laws.mooney_rivlin_2)
_neo_hookean = _jit_law(laws.neo_hookean)
_yeoh = _jit_law(laws.yeoh)
_ogden = _jit_law(laws.ogden)
_ogden_hessian = _jit_law(laws.ogden_hessian)
_OGDEN = laws.OGDEN_INDEX
_MOONEY_RIVLIN_3 = laws.LAWS["mooney_rivlin_3"].index
_MOONEY_RIVLIN_2 = laws.LAWS["mooney_rivlin_2"].index
_NEO_HOOKEAN = laws.LAWS["neo_hookean"].index
_YEOH = laws.LAWS["yeoh"].index


@numba.njit(cache=True, inline="always")
def law_derivatives(law, p, i1, i2):
    """(W, W1, W2, W11, W12, W22) of law number ``law`` with parameters ``p`` at (I1, I2); all
    NaN for an index without a branch (which :func:`check_dispatched` reports)."""
    if law == _MOONEY_RIVLIN_3:
        return _mooney_rivlin_3(i1, i2, p)
    if law == _MOONEY_RIVLIN_2:
        return _mooney_rivlin_2(i1, i2, p)
    if law == _NEO_HOOKEAN:
        return _neo_hookean(i1, i2, p)
    if law == _YEOH:
        return _yeoh(i1, i2, p)
    nan = math.nan
    return nan, nan, nan, nan, nan, nan


def check_dispatched(law, params):
    """Raise if the kernels have no branch for ``law`` (of :data:`colonsim.laws.WALL_LAWS`): its
    membrane stress in a stretched state must be finite."""
    if not np.all(np.isfinite(_membrane_stress(1.2, 0.05, 0.9, law.index, params))):
        raise ColonsimError(f"the shell kernels do not dispatch law {law.name} (index {law.index}); add its branch "
                            "to colonsim.insertion.engine.shell_membrane.law_derivatives.")


def reference_frames(nodes, triangles):
    """Inverse reference edge matrices and areas of the triangles.

    Returns
    -------
    dm_inv : (nt, 2, 2) float64
        Inverse of the 2x2 matrix of reference edges (x1 - x0, x2 - x0) in a local
        orthonormal frame of each triangle's plane.
    area0 : (nt,) float64
        Reference areas, m^2.
    """
    p = nodes[triangles]
    e1 = p[:, 1] - p[:, 0]
    e2 = p[:, 2] - p[:, 0]
    normal = np.cross(e1, e2)
    twice_area = np.linalg.norm(normal, axis=1)
    if np.any(twice_area <= 1e-14 * np.einsum("ij,ij->i", e1, e1)):
        bad = int(np.argmin(twice_area))
        raise ColonsimError(f"triangle {bad} of the wall mesh is degenerate (zero area); fix the mesh.")
    t1 = e1 / np.linalg.norm(e1, axis=1)[:, None]
    n = normal / twice_area[:, None]
    t2 = np.cross(n, t1)
    dm = np.empty((len(triangles), 2, 2))
    dm[:, 0, 0] = np.einsum("ij,ij->i", e1, t1)
    dm[:, 0, 1] = np.einsum("ij,ij->i", e2, t1)
    dm[:, 1, 0] = 0.0
    dm[:, 1, 1] = np.einsum("ij,ij->i", e2, t2)
    return np.ascontiguousarray(np.linalg.inv(dm)), 0.5 * twice_area


@numba.njit(cache=True, inline="always")
def _ogden_membrane_stress(c00, c01, c11, p):
    """W and S = 2 dW/dC of Ogden's law (parameters ``p``) for C = [[c00, c01], [c01, c11]], det C > 0."""
    half_diff = 0.5 * (c00 - c11)
    disc = math.sqrt(half_diff * half_diff + c01 * c01)
    ca = 0.5 * (c00 + c11) + disc
    cb = (c00 * c11 - c01 * c01) / ca  # det C / c_a: no cancellation when c_b << c_a
    w, ta, tb = _ogden(math.sqrt(ca), math.sqrt(cb), p)
    sa = ta / ca
    sb = tb / cb
    if disc > 0.0:
        # projector on C's first eigenvector: (C - c_b I) / (c_a - c_b), entries in [-1, 1]
        n00 = 0.5 + 0.5 * half_diff / disc
        n11 = 0.5 - 0.5 * half_diff / disc
        n01 = 0.5 * c01 / disc
        ds = sa - sb
        return w, sb + ds * n00, ds * n01, sb + ds * n11
    return w, sa, 0.0, sa  # equal stretches: isotropic in-plane stress


@numba.njit(cache=True, inline="always")
def _membrane_stress(c00, c01, c11, law, p):
    """Reduced energy density W and S = 2 dW/dC for a 2x2 C = [[c00, c01], [c01, c11]]."""
    if law == _OGDEN:
        return _ogden_membrane_stress(c00, c01, c11, p)
    det = c00 * c11 - c01 * c01
    inv_det = 1.0 / det
    tr = c00 + c11
    i1 = tr + inv_det
    i2 = tr * inv_det + det
    w, w1, w2, _, _, _ = law_derivatives(law, p, i1, i2)
    # C^-1 = [[c11, -c01], [-c01, c00]] / det
    # dI1/dC = I - C^-1 / det ; dI2/dC = I / det + (det - tr / det) C^-1
    a = w1 * (-inv_det) + w2 * (det - tr * inv_det)  # coefficient of C^-1
    b = w1 + w2 * inv_det  # coefficient of I
    s00 = 2.0 * (b + a * c11 * inv_det)
    s11 = 2.0 * (b + a * c00 * inv_det)
    s01 = 2.0 * (-a * c01 * inv_det)
    return w, s00, s01, s11


@numba.njit(cache=True, inline="always")
def membrane_triangle(x, tri, dm_inv, vol, law, p, e):
    """Energy and forces of triangle ``e`` (volume ``vol``): (energy, ok, h1, h2) with h1, h2 the
    force 3-vectors on its nodes 1 and 2 (node 0 gets -(h1 + h2)); ok False if det C <= 0."""
    i0 = tri[e, 0]
    i1 = tri[e, 1]
    i2 = tri[e, 2]
    return membrane_terms(x[i1, 0] - x[i0, 0], x[i1, 1] - x[i0, 1], x[i1, 2] - x[i0, 2], x[i2, 0] - x[i0, 0],
                          x[i2, 1] - x[i0, 1], x[i2, 2] - x[i0, 2], dm_inv[e, 0, 0], dm_inv[e, 0, 1], dm_inv[e, 1, 0],
                          dm_inv[e, 1, 1], vol, law, p)


@numba.njit(cache=True, inline="always")
def membrane_terms(d10, d11, d12, d20, d21, d22, m00, m01, m10, m11, vol, law, p):
    """:func:`membrane_triangle` from the triangle's edges (d1 = x1 - x0, d2 = x2 - x0), the
    entries of its Dm_inv and its volume: no memory access but the law's parameters ``p``, so a
    loop over a block of triangles runs several at once in the vector registers."""
    # Ds = [x1 - x0, x2 - x0] (3x2); F = Ds Dm_inv
    f00 = d10 * m00 + d20 * m10
    f10 = d11 * m00 + d21 * m10
    f20 = d12 * m00 + d22 * m10
    f01 = d10 * m01 + d20 * m11
    f11 = d11 * m01 + d21 * m11
    f21 = d12 * m01 + d22 * m11
    c00 = f00 * f00 + f10 * f10 + f20 * f20
    c11 = f01 * f01 + f11 * f11 + f21 * f21
    c01 = f00 * f01 + f10 * f11 + f20 * f21
    if c00 * c11 - c01 * c01 <= 0.0:
        return 0.0, False, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    w, s00, s01, s11 = _membrane_stress(c00, c01, c11, law, p)
    # P = F S (3x2); H = -vol P Dm_inv^T gives the forces on nodes 1 and 2.
    p00 = f00 * s00 + f01 * s01
    p01 = f00 * s01 + f01 * s11
    p10 = f10 * s00 + f11 * s01
    p11 = f10 * s01 + f11 * s11
    p20 = f20 * s00 + f21 * s01
    p21 = f20 * s01 + f21 * s11
    h10 = -vol * (p00 * m00 + p01 * m01)
    h11 = -vol * (p10 * m00 + p11 * m01)
    h12 = -vol * (p20 * m00 + p21 * m01)
    h20 = -vol * (p00 * m10 + p01 * m11)
    h21 = -vol * (p10 * m10 + p11 * m11)
    h22 = -vol * (p20 * m10 + p21 * m11)
    return vol * w, True, (h10, h11, h12), (h20, h21, h22)


@numba.njit(cache=True)
def _sym2_max_eig(a, b, c):
    """Largest eigenvalue of [[a, b], [b, c]]."""
    return 0.5 * (a + c) + math.sqrt(0.25 * (a - c) ** 2 + b * b)


@numba.njit(cache=True)
def _ogden_principal_stress_tangent(a, b, params):
    """:func:`_principal_stress_tangent` of Ogden's law, from its derivatives in the stretches
    l1 = sqrt(a), l2 = sqrt(b) (:func:`colonsim.laws.ogden_hessian`): with W_1 = t_1 / l1,
    2 dW/da = t_1 / a, 4 d2W/da2 = (W_11 - t_1 / a) / a and 4 d2W/dadb = W_12 / (l1 l2)."""
    l1 = math.sqrt(a)
    l2 = math.sqrt(b)
    _, t1, _ = _ogden(l1, l2, params)
    w11, w12, _ = _ogden_hessian(l1, l2, params)
    s_a = t1 / a
    return s_a, (w11 - s_a) / a, w12 / (l1 * l2)


@numba.njit(cache=True)
def _principal_stress_tangent(p, q, law, params):
    """S_1 = 2 dW/da and the second derivatives 4 d2W/da2, 4 d2W/dadb of the reduced energy in
    the principal values (a, b) = (p, q) of C."""
    if law == _OGDEN:
        return _ogden_principal_stress_tangent(p, q, params)
    # I1 = a + b + 1/(ab); I2 = 1/a + 1/b + ab
    i1 = p + q + 1.0 / (p * q)
    i2 = 1.0 / p + 1.0 / q + p * q
    _, w1, w2, w11, w12, w22 = law_derivatives(law, params, i1, i2)
    i1_a = 1.0 - 1.0 / (p * p * q)
    i1_b = 1.0 - 1.0 / (p * q * q)
    i2_a = -1.0 / (p * p) + q
    i2_b = -1.0 / (q * q) + p
    i1_aa = 2.0 / (p * p * p * q)
    i1_ab = 1.0 / (p * p * q * q)
    i2_aa = 2.0 / (p * p * p)
    i2_ab = 1.0
    s_a = 2.0 * (w1 * i1_a + w2 * i2_a)
    # chain rule; the W12 term first, then those a Mooney-Rivlin law has zero
    w_aa = w1 * i1_aa + w2 * i2_aa + 2.0 * w12 * i1_a * i2_a + w11 * i1_a * i1_a + w22 * i2_a * i2_a
    w_ab = w1 * i1_ab + w2 * i2_ab + w12 * (i1_a * i2_b + i1_b * i2_a) + w11 * i1_a * i1_b + w22 * i2_a * i2_b
    return s_a, 4.0 * w_aa, 4.0 * w_ab


@numba.njit(parallel=True, cache=True)
def membrane_omega2_kernel(x, tri, dm_inv, thickness, density, law, params, mass_scale, out):
    """Upper bound of each triangle's largest squared eigenfrequency, rad^2/s^2, into ``out``.

    Element eigenvalue bound (Irons): the lumped element mass is density t A / 3 per node
    (times the smallest mass-scaling factor of its nodes) and
    u.K_e.u = t A H:A:H <= t A a_max |H|^2 <= t A a_max lambda_max(G) |u|^2, with H = grad u,
    G_ij = g_i . g_j the Gram matrix of the shape function gradients and a_max the exact largest
    eigenvalue of the current tangent A = d2W/dF2. For the reduced energy Psi(l1, l2) of the
    in-plane principal stretches, A splits into the normal block d2Psi/dl_i dl_j, the in-plane
    shear pair with eigenvalues (Psi_1 - Psi_2)/(l1 - l2) and (Psi_1 + Psi_2)/(l1 + l2), and the
    out-of-plane (membrane tension) terms Psi_i / l_i.
    """
    nt = tri.shape[0]
    for e in numba.prange(nt):
        i0 = tri[e, 0]
        i1 = tri[e, 1]
        i2 = tri[e, 2]
        m00 = dm_inv[e, 0, 0]
        m01 = dm_inv[e, 0, 1]
        m10 = dm_inv[e, 1, 0]
        m11 = dm_inv[e, 1, 1]
        c00 = 0.0
        c11 = 0.0
        c01 = 0.0
        for k in range(3):
            d1 = x[i1, k] - x[i0, k]
            d2 = x[i2, k] - x[i0, k]
            fa = d1 * m00 + d2 * m10
            fb = d1 * m01 + d2 * m11
            c00 += fa * fa
            c11 += fb * fb
            c01 += fa * fb
        half_tr = 0.5 * (c00 + c11)
        disc = math.sqrt(max(0.25 * (c00 - c11) ** 2 + c01 * c01, 0.0))
        pa = half_tr + disc
        pb = half_tr - disc
        if pb <= 0.0:
            out[e] = np.inf
            continue
        # S_i = 2 dW/dC_i, c_ij = 4 d2W/dC_i dC_j in the principal values of C.
        s_a, caa, cab = _principal_stress_tangent(pa, pb, law, params)
        s_b, cbb, _ = _principal_stress_tangent(pb, pa, law, params)
        la = math.sqrt(pa)
        lb = math.sqrt(pb)
        # Psi_i = l_i S_i, Psi_ii = S_i + C_i c_ii, Psi_ab = l_a l_b c_ab.
        psi_a = la * s_a
        psi_b = lb * s_b
        psi_aa = s_a + pa * caa
        psi_bb = s_b + pb * cbb
        psi_ab = la * lb * cab
        a_max = _sym2_max_eig(psi_aa, psi_ab, psi_bb)
        if la - lb > 1e-6 * la:
            shear = (psi_a - psi_b) / (la - lb)
        else:
            shear = psi_aa - psi_ab
        a_max = max(a_max, shear, (psi_a + psi_b) / (la + lb), s_a, s_b, 0.0)
        # Shape-function gradient Gram matrix: rows of Dm_inv are g_1, g_2; g_0 = -(g_1 + g_2).
        # Nonzero eigenvalues of G equal those of B^T B with B = [g_0; g_1; g_2] (3x2).
        g1x = m00
        g1y = m01
        g2x = m10
        g2y = m11
        g0x = -(g1x + g2x)
        g0y = -(g1y + g2y)
        bxx = g0x * g0x + g1x * g1x + g2x * g2x
        byy = g0y * g0y + g1y * g1y + g2y * g2y
        bxy = g0x * g0y + g1x * g1y + g2x * g2y
        lam_g = _sym2_max_eig(bxx, bxy, byy)
        smin = min(mass_scale[i0], mass_scale[i1], mass_scale[i2])
        out[e] = 3.0 * a_max * lam_g / (density * smin)
