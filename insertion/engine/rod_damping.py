"""Implicit strain-rate damping of the rod (docs/model.md, "Time integration and damping").

Each axial spring of the rod carries a dashpot in parallel (Kelvin-Voigt): the force between the
segment's two nodes is ``c_e t_e t_e^T (v_b - v_a)``, with ``t_e`` the unit segment direction and
``c_e = tau EA / L0`` (``tau``, s, the damping time of the material). It resists only the rate of
axial strain: a rod that slides along itself or moves rigidly feels no force, so the push through
the sheath is not dragged, while the axial waves that make the push force ring are damped, the
shorter ones the most (damping ratio ``tau omega / 2`` at angular frequency omega).

Explicitly, such a dashpot would cut the stable time step to ``2 / omega (sqrt(1 + z^2) - z)``,
``z = tau omega_max / 2``: for the scope's highest axial frequency a damping time that matters for
its first mode costs a factor of 10 to 100. Taken implicitly (trapezoidal, the average of the old
and new half-step velocities, like the solver's mass damping) it is unconditionally stable, and
the velocity update becomes a block-tridiagonal solve along the chain: 3 x 3 blocks, a few
microseconds for a scope's hundred nodes.

Constraints enter the solve as rows: a node's velocity components in a constrained subspace
(projector ``Q``) are set to a target ``w``; the momentum balance holds in the rest. The reaction
is what the balance lacks on the constrained components. Per node the constrained subspace is
none, the plane across a line (:data:`~colonsim.insertion.engine.constraints.ON_LINE`, the sheath)
or everything (:data:`~colonsim.insertion.engine.constraints.HELD`, a driven or fixed node).
"""

import numba
import numpy as np

from colonsim.insertion.engine.constraints import FREE, HELD, ON_LINE


@numba.njit(cache=True)
def merge_rows(node_kind, node_dir, node_target, nodes, kind, vectors):
    """Add one constraint's rows to the per-node rows (kind, line direction, target velocity).

    A later constraint sets the components it constrains and keeps the earlier ones' others, as
    the solver applies constraints to an explicit body one after the other."""
    for j in range(nodes.shape[0]):
        i = nodes[j]
        old = node_kind[i]
        if kind == HELD or old == FREE:
            node_kind[i] = kind
            for a in range(3):
                node_dir[i, a] = vectors[j, a] if kind == ON_LINE else 0.0
                node_target[i, a] = vectors[j, a] if kind == HELD else 0.0
        elif old == HELD:  # a line on a held node: keep the held target's component along it
            along = 0.0
            for a in range(3):
                along += vectors[j, a] * node_target[i, a]
            for a in range(3):
                node_target[i, a] = along * vectors[j, a]
        else:  # two lines: the same line, or held at rest
            c = 0.0
            for a in range(3):
                c += vectors[j, a] * node_dir[i, a]
            if abs(c) < 1.0 - 1e-12:
                node_kind[i] = HELD
                for a in range(3):
                    node_dir[i, a] = 0.0
                    node_target[i, a] = 0.0


@numba.njit(cache=True, inline="always")
def _projector(kind, d, Q):
    for a in range(3):
        for b in range(3):
            if kind == HELD:
                Q[a, b] = 1.0 if a == b else 0.0
            elif kind == ON_LINE:
                Q[a, b] = (1.0 if a == b else 0.0) - d[a] * d[b]
            else:
                Q[a, b] = 0.0


@numba.njit(cache=True, inline="always")
def _inv3(a, out):
    """Inverse of a 3 x 3 matrix into ``out``."""
    c00 = a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]
    c01 = a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]
    c02 = a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]
    det = a[0, 0] * c00 + a[0, 1] * c01 + a[0, 2] * c02
    r = 1.0 / det
    out[0, 0] = c00 * r
    out[1, 0] = c01 * r
    out[2, 0] = c02 * r
    out[0, 1] = (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) * r
    out[1, 1] = (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) * r
    out[2, 1] = (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) * r
    out[0, 2] = (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1]) * r
    out[1, 2] = (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2]) * r
    out[2, 2] = (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0]) * r


@numba.njit(cache=True)
def damped_rod_velocity(x, v, f_int, f_con, f_ext, mass, alpha, alpha_lat, dashpot, node_kind, node_dir, W, dt, v_new,
                        f_damp, reaction):
    """Velocity update of a rod with mass-proportional damping ``alpha`` and axial dashpots,
    both trapezoidal, and constraint rows.

    Solves, for the new half-step velocities v+ (old ones v-, forces f at the current positions),

        m (v+ - v-) / dt = f - alpha m (v- + v+) / 2 - C (v- + v+) / 2 + R

    with C the dashpots' damping matrix (block tridiagonal) and the lateral damping (below),
    ``Q_i v+_i = W_i`` on every node and the reaction R in the span of ``Q_i``.

    Parameters
    ----------
    x : (n, 3) positions, m (the dashpot directions)
    v : (n, 3) old half-step velocities, m/s
    f_int, f_con, f_ext : (n, 3) forces, N
    mass : (n,) kg
    alpha : float, 1/s
    alpha_lat : float
        Mass-proportional damping of the velocity across the rod (the node's tangent: the chord
        of its neighbours), 1/s: it damps the rod's lateral vibration and leaves sliding along
        itself free.
    dashpot : (n - 1,) dashpot coefficient of each segment, N s/m
    node_kind, node_dir, W : (n,), (n, 3), (n, 3) each node's rows (:func:`merge_rows`): the
        constrained components and the target velocity in them, m/s
    dt : float, s (the step of the staggered velocities)
    v_new, f_damp, reaction : (n, 3) outputs: new velocities, damping force (mass and dashpot, at
        the mean velocity), constraint reaction, N
    """
    n = x.shape[0]
    h = 0.5 * dt
    T = np.zeros((n - 1, 3, 3))
    d = np.empty(3)
    for e in range(n - 1):
        for a in range(3):
            d[a] = x[e + 1, a] - x[e, a]
        d /= np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        for a in range(3):
            for b in range(3):
                T[e, a, b] = dashpot[e] * d[a] * d[b]
    G = np.zeros((n, 3, 3))
    if alpha_lat > 0.0:
        for i in range(n):
            lo = max(i - 1, 0)
            hi = min(i + 1, n - 1)
            for a in range(3):
                d[a] = x[hi, a] - x[lo, a]
            d /= np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
            for a in range(3):
                for b in range(3):
                    G[i, a, b] = alpha_lat * mass[i] * ((1.0 if a == b else 0.0) - d[a] * d[b])
    # C v- (the explicit half of the trapezoid)
    cv = np.zeros((n, 3))
    for i in range(n):
        for a in range(3):
            for b in range(3):
                cv[i, a] -= G[i, a, b] * v[i, b]
    for e in range(n - 1):
        for a in range(3):
            s = 0.0
            for b in range(3):
                s += T[e, a, b] * (v[e + 1, b] - v[e, b])
            cv[e, a] += s
            cv[e + 1, a] -= s
    # rows: (I - Q)(D v_i + L v_{i-1} + U v_{i+1} - r) + Q (v_i - w) = 0
    Qi = np.zeros((3, 3))
    Dp = np.zeros((n, 3, 3))  # eliminated diagonal blocks, inverted
    y = np.zeros((n, 3))
    upper = np.zeros((n, 3, 3))  # (I - Q_i) U_i
    A = np.zeros((3, 3))
    P = np.zeros((3, 3))
    M = np.zeros((3, 3))
    # per-node scratch, allocated once (an allocation per node cost more than the solve)
    r = np.zeros(3)
    D = np.zeros((3, 3))
    rhs = np.zeros(3)
    B = np.zeros((3, 3))
    z = np.zeros(3)
    g = np.zeros(3)
    for i in range(n):
        m = mass[i]
        _projector(node_kind[i], node_dir[i], Qi)
        for a in range(3):
            for b in range(3):
                P[a, b] = (1.0 if a == b else 0.0) - Qi[a, b]
        D[:, :] = 0.0
        for a in range(3):
            r[a] = m * (1.0 - h * alpha) * v[i, a] + dt * (f_int[i, a] + f_con[i, a] + f_ext[i, a]) + h * cv[i, a]
            D[a, a] = m * (1.0 + h * alpha)
            for b in range(3):
                D[a, b] += h * G[i, a, b]
        if i > 0:
            for a in range(3):
                for b in range(3):
                    D[a, b] += h * T[i - 1, a, b]
        if i < n - 1:
            for a in range(3):
                for b in range(3):
                    D[a, b] += h * T[i, a, b]
        for a in range(3):
            s = 0.0
            for b in range(3):
                s += P[a, b] * r[b] + Qi[a, b] * W[i, b]
            rhs[a] = s
            for b in range(3):
                acc = Qi[a, b]
                for k in range(3):
                    acc += P[a, k] * D[k, b]
                A[a, b] = acc
        if i < n - 1:  # U_i = -h T_i
            for a in range(3):
                for b in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc -= P[a, k] * h * T[i, k, b]
                    upper[i, a, b] = acc
        if i > 0:  # B_i = (I - Q_i) L_i, L_i = -h T_{i-1}; eliminate v_{i-1}
            for a in range(3):
                for b in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc -= P[a, k] * h * T[i - 1, k, b]
                    B[a, b] = acc
            # M = B Dp_{i-1}; A -= M upper_{i-1}; rhs -= M y_{i-1}
            for a in range(3):
                for b in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += B[a, k] * Dp[i - 1, k, b]
                    M[a, b] = acc
            for a in range(3):
                for b in range(3):
                    acc = 0.0
                    for k in range(3):
                        acc += M[a, k] * upper[i - 1, k, b]
                    A[a, b] -= acc
                acc = 0.0
                for k in range(3):
                    acc += M[a, k] * y[i - 1, k]
                rhs[a] -= acc
        _inv3(A, Dp[i])
        for a in range(3):
            y[i, a] = rhs[a]
    for i in range(n - 1, -1, -1):
        for a in range(3):
            z[a] = y[i, a]
            if i < n - 1:
                for b in range(3):
                    z[a] -= upper[i, a, b] * v_new[i + 1, b]
        for a in range(3):
            acc = 0.0
            for b in range(3):
                acc += Dp[i, a, b] * z[b]
            v_new[i, a] = acc
    # damping force at the mean velocity, and the reaction that closes the balance
    for i in range(n):
        for a in range(3):
            f_damp[i, a] = -0.5 * alpha * mass[i] * (v[i, a] + v_new[i, a])
            for b in range(3):
                f_damp[i, a] -= 0.5 * G[i, a, b] * (v[i, b] + v_new[i, b])
    for e in range(n - 1):
        for a in range(3):
            s = 0.0
            for b in range(3):
                s += T[e, a, b] * (v[e + 1, b] + v_new[e + 1, b] - v[e, b] - v_new[e, b])
            f_damp[e, a] += 0.5 * s
            f_damp[e + 1, a] -= 0.5 * s
    for i in range(n):
        for a in range(3):
            g[a] = mass[i] * (v_new[i, a] - v[i, a]) / dt - (f_int[i, a] + f_con[i, a] + f_ext[i, a] + f_damp[i, a])
        _projector(node_kind[i], node_dir[i], Qi)
        for a in range(3):
            acc = 0.0
            for b in range(3):
                acc += Qi[a, b] * g[b]
            reaction[i, a] = acc
