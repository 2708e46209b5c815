"""Constraints and loads of the explicit solver.

One contract (after PyElastica's constraint base, which has ``constrain_values`` and
``constrain_rates``): the integrator updates positions from constrained velocities only
(x_{n+1} = x_n + dt v_{n+1/2}), so a constraint acts on the rates. After the damped velocity
update, every active constraint's :meth:`Constraint.constrain_rates` overwrites the
velocities of its nodes, adds the reaction impulse / dt into the body's reaction buffer and
returns the total reaction force (N). Fixed nodes are imposed first, inside the velocity update
(:attr:`Constraint.holds_at_rest`), then the other constraints in the solver's list order, each
on the velocities left by the previous ones. Loads add forces before the update.
"""

import math

import numba
import numpy as np

from colonsim.errors import ColonsimError

#: kinds of velocity rows (:meth:`Constraint.velocity_rows`)
FREE, ON_LINE, HELD = 0, 1, 2


@numba.njit(cache=True, inline="always")
def _along_line(x, i, point, direction):
    """Coordinate of node ``i`` along the line through ``point`` with unit ``direction``, m."""
    s = 0.0
    for k in range(3):
        s += (x[i, k] - point[k]) * direction[k]
    return s


@numba.njit(cache=True)
def line_constraint_kernel(x, v_new, reaction, mass, nodes, point, direction, s_min, s_max, dt, hold=1.0):
    """Remove the velocity across the line (the fraction ``hold`` of it) on the listed nodes lying
    within [s_min, s_max] along it; add the reaction impulse / dt. Returns the total reaction
    force (3,)."""
    total = np.zeros(3)
    for j in range(nodes.shape[0]):
        i = nodes[j]
        s = _along_line(x, i, point, direction)
        if s < s_min or s > s_max:
            continue
        along = 0.0
        for k in range(3):
            along += v_new[i, k] * direction[k]
        for k in range(3):
            vc = along * direction[k] + (1.0 - hold) * (v_new[i, k] - along * direction[k])
            r = mass[i] * (vc - v_new[i, k]) / dt
            reaction[i, k] += r
            total[k] += r
            v_new[i, k] = vc
    return total


@numba.njit(cache=True)
def nodes_on_line(x, nodes, point, direction, s_min, s_max):
    """The listed nodes whose coordinate along the line lies within [s_min, s_max]."""
    inside = np.empty(nodes.shape[0], dtype=np.int64)
    n = 0
    for j in range(nodes.shape[0]):
        i = nodes[j]
        s = _along_line(x, i, point, direction)
        if s_min <= s <= s_max:
            inside[n] = i
            n += 1
    return inside[:n]


@numba.njit(cache=True)
def _row_sum(values, rows):
    """Sum of ``values[rows]`` (k, 3) without gathering them first."""
    total = np.zeros(3)
    for j in range(rows.shape[0]):
        for a in range(3):
            total[a] += values[rows[j], a]
    return total


class _Window:
    """A node set of one body, active on the time window [start, end).

    ``reaction`` holds the total force (N) the constraint applied to its nodes during the last
    step (for a pushed end: the push force).
    """

    def _init_window(self, body, nodes, start, end):
        self.body = body
        if nodes is None:
            nodes = np.arange(len(body.x0))
        self.nodes = np.unique(np.asarray(nodes, dtype=np.int64).ravel())
        if len(self.nodes) and (self.nodes.min() < 0 or self.nodes.max() >= len(body.x0)):
            raise ColonsimError(
                f"constraint or load on body '{body.name}' names nodes that do not exist; fix the node list."
            )
        if not end > start:
            raise ColonsimError(f"time window [{start}, {end}) is empty; give end > start.")
        self.start = float(start)
        self.end = float(end)
        self.reaction = np.zeros(3)

    def active(self, t):
        return self.start <= t < self.end


class Constraint(_Window):
    """Base of the constraints: see the module docstring for the contract."""

    #: True for constraints the velocity update itself holds at rest (it also stores their reactions).
    holds_at_rest = False

    def constrain_rates(self, t_mid, state, dt_mid):
        """Constrain ``state.v_new`` on the nodes, add the reactions into ``state.reaction``; return
        the total reaction force (3,), N. ``t_mid``: mid-step time, s; ``dt_mid``: the step of
        the staggered velocities, s."""
        raise NotImplementedError

    def velocity_rows(self, t_mid, state):
        """The constraint as rows of an implicit velocity update (a body with implicit damping,
        :mod:`colonsim.insertion.engine.rod_damping`): ``(nodes, kind, vectors)``, the nodes it
        constrains now, :data:`HELD` (the whole velocity is set: ``vectors`` (k, 3) are the target
        velocities, m/s) or :data:`ON_LINE` (the velocity across a line is zero: ``vectors`` are the
        line's unit directions)."""
        raise NotImplementedError


class FixedNodes(Constraint):
    """Nodes held at rest (zero velocity) while active.

    Parameters
    ----------
    body : body object
    nodes : int array
    start, end : float
        Time window in which the constraint acts, s ("birth and death").
    """

    holds_at_rest = True

    def __init__(self, body, nodes, start=0.0, end=math.inf):
        self._init_window(body, nodes, start, end)
        self._summed = (None, self.nodes)  # (the body's moving nodes, the nodes of ours among them)

    def constrain_rates(self, t_mid, state, dt_mid):
        # the reactions of the nodes the update leaves out are zero: the sum skips them (same bits)
        moving = getattr(state, "moving", None)
        if moving is not self._summed[0]:
            every = moving is None or moving is state.every_node
            self._summed = (moving, self.nodes if every else np.intersect1d(self.nodes, moving, assume_unique=True))
        return _row_sum(state.reaction, self._summed[1])

    def velocity_rows(self, t_mid, state):
        return self.nodes, HELD, np.zeros((len(self.nodes), 3))


class PrescribedVelocity(Constraint):
    """Nodes moving with a prescribed velocity while active.

    Parameters
    ----------
    body : body object
    nodes : int array
    velocity : (3,) array or callable t -> (3,) array
        Velocity, m/s.
    ramp : float
        Duration of a smooth (1 - cos) start-up ramp from the window start, s (0 = step).
    start, end : float
        Time window, s.
    """

    def __init__(self, body, nodes, velocity, ramp=0.0, start=0.0, end=math.inf):
        self._init_window(body, nodes, start, end)
        self._velocity = velocity if callable(velocity) else np.asarray(velocity, dtype=np.float64).reshape(3)
        if ramp < 0.0:
            raise ColonsimError(f"ramp = {ramp} s must be >= 0; fix it.")
        self.ramp = float(ramp)
        self._targets = np.empty((len(self.nodes), 3))  # velocity_rows' targets, refilled every step

    def velocity(self, t):
        """Prescribed velocity at time t, m/s."""
        v = np.asarray(self._velocity(t) if callable(self._velocity) else self._velocity, dtype=np.float64)
        tau = t - self.start
        if self.ramp > 0.0 and tau < self.ramp:
            v = v * 0.5 * (1.0 - math.cos(math.pi * max(tau, 0.0) / self.ramp))
        return v

    def constrain_rates(self, t_mid, state, dt_mid):
        vc = self.velocity(t_mid)
        idx = self.nodes
        r = self.body.mass[idx, None] * (vc[None, :] - state.v_new[idx]) / dt_mid
        state.reaction[idx] += r
        state.v_new[idx] = vc
        return r.sum(axis=0)

    def velocity_rows(self, t_mid, state):
        self._targets[:] = self.velocity(t_mid)
        return self.nodes, HELD, self._targets


class LineConstraint(Constraint):
    """Nodes confined to a straight line (a rigid sheath) while they lie inside its extent.

    A node is guided when its coordinate along the line, s = (x - point) . direction, lies in
    [s_min, s_max]: its velocity component across the line is removed (motion along the line stays
    free). Nodes started on the line stay on it.

    Parameters
    ----------
    body : body object
    point, direction : (3,) arrays
        A point of the line and its direction.
    extent : (s_min, s_max)
        Guided stretch of the line, m.
    nodes : int array or None
        Candidate nodes (None = all nodes of the body).
    start, end : float
        Time window, s.
    release : float
        Let go gradually over this long after ``end``, s (0: at once): each step removes the
        fraction ``1 - (t - end) / release`` of the velocity across the line, a damper that fades
        out, so a part held against its load comes to its free equilibrium without a snap.
    """

    def __init__(self, body, point, direction, extent=(-math.inf, math.inf), nodes=None, start=0.0, end=math.inf,
                 release=0.0):
        if not (math.isfinite(release) and release >= 0.0):
            raise ColonsimError(f"line constraint release = {release!r} s must be >= 0; fix it.")
        self._init_window(body, nodes, start, end + release)
        self.held_until = float(end)
        self.release = float(release)
        d = np.asarray(direction, dtype=np.float64).reshape(3)
        if not np.linalg.norm(d) > 0.0:
            raise ColonsimError("line constraint direction must be a non-zero vector; fix it.")
        self.direction = d / np.linalg.norm(d)
        self.point = np.asarray(point, dtype=np.float64).reshape(3)
        self.extent = (float(extent[0]), float(extent[1]))
        self._directions = np.tile(self.direction, (len(self.nodes), 1))  # one row per node it may guide
        self._directions.setflags(write=False)

    def hold(self, t):
        """Fraction of the velocity across the line removed at time ``t`` (1 while held)."""
        if t < self.held_until or self.release == 0.0:
            return 1.0
        return max(0.0, 1.0 - (t - self.held_until) / self.release)

    def constrain_rates(self, t_mid, state, dt_mid):
        return line_constraint_kernel(state.x, state.v_new, state.reaction, self.body.mass, self.nodes, self.point,
                                      self.direction, self.extent[0], self.extent[1], dt_mid, self.hold(t_mid))

    def velocity_rows(self, t_mid, state):
        if self.hold(t_mid) < 1.0:
            raise ColonsimError("a line constraint let go gradually acts on explicit bodies only (a wall); give the "
                                "implicitly damped body's constraint no release")
        nodes = nodes_on_line(state.x, self.nodes, self.point, self.direction, self.extent[0], self.extent[1])
        return nodes, ON_LINE, self._directions[:len(nodes)]


class NodalLoad(_Window):
    """Applied nodal forces while active.

    Parameters
    ----------
    body : body object
    nodes : int array
    force : (3,) array, (len(nodes), 3) array, or callable t -> one of those
        Force per node, N.
    start, end : float
        Time window, s.
    """

    def __init__(self, body, nodes, force, start=0.0, end=math.inf):
        nodes_arr = np.asarray(nodes, dtype=np.int64).ravel()
        self._init_window(body, nodes, start, end)
        if len(np.unique(nodes_arr)) != len(nodes_arr):
            raise ColonsimError("a nodal load lists a node twice; give each node once.")
        self.nodes = nodes_arr
        self.force = force

    def add_forces(self, t, f):
        """Add the load at time t into the force buffer f (n, 3), N."""
        force = self.force(t) if callable(self.force) else self.force
        f[self.nodes] += np.asarray(force, dtype=np.float64)
