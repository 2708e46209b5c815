"""The lip of the rigid sheath: where the scope leaves it, a stiff lateral support on the scope.

Inside the sheath every scope node is held to the sheath's axis (a line constraint,
:class:`colonsim.insertion.engine.constraints.LineConstraint`). If that were all, the last
supported point of a bent scope would jump from node to node as the scope advances, and the push
force would jump with it once per node spacing (measured: a 5 mm sawtooth of about 1 N on the RSJ
push force, with lateral reaction spikes of 20-37 N each time a node left the sheath). The lip
supports instead the scope's material point at the lip plane, on the segment that straddles it: a
penalty spring with damping, pulling that point back onto the axis, its force split linearly
between the segment's two nodes. The support then slides continuously along the scope.

The object follows the solver's contact protocol (``compute``, ``finish_step``, ``record``,
``frequency_squared``, ``follow_wall``), being a contact with a rigid body.
"""

import math

import numba
import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.contact import damped_step_reduction


@numba.njit(cache=True)
def lip_kernel(x, v, f, point, direction, lip, stiffness, dashpot, out):
    """The lip's spring and dashpot on the segment straddling the plane at ``lip`` along the
    axis: forces added into ``f``; ``out`` gets (segment, fraction t, energy, force (3),
    damping force (3), dissipated power). Segment -1: no node is beyond the lip, or all are."""
    n = x.shape[0]
    out[:] = 0.0
    out[0] = -1.0
    prev = 0.0
    for i in range(n):
        s = 0.0
        for a in range(3):
            s += (x[i, a] - point[a]) * direction[a]
        if s > lip:
            if i == 0:
                return
            t = (lip - prev) / (s - prev)
            e = i - 1
            offset = np.zeros(3)
            vp = np.zeros(3)
            for a in range(3):
                offset[a] = (1.0 - t) * x[e, a] + t * x[i, a] - point[a]
                vp[a] = (1.0 - t) * v[e, a] + t * v[i, a]
            along = 0.0
            v_along = 0.0
            for a in range(3):
                along += offset[a] * direction[a]
                v_along += vp[a] * direction[a]
            energy = 0.0
            power = 0.0
            for a in range(3):
                across = offset[a] - along * direction[a]
                v_across = vp[a] - v_along * direction[a]
                damping = -dashpot * v_across
                force = -stiffness * across + damping
                f[e, a] += (1.0 - t) * force
                f[i, a] += t * force
                energy += 0.5 * stiffness * across * across
                power -= damping * vp[a]
                out[3 + a] = force
                out[6 + a] = damping
            out[0] = e
            out[1] = t
            out[2] = energy
            out[9] = power
            return
        prev = s


@numba.njit(cache=True)
def lip_dissipation(v, out):
    """Twice the lip's mean dissipated power over a step, W: the power at the last evaluation
    (``out`` of :func:`lip_kernel`) plus that of its damping force against the lip point's new
    velocity (from ``v``). The segment of ``out`` must be >= 0."""
    e = int(out[0])
    t = out[1]
    new = 0.0
    for a in range(3):
        new += out[6 + a] * ((1.0 - t) * v[e, a] + t * v[e + 1, a])
    return out[9] - new


class SheathLip:
    """Penalty support of a rod at the lip of a straight rigid sheath.

    Parameters
    ----------
    rod : colonsim.insertion.engine.rod.Rod
    point, direction : (3,) arrays
        A point of the sheath axis and its direction (towards the colon).
    lip : float
        Position of the lip along the axis, m (the line constraint guides nodes up to it).
    stiffness : float or None
        Lateral penalty, N/m. None: the lightest rod node on the spring alone oscillates at half
        the rod's highest frequency (like the contact penalty of a free wall node); the lip point
        then gives way by ``F / k``, under 10 um at 5 N for the standard scope.
    damping_ratio : float
        Fraction of critical damping of the spring on the lightest rod node.
    name : str
    """

    def __init__(self, rod, point, direction, lip, stiffness=None, damping_ratio=0.5):
        d = np.asarray(direction, dtype=np.float64).reshape(3)
        if not np.linalg.norm(d) > 0.0:
            raise ColonsimError("sheath direction must be a non-zero vector; fix it.")
        self.rod = rod
        self.direction = d / np.linalg.norm(d)
        self.point = np.asarray(point, dtype=np.float64).reshape(3)
        self.lip = float(lip)
        m_min = float(rod.mass.min())
        if stiffness is None:
            omega = 2.0 / rod.critical_time_step(np.ascontiguousarray(rod.x0))
            stiffness = 0.25 * m_min * omega**2
        if not (np.isfinite(stiffness) and stiffness > 0.0 and damping_ratio >= 0.0):
            raise ColonsimError(f"sheath lip stiffness {stiffness!r} N/m and damping ratio {damping_ratio!r} must be "
                                "positive; fix them.")
        self.stiffness = float(stiffness)
        self.damping_ratio = float(damping_ratio)
        self._dashpot = 2.0 * self.damping_ratio * math.sqrt(self.stiffness * m_min)
        self.energy = 0.0
        self.dissipated = 0.0
        self._out = np.zeros(10)  # lip_kernel's results of the last evaluation

    def compute(self, state, dt):
        """Add the lip's force on the rod at the current state into its ``f_con`` buffer."""
        r = state[self.rod.name]
        lip_kernel(r.x, r.v, r.f_con, self.point, self.direction, self.lip, self.stiffness, self._dashpot, self._out)
        self.energy = float(self._out[2])

    revision = 0  # what nodes_on returns never changes

    def nodes_on(self, body):
        """The nodes of ``body`` the lip may put a force on: any of the rod's (None), none of another body's."""
        return None if body is self.rod else np.zeros(0, dtype=np.int64)

    @property
    def force(self):
        """The lip's force on the rod at the last evaluation, N (3,)."""
        return self._out[3:6].copy()

    def finish_step(self, state, dt):
        """Dissipation of the step: the damping force times the lip point's mean velocity."""
        if self._out[0] < 0.0:
            return
        self.dissipated += 0.5 * lip_dissipation(state[self.rod.name].v, self._out) * dt

    def spring_action(self, state, u, ku):
        """Add K u of the lip's spring (across the axis, k / r^2 for its damping, as
        :meth:`frequency_squared` counts it) into ``ku[rod name]``."""
        e = int(self._out[0])
        if e < 0:
            return
        t = self._out[1]
        ur = u[self.rod.name]
        d = (1.0 - t) * ur[e] + t * ur[e + 1]
        k = self.stiffness / damped_step_reduction(self.damping_ratio) ** 2
        force = k * (d - (d @ self.direction) * self.direction)
        out = ku[self.rod.name]
        out[e] += (1.0 - t) * force
        out[e + 1] += t * force

    def record(self):
        return {"energy": self.energy, "dissipated": self.dissipated, "lip_force": self.force}

    def follow_wall(self, body_omega2):
        """The sheath is rigid: nothing to follow."""

    def frequency_squared(self):
        """The spring's squared frequency on the lightest rod node, as a damped spring (rad^2/s^2)."""
        reduction = damped_step_reduction(self.damping_ratio) ** 2
        return {self.rod.name: self.stiffness / float(self.rod.mass.min()) / reduction}
