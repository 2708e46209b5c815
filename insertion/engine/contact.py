"""Frictional penalty contact between a rod (the scope) and the nodes of a shell (the colon wall).

The scope surface is the union of capsules of radius ``rod.radius`` around its segments; the
end caps are spheres, so the distal one is the hemispherical tip. The wall is its node set,
offset by half the wall thickness (the mid-surface carries the nodes, the lumen is ``offset``
inside it). Each wall node in contact takes the closest point of the scope surface (the minimum
over capsules, so a node near a joint between two segments is counted once):

    gap g = |p - c| - radius - offset,   n = (p - c) / |p - c|
    normal force  f_n = max(k (-g) - c_n v_n, 0),   c_n = 2 zeta sqrt(k m_eff)
    friction      f_t = -mu f_n v_t / max(|v_t|, v_reg)

with c the closest point on the segment axis, v_n, v_t the normal and tangential relative
velocity, m_eff the reduced mass of the wall node (infinite when fixed) and the rod point, and k
the penalty of a free wall node, or the stiffer one of a held node (whose spring loads only the
rod, so the wall's light nodes do not limit it). Given ``held_normals``, a held node's n is the
fixed wall's rest normal instead: the fixed colon acts as a rigid smooth tube (docs/model.md,
"Contact"), which pushes the scope across its axis but never back along it.
Friction is Coulomb, regularised by a slip velocity v_reg: below mu f_n the contact "sticks"
by creeping at |v_t| = v_reg |F_t| / (mu f_n); v_reg is raised where needed to mu f_n dt / m_eff
so that the viscous friction stays stable in explicit time stepping. The reaction on the rod is
split linearly between the segment's two nodes.

Broad phase: candidate (wall node, segment) pairs within radius + offset + skin, found with
a uniform cell hash of the inflated segment boxes (sorted cell keys, one binary search per wall
node); rebuilt only when the nodes have moved more than the skin since the last build, so the
per-step cost scales with the number of candidates, not with all pairs. The narrow phase runs
on threads for large candidate lists (``parallel_min_candidates``), serially otherwise.
"""

import math

import numba
import numpy as np

from colonsim.errors import ColonsimError

_OFF = 1 << 20
_BASE = 1 << 21


@numba.njit(cache=True)
def _cell_key(ix, iy, iz):
    return ((ix + _OFF) * _BASE + (iy + _OFF)) * _BASE + (iz + _OFF)


def segment_cell_table(xr, seg, cutoff, cell):
    """Sorted cell keys of the segments' inflated bounding boxes and the matching segment ids.

    With ``cell`` at least the longest segment and twice ``cutoff``, a box spans at most three
    cells per axis, so 27 offsets from its lower cell cover it (numpy: a rod has few segments).
    """
    a = xr[seg[:, 0]]
    b = xr[seg[:, 1]]
    lo = np.floor((np.minimum(a, b) - cutoff) / cell).astype(np.int64)
    hi = np.floor((np.maximum(a, b) + cutoff) / cell).astype(np.int64)
    off = np.stack(np.meshgrid(np.arange(3), np.arange(3), np.arange(3), indexing="ij"), axis=-1).reshape(-1, 3)
    cells = lo[:, None, :] + off[None, :, :]
    valid = np.all(cells <= hi[:, None, :], axis=2)
    cells = cells[valid]
    ids = np.broadcast_to(np.arange(len(seg), dtype=np.int64)[:, None], valid.shape)[valid]
    keys = ((cells[:, 0] + _OFF) * _BASE + (cells[:, 1] + _OFF)) * _BASE + (cells[:, 2] + _OFF)
    order = np.argsort(keys, kind="stable")
    return np.ascontiguousarray(keys[order]), np.ascontiguousarray(ids[order])


@numba.njit(cache=True, inline="always")
def _point_segment(xs, i, xr, a, b):
    """Squared distance from wall node i to segment (a, b) and the segment parameter t in [0, 1]."""
    e0 = xr[b, 0] - xr[a, 0]
    e1 = xr[b, 1] - xr[a, 1]
    e2 = xr[b, 2] - xr[a, 2]
    w0 = xs[i, 0] - xr[a, 0]
    w1 = xs[i, 1] - xr[a, 1]
    w2 = xs[i, 2] - xr[a, 2]
    ee = e0 * e0 + e1 * e1 + e2 * e2
    t = (w0 * e0 + w1 * e1 + w2 * e2) / ee if ee > 0.0 else 0.0
    t = min(max(t, 0.0), 1.0)
    d0 = w0 - t * e0
    d1 = w1 - t * e1
    d2 = w2 - t * e2
    return d0 * d0 + d1 * d1 + d2 * d2, t


@numba.njit(cache=True)
def candidate_counts(xs, xr, seg, keys, ids, cutoff, cell, counts):
    """Number of segments within ``cutoff`` of each wall node, into ``counts``.

    Serial: it runs only when the list is rebuilt (every few hundred steps) and costs a hash
    lookup per wall node."""
    n = xs.shape[0]
    c2 = cutoff * cutoff
    for i in range(n):
        key = _cell_key(int(math.floor(xs[i, 0] / cell)), int(math.floor(xs[i, 1] / cell)),
                        int(math.floor(xs[i, 2] / cell)))
        lo = np.searchsorted(keys, key, side="left")
        hi = np.searchsorted(keys, key, side="right")
        m = 0
        for j in range(lo, hi):
            s = ids[j]
            d2, _ = _point_segment(xs, i, xr, seg[s, 0], seg[s, 1])
            if d2 < c2:
                m += 1
        counts[i] = m


@numba.njit(cache=True)
def candidate_fill(xs, xr, seg, keys, ids, cutoff, cell, nodes, ptr, out):
    """Segment ids near each listed wall node into ``out[ptr[c]:ptr[c + 1]]`` (serial, see
    :func:`candidate_counts`)."""
    c2 = cutoff * cutoff
    for c in range(nodes.shape[0]):
        i = nodes[c]
        key = _cell_key(int(math.floor(xs[i, 0] / cell)), int(math.floor(xs[i, 1] / cell)),
                        int(math.floor(xs[i, 2] / cell)))
        lo = np.searchsorted(keys, key, side="left")
        hi = np.searchsorted(keys, key, side="right")
        p = ptr[c]
        for j in range(lo, hi):
            s = ids[j]
            d2, _ = _point_segment(xs, i, xr, seg[s, 0], seg[s, 1])
            if d2 < c2:
                out[p] = s
                p += 1


@numba.njit(cache=True)
def max_displacement(x, x_ref):
    """Largest nodal distance between x and x_ref, m (serial: a few flops per node)."""
    worst = 0.0
    for i in range(x.shape[0]):
        d0 = x[i, 0] - x_ref[i, 0]
        d1 = x[i, 1] - x_ref[i, 1]
        d2 = x[i, 2] - x_ref[i, 2]
        worst = max(worst, d0 * d0 + d1 * d1 + d2 * d2)
    return math.sqrt(worst)


@numba.njit(cache=True, inline="always")  # a call per node would cost more than its work
def _contact_one(c, xs, vs, ms, fixed_s, held_n, xr, vr, mr, seg, nodes, ptr, cand, radius, offset, k_free, k_held,
                 zeta, mu, v_slip, dt, fs, rod_seg, rod_t, rod_k, rod_f, damp_f, fric_f):
    """Contact of candidate wall node ``nodes[c]``: (energy, damping power, friction power,
    active 0/1, normal force)."""
    reach = radius + offset
    rod_seg[c] = -1
    i = nodes[c]
    best = np.inf
    best_s = -1
    best_t = 0.0
    for p in range(ptr[c], ptr[c + 1]):
        s = cand[p]
        d2, t = _point_segment(xs, i, xr, seg[s, 0], seg[s, 1])
        if d2 < best:
            best = d2
            best_s = s
            best_t = t
    if best_s < 0 or best >= reach * reach or best <= 0.0:
        return 0.0, 0.0, 0.0, 0, 0.0
    dist = math.sqrt(best)
    pen = reach - dist
    a = seg[best_s, 0]
    b = seg[best_s, 1]
    t = best_t
    if fixed_s[i] and (held_n[i, 0] != 0.0 or held_n[i, 1] != 0.0 or held_n[i, 2] != 0.0):
        # a point of the rigid fixed wall: it pushes along that wall's normal at rest
        n0 = held_n[i, 0]
        n1 = held_n[i, 1]
        n2 = held_n[i, 2]
    else:
        n0 = (xs[i, 0] - ((1.0 - t) * xr[a, 0] + t * xr[b, 0])) / dist
        n1 = (xs[i, 1] - ((1.0 - t) * xr[a, 1] + t * xr[b, 1])) / dist
        n2 = (xs[i, 2] - ((1.0 - t) * xr[a, 2] + t * xr[b, 2])) / dist
    mrc = (1.0 - t) * mr[a] + t * mr[b]
    meff = mrc if fixed_s[i] else ms[i] * mrc / (ms[i] + mrc)
    k = k_held if fixed_s[i] else k_free
    u0 = vs[i, 0] - ((1.0 - t) * vr[a, 0] + t * vr[b, 0])
    u1 = vs[i, 1] - ((1.0 - t) * vr[a, 1] + t * vr[b, 1])
    u2 = vs[i, 2] - ((1.0 - t) * vr[a, 2] + t * vr[b, 2])
    vn = u0 * n0 + u1 * n1 + u2 * n2
    elastic = k * pen
    fn = elastic - 2.0 * zeta * math.sqrt(k * meff) * vn
    if fn < 0.0:
        fn = 0.0
    energy = 0.5 * k * pen * pen
    p_damp = -(fn - elastic) * vn
    damp_f[c, 0] = (fn - elastic) * n0
    damp_f[c, 1] = (fn - elastic) * n1
    damp_f[c, 2] = (fn - elastic) * n2
    t0 = u0 - vn * n0
    t1 = u1 - vn * n1
    t2 = u2 - vn * n2
    vt = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    ft = 0.0
    p_fric = 0.0
    if mu > 0.0 and fn > 0.0:
        vreg = max(v_slip, mu * fn * dt / meff)
        ft = mu * fn / max(vt, vreg)
        p_fric = ft * vt * vt
    fric_f[c, 0] = -ft * t0
    fric_f[c, 1] = -ft * t1
    fric_f[c, 2] = -ft * t2
    f0 = fn * n0 - ft * t0
    f1 = fn * n1 - ft * t1
    f2 = fn * n2 - ft * t2
    fs[i, 0] += f0
    fs[i, 1] += f1
    fs[i, 2] += f2
    rod_seg[c] = best_s
    rod_t[c] = t
    rod_k[c] = k
    rod_f[c, 0] = -f0
    rod_f[c, 1] = -f1
    rod_f[c, 2] = -f2
    return energy, p_damp, p_fric, 1, fn


@numba.njit(parallel=True, cache=True)
def contact_kernel(xs, vs, ms, fixed_s, held_n, xr, vr, mr, seg, nodes, ptr, cand, radius, offset, k_free, k_held, zeta,
                   mu, v_slip, dt, fs, rod_seg, rod_t, rod_k, rod_f, damp_f, fric_f):
    """Penalty contact forces on the candidate wall nodes (added into ``fs``) and the reactions on
    the rod per candidate (``rod_seg`` = -1 if not in contact, ``rod_t``, ``rod_k`` the penalty
    used, ``rod_f``); the damping and friction parts of the force on the wall node go to
    ``damp_f`` and ``fric_f``. Free wall nodes get the penalty ``k_free``, held ones ``k_held``.

    Returns
    -------
    energy : float
        Penalty energy sum k g^2 / 2, J.
    p_damp, p_fric : float
        Power dissipated by contact damping and by friction, W (>= 0).
    n_active : int
    normal : float
        Sum of the normal forces, N.
    """
    energy = 0.0
    p_damp = 0.0
    p_fric = 0.0
    n_active = 0
    normal = 0.0
    for c in numba.prange(nodes.shape[0]):
        e, pd, pf, a, fn = _contact_one(c, xs, vs, ms, fixed_s, held_n, xr, vr, mr, seg, nodes, ptr, cand, radius,
                                        offset, k_free, k_held, zeta, mu, v_slip, dt, fs, rod_seg, rod_t, rod_k,
                                        rod_f, damp_f, fric_f)
        energy += e
        p_damp += pd
        p_fric += pf
        n_active += a
        normal += fn
    return energy, p_damp, p_fric, n_active, normal


@numba.njit(cache=True)
def contact_kernel_serial(xs, vs, ms, fixed_s, held_n, xr, vr, mr, seg, nodes, ptr, cand, radius, offset, k_free,
                          k_held, zeta, mu, v_slip, dt, fs, rod_seg, rod_t, rod_k, rod_f, damp_f, fric_f):
    """Serial :func:`contact_kernel` for candidate lists too short to pay for threads."""
    energy = 0.0
    p_damp = 0.0
    p_fric = 0.0
    n_active = 0
    normal = 0.0
    for c in range(nodes.shape[0]):
        e, pd, pf, a, fn = _contact_one(c, xs, vs, ms, fixed_s, held_n, xr, vr, mr, seg, nodes, ptr, cand, radius,
                                        offset, k_free, k_held, zeta, mu, v_slip, dt, fs, rod_seg, rod_t, rod_k,
                                        rod_f, damp_f, fric_f)
        energy += e
        p_damp += pd
        p_fric += pf
        n_active += a
        normal += fn
    return energy, p_damp, p_fric, n_active, normal


@numba.njit(cache=True)
def dissipation_rates(vs, vr, seg, nodes, rod_seg, rod_t, damp_f, fric_f):
    """Power (W, >= 0) taken out by the stored damping and friction forces at velocities vs, vr
    (serial: a few flops per contact)."""
    p_damp = 0.0
    p_fric = 0.0
    for c in range(nodes.shape[0]):
        s = rod_seg[c]
        if s < 0:
            continue
        i = nodes[c]
        a = seg[s, 0]
        b = seg[s, 1]
        t = rod_t[c]
        for k in range(3):
            u = vs[i, k] - ((1.0 - t) * vr[a, k] + t * vr[b, k])
            p_damp -= damp_f[c, k] * u
            p_fric -= fric_f[c, k] * u
    return p_damp, p_fric


@numba.njit(cache=True)
def rod_reactions(seg, rod_seg, rod_t, rod_k, rod_f, mr, fr, load):
    """Linear split of the contact reactions onto the rod nodes (serial: contacts are few and
    several of them share rod nodes). Returns the total force on the rod and
    max over rod nodes of (penalty stiffness acting on it / mass), 1/s^2."""
    for j in range(load.shape[0]):
        load[j] = 0.0
    t0 = 0.0
    t1 = 0.0
    t2 = 0.0
    for c in range(rod_seg.shape[0]):
        s = rod_seg[c]
        if s < 0:
            continue
        a = seg[s, 0]
        b = seg[s, 1]
        t = rod_t[c]
        for k in range(3):
            fr[a, k] += (1.0 - t) * rod_f[c, k]
            fr[b, k] += t * rod_f[c, k]
        load[a] += (1.0 - t) * rod_k[c]
        load[b] += t * rod_k[c]
        t0 += rod_f[c, 0]
        t1 += rod_f[c, 1]
        t2 += rod_f[c, 2]
    worst = 0.0
    for j in range(load.shape[0]):
        worst = max(worst, load[j] / mr[j])
    return t0, t1, t2, worst


class RodShellContact:
    """Penalty contact with damping and regularised Coulomb friction between a rod and a shell.

    Parameters
    ----------
    rod : colonsim.insertion.engine.rod.Rod
    shell : colonsim.insertion.engine.shell.Shell
    stiffness : float or None
        Penalty stiffness per free wall node, N/m. None: chosen so that the lightest wall node on
        its contact spring oscillates at half the shell's highest frequency (with the default
        damping the penalty then cuts the stable time step of the wall by about 20 %), and kept
        so as the wall stiffens (:meth:`follow_wall`).
    held_stiffness : float or None
        Penalty stiffness per held (fixed) wall node, N/m. A held node does not move, so its
        spring loads the rod alone and the wall's light nodes need not limit it. None: sixteen held
        springs on the lightest rod node add what one free spring adds to the lightest wall node
        (``stiffness * m_rod_min / (16 m_wall_min)``, never less than ``stiffness``; with four, a
        7.5 mm wall mesh went unstable between two time-step updates). A soft spring on a held
        node would let a hard-pushed scope sink through the fixed end rings.
    damping_ratio : float
        Fraction zeta of critical damping of each contact spring.
    friction : float
        Coulomb coefficient mu.
    slip_velocity : float
        Regularisation velocity v_reg of the friction law, m/s.
    offset : float or None
        Distance from the wall mid-surface to the contact surface, m (None: half the thickness).
    skin : float or None
        Extra search distance of the broad phase, m (None: half the rod radius).
    held_normals : (n, 3) float or None
        Unit normals of the wall at rest, pointing away from the rod's side (out of a tube's
        lumen). Given, a held node is a point of a rigid smooth wall and pushes the rod along its
        normal (docs/model.md, "Contact"): a held ring next to a bulged mobile wall is then a
        boundary the tip slides along, not a ledge it catches on. None: held nodes push along the
        line from the rod's axis to the node, like free ones.
    """

    def __init__(self, rod, shell, stiffness=None, damping_ratio=0.5, friction=0.0, slip_velocity=1e-3,
                 offset=None, skin=None, held_stiffness=None, held_normals=None):
        self.rod = rod
        self.shell = shell
        self.offset = 0.5 * shell.thickness if offset is None else float(offset)
        self.skin = 0.5 * rod.radius if skin is None else float(skin)
        self._free_follows_wall = stiffness is None
        self._held_follows_wall = held_stiffness is None
        if stiffness is None:
            omega = 2.0 / shell.critical_time_step(np.ascontiguousarray(shell.x0))
            stiffness = self._free_penalty(omega**2)
        if held_stiffness is None:
            held_stiffness = self._held_penalty(stiffness)
        checks = (("stiffness", stiffness, stiffness > 0.0), ("held_stiffness", held_stiffness, held_stiffness > 0.0),
                  ("damping_ratio", damping_ratio, damping_ratio >= 0.0),
                  ("friction", friction, friction >= 0.0), ("slip_velocity", slip_velocity, slip_velocity > 0.0),
                  ("offset", self.offset, self.offset >= 0.0), ("skin", self.skin, self.skin > 0.0))
        for label, value, ok in checks:
            if not (np.isfinite(value) and ok):
                raise ColonsimError(f"contact {label} = {value!r} is out of range; fix it.")
        self.stiffness = float(stiffness)
        self.held_stiffness = float(held_stiffness)
        self.damping_ratio = float(damping_ratio)
        self.friction = float(friction)
        self.slip_velocity = float(slip_velocity)
        self.cutoff = rod.radius + self.offset + self.skin
        self.cell = max(2.0 * self.cutoff, float(rod.rest_length.max()))
        if held_normals is None:  # zeros: the kernel's flag to push along the axis-to-node line
            self._held_normal = np.zeros_like(shell.x0)
        else:
            self._held_normal = np.ascontiguousarray(held_normals, dtype=np.float64)
            if self._held_normal.shape != shell.x0.shape or not np.all(np.isfinite(self._held_normal)):
                raise ColonsimError(f"held_normals must be finite unit vectors of shape {shell.x0.shape}; fix them.")
        self._xr_build = None
        self._xs_build = None
        self.n_rebuilds = 0
        # below this many candidate wall nodes the narrow phase runs serially (cheaper than threads)
        self.parallel_min_candidates = 20_000
        self._nodes = np.zeros(0, dtype=np.int64)
        self._ptr = np.zeros(1, dtype=np.int64)
        self._cand = np.zeros(0, dtype=np.int64)
        self._counts = np.zeros(len(shell.x0), dtype=np.int64)
        self._load = np.zeros(len(rod.x0))
        self._rod_weight = 0.0
        self.energy = 0.0
        self.dissipated = 0.0
        self.friction_dissipated = 0.0
        self.n_active = 0
        self.normal_force = 0.0
        self.force_on_rod = np.zeros(3)
        self._p_damp = 0.0
        self._p_fric = 0.0

    def _free_penalty(self, wall_omega2):
        return 0.25 * float(self.shell.mass.min()) * wall_omega2

    def _held_penalty(self, free):
        return free * max(1.0, float(self.rod.mass.min()) / (16.0 * float(self.shell.mass.min())))

    def follow_wall(self, body_omega2):
        """Penalties left to their defaults follow the wall's current highest squared frequency
        (``body_omega2[shell name]``, rad^2/s^2; the solver passes it at every time-step update).

        The Mooney-Rivlin wall stiffens several-fold as it stretches; a penalty set once at the
        unstretched state would let the scope sink through a stretched wall. Following the wall
        keeps the penalty's share of the stable time step what it was at the start.
        """
        if self._free_follows_wall:
            self.stiffness = self._free_penalty(body_omega2[self.shell.name])
        if self._held_follows_wall:
            self.held_stiffness = self._held_penalty(self.stiffness)

    # -- broad phase -------------------------------------------------------------------------

    @property
    def n_candidates(self):
        """Candidate (wall node, segment) pairs of the current list."""
        return len(self._cand)

    def _needs_rebuild(self, xr, xs):
        if self._xr_build is None:
            return True
        moved = max_displacement(xr, self._xr_build) + max_displacement(xs, self._xs_build)
        return moved > self.skin

    def build_candidates(self, xr, xs):
        """Rebuild the candidate pairs for rod positions xr and wall positions xs."""
        seg = self.rod.segments
        keys, ids = segment_cell_table(xr, seg, self.cutoff, self.cell)
        candidate_counts(xs, xr, seg, keys, ids, self.cutoff, self.cell, self._counts)
        nodes = np.flatnonzero(self._counts).astype(np.int64)
        ptr = np.zeros(len(nodes) + 1, dtype=np.int64)
        np.cumsum(self._counts[nodes], out=ptr[1:])
        cand = np.empty(ptr[-1], dtype=np.int64)
        candidate_fill(xs, xr, seg, keys, ids, self.cutoff, self.cell, nodes, ptr, cand)
        self._nodes, self._ptr, self._cand = nodes, ptr, cand
        self._rod_seg = np.full(len(nodes), -1, dtype=np.int64)
        self._rod_t = np.zeros(len(nodes))
        self._rod_k = np.zeros(len(nodes))
        self._rod_f = np.zeros((len(nodes), 3))
        self._damp_f = np.zeros((len(nodes), 3))
        self._fric_f = np.zeros((len(nodes), 3))
        self._xr_build = xr.copy()
        self._xs_build = xs.copy()
        self.n_rebuilds += 1

    # -- solver interface --------------------------------------------------------------------

    def compute(self, state, dt):
        """Add contact forces at the current state into the bodies' ``f_con`` buffers."""
        r = state[self.rod.name]
        s = state[self.shell.name]
        if self._needs_rebuild(r.x, s.x):
            self.build_candidates(r.x, s.x)
        kernel = contact_kernel if len(self._nodes) >= self.parallel_min_candidates else contact_kernel_serial
        energy, p_damp, p_fric, n_active, normal = kernel(
            s.x, s.v, self.shell.mass, s.fixed, self._held_normal, r.x, r.v, self.rod.mass, self.rod.segments,
            self._nodes, self._ptr,
            self._cand, self.rod.radius, self.offset, self.stiffness, self.held_stiffness, self.damping_ratio,
            self.friction, self.slip_velocity, dt, s.f_con, self._rod_seg, self._rod_t, self._rod_k, self._rod_f,
            self._damp_f, self._fric_f,
        )
        f0, f1, f2, weight = rod_reactions(self.rod.segments, self._rod_seg, self._rod_t, self._rod_k, self._rod_f,
                                           self.rod.mass, r.f_con, self._load)
        self.energy = energy
        self._p_damp = p_damp
        self._p_fric = p_fric
        self.n_active = n_active
        self.normal_force = normal
        self.force_on_rod = np.array([f0, f1, f2])
        self._rod_weight = weight

    def finish_step(self, state, dt):
        """Accumulate the energy dissipated during the step: the forces of the step times the
        relative velocity averaged over the old and new half-step velocities (as the solver
        sums the work on the bodies)."""
        if len(self._nodes) == 0:
            return
        p_damp, p_fric = dissipation_rates(state[self.shell.name].v, state[self.rod.name].v, self.rod.segments,
                                           self._nodes, self._rod_seg, self._rod_t, self._damp_f, self._fric_f)
        self.dissipated += 0.5 * (self._p_damp + p_damp + self._p_fric + p_fric) * dt
        self.friction_dissipated += 0.5 * (self._p_fric + p_fric) * dt

    def record(self):
        """Scalars of the current step for the history."""
        return {
            "energy": self.energy,
            "dissipated": self.dissipated,
            "friction_dissipated": self.friction_dissipated,
            "normal_force": self.normal_force,
            "force_on_rod": self.force_on_rod.copy(),
            "n_active": self.n_active,
            "n_candidates": self.n_candidates,
        }

    # -- time step ---------------------------------------------------------------------------

    def frequency_squared(self):
        """Squared frequency the penalty springs add to each body (Gershgorin rows), rad^2/s^2.

        Wall: one free spring per node, k / m. Rod: the largest penalty stiffness per unit mass
        on a rod node of the last evaluation, doubled for contacts appearing before the next
        update, and at least that of four full held-node contacts on the lightest rod node. Both
        are divided by the square of :meth:`damping_reduction` (a damped spring counts as a
        stiffer undamped one).
        """
        reduction = self.damping_reduction() ** 2
        rod_w2 = max(2.0 * self._rod_weight, 4.0 * self.held_stiffness / float(self.rod.mass.min()))
        return {self.shell.name: self.stiffness / float(self.shell.mass.min()) / reduction,
                self.rod.name: rod_w2 / reduction}

    def damping_reduction(self):
        """Factor sqrt(1 + zeta^2) - zeta on the stable step of a damped spring (damping force from
        the previous half-step velocity)."""
        z = self.damping_ratio
        return math.sqrt(1.0 + z * z) - z

    def critical_time_step(self):
        """Stable step of the contact springs alone, s."""
        return 2.0 / math.sqrt(max(self.frequency_squared().values()))
