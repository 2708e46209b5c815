"""The state of one body in the explicit solver, and its velocity and position update.

:class:`BodyState` holds positions, staggered velocities and the force and work buffers of a body.
:func:`step_body` takes it through one (sub)step once its forces are known: the damped velocity
update with the constraints (explicitly, or implicitly with the rod's dashpots and the
constraints as rows: :mod:`colonsim.insertion.engine.rod_damping`), then the position update
with the work of every force family (:mod:`colonsim.insertion.engine.integrator_kernels`).
"""

import numba
import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.constraints import FREE, ON_LINE
from colonsim.insertion.engine.integrator_kernels import (advance_kernel, advance_kernel_serial, clear_rows,
                                                          velocity_kernel, velocity_kernel_serial)
from colonsim.insertion.engine.rod_damping import damped_rod_velocity, merge_rows
from colonsim.insertion.engine.tip_resistance import resisted_update


class BodyState:
    """Positions, velocities and force/energy buffers of one body."""

    def __init__(self, body, velocity, parallel_min_nodes):
        n = len(body.x0)
        self.body = body
        # Nodal updates are a few flops per node: threads pay only for very large bodies.
        self.parallel = n >= parallel_min_nodes
        self.x = np.ascontiguousarray(body.x0, dtype=np.float64).copy()
        self.v = np.zeros((n, 3)) if velocity is None else np.ascontiguousarray(velocity, dtype=np.float64).copy()
        if self.v.shape != (n, 3):
            raise ColonsimError(f"initial velocity of body '{body.name}' must have shape {(n, 3)}; got {self.v.shape}.")
        self.v_new = np.zeros((n, 3))
        self.f_int = np.zeros((n, 3))
        self.f_con = np.zeros((n, 3))
        self.f_ext = np.zeros((n, 3))
        self.f_damp = np.zeros((n, 3))
        self.reaction = np.zeros((n, 3))
        self.fixed = np.zeros(n, dtype=np.uint8)
        self.every_node = np.arange(n, dtype=np.int64)
        self.moving = self.every_node  # the nodes the explicit update visits (:meth:`leave_out_quiet`)
        # a body with dashpots (a rod's strain-rate damping) takes an implicit velocity update
        # with its constraints as rows (:mod:`colonsim.insertion.engine.rod_damping`)
        dashpot = getattr(body, "dashpot", None)
        self.implicit = dashpot is not None and (bool(np.any(dashpot > 0.0)) or body.lateral_damping > 0.0)
        if self.implicit:
            self.row_kind = np.zeros(n, dtype=np.int64)
            self.row_dir = np.zeros((n, 3))
            self.row_target = np.zeros((n, 3))
        self.internal = 0.0
        self.kinetic = 0.0
        self.work_internal = 0.0
        self.work_contact = 0.0
        self.work_external = 0.0
        self.work_reaction = 0.0
        self.dissipated_damping = 0.0

    def clear_forces(self, external):
        """Zero the internal and contact force buffers (and the external ones if ``external``)
        before a step's forces: the rows of the nodes left out are zero already and stay so."""
        if self.moving is self.every_node:
            self.f_int[:] = 0.0
            self.f_con[:] = 0.0
        else:
            clear_rows(self.moving, self.f_int, self.f_con)
        if external:
            self.f_ext[:] = 0.0

    def leave_out_quiet(self, quiet):
        """Visit every node in the explicit update but the ``quiet`` ones (bool (n,), or None for none).

        A quiet node is held, at rest, and no force can reach it until the solver says otherwise
        (no element of the body's that is not all held, no contact's candidate, no load): its update
        is zeros (the integrator kernels' held branch) and leaves its position alone, so it is
        written as zeros once, here, and left out after. On a colon model most of the wall is such
        (RSF: 8,280 of 11,320 nodes), and the nodal updates then stream a quarter of the arrays."""
        if quiet is None or not quiet.any():
            self.moving = self.every_node
            return
        for a in (self.v_new, self.f_damp, self.reaction):
            a[quiet] = 0.0
        self.moving = np.flatnonzero(~quiet)


@numba.njit(cache=True)
def take_reaction(left, nodes, kind, vectors, total):
    """One constraint's share of the nodal reactions ``left`` (n, 3), taken out of them: all of
    it at its nodes, or for :data:`ON_LINE` the part across the line (``vectors``: the lines' unit
    directions); its sum over the nodes into ``total`` (3,), N."""
    total[:] = 0.0
    for j in range(nodes.shape[0]):
        i = nodes[j]
        along = 0.0
        if kind == ON_LINE:
            along = left[i, 0] * vectors[j, 0] + left[i, 1] * vectors[j, 1] + left[i, 2] * vectors[j, 2]
        for a in range(3):
            part = left[i, a] - along * vectors[j, a] if kind == ON_LINE else left[i, a]
            left[i, a] -= part
            total[a] += part


def share_reactions(rows, reaction):
    """Each constraint's total reaction force (N) from a body's nodal reactions: in the solver's
    order, a constraint takes the components of what is left at its nodes that it constrains
    (a kernel: in numpy this was a tenth of a coarse insertion's time)."""
    left = reaction.copy()
    for c, nodes, kind, vectors in rows:
        c.reaction = np.empty(3)
        take_reaction(left, nodes, kind, vectors, c.reaction)


def constraint_rows(s, constraints, t, t_mid):
    """Every active constraint on body state ``s`` as velocity rows, merged per node
    (:func:`~colonsim.insertion.engine.rod_damping.merge_rows`) in the solver's order; returns
    ``[(constraint, nodes, kind, vectors), ...]`` for sharing out the reactions."""
    s.row_kind[:] = FREE
    rows = []
    for c in constraints:
        if not c.active(t):
            continue
        nodes, kind, vectors = c.velocity_rows(t_mid, s)
        rows.append((c, nodes, kind, vectors))
        merge_rows(s.row_kind, s.row_dir, s.row_target, nodes, kind, vectors)
    return rows


def step_body(s, constraints, alpha, t, t_mid, dt_mid, dt, resistances=()):
    """Velocity update (damping ``alpha``, 1/s), ``constraints`` of this body (their ``reaction``
    set), then positions; returns the work done on the body by each force family during the
    step (internal, contact, external, damping, reaction; J) and its mid-step kinetic energy.
    ``resistances``: :class:`~colonsim.insertion.engine.tip_resistance.TipResistance` objects on
    this body, taken implicitly with the velocity update."""
    b = s.body
    outputs = (s.v_new, s.f_damp, s.reaction)
    if s.implicit:
        rows = constraint_rows(s, constraints, t, t_mid)

        def update():
            damped_rod_velocity(s.x, s.v, s.f_int, s.f_con, s.f_ext, b.mass, alpha, b.lateral_damping, b.dashpot,
                                s.row_kind, s.row_dir, s.row_target, dt_mid, s.v_new, s.f_damp, s.reaction)
        resisted_update(resistances, s, update, outputs)
        share_reactions(rows, s.reaction)
        for c in constraints:
            if not c.active(t):
                c.reaction = np.zeros(3)
    else:
        kernel = velocity_kernel if s.parallel else velocity_kernel_serial

        def update():
            kernel(s.moving, s.v, s.f_int, s.f_con, s.f_ext, b.mass, s.fixed, alpha, dt_mid, s.v_new, s.f_damp,
                   s.reaction)
        resisted_update(resistances, s, update, outputs)
        for c in constraints:
            c.reaction = c.constrain_rates(t_mid, s, dt_mid) if c.active(t) else np.zeros(3)
    kernel = advance_kernel if s.parallel else advance_kernel_serial
    return kernel(s.moving, s.x, s.v, s.v_new, b.mass, s.f_int, s.f_con, s.f_ext, s.f_damp, s.reaction, dt_mid, dt)
