"""Colonoscope as a discrete elastic rod: axial stretching and bending, hemispherical tip.

The rod is a chain of nodes joined by segments. Each segment is an axial spring with the energy
(EA / 2 L0) (l - L0)^2. Each interior node carries a bending hinge with the energy
(EI / 2 lbar) phi^2, where phi is the turning angle between its two segments and lbar the mean
reference length of those segments; for a circular arc of curvature kappa, phi = kappa lbar and
the sum tends to the beam energy integral of EI kappa^2 / 2. The natural (stress-free) shape is
straight with the reference segment lengths of the given nodes, so a rod built along a curve
starts bent and loaded.

Twist is left out: the section is circular and isotropic and the scope is pushed axially without
applied torque, so twist decouples from bending and stretching (no material frame is needed).

Contact sees the rod as capsules of radius ``radius`` around its segments; at the distal end
(``tip_node``) the end cap is the hemispherical tip, centred on the tip node.

Kernels are serial ``numba`` functions: a scope has a few hundred elements, too little work
to pay for starting threads, and a serial loop adds element forces onto nodes without races.
"""

import math

import numba
import numpy as np
from scipy.linalg import eig_banded

from colonsim.errors import ColonsimError


@numba.njit(cache=True, inline="always")
def _turning(x, i0, i1, i2):
    """Turning angle phi at node i1 and the unit tangents / lengths of its two segments."""
    a0 = x[i1, 0] - x[i0, 0]
    a1 = x[i1, 1] - x[i0, 1]
    a2 = x[i1, 2] - x[i0, 2]
    b0 = x[i2, 0] - x[i1, 0]
    b1 = x[i2, 1] - x[i1, 1]
    b2 = x[i2, 2] - x[i1, 2]
    la = math.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
    lb = math.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
    a0 /= la
    a1 /= la
    a2 /= la
    b0 /= lb
    b1 /= lb
    b2 /= lb
    c = a0 * b0 + a1 * b1 + a2 * b2
    s0 = a1 * b2 - a2 * b1
    s1 = a2 * b0 - a0 * b2
    s2 = a0 * b1 - a1 * b0
    s = math.sqrt(s0 * s0 + s1 * s1 + s2 * s2)
    phi = math.atan2(s, c)
    return phi, s, c, la, lb, a0, a1, a2, b0, b1, b2


@numba.njit(cache=True)
def rod_kernel(x, rest_length, axial_k, bend_k, f):
    """Add the axial and bending forces of a node chain into ``f`` (n, 3).

    Serial on purpose: a scope has a few hundred elements, less work than starting threads
    (which on a loaded machine costs milliseconds), and a serial loop scatters without races.

    Parameters
    ----------
    x : (n, 3) positions, m
    rest_length, axial_k : (n - 1,) reference lengths (m) and EA / L0 (N/m) of the segments
    bend_k : (n - 2,) EI / lbar of the interior nodes, N m
    f : (n, 3) forces, added to

    Returns
    -------
    energy : float
        Strain energy, J.
    n_bad : int
        Segments of zero length (their forces are left out).
    """
    ns = rest_length.shape[0]
    energy = 0.0
    n_bad = 0
    for e in range(ns):
        d0 = x[e + 1, 0] - x[e, 0]
        d1 = x[e + 1, 1] - x[e, 1]
        d2 = x[e + 1, 2] - x[e, 2]
        l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        if not l > 0.0:
            n_bad += 1
            continue
        stretch = l - rest_length[e]
        energy += 0.5 * axial_k[e] * stretch * stretch
        tension = axial_k[e] * stretch / l
        f[e, 0] += tension * d0
        f[e, 1] += tension * d1
        f[e, 2] += tension * d2
        f[e + 1, 0] -= tension * d0
        f[e + 1, 1] -= tension * d1
        f[e + 1, 2] -= tension * d2
    nv = bend_k.shape[0]
    for v in range(nv):
        phi, s, c, la, lb, a0, a1, a2, b0, b1, b2 = _turning(x, v, v + 1, v + 2)
        if not (la > 0.0 and lb > 0.0):
            n_bad += 1
            continue
        energy += 0.5 * bend_k[v] * phi * phi
        # dE/dt_a = -k phi/sin(phi) (t_b - c t_a); phi / sin(phi) -> 1 for a straight hinge.
        ratio = phi / s if s > 1e-12 else 1.0
        q = -bend_k[v] * ratio
        ga0 = q * (b0 - c * a0) / la
        ga1 = q * (b1 - c * a1) / la
        ga2 = q * (b2 - c * a2) / la
        gb0 = q * (a0 - c * b0) / lb
        gb1 = q * (a1 - c * b1) / lb
        gb2 = q * (a2 - c * b2) / lb
        f[v, 0] += ga0
        f[v, 1] += ga1
        f[v, 2] += ga2
        f[v + 1, 0] += gb0 - ga0
        f[v + 1, 1] += gb1 - ga1
        f[v + 1, 2] += gb2 - ga2
        f[v + 2, 0] -= gb0
        f[v + 2, 1] -= gb1
        f[v + 2, 2] -= gb2
    return energy, n_bad


@numba.njit(cache=True)
def stiffness_band(x, rest_length, axial_k, bend_k, eps, ab):
    """The upper band of the tangent stiffness at ``x`` into ``ab`` (LAPACK upper banded storage:
    ``ab[u + r - c, c] = K[r, c]`` for r <= c, u = ``ab.shape[0] - 1`` = 8), N/m.

    Column by column from central differences of :func:`rod_kernel`'s forces with step ``eps`` (m),
    perturbing every fifth node at once (their bands do not overlap): 15 pairs of evaluations.
    """
    n = x.shape[0]
    u = ab.shape[0] - 1
    xp = np.empty_like(x)
    xm = np.empty_like(x)
    fp = np.empty_like(x)
    fm = np.empty_like(x)
    for color in range(5):
        for a in range(3):
            xp[:, :] = x
            xm[:, :] = x
            for j in range(color, n, 5):
                xp[j, a] += eps
                xm[j, a] -= eps
            fp[:, :] = 0.0
            fm[:, :] = 0.0
            rod_kernel(xp, rest_length, axial_k, bend_k, fp)
            rod_kernel(xm, rest_length, axial_k, bend_k, fm)
            for j in range(color, n, 5):
                c = 3 * j + a
                for i in range(max(j - 2, 0), j + 1):  # rows of nodes j - 2 .. j: the upper triangle
                    for b in range(3):
                        r = 3 * i + b
                        if r <= c:
                            ab[u + r - c, c] = -(fp[i, b] - fm[i, b]) / (2.0 * eps)


@numba.njit(cache=True)
def rod_omega2_kernel(x, rest_length, axial_k, bend_k, mass, out):
    """Gershgorin bound of each node's row of M^-1 K (rad^2/s^2) into ``out`` (n,).

    Axial spring: block row sum 2 (EA/L0 + |N| / l) (the second term is the geometric stiffness of
    the axial force N). Hinge: stiffness k g g^T with |g| = 1/l_a, 1/l_a + 1/l_b, 1/l_b on its three
    nodes (small-angle gradient of phi), times (1 + phi) for the curvature of phi itself.
    """
    n = x.shape[0]
    ns = rest_length.shape[0]
    nv = bend_k.shape[0]
    for i in range(n):
        row = 0.0
        for e in range(max(i - 1, 0), min(i + 1, ns)):
            d0 = x[e + 1, 0] - x[e, 0]
            d1 = x[e + 1, 1] - x[e, 1]
            d2 = x[e + 1, 2] - x[e, 2]
            l = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            row += 2.0 * (axial_k[e] + abs(axial_k[e] * (l - rest_length[e])) / l)
        for v in range(max(i - 2, 0), min(i + 1, nv)):
            phi, s, c, la, lb, a0, a1, a2, b0, b1, b2 = _turning(x, v, v + 1, v + 2)
            total = 2.0 * (1.0 / la + 1.0 / lb)
            local = i - v  # 0, 1, 2 = node v, v + 1, v + 2 of the hinge
            if local == 0:
                gi = 1.0 / la
            elif local == 1:
                gi = 1.0 / la + 1.0 / lb
            else:
                gi = 1.0 / lb
            row += bend_k[v] * gi * total * (1.0 + phi)
        out[i] = row / mass[i]


class Rod:
    """Colonoscope as a discrete elastic rod (body protocol of the solver).

    Parameters
    ----------
    nodes : (n, 3) float array
        Node positions along the rod, proximal end first, m (n >= 3). The stress-free state is
        straight with these segment lengths.
    diameter : float
        Outer diameter, m.
    youngs_modulus : float
        Young's modulus, Pa.
    density : float
        Density of the section material, kg/m^3.
    inner_diameter : float, optional
        Inner diameter of a hollow section, m (0 = solid).
    name : str
    damping_time : float, optional
        Kelvin-Voigt damping time tau of the axial springs, s: a dashpot tau EA / L0 in parallel
        with each (:mod:`colonsim.insertion.engine.rod_damping`, integrated implicitly by the
        solver). 0 = none.
    lateral_damping : float, optional
        Mass-proportional damping of the velocity across the rod, 1/s (sliding along itself is
        not damped; integrated implicitly by the solver). 0 = none.

    Attributes
    ----------
    radius : float
        Outer radius (capsule and tip hemisphere radius), m.
    segments : (n - 1, 2) int64
        Node pairs along the rod.
    tip_node : int
        Distal node, centre of the hemispherical tip.
    area, second_moment : float
        Section area (m^2) and second moment of area (m^4).
    """

    def __init__(self, nodes, diameter, youngs_modulus, density, inner_diameter=0.0, name="scope", damping_time=0.0,
                 lateral_damping=0.0):
        nodes = np.ascontiguousarray(nodes, dtype=np.float64)
        if nodes.ndim != 2 or nodes.shape[1] != 3 or len(nodes) < 3:
            raise ColonsimError(f"rod nodes must be an (n, 3) array with n >= 3, got shape {nodes.shape}.")
        for label, value in (("diameter", diameter), ("youngs_modulus", youngs_modulus), ("density", density)):
            if not (np.isfinite(value) and value > 0.0):
                raise ColonsimError(f"rod {label} = {value!r} must be positive; fix it.")
        for label, value in (("damping_time", damping_time), ("lateral_damping", lateral_damping)):
            if not (np.isfinite(value) and value >= 0.0):
                raise ColonsimError(f"rod {label} = {value!r} must be >= 0; fix it.")
        if not (np.isfinite(inner_diameter) and 0.0 <= inner_diameter < diameter):
            raise ColonsimError(
                f"rod inner_diameter = {inner_diameter!r} m must lie in [0, diameter = {diameter}); fix it."
            )
        rest_length = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
        if np.any(rest_length <= 0.0):
            raise ColonsimError("two consecutive rod nodes coincide (zero-length segment); fix the nodes.")

        self.name = name
        self.x0 = nodes
        self.diameter = float(diameter)
        self.inner_diameter = float(inner_diameter)
        self.radius = 0.5 * self.diameter
        self.youngs_modulus = float(youngs_modulus)
        self.density = float(density)
        self.area = math.pi / 4.0 * (diameter**2 - inner_diameter**2)
        self.second_moment = math.pi / 64.0 * (diameter**4 - inner_diameter**4)
        n = len(nodes)
        self.segments = np.column_stack((np.arange(n - 1), np.arange(1, n))).astype(np.int64)
        self.tip_node = n - 1
        self.rest_length = rest_length
        self.axial_stiffness = self.youngs_modulus * self.area / rest_length
        self.bending_stiffness = self.youngs_modulus * self.second_moment / (0.5 * (rest_length[:-1] + rest_length[1:]))
        self.damping_time = float(damping_time)
        self.dashpot = self.damping_time * self.axial_stiffness  # N s/m per segment
        self.lateral_damping = float(lateral_damping)  # 1/s

        self._lumped_mass = np.zeros(n)
        seg_mass = self.density * self.area * rest_length
        self._lumped_mass[:-1] += 0.5 * seg_mass
        self._lumped_mass[1:] += 0.5 * seg_mass
        self.mass = self._lumped_mass.copy()

        self._omega2 = np.zeros(n)

    @classmethod
    def straight(cls, length, diameter, youngs_modulus, density, spacing=5e-3, start=(0.0, 0.0, 0.0),
                 direction=(1.0, 0.0, 0.0), inner_diameter=0.0, name="scope", damping_time=0.0, lateral_damping=0.0):
        """Straight rod from ``start`` along ``direction``; nodes about ``spacing`` apart.

        ``length`` is the distance from the proximal node to the tip node (the hemispherical tip
        reaches one radius further).
        """
        if not (np.isfinite(length) and length > 0.0 and np.isfinite(spacing) and spacing > 0.0):
            raise ColonsimError(f"rod length {length!r} m and spacing {spacing!r} m must be positive; fix them.")
        d = np.asarray(direction, dtype=np.float64)
        norm = np.linalg.norm(d)
        if not norm > 0.0:
            raise ColonsimError("rod direction must be a non-zero vector; fix it.")
        n_seg = max(2, int(round(length / spacing)))
        s = np.linspace(0.0, length, n_seg + 1)
        nodes = np.asarray(start, dtype=np.float64)[None, :] + s[:, None] * (d / norm)[None, :]
        return cls(nodes, diameter, youngs_modulus, density, inner_diameter=inner_diameter, name=name,
                   damping_time=damping_time, lateral_damping=lateral_damping)

    @property
    def n_nodes(self):
        return len(self.x0)

    @property
    def flexural_rigidity(self):
        """EI, N m^2."""
        return self.youngs_modulus * self.second_moment

    def _check_x(self, x):
        if x.shape != self.x0.shape or x.dtype != np.float64 or not x.flags.c_contiguous:
            raise ColonsimError(
                f"rod positions must be a C-contiguous float64 array of shape {self.x0.shape}; got {x.dtype} {x.shape}."
            )

    def internal_forces(self, x, f):
        """Add internal elastic forces (-dE/dx) for positions x into f (n, 3); return strain energy, J."""
        self._check_x(x)
        energy, n_bad = rod_kernel(x, self.rest_length, self.axial_stiffness, self.bending_stiffness, f)
        if n_bad:
            raise ColonsimError(
                f"{n_bad} segment(s) of rod '{self.name}' collapsed to zero length; the simulation diverged: "
                "reduce the time step or the loading rate."
            )
        return energy

    def frequency_bound(self, x):
        """Gershgorin upper bound of the largest angular frequency at configuration x, rad/s.

        Adds the axial and the flexural rows, so it overestimates a straight rod's highest
        frequency, max(2 c / h, 4 sqrt(EI / rho A) / h^2), by up to sqrt(2).
        """
        self._check_x(x)
        rod_omega2_kernel(x, self.rest_length, self.axial_stiffness, self.bending_stiffness, self.mass, self._omega2)
        omega2 = float(self._omega2.max())
        if not (np.isfinite(omega2) and omega2 > 0.0):
            raise ColonsimError(f"rod '{self.name}' has a collapsed segment; no stable time step exists.")
        return math.sqrt(omega2)

    def max_frequency(self, x):
        """Largest angular frequency of the rod linearised at configuration x, rad/s.

        The tangent stiffness is banded (a node couples to its two neighbours on each side):
        :func:`stiffness_band` finds it from central differences of the forces, and the largest
        eigenvalue of M^-1/2 K M^-1/2 comes from a banded symmetric eigensolver.
        """
        self._check_x(x)
        ndof = 3 * len(x)
        u = 8  # upper bandwidth in DOFs: node i reaches node i + 2
        ab = np.zeros((u + 1, ndof))
        eps = 1e-6 * float(self.rest_length.min())
        stiffness_band(x, self.rest_length, self.axial_stiffness, self.bending_stiffness, eps, ab)
        d = np.repeat(1.0 / np.sqrt(self.mass), 3)
        for k in range(u + 1):
            off = u - k  # ab[k, c] holds K[c - off, c]
            ab[k, off:] *= d[: ndof - off] * d[off:]
        top = eig_banded(ab, eigvals_only=True, select="i", select_range=(ndof - 1, ndof - 1))[0]
        if not (np.isfinite(top) and top > 0.0):
            raise ColonsimError(f"rod '{self.name}' has a collapsed segment; no stable time step exists.")
        return math.sqrt(top)

    def critical_time_step(self, x):
        """Stable central-difference time step at configuration x, s: 2 / omega_max.

        omega_max from :meth:`max_frequency` (exact for the linearised rod), never above the
        Gershgorin bound of :meth:`frequency_bound`; bending usually dominates,
        omega ~ 4 sqrt(EI / rho A) / h^2 for nodes h apart.
        """
        omega = min(self.max_frequency(x), self.frequency_bound(x))
        return 2.0 / omega
