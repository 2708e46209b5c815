"""Bending of the wall shell: discrete hinges (Grinspun et al. 2003, Bridson et al. 2003).

Energy k_e (theta - theta0)^2 per interior edge, with k_e = D |e|^2 / (2 (A_1 + A_2)) from the
reference edge length and the areas of its two triangles. On an equilateral mesh bent by a small
curvature tensor K, a hinge whose edge has in-plane unit normal n turns by
theta = -(|e| / sqrt(3)) (2 K_nn - tr K / 2); summed over the three edge directions this gives
sum |e|^2 theta^2 / (A_1 + A_2) = (4/3) (m^2 + 2 r^2) per unit area, with m = (k1 + k2)/2 and
r = (k1 - k2)/2 from the principal curvatures. For a cylinder of radius R (m = r = 1/(2R)) that is
1/R^2 whatever the cylinder's direction, so this k_e gives D / (2 R^2) per area, the plate energy
of cylindrical bending, with D = E0 t^3 / (12 (1 - nu^2)) = E0 t^3 / 9 for nu = 1/2. The hinge
model's own Poisson ratio is -1/3 (energy (2/3) D (m^2 + 2 r^2) against D ((1 + nu) m^2 +
(1 - nu) r^2) for a plate): cylindrical bending, the dominant mode of a colon wall, is matched
exactly; spherical bending is 2.25 times too soft and saddle bending 2.7 times too stiff
(docs/model.md). Tests: tests/test_shell_bending.py.
"""

import math

import numba
import numpy as np


def bending_stiffness(material, thickness):
    """Plate bending stiffness D = E0 t^3 / (12 (1 - nu^2)) with nu = 1/2, i.e. E0 t^3 / 9, N m."""
    return material.E0 * thickness**3 / 9.0


def hinge_stiffness(nodes, hinges, bending_stiffness):
    """k_e = D |e|^2 / (2 (A_1 + A_2)) of each hinge (a, b, c, d) of edge a-b, at the reference
    positions ``nodes``, N m."""
    edge = nodes[hinges[:, 1]] - nodes[hinges[:, 0]]
    area_pair = 0.5 * (
        np.linalg.norm(np.cross(edge, nodes[hinges[:, 2]] - nodes[hinges[:, 0]]), axis=1)
        + np.linalg.norm(np.cross(nodes[hinges[:, 3]] - nodes[hinges[:, 0]], edge), axis=1)
    )
    return 0.5 * bending_stiffness * np.einsum("ij,ij->i", edge, edge) / area_pair


@numba.njit(cache=True, inline="always")
def fast_atan(t):
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
def fast_atan2(y, x):
    """atan2(y, x) through :func:`fast_atan` (same quadrants and signed zeros as math.atan2); x = 0
    and NaN go to math.atan2."""
    if x > 0.0:
        return fast_atan(y / x)
    if x < 0.0:
        return fast_atan(y / x) + math.copysign(math.pi, y)
    return math.atan2(y, x)


@numba.njit(cache=True, inline="always")
def hinge_terms(x, a, b, c, d):
    """Arguments of the signed dihedral angle of hinge (a, b, c, d) and its gradient.

    theta = atan2((n1 x n2) . e_hat, n1 . n2), n1 = e x (x_c - x_a), n2 = (x_d - x_a) x e,
    e = x_b - x_a. Zero for a flat hinge; the standard gradient
    d theta/d x_c = -|e| n1 / |n1|^2, d theta/d x_d = -|e| n2 / |n2|^2 and the edge nodes'
    shares from the projections of x_c, x_d on the edge (translation invariance):
    d theta/d x_a = -(1 - al1) g_c - (1 - al2) g_d, d theta/d x_b = -al1 g_c - al2 g_d.
    Returns (sin_part, cos_part, ok, g_c, g_d, al1, al2), theta = atan2(sin_part, cos_part), with
    ok False for a zero-area triangle (gradient then undefined).
    """
    return hinge_terms_of_edges(x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2], x[c, 0] - x[a, 0],
                                x[c, 1] - x[a, 1], x[c, 2] - x[a, 2], x[d, 0] - x[a, 0], x[d, 1] - x[a, 1],
                                x[d, 2] - x[a, 2])


@numba.njit(cache=True, inline="always")
def hinge_terms_of_edges(e0, e1, e2, u0, u1, u2, v0, v1, v2):
    """:func:`hinge_terms` from the edge e = x_b - x_a and the wings u = x_c - x_a, v = x_d - x_a:
    no memory access, so a loop over a block of hinges runs several at once in the vector
    registers."""
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
    """Signed dihedral angle of hinge (a, b, c, d) and its gradient (see :func:`hinge_terms`):
    (theta, ok, g_c, g_d, al1, al2)."""
    sin_part, cos_part, ok, gc, gd, al1, al2 = hinge_terms(x, a, b, c, d)
    return fast_atan2(sin_part, cos_part), ok, gc, gd, al1, al2


@numba.njit(cache=True, inline="always")
def hinge_geometry(x, a, b, c, d, g, h):
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
        theta, ok = hinge_geometry(x, hinge[h, 0], hinge[h, 1], hinge[h, 2], hinge[h, 3], g, h)
        out[h] = theta if ok else np.nan
    return out



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
        theta, ok = hinge_geometry(x, hinge[h, 0], hinge[h, 1], hinge[h, 2], hinge[h, 3], elem_f, h)
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
def max_row_over_mass(rows, mass):
    """max_i rows[i, 0] / mass[i] (the Gershgorin bound of M^-1 K_hinge), 1/s^2."""
    n = rows.shape[0]
    out = 0.0
    for i in numba.prange(n):
        out = max(out, rows[i, 0] / mass[i])
    return out

