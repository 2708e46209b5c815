"""Narrow phase of the rod-shell contact: penalty, damping and friction forces per candidate
contact point of the wall (the law is in :mod:`colonsim.insertion.engine.contact`'s docstring;
the points, wall nodes or points on its faces, in :mod:`colonsim.insertion.engine.contact_points`),
the power they dissipate, and the reactions split onto the rod nodes and the wall nodes; the
active springs' stiffness times a displacement, for the global time-step estimate
(:mod:`colonsim.insertion.engine.global_time_step`).

A point rests on ``pn[q, :]`` wall nodes with weights ``pw[q, :]`` and takes ``ps[q]`` of a node's
penalty and mass. Gathering starts from the first node's term, so a point that is a node (one
node, weight 1, share 1) gives the node's own numbers to the bit.

The force kernel is one source compiled threaded and serial (:mod:`._compile`).
"""

import math

import numba
import numpy as np

from colonsim.insertion.engine._compile import threaded_and_serial


@numba.njit(cache=True, inline="always")
def point_segment_at(p0, p1, p2, xr, a, b):
    """Squared distance from the point (p0, p1, p2) to segment (a, b) and the segment parameter t in [0, 1]."""
    e0 = xr[b, 0] - xr[a, 0]
    e1 = xr[b, 1] - xr[a, 1]
    e2 = xr[b, 2] - xr[a, 2]
    w0 = p0 - xr[a, 0]
    w1 = p1 - xr[a, 1]
    w2 = p2 - xr[a, 2]
    ee = e0 * e0 + e1 * e1 + e2 * e2
    t = (w0 * e0 + w1 * e1 + w2 * e2) / ee if ee > 0.0 else 0.0
    t = min(max(t, 0.0), 1.0)
    d0 = w0 - t * e0
    d1 = w1 - t * e1
    d2 = w2 - t * e2
    return d0 * d0 + d1 * d1 + d2 * d2, t


@numba.njit(cache=True, inline="always")
def point_segment(xs, i, xr, a, b):
    """Squared distance from point i of ``xs`` to segment (a, b) and the segment parameter t in [0, 1]."""
    return point_segment_at(xs[i, 0], xs[i, 1], xs[i, 2], xr, a, b)


@numba.njit(cache=True, inline="always")
def gather(values, pn, pw, q, k):
    """Component k of point q's interpolation of the nodal ``values`` (n, 3)."""
    s = pw[q, 0] * values[pn[q, 0], k]
    for j in range(1, pn.shape[1]):
        s += pw[q, j] * values[pn[q, j], k]
    return s


@numba.njit(cache=True, inline="always")
def point_held(fixed_s, pn, pw, q):
    """Is point q held: do the nodes held at rest carry at least half its weight? (A node point:
    is its node held.) On the seam between the fixed and the mobile wall, the points nearer the
    held nodes are then the rigid wall's, as the held nodes are."""
    held = 0.0
    for j in range(pn.shape[1]):
        if fixed_s[pn[q, j]] != 0:
            held += pw[q, j]
    return held >= 0.5


@numba.njit(cache=True, inline="always")
def _nearest_segment(p0, p1, p2, xr, seg, ptr, cand, c):
    """(squared distance, segment, t) of candidate point c's nearest candidate segment (segment
    -1 if it has none), the first of equals."""
    best = np.inf
    best_s = -1
    best_t = 0.0
    for p in range(ptr[c], ptr[c + 1]):
        s = cand[p]
        d2, t = point_segment_at(p0, p1, p2, xr, seg[s, 0], seg[s, 1])
        if d2 < best:
            best = d2
            best_s = s
            best_t = t
    return best, best_s, best_t


def _contact_forces(xs, vs, ms, fixed_s, pn, pw, ps, held_n, xr, vr, mr, seg, points, ptr, cand, radius, offset,
                    k_free, k_held, zeta, mu, v_slip, dt, rod_seg, rod_t, rod_k, rod_f, damp_f, fric_f):
    """Penalty contact forces of the candidate points: the reaction on the rod per candidate
    (``rod_seg`` = -1 if not in contact, ``rod_t``, ``rod_k`` the penalty used, ``rod_f``; the
    force on the wall is its opposite, :func:`wall_reactions`); the damping and friction parts of
    the force on the wall go to ``damp_f`` and ``fric_f``. Free points get the penalty ``k_free``,
    held ones ``k_held``, each times its share ``ps``.

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
    reach = radius + offset
    reach2 = reach * reach
    for c in numba.prange(points.shape[0]):
        # The search and the test for reach first, then the contact law written out in the loop:
        # with the test's early return inside an inlined law, a point out of reach cost 240 ns
        # instead of about 30; with the law a call of 34 arguments, a point in reach cost about
        # 500 ns more than written out (measured: THF beta 45 at 3 s, 188 of 1,006 points in
        # reach, 132-156 against 50-60 us a call).
        rod_seg[c] = -1
        q = points[c]
        p0 = gather(xs, pn, pw, q, 0)
        p1 = gather(xs, pn, pw, q, 1)
        p2 = gather(xs, pn, pw, q, 2)
        best, best_s, best_t = _nearest_segment(p0, p1, p2, xr, seg, ptr, cand, c)
        if best_s < 0 or best >= reach2 or best <= 0.0:
            continue
        dist = math.sqrt(best)
        pen = reach - dist
        a = seg[best_s, 0]
        b = seg[best_s, 1]
        t = best_t
        held = point_held(fixed_s, pn, pw, q)
        if held and (held_n[q, 0] != 0.0 or held_n[q, 1] != 0.0 or held_n[q, 2] != 0.0):
            # a point of the rigid fixed wall: it pushes along that wall's normal at rest
            n0 = held_n[q, 0]
            n1 = held_n[q, 1]
            n2 = held_n[q, 2]
        else:
            n0 = (p0 - ((1.0 - t) * xr[a, 0] + t * xr[b, 0])) / dist
            n1 = (p1 - ((1.0 - t) * xr[a, 1] + t * xr[b, 1])) / dist
            n2 = (p2 - ((1.0 - t) * xr[a, 2] + t * xr[b, 2])) / dist
        m = pw[q, 0] * ms[pn[q, 0]]
        for j in range(1, pn.shape[1]):
            m += pw[q, j] * ms[pn[q, j]]
        m *= ps[q]
        mrc = (1.0 - t) * mr[a] + t * mr[b]
        meff = mrc if held else m * mrc / (m + mrc)
        k = (k_held if held else k_free) * ps[q]
        u0 = gather(vs, pn, pw, q, 0) - ((1.0 - t) * vr[a, 0] + t * vr[b, 0])
        u1 = gather(vs, pn, pw, q, 1) - ((1.0 - t) * vr[a, 1] + t * vr[b, 1])
        u2 = gather(vs, pn, pw, q, 2) - ((1.0 - t) * vr[a, 2] + t * vr[b, 2])
        vn = u0 * n0 + u1 * n1 + u2 * n2
        elastic = k * pen
        fn = elastic - 2.0 * zeta * math.sqrt(k * meff) * vn
        if fn < 0.0:
            fn = 0.0
        e_c = 0.5 * k * pen * pen
        pd_c = -(fn - elastic) * vn
        damp_f[c, 0] = (fn - elastic) * n0
        damp_f[c, 1] = (fn - elastic) * n1
        damp_f[c, 2] = (fn - elastic) * n2
        t0 = u0 - vn * n0
        t1 = u1 - vn * n1
        t2 = u2 - vn * n2
        vt = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
        ft = 0.0
        pf_c = 0.0
        if mu > 0.0 and fn > 0.0:
            vreg = max(v_slip, mu * fn * dt / meff)
            ft = mu * fn / max(vt, vreg)
            pf_c = ft * vt * vt
        fric_f[c, 0] = -ft * t0
        fric_f[c, 1] = -ft * t1
        fric_f[c, 2] = -ft * t2
        rod_seg[c] = best_s
        rod_t[c] = t
        rod_k[c] = k
        rod_f[c, 0] = -(fn * n0 - ft * t0)
        rod_f[c, 1] = -(fn * n1 - ft * t1)
        rod_f[c, 2] = -(fn * n2 - ft * t2)
        energy += e_c
        p_damp += pd_c
        p_fric += pf_c
        n_active += 1
        normal += fn
    return energy, p_damp, p_fric, n_active, normal


contact_kernel, contact_kernel_serial = threaded_and_serial(_contact_forces)


@numba.njit(cache=True)
def wall_reactions(points, pn, pw, rod_seg, rod_f, fs):
    """Add the contact forces of the active candidate points onto the wall nodes they rest on
    (``fs``), by their weights (serial: points share nodes)."""
    for c in range(points.shape[0]):
        if rod_seg[c] < 0:
            continue
        q = points[c]
        for j in range(pn.shape[1]):
            i = pn[q, j]
            w = pw[q, j]
            fs[i, 0] += w * -rod_f[c, 0]
            fs[i, 1] += w * -rod_f[c, 1]
            fs[i, 2] += w * -rod_f[c, 2]


@numba.njit(cache=True, inline="always")
def _active_pair(c, seg, points, rod_seg, rod_t):
    """(in contact, contact point, segment's first and second node, fraction t along it) of candidate c."""
    s = rod_seg[c]
    if s < 0:
        return False, 0, 0, 0, 0.0
    return True, points[c], seg[s, 0], seg[s, 1], rod_t[c]


@numba.njit(cache=True)
def dissipation_rates(vs, vr, seg, points, pn, pw, rod_seg, rod_t, damp_f, fric_f):
    """Power (W, >= 0) taken out by the stored damping and friction forces at velocities vs, vr
    (serial: a few flops per contact)."""
    p_damp = 0.0
    p_fric = 0.0
    for c in range(points.shape[0]):
        active, q, a, b, t = _active_pair(c, seg, points, rod_seg, rod_t)
        if not active:
            continue
        for k in range(3):
            u = gather(vs, pn, pw, q, k) - ((1.0 - t) * vr[a, k] + t * vr[b, k])
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


@numba.njit(cache=True)
def contact_spring_action(xs, xr, seg, points, pn, pw, rod_seg, rod_t, rod_k, fixed_s, held_n, scale, us, ur, out_s,
                          out_r):
    """Add the active penalty springs' K u into ``out_s`` (wall) and ``out_r`` (scope): for
    candidate c in contact (``rod_seg[c]`` >= 0), contact point q, the scope point
    p = (1 - t) x_a + t x_b, the normal n from p to the point (a held point's rest normal
    ``held_n[q]`` when it is nonzero), the relative displacement d = u_q - ((1 - t) u_a + t u_b)
    (u_q interpolated from its nodes, 0 for a held point) and the spring force
    ``scale * k (n . d) n``, split onto the point's nodes by their weights and linearly onto the
    segment's nodes."""
    for c in range(points.shape[0]):
        active, q, a, b, t = _active_pair(c, seg, points, rod_seg, rod_t)
        if not active:
            continue
        held = point_held(fixed_s, pn, pw, q)
        n0 = 0.0
        n1 = 0.0
        n2 = 0.0
        if held and (held_n[q, 0] != 0.0 or held_n[q, 1] != 0.0 or held_n[q, 2] != 0.0):
            n0 = held_n[q, 0]
            n1 = held_n[q, 1]
            n2 = held_n[q, 2]
        else:
            n0 = gather(xs, pn, pw, q, 0) - ((1.0 - t) * xr[a, 0] + t * xr[b, 0])
            n1 = gather(xs, pn, pw, q, 1) - ((1.0 - t) * xr[a, 1] + t * xr[b, 1])
            n2 = gather(xs, pn, pw, q, 2) - ((1.0 - t) * xr[a, 2] + t * xr[b, 2])
            norm = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
            if norm == 0.0:
                continue
            n0 /= norm
            n1 /= norm
            n2 /= norm
        d0 = -((1.0 - t) * ur[a, 0] + t * ur[b, 0])
        d1 = -((1.0 - t) * ur[a, 1] + t * ur[b, 1])
        d2 = -((1.0 - t) * ur[a, 2] + t * ur[b, 2])
        if not held:
            d0 += gather(us, pn, pw, q, 0)
            d1 += gather(us, pn, pw, q, 1)
            d2 += gather(us, pn, pw, q, 2)
        g = scale * rod_k[c] * (n0 * d0 + n1 * d1 + n2 * d2)
        if not held:
            for j in range(pn.shape[1]):
                i = pn[q, j]
                w = pw[q, j]
                out_s[i, 0] += w * (g * n0)
                out_s[i, 1] += w * (g * n1)
                out_s[i, 2] += w * (g * n2)
        out_r[a, 0] -= (1.0 - t) * g * n0
        out_r[a, 1] -= (1.0 - t) * g * n1
        out_r[a, 2] -= (1.0 - t) * g * n2
        out_r[b, 0] -= t * g * n0
        out_r[b, 1] -= t * g * n1
        out_r[b, 2] -= t * g * n2
