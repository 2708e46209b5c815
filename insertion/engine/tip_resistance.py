"""The distal resistance: the force the colon beyond the model opposes to the scope tip's advance
(docs/model.md, "Loading").

A force of magnitude ``R`` acts on the tip node along ``-d``, ``d`` the lumen's direction at the
tip, opposing the tip's axial velocity ``u = v_tip . d`` like Coulomb friction regularised on
that speed:

    F = -R e sat(u / v_c),   sat(z) = max(-1, min(1, z)),

with ``v_c`` the creep speed (a tip loaded below ``R`` creeps at ``v_c`` times the load over
``R``) and ``e`` the engagement in [0, 1], which the caller sets from where the tip is (an
insertion: from the tip's position along the centerline, rising over the first centimetre of
the fixed exit; :mod:`colonsim.insertion.case.scenario`), as it sets ``d``.

For any creep speed that matters (``R / v_c`` of thousands of N s/m on a tip node of a gram) the
force is far too stiff for the explicit step, so it is taken implicitly, at the new velocity.
The velocity update is linear in the tip's external force (:func:`resisted_update`): one update
without the force, one with a unit force give ``u = u0 + b F`` (``b`` > 0, the tip's compliance
over the step), and the regularised law is solved exactly for ``F``. Every output of the update
(velocities, damping forces, reactions) is then the same combination of the two, and the force
enters the body's external forces, so its work is accounted for like any load's.
"""

import math

import numpy as np

from colonsim.errors import ColonsimError


def regularised_force(u0, b, resistance, creep_speed):
    """The force F along the axis (N, opposing the motion) for which ``u = u0 + b F`` and
    ``F = -resistance sat(u / creep_speed)`` hold together (``creep_speed`` 0: plain Coulomb,
    the tip sticks while ``|u0| <= b resistance``)."""
    if resistance <= 0.0 or u0 == 0.0:
        return 0.0
    if creep_speed > 0.0:
        u = u0 / (1.0 + b * resistance / creep_speed)
        if abs(u) <= creep_speed:
            return -resistance * u / creep_speed
    elif abs(u0) <= b * resistance:
        return -u0 / b
    return -math.copysign(resistance, u0)


class TipResistance:
    """A resisting force on one node of a body (the scope's tip).

    Parameters
    ----------
    body : body object
    node : int
        The resisted node (the tip).
    direction : (3,) array
        The way the tip advances (the lumen's direction at the tip).
    resistance : float
        Force at full engagement while the tip moves faster than ``creep_speed``, N.
    creep_speed : float
        Regularisation speed, m/s (0: plain Coulomb).
    engagement : float
        Share of ``resistance`` engaged at the start, in [0, 1] (:meth:`engage` changes it).

    Attributes
    ----------
    force : float
        The resisting force of the last step along ``-direction``, N (positive while it holds the
        tip back).
    """

    def __init__(self, body, node, direction, resistance, creep_speed=0.0, engagement=1.0):
        for name, value in (("resistance", resistance), ("creep_speed", creep_speed)):
            if not (math.isfinite(value) and value >= 0.0):
                raise ColonsimError(f"tip resistance {name} = {value!r} must be a finite number >= 0; fix it.")
        if not 0 <= node < len(body.x0):
            raise ColonsimError(f"tip resistance on node {node}, which body '{body.name}' does not have; fix the node.")
        self.body = body
        self.node = int(node)
        self.resistance = float(resistance)
        self.creep_speed = float(creep_speed)
        self.force = 0.0
        self.engage(engagement, direction)

    @staticmethod
    def _unit(direction):
        d = np.asarray(direction, dtype=np.float64).reshape(3)
        norm = float(np.linalg.norm(d))
        if not norm > 0.0:
            raise ColonsimError("tip resistance direction must be a non-zero vector; fix it.")
        return d / norm

    def engage(self, share, direction=None):
        """From now on, resist with ``share`` (in [0, 1]) of the resistance, along ``direction``
        (None: the direction it had)."""
        if not (math.isfinite(share) and 0.0 <= share <= 1.0):
            raise ColonsimError(f"tip resistance engagement {share!r} must lie in [0, 1]; fix it.")
        self.engagement = float(share)
        if direction is not None:
            self.direction = self._unit(direction)

    @property
    def engaged_force(self) -> float:
        """The resistance at the current engagement, N."""
        return self.resistance * self.engagement


def resisted_update(resistances, state, update, outputs):
    """Run the velocity ``update()`` of body ``state`` with the ``resistances`` on it.

    ``update`` fills ``outputs`` (arrays of the state, linear in its external forces ``f_ext``)
    from the current forces; the resisted tip forces are solved implicitly (module docstring),
    added into ``f_ext`` and the outputs combined accordingly. One resistance per body."""
    update()
    active = [r for r in resistances if r.engaged_force > 0.0]
    for r in resistances:
        r.force = 0.0
    if not active:
        return
    if len(active) > 1:
        raise ColonsimError("one tip resistance per body is supported; merge them.")
    r = active[0]
    i, d = r.node, r.direction
    free = [a.copy() for a in outputs]
    u0 = float(np.dot(state.v_new[i], d))
    state.f_ext[i] += d  # a unit force: the tip's compliance over the step
    update()
    b = float(np.dot(state.v_new[i], d)) - u0
    if not b > 0.0:
        state.f_ext[i] -= d
        for a, a0 in zip(outputs, free):
            a[:] = a0
        return  # the tip is held by a constraint: nothing to resist
    F = regularised_force(u0, b, r.engaged_force, r.creep_speed)
    state.f_ext[i] += (F - 1.0) * d
    for a, a0 in zip(outputs, free):
        a[:] = a0 + F * (a - a0)
    r.force = -F
