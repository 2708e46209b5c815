"""Nodal kernels of the explicit integrator (docs/model.md, "Time integration and damping"): the damped
velocity update and the position update with the work of each force family.

Each kernel is one source compiled threaded and serial (:mod:`._compile`); the solver picks the
serial one for bodies too small to pay for threads. Both visit the nodes listed in ``nodes`` (in
that order): every node, or all but the wall's quiet held nodes, whose update is zeros
(:meth:`colonsim.insertion.engine.body_state.BodyState.leave_out_quiet`).
"""

import numba

from colonsim.insertion.engine._compile import threaded_and_serial


def _velocity_update(nodes, v, f_int, f_con, f_ext, mass, fixed, alpha, dt, v_new, f_damp, reaction):
    """Damped velocity update of ``nodes`` into ``v_new``; fixed nodes get zero velocity and their
    reaction.

    The loop body is written out here: as an inlined function of a node, the branch for held
    nodes made the loop 25 times slower (measured)."""
    h = 0.5 * alpha * dt
    keep = (1.0 - h) / (1.0 + h)
    for j in numba.prange(nodes.shape[0]):
        i = nodes[j]
        if fixed[i] and v[i, 0] == 0.0 and v[i, 1] == 0.0 and v[i, 2] == 0.0 \
                and f_int[i, 0] + f_con[i, 0] + f_ext[i, 0] == 0.0 and f_int[i, 1] + f_con[i, 1] + f_ext[i, 1] == 0.0 \
                and f_int[i, 2] + f_con[i, 2] + f_ext[i, 2] == 0.0:
            # most of a wall is held and carries no force: its update is zeros, without the division
            for k in range(3):
                v_new[i, k] = 0.0
                f_damp[i, k] = 0.0
                reaction[i, k] = 0.0
            continue
        # one division per node: divisions dominate this otherwise memory-bound loop
        m = mass[i]
        gain = dt / (m * (1.0 + h))
        for k in range(3):
            ftot = f_int[i, k] + f_con[i, k] + f_ext[i, k]
            vf = keep * v[i, k] + gain * ftot
            f_damp[i, k] = -0.5 * alpha * m * (v[i, k] + vf)
            if fixed[i]:
                v_new[i, k] = 0.0
                reaction[i, k] = -vf * (m / dt)
            else:
                v_new[i, k] = vf
                reaction[i, k] = 0.0


velocity_kernel, velocity_kernel_serial = threaded_and_serial(_velocity_update)


@numba.njit(cache=True, inline="always")  # a call per node would cost more than its work
def _advance_node(i, x, v, v_new, mass, f_int, f_con, f_ext, f_damp, reaction, dt):
    w_int = 0.0
    w_con = 0.0
    w_ext = 0.0
    w_damp = 0.0
    w_react = 0.0
    kinetic = 0.0
    if v[i, 0] == 0.0 and v[i, 1] == 0.0 and v[i, 2] == 0.0 and v_new[i, 0] == 0.0 and v_new[i, 1] == 0.0 \
            and v_new[i, 2] == 0.0:
        return w_int, w_con, w_ext, w_damp, w_react, kinetic  # a node at rest: no work, no motion
    for k in range(3):
        va = 0.5 * (v[i, k] + v_new[i, k])
        w_int += f_int[i, k] * va
        w_con += f_con[i, k] * va
        w_ext += f_ext[i, k] * va
        w_damp += f_damp[i, k] * va
        w_react += reaction[i, k] * va
        kinetic += 0.5 * mass[i] * va * va
        x[i, k] += dt * v_new[i, k]
        v[i, k] = v_new[i, k]
    return w_int, w_con, w_ext, w_damp, w_react, kinetic


def _advance(nodes, x, v, v_new, mass, f_int, f_con, f_ext, f_damp, reaction, dt_mid, dt):
    """Work increments of each force family, mid-step kinetic energy; then x += dt v_new, v = v_new,
    at ``nodes`` (a node left out must be at rest, v = v_new = 0: it adds nothing).

    Returns
    -------
    w_int, w_con, w_ext, w_damp, w_react, kinetic : float
        Work (J) done on the body during the step by each family, and the kinetic energy at the
        mid-step velocity (v_old + v_new) / 2.
    """
    w_int = 0.0
    w_con = 0.0
    w_ext = 0.0
    w_damp = 0.0
    w_react = 0.0
    kinetic = 0.0
    for j in numba.prange(nodes.shape[0]):
        a, b, c, d, e, k = _advance_node(nodes[j], x, v, v_new, mass, f_int, f_con, f_ext, f_damp, reaction, dt)
        w_int += a
        w_con += b
        w_ext += c
        w_damp += d
        w_react += e
        kinetic += k
    return w_int * dt_mid, w_con * dt_mid, w_ext * dt_mid, w_damp * dt_mid, w_react * dt_mid, kinetic


advance_kernel, advance_kernel_serial = threaded_and_serial(_advance)


@numba.njit(cache=True)
def clear_rows(nodes, a, b):
    """Zero the rows ``nodes`` of the (n, 3) arrays ``a`` and ``b`` (a body's force buffers, where
    the other rows are never written)."""
    for j in range(nodes.shape[0]):
        i = nodes[j]
        for k in range(3):
            a[i, k] = 0.0
            b[i, k] = 0.0
