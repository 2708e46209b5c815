"""Thin hyperelastic shell for the colon wall: membrane triangles, hinge bending, pressure.

Membrane: constant-strain triangles, incompressible Mooney-Rivlin in plane stress. With the
in-plane right Cauchy-Green tensor C (2x2) of a triangle, incompressibility gives the thickness
stretch lambda_3^2 = 1/det C, so I1 = tr C + 1/det C and I2 = tr C/det C + det C; the reduced
energy W(C) already contains the zero through-thickness stress, and S = 2 dW/dC.

Bending: discrete hinges (Grinspun et al. 2003, Bridson et al. 2003), energy
k_e (theta - theta0)^2 per interior edge, with k_e = D |e|^2 / (2 (A_1 + A_2)) from the reference
edge length and the areas of its two triangles. On an equilateral mesh bent by a small curvature
tensor K, a hinge whose edge has in-plane unit normal n turns by
theta = -(|e| / sqrt(3)) (2 K_nn - tr K / 2); summed over the three edge directions this gives
sum |e|^2 theta^2 / (A_1 + A_2) = (4/3) (m^2 + 2 r^2) per unit area, with m = (k1 + k2)/2 and
r = (k1 - k2)/2 from the principal curvatures. For a cylinder of radius R (m = r = 1/(2R)) that is
1/R^2 whatever the cylinder's direction, so this k_e gives D / (2 R^2) per area, the plate energy
of cylindrical bending, with D = E0 t^3 / (12 (1 - nu^2)) = E0 t^3 / 9 for nu = 1/2. The hinge
model's own Poisson ratio is -1/3 (energy (2/3) D (m^2 + 2 r^2) against D ((1 + nu) m^2 +
(1 - nu) r^2) for a plate): cylindrical bending, the dominant mode of a colon wall, is matched
exactly; spherical bending is 2.25 times too soft and saddle bending 2.7 times too stiff.
Tests: tests/test_shell_bending.py.

All kernels are ``numba`` functions over raw arrays writing per-element buffers that
:func:`colonsim.insertion.engine._scatter.gather` sums onto nodes without races.
"""

import math

import numba
import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.engine._scatter import gather, node_incidence
from colonsim.insertion.engine.sheet_mesh import hinges as mesh_hinges

# ---------------------------------------------------------------------------------------------
# Reference geometry
# ---------------------------------------------------------------------------------------------


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


# ---------------------------------------------------------------------------------------------
# Membrane
# ---------------------------------------------------------------------------------------------


@numba.njit(cache=True, inline="always")
def _mr_stress(c00, c01, c11, C10, C01, C11):
    """Reduced Mooney-Rivlin energy density W and S = 2 dW/dC for a 2x2 C = [[c00, c01], [c01, c11]]."""
    det = c00 * c11 - c01 * c01
    inv_det = 1.0 / det
    tr = c00 + c11
    i1 = tr + inv_det
    i2 = tr * inv_det + det
    w1 = C10 + C11 * (i2 - 3.0)
    w2 = C01 + C11 * (i1 - 3.0)
    w = C10 * (i1 - 3.0) + C01 * (i2 - 3.0) + C11 * (i1 - 3.0) * (i2 - 3.0)
    # C^-1 = [[c11, -c01], [-c01, c00]] / det
    # dI1/dC = I - C^-1 / det ; dI2/dC = I / det + (det - tr / det) C^-1
    a = w1 * (-inv_det) + w2 * (det - tr * inv_det)  # coefficient of C^-1
    b = w1 + w2 * inv_det  # coefficient of I
    s00 = 2.0 * (b + a * c11 * inv_det)
    s11 = 2.0 * (b + a * c00 * inv_det)
    s01 = 2.0 * (-a * c01 * inv_det)
    return w, s00, s01, s11


@numba.njit(cache=True, inline="always")
def _membrane_triangle(x, tri, dm_inv, vol, C10, C01, C11, e):
    """Energy and forces of triangle ``e`` (volume ``vol``): (energy, ok, h1, h2) with h1, h2 the
    force 3-vectors on its nodes 1 and 2 (node 0 gets -(h1 + h2)); ok False if det C <= 0."""
    i0 = tri[e, 0]
    i1 = tri[e, 1]
    i2 = tri[e, 2]
    # Ds = [x1 - x0, x2 - x0] (3x2); F = Ds Dm_inv
    d10 = x[i1, 0] - x[i0, 0]
    d11 = x[i1, 1] - x[i0, 1]
    d12 = x[i1, 2] - x[i0, 2]
    d20 = x[i2, 0] - x[i0, 0]
    d21 = x[i2, 1] - x[i0, 1]
    d22 = x[i2, 2] - x[i0, 2]
    m00 = dm_inv[e, 0, 0]
    m01 = dm_inv[e, 0, 1]
    m10 = dm_inv[e, 1, 0]
    m11 = dm_inv[e, 1, 1]
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
    w, s00, s01, s11 = _mr_stress(c00, c01, c11, C10, C01, C11)
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


@numba.njit(parallel=True, cache=True)
def membrane_kernel(x, tri, dm_inv, area0, thickness, C10, C01, C11, elem_f):
    """Constant-strain Mooney-Rivlin membrane: per-triangle forces into ``elem_f`` (nt, 3, 3).

    Returns
    -------
    energy : float
        Membrane strain energy, J.
    n_inverted : int
        Number of triangles with det C <= 0 (their forces are set to zero).
    """
    nt = tri.shape[0]
    energy = 0.0
    n_inverted = 0
    for e in numba.prange(nt):
        w, ok, h1, h2 = _membrane_triangle(x, tri, dm_inv, thickness * area0[e], C10, C01, C11, e)
        if not ok:
            n_inverted += 1
        energy += w
        for k in range(3):
            elem_f[e, 1, k] = h1[k]
            elem_f[e, 2, k] = h2[k]
            elem_f[e, 0, k] = -(h1[k] + h2[k])
    return energy, n_inverted


@numba.njit(cache=True)
def _sym2_max_eig(a, b, c):
    """Largest eigenvalue of [[a, b], [b, c]]."""
    return 0.5 * (a + c) + math.sqrt(0.25 * (a - c) ** 2 + b * b)


@numba.njit(cache=True)
def _mr_principal(p, q, C10, C01, C11):
    """S_1 = 2 dW/da and the second derivatives 4 d2W/da2, 4 d2W/dadb of the reduced energy in
    the principal values (a, b) = (p, q) of C."""
    # I1 = a + b + 1/(ab); I2 = 1/a + 1/b + ab
    i1 = p + q + 1.0 / (p * q)
    i2 = 1.0 / p + 1.0 / q + p * q
    w1 = C10 + C11 * (i2 - 3.0)
    w2 = C01 + C11 * (i1 - 3.0)
    i1_a = 1.0 - 1.0 / (p * p * q)
    i1_b = 1.0 - 1.0 / (p * q * q)
    i2_a = -1.0 / (p * p) + q
    i2_b = -1.0 / (q * q) + p
    i1_aa = 2.0 / (p * p * p * q)
    i1_ab = 1.0 / (p * p * q * q)
    i2_aa = 2.0 / (p * p * p)
    i2_ab = 1.0
    s_a = 2.0 * (w1 * i1_a + w2 * i2_a)
    w_aa = w1 * i1_aa + w2 * i2_aa + 2.0 * C11 * i1_a * i2_a
    w_ab = w1 * i1_ab + w2 * i2_ab + C11 * (i1_a * i2_b + i1_b * i2_a)
    return s_a, 4.0 * w_aa, 4.0 * w_ab


@numba.njit(parallel=True, cache=True)
def membrane_omega2_kernel(x, tri, dm_inv, thickness, density, C10, C01, C11, mass_scale, out):
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
        s_a, caa, cab = _mr_principal(pa, pb, C10, C01, C11)
        s_b, cbb, _ = _mr_principal(pb, pa, C10, C01, C11)
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


# ---------------------------------------------------------------------------------------------
# Bending hinges
# ---------------------------------------------------------------------------------------------


@numba.njit(cache=True, inline="always")
def _atan(t):
    """Arctangent of t to about 1 ulp (Cephes atan, S. Moshier): rational approximation after a
    reduction to |t| <= 0.66, without the slow correctly-rounded paths of libm's atan2, which
    cost ~20 ns per call and made up a third of the hinge kernel. Written with selects rather
    than branches so that a loop over many angles runs them side by side."""
    a = abs(t)
    big = a > 2.41421356237309504880  # tan(3 pi / 8)
    mid = a > 0.66
    more_bits = 6.123233995736765886130e-17  # pi/2 - float(pi/2)
    num = -1.0 if big else (a - 1.0 if mid else a)
    den = a if big else (a + 1.0 if mid else 1.0)
    y = 0.5 * math.pi if big else (0.25 * math.pi if mid else 0.0)
    corr = more_bits if big else (0.5 * more_bits if mid else 0.0)
    r = num / den
    z = r * r
    p = (
        (((-8.750608600031904122785e-1 * z - 1.615753718733365076637e1) * z - 7.500855792314704667340e1) * z
         - 1.228866684490136173410e2) * z
        - 6.485021904942025371773e1
    )
    q = (
        ((((z + 2.485846490142306297962e1) * z + 1.650270098316988542046e2) * z + 4.328810604912902668951e2) * z
         + 4.853903996359136964868e2) * z
        + 1.945506571482613964425e2
    )
    z = r * (z * p / q) + r
    return math.copysign(y + (z + corr), t)


@numba.njit(cache=True, inline="always")
def _atan2(y, x):
    """atan2(y, x) through :func:`_atan` (same quadrants and signed zeros as math.atan2); x = 0
    and NaN go to math.atan2."""
    if x > 0.0:
        return _atan(y / x)
    if x < 0.0:
        return _atan(y / x) + math.copysign(math.pi, y)
    return math.atan2(y, x)


@numba.njit(cache=True, inline="always")
def _hinge_terms(x, a, b, c, d):
    """Arguments of the signed dihedral angle of hinge (a, b, c, d) and its gradient.

    theta = atan2((n1 x n2) . e_hat, n1 . n2), n1 = e x (x_c - x_a), n2 = (x_d - x_a) x e,
    e = x_b - x_a. Zero for a flat hinge; the standard gradient
    d theta/d x_c = -|e| n1 / |n1|^2, d theta/d x_d = -|e| n2 / |n2|^2 and the edge nodes'
    shares from the projections of x_c, x_d on the edge (translation invariance):
    d theta/d x_a = -(1 - al1) g_c - (1 - al2) g_d, d theta/d x_b = -al1 g_c - al2 g_d.
    Returns (sin_part, cos_part, ok, g_c, g_d, al1, al2), theta = atan2(sin_part, cos_part), with
    ok False for a zero-area triangle (gradient then undefined).
    """
    e0 = x[b, 0] - x[a, 0]
    e1 = x[b, 1] - x[a, 1]
    e2 = x[b, 2] - x[a, 2]
    u0 = x[c, 0] - x[a, 0]
    u1 = x[c, 1] - x[a, 1]
    u2 = x[c, 2] - x[a, 2]
    v0 = x[d, 0] - x[a, 0]
    v1 = x[d, 1] - x[a, 1]
    v2 = x[d, 2] - x[a, 2]
    # n1 = e x u ; n2 = v x e
    n10 = e1 * u2 - e2 * u1
    n11 = e2 * u0 - e0 * u2
    n12 = e0 * u1 - e1 * u0
    n20 = v1 * e2 - v2 * e1
    n21 = v2 * e0 - v0 * e2
    n22 = v0 * e1 - v1 * e0
    ee = e0 * e0 + e1 * e1 + e2 * e2
    nn1 = n10 * n10 + n11 * n11 + n12 * n12
    nn2 = n20 * n20 + n21 * n21 + n22 * n22
    zero = (0.0, 0.0, 0.0)
    if not (nn1 > 0.0 and nn2 > 0.0 and ee > 0.0):
        return 0.0, 1.0, False, zero, zero, 0.0, 0.0
    le = math.sqrt(ee)
    # (n1 x n2) . e / |e| and n1 . n2
    cx0 = n11 * n22 - n12 * n21
    cx1 = n12 * n20 - n10 * n22
    cx2 = n10 * n21 - n11 * n20
    sin_part = (cx0 * e0 + cx1 * e1 + cx2 * e2) / le
    cos_part = n10 * n20 + n11 * n21 + n12 * n22
    s1 = -le / nn1
    s2 = -le / nn2
    al1 = (u0 * e0 + u1 * e1 + u2 * e2) / ee
    al2 = (v0 * e0 + v1 * e1 + v2 * e2) / ee
    return sin_part, cos_part, True, (s1 * n10, s1 * n11, s1 * n12), (s2 * n20, s2 * n21, s2 * n22), al1, al2


@numba.njit(cache=True, inline="always")
def _hinge_gradient(x, a, b, c, d):
    """Signed dihedral angle of hinge (a, b, c, d) and its gradient (see :func:`_hinge_terms`):
    (theta, ok, g_c, g_d, al1, al2)."""
    sin_part, cos_part, ok, gc, gd, al1, al2 = _hinge_terms(x, a, b, c, d)
    return _atan2(sin_part, cos_part), ok, gc, gd, al1, al2


@numba.njit(cache=True, inline="always")
def _hinge_geometry(x, a, b, c, d, g, h):
    """Signed dihedral angle of hinge (a, b, c, d) (see :func:`_hinge_gradient`); its gradient
    goes to ``g[h]`` (4, 3). Returns (theta, ok)."""
    theta, ok, gc, gd, al1, al2 = _hinge_gradient(x, a, b, c, d)
    for k in range(3):
        g[h, 2, k] = gc[k]
        g[h, 3, k] = gd[k]
        g[h, 0, k] = -(1.0 - al1) * gc[k] - (1.0 - al2) * gd[k]
        g[h, 1, k] = -al1 * gc[k] - al2 * gd[k]
    return theta, ok


@numba.njit(parallel=True, cache=True)
def dihedral_angles(x, hinge):
    """Signed dihedral angles (nh,) of the hinges at positions x, rad (NaN for a collapsed triangle)."""
    nh = hinge.shape[0]
    out = np.empty(nh)
    g = np.empty((nh, 4, 3))
    for h in numba.prange(nh):
        theta, ok = _hinge_geometry(x, hinge[h, 0], hinge[h, 1], hinge[h, 2], hinge[h, 3], g, h)
        out[h] = theta if ok else np.nan
    return out


@numba.njit(parallel=True, cache=True)
def hinge_kernel(x, hinge, stiffness, theta0, elem_f):
    """Hinge bending energy sum k (theta - theta0)^2 and per-hinge forces into ``elem_f`` (nh, 4, 3).

    Returns
    -------
    energy : float
    n_degenerate : int
        Hinges with a zero-area triangle (forces set to zero).
    """
    nh = hinge.shape[0]
    energy = 0.0
    n_bad = 0
    for h in numba.prange(nh):
        theta, ok = _hinge_geometry(x, hinge[h, 0], hinge[h, 1], hinge[h, 2], hinge[h, 3], elem_f, h)
        if ok:
            dth = theta - theta0[h]
            energy += stiffness[h] * dth * dth
            coef = -2.0 * stiffness[h] * dth
        else:
            n_bad += 1
            coef = 0.0
        for a in range(4):
            for k in range(3):
                elem_f[h, a, k] *= coef
    return energy, n_bad


_HINGE_BLOCK = 64  # hinges per block of the fused kernel (scratch stays in L1)


@numba.njit(parallel=True, cache=True)
def internal_forces_kernel(x, tri, dm_inv, area0, thickness, C10, C01, C11, hinge, stiffness, theta0, out, zero,
                           energy, count):
    """Membrane and hinge forces in one parallel region, scattered straight onto nodes.

    The elements are split into ``out.shape[0]`` contiguous chunks, one per thread; chunk ``c``
    adds the forces of its triangles and hinges into its own nodal array ``out[c]`` (n, 3), so no
    two threads write the same memory. With one chunk ``out`` can be a view of the force array
    itself and no gather is needed; with several, :func:`sum_chunks` adds them up. This replaces
    two element kernels and two gathers (four fork/joins and a 4 MB buffer round trip per step).

    Parameters
    ----------
    out : (n_chunks, n, 3) float64
        Per-chunk nodal forces, added to (set to zero first if ``zero``).
    energy : (n_chunks, 2) float64
        Membrane and bending strain energy of each chunk, J (written).
    count : (n_chunks, 2) int64
        Inverted triangles and collapsed hinges of each chunk (written).
    """
    n_chunks = out.shape[0]
    nt = tri.shape[0]
    nh = hinge.shape[0]
    for c in numba.prange(n_chunks):
        f = out[c]
        if zero:
            f[:, :] = 0.0
        e_mem = 0.0
        n_inv = 0
        for e in range(c * nt // n_chunks, (c + 1) * nt // n_chunks):
            w, ok, h1, h2 = _membrane_triangle(x, tri, dm_inv, thickness * area0[e], C10, C01, C11, e)
            if not ok:
                n_inv += 1
            e_mem += w
            i0 = tri[e, 0]
            i1 = tri[e, 1]
            i2 = tri[e, 2]
            for k in range(3):
                f[i1, k] += h1[k]
                f[i2, k] += h2[k]
                f[i0, k] += -(h1[k] + h2[k])
        # Hinges in blocks: the angle arguments and gradients of a block first, then all its
        # arctangents in one tight loop (one long dependency chain each, which a loop of whole
        # hinges cannot overlap), then the forces.
        e_bend = 0.0
        n_bad = 0
        ys = np.empty(_HINGE_BLOCK)
        xs = np.empty(_HINGE_BLOCK)
        th = np.empty(_HINGE_BLOCK)
        g = np.empty((_HINGE_BLOCK, 9))
        h_end = (c + 1) * nh // n_chunks
        for start in range(c * nh // n_chunks, h_end, _HINGE_BLOCK):
            nb = min(_HINGE_BLOCK, h_end - start)
            for j in range(nb):
                h = start + j
                sin_part, cos_part, ok, gc, gd, al1, al2 = _hinge_terms(
                    x, hinge[h, 0], hinge[h, 1], hinge[h, 2], hinge[h, 3]
                )
                ys[j] = sin_part
                xs[j] = cos_part
                for k in range(3):
                    g[j, k] = gc[k]
                    g[j, 3 + k] = gd[k]
                g[j, 6] = al1
                g[j, 7] = al2
                g[j, 8] = 1.0 if ok else 0.0
            for j in range(nb):  # _atan2 without its branches
                t = _atan(ys[j] / xs[j])
                th[j] = t + math.copysign(math.pi, ys[j]) if xs[j] < 0.0 else t
            for j in range(nb):
                h = start + j
                if g[j, 8] == 0.0:
                    n_bad += 1
                    continue
                theta = th[j]
                if not (xs[j] > 0.0 or xs[j] < 0.0):  # cos_part 0 or NaN: as _atan2 does
                    theta = math.atan2(ys[j], xs[j])
                dth = theta - theta0[h]
                e_bend += stiffness[h] * dth * dth
                coef = -2.0 * stiffness[h] * dth
                a = hinge[h, 0]
                b = hinge[h, 1]
                cc = hinge[h, 2]
                d = hinge[h, 3]
                al1 = g[j, 6]
                al2 = g[j, 7]
                for k in range(3):
                    gc = g[j, k]
                    gd = g[j, 3 + k]
                    f[cc, k] += gc * coef
                    f[d, k] += gd * coef
                    f[a, k] += (-(1.0 - al1) * gc - (1.0 - al2) * gd) * coef
                    f[b, k] += (-al1 * gc - al2 * gd) * coef
        energy[c, 0] = e_mem
        energy[c, 1] = e_bend
        count[c, 0] = n_inv
        count[c, 1] = n_bad


@numba.njit(parallel=True, cache=True)
def sum_chunks(out, f):
    """Add the per-chunk nodal forces ``out`` (n_chunks, n, 3) into ``f`` (n, 3)."""
    n_chunks = out.shape[0]
    for i in numba.prange(f.shape[0]):
        for k in range(3):
            s = 0.0
            for c in range(n_chunks):
                s += out[c, i, k]
            f[i, k] += s


@numba.njit(parallel=True, cache=True)
def hinge_rowsum_kernel(x, hinge, stiffness, theta0, elem_f):
    """Per-hinge Gershgorin row sums of the hinge stiffness for the time-step bound.

    The hinge Hessian is 2k (g g^T + (theta - theta0) d2theta); the block row of node i is bounded
    by 2k |g_i| sum_j |g_j| (1 + |theta - theta0|), the last factor an estimate of the curvature
    term (second derivatives of theta scale like products of first ones). Written to component 0;
    infinite for a collapsed triangle.
    """
    nh = hinge.shape[0]
    for h in numba.prange(nh):
        theta, ok = _hinge_geometry(x, hinge[h, 0], hinge[h, 1], hinge[h, 2], hinge[h, 3], elem_f, h)
        if not ok:
            for a in range(4):
                elem_f[h, a, 0] = np.inf
                elem_f[h, a, 1] = 0.0
                elem_f[h, a, 2] = 0.0
            continue
        total = 0.0
        for a in range(4):
            na = math.sqrt(elem_f[h, a, 0] ** 2 + elem_f[h, a, 1] ** 2 + elem_f[h, a, 2] ** 2)
            elem_f[h, a, 0] = na
            total += na
        scale = 2.0 * stiffness[h] * (1.0 + abs(theta - theta0[h])) * total
        for a in range(4):
            elem_f[h, a, 0] *= scale
            elem_f[h, a, 1] = 0.0
            elem_f[h, a, 2] = 0.0


@numba.njit(parallel=True, cache=True)
def _max_row_over_mass(rows, mass):
    """max_i rows[i, 0] / mass[i] (the Gershgorin bound of M^-1 K_hinge), 1/s^2."""
    n = rows.shape[0]
    out = 0.0
    for i in numba.prange(n):
        out = max(out, rows[i, 0] / mass[i])
    return out


# ---------------------------------------------------------------------------------------------
# Pressure and geometry
# ---------------------------------------------------------------------------------------------


@numba.njit(parallel=True, cache=True)
def area_vector_kernel(x, tri, scale, elem_f):
    """``scale`` times each triangle's area vector (1/2)(x1 - x0) x (x2 - x0), on each of its nodes.

    With ``scale = p / 3`` this is the follower pressure load (positive p pushes along the
    triangle normals); with ``scale = 1`` and a gather, the area-weighted nodal normals.
    """
    nt = tri.shape[0]
    for e in numba.prange(nt):
        i0 = tri[e, 0]
        i1 = tri[e, 1]
        i2 = tri[e, 2]
        a0 = x[i1, 0] - x[i0, 0]
        a1 = x[i1, 1] - x[i0, 1]
        a2 = x[i1, 2] - x[i0, 2]
        b0 = x[i2, 0] - x[i0, 0]
        b1 = x[i2, 1] - x[i0, 1]
        b2 = x[i2, 2] - x[i0, 2]
        s = 0.5 * scale
        n0 = s * (a1 * b2 - a2 * b1)
        n1 = s * (a2 * b0 - a0 * b2)
        n2 = s * (a0 * b1 - a1 * b0)
        for a in range(3):
            elem_f[e, a, 0] = n0
            elem_f[e, a, 1] = n1
            elem_f[e, a, 2] = n2


@numba.njit(parallel=True, cache=True)
def enclosed_volume(x, tri):
    """Signed volume sum (1/6) x0 . (x1 x x2) over the triangles, m^3.

    For a closed outward-oriented surface it is the enclosed volume. For a tube whose end rings are
    held fixed it differs from the lumen volume by a constant, and its gradient on the free nodes
    equals the follower pressure load per unit pressure, so -p V is the pressure's potential.
    """
    nt = tri.shape[0]
    vol = 0.0
    for e in numba.prange(nt):
        i0 = tri[e, 0]
        i1 = tri[e, 1]
        i2 = tri[e, 2]
        cx = x[i1, 1] * x[i2, 2] - x[i1, 2] * x[i2, 1]
        cy = x[i1, 2] * x[i2, 0] - x[i1, 0] * x[i2, 2]
        cz = x[i1, 0] * x[i2, 1] - x[i1, 1] * x[i2, 0]
        vol += x[i0, 0] * cx + x[i0, 1] * cy + x[i0, 2] * cz
    return vol / 6.0


# ---------------------------------------------------------------------------------------------
# Body
# ---------------------------------------------------------------------------------------------


def bending_stiffness(material, thickness):
    """Plate bending stiffness D = E0 t^3 / (12 (1 - nu^2)) with nu = 1/2, i.e. E0 t^3 / 9, N m."""
    return material.E0 * thickness**3 / 9.0


class Shell:
    """Colon wall as a thin incompressible Mooney-Rivlin shell (body protocol of the solver).

    Parameters
    ----------
    nodes : (n, 3) float array
        Reference mid-surface node positions, m (the stress-free, bending-free state).
    triangles : (nt, 3) int array
        Consistently oriented triangles; for a tube, normals out of the lumen.
    thickness : float
        Reference wall thickness, m.
    material : colonsim.insertion.engine.material.MooneyRivlin
    density : float
        Wall density, kg/m^3.
    name : str

    Notes
    -----
    The instance owns work buffers, so one instance must not be evaluated from two threads.
    """

    def __init__(self, nodes, triangles, thickness, material, density=1040.0, name="colon"):
        nodes = np.ascontiguousarray(nodes, dtype=np.float64)
        triangles = np.ascontiguousarray(triangles, dtype=np.int64)
        if nodes.ndim != 2 or nodes.shape[1] != 3:
            raise ColonsimError(f"shell nodes must be an (n, 3) array, got shape {nodes.shape}; fix the mesh.")
        if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
            raise ColonsimError(
                f"shell triangles must be a non-empty (nt, 3) array, got shape {triangles.shape}; fix the mesh."
            )
        if triangles.min() < 0 or triangles.max() >= len(nodes):
            raise ColonsimError("shell triangles reference nodes that do not exist; fix the mesh.")
        used = np.zeros(len(nodes), dtype=bool)
        used[triangles.ravel()] = True
        if not used.all():
            raise ColonsimError(
                f"{int((~used).sum())} shell node(s) belong to no triangle (zero mass); remove them."
            )
        if not (np.isfinite(thickness) and thickness > 0.0):
            raise ColonsimError(f"shell thickness = {thickness!r} m must be positive; fix it.")
        if not (np.isfinite(density) and density > 0.0):
            raise ColonsimError(f"shell density = {density!r} kg/m^3 must be positive; fix it.")

        self.name = name
        self.x0 = nodes
        self.triangles = triangles
        self.thickness = float(thickness)
        self.material = material
        self.density = float(density)
        self.hinges = mesh_hinges(triangles)

        self.dm_inv, self.area0 = reference_frames(nodes, triangles)
        self._lumped_mass = np.zeros(len(nodes))
        np.add.at(self._lumped_mass, triangles.ravel(), np.repeat(self.density * self.thickness * self.area0 / 3.0, 3))
        self.mass = self._lumped_mass.copy()

        self.bending_stiffness = bending_stiffness(material, self.thickness)
        h = self.hinges
        edge = nodes[h[:, 1]] - nodes[h[:, 0]]
        area_pair = 0.5 * (
            np.linalg.norm(np.cross(edge, nodes[h[:, 2]] - nodes[h[:, 0]]), axis=1)
            + np.linalg.norm(np.cross(nodes[h[:, 3]] - nodes[h[:, 0]], edge), axis=1)
        )
        self.hinge_stiffness = 0.5 * self.bending_stiffness * np.einsum("ij,ij->i", edge, edge) / area_pair
        self.theta0 = dihedral_angles(nodes, h) if len(h) else np.zeros(0)

        self._tri_ptr, self._tri_slots = node_incidence(triangles, len(nodes))
        self._tri_buf = np.zeros((len(triangles), 3, 3))
        self._hinge_ptr, self._hinge_slots = node_incidence(h.reshape(-1, 4), len(nodes))
        self._hinge_buf = np.zeros((len(h), 4, 3))
        self._omega2 = np.zeros(len(triangles))
        self._node_tmp = np.zeros((len(nodes), 3))
        self._mass_scale = np.ones(len(nodes))
        self._chunk_f = np.zeros((0,) + nodes.shape)  # per-thread nodal forces, sized on first use
        self._chunk_energy = np.zeros((0, 2))
        self._chunk_count = np.zeros((0, 2), dtype=np.int64)

    @property
    def n_nodes(self):
        return len(self.x0)

    def _check_x(self, x):
        if x.shape != self.x0.shape or x.dtype != np.float64 or not x.flags.c_contiguous:
            raise ColonsimError(
                f"shell positions must be a C-contiguous float64 array of shape {self.x0.shape}; "
                f"got {x.dtype} {x.shape}."
            )

    def membrane_forces(self, x, f):
        """Add membrane forces for positions x into f; return membrane strain energy, J."""
        self._check_x(x)
        m = self.material
        energy, n_inv = membrane_kernel(
            x, self.triangles, self.dm_inv, self.area0, self.thickness, m.C10, m.C01, m.C11, self._tri_buf
        )
        if n_inv:
            raise ColonsimError(
                f"{n_inv} wall triangle(s) of '{self.name}' are inverted or collapsed (det C <= 0); "
                "the simulation diverged: reduce the time step or the loading rate."
            )
        gather(self._tri_buf, self._tri_ptr, self._tri_slots, f)
        return energy

    def bending_forces(self, x, f):
        """Add hinge bending forces for positions x into f; return bending energy, J."""
        self._check_x(x)
        if len(self.hinges) == 0:
            return 0.0
        energy, n_bad = hinge_kernel(x, self.hinges, self.hinge_stiffness, self.theta0, self._hinge_buf)
        if n_bad:
            raise ColonsimError(
                f"{n_bad} bending hinge(s) of '{self.name}' have a collapsed triangle; "
                "the simulation diverged: reduce the time step or the loading rate."
            )
        gather(self._hinge_buf, self._hinge_ptr, self._hinge_slots, f)
        return energy

    def internal_forces(self, x, f):
        """Add internal elastic forces (-dE/dx) for positions x into f (n, 3); return strain energy, J.

        The sum of :meth:`membrane_forces` and :meth:`bending_forces` (up to rounding), computed
        by one fused kernel.
        """
        self._check_x(x)
        m = self.material
        n_chunks = numba.get_num_threads()
        if self._chunk_energy.shape[0] != n_chunks:
            self._chunk_f = np.zeros((n_chunks,) + x.shape)
            self._chunk_energy = np.zeros((n_chunks, 2))
            self._chunk_count = np.zeros((n_chunks, 2), dtype=np.int64)
        # one chunk adds straight into f (a view), several into their own arrays summed below
        direct = n_chunks == 1 and f.dtype == np.float64 and f.flags.c_contiguous and f.shape == x.shape
        out = f.reshape((1,) + f.shape) if direct else self._chunk_f
        internal_forces_kernel(
            x, self.triangles, self.dm_inv, self.area0, self.thickness, m.C10, m.C01, m.C11,
            self.hinges, self.hinge_stiffness, self.theta0, out, not direct, self._chunk_energy, self._chunk_count,
        )
        n_inv, n_bad = self._chunk_count.sum(axis=0)
        if n_inv:
            raise ColonsimError(
                f"{n_inv} wall triangle(s) of '{self.name}' are inverted or collapsed (det C <= 0); "
                "the simulation diverged: reduce the time step or the loading rate."
            )
        if n_bad:
            raise ColonsimError(
                f"{n_bad} bending hinge(s) of '{self.name}' have a collapsed triangle; "
                "the simulation diverged: reduce the time step or the loading rate."
            )
        if not direct:
            sum_chunks(out, f)
        return float(self._chunk_energy.sum())

    def pressure_forces(self, x, pressure, f):
        """Add the follower load of an internal pressure (Pa, positive pushes along the outward
        normals) into f."""
        self._check_x(x)
        area_vector_kernel(x, self.triangles, pressure / 3.0, self._tri_buf)
        gather(self._tri_buf, self._tri_ptr, self._tri_slots, f)

    def enclosed_volume(self, x):
        """Signed volume term whose gradient is the pressure load per Pa (see :func:`enclosed_volume`), m^3."""
        self._check_x(x)
        return enclosed_volume(x, self.triangles)

    def node_normals(self, x):
        """Unit outward normals (n, 3), area-weighted over the incident triangles."""
        self._check_x(x)
        area_vector_kernel(x, self.triangles, 1.0, self._tri_buf)
        normals = np.zeros_like(x)
        gather(self._tri_buf, self._tri_ptr, self._tri_slots, normals)
        norm = np.linalg.norm(normals, axis=1)
        return normals / np.where(norm > 0.0, norm, 1.0)[:, None]

    def critical_time_step(self, x):
        """Conservative stable central-difference time step at configuration x, s.

        2 / omega_max with omega_max^2 <= (membrane element bound at the current stretches)
        + (Gershgorin bound of the hinge stiffness), both with the current nodal masses.
        """
        self._check_x(x)
        m = self.material
        # The solver may replace or rescale self.mass (mass scaling); the membrane bound needs the
        # per-node scaling factor relative to the physical lumped mass.
        scale = self._mass_scale
        np.divide(self.mass, self._lumped_mass, out=scale)
        membrane_omega2_kernel(
            x, self.triangles, self.dm_inv, self.thickness, self.density, m.C10, m.C01, m.C11, scale, self._omega2
        )
        omega2 = float(self._omega2.max())
        if len(self.hinges):
            hinge_rowsum_kernel(x, self.hinges, self.hinge_stiffness, self.theta0, self._hinge_buf)
            rows = self._node_tmp
            rows[:] = 0.0
            gather(self._hinge_buf, self._hinge_ptr, self._hinge_slots, rows)
            omega2 += _max_row_over_mass(rows, self.mass)
        if not np.isfinite(omega2):
            raise ColonsimError(
                f"wall of '{self.name}' has an inverted or collapsed triangle; no stable time step exists."
            )
        return 2.0 / math.sqrt(omega2)
