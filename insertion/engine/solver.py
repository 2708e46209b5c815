"""Explicit central-difference integration of several bodies with contact and constraints.

Scheme (lumped masses, staggered velocities, mass-proportional damping alpha averaged over the
step so that it never limits the time step)::

    v_{n+1/2} = ((1 - h) v_{n-1/2} + dt f_n / m) / (1 + h),   h = alpha dt / 2
    constraints overwrite v_{n+1/2} on their nodes (the change is the reaction impulse)
    x_{n+1} = x_n + dt v_{n+1/2}

Energy accounting per body: the work of every force family (internal, contact, loads, damping,
constraint reactions) is summed as dt F_n . (v_{n-1/2} + v_{n+1/2}) / 2, which makes the kinetic
energy balance exact; kinetic energy is reported at the mid-velocity, internal (strain) energy from
the body at x_n. Contact penalty energy and contact dissipation (damping and friction) are kept by
the contact objects.

Constraints and loads: :mod:`colonsim.insertion.engine.constraints`; nodal kernels:
:mod:`colonsim.insertion.engine.integrator_kernels`.

Divergence guard: a non-finite state, or mechanical energy growing beyond ``energy_growth_limit``
times (initial energy + absolute work put in), stops the run with a :class:`ColonsimError` naming
the time, the step and the remedy.

Example (run by the test suite)::

    import numpy as np
    from colonsim.insertion.engine.contact import RodShellContact
    from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
    from colonsim.insertion.engine.rod import Rod
    from colonsim.insertion.engine.sheet_mesh import straight_tube
    from colonsim.insertion.engine.shell import Shell
    from colonsim.insertion.engine.constraints import FixedNodes, LineConstraint, PrescribedVelocity
    from colonsim.insertion.engine.solver import ExplicitSolver

    nodes, tri, ring = straight_tube(0.1, 0.038, 6e-3)  # mid-surface diameter = lumen + wall
    colon = Shell(nodes, tri, 2e-3, load_material(REFERENCE_MATERIAL_PATH), name="colon")
    scope = Rod.straight(0.15, 12.8e-3, 16e6, 2944.0, spacing=5e-3, start=(-0.1, 0.0, -0.01))
    sim = ExplicitSolver(
        [scope, colon],
        contacts=[RodShellContact(scope, colon, friction=0.1)],
        constraints=[
            FixedNodes(colon, np.flatnonzero((ring == 0) | (ring == ring.max()))),
            PrescribedVelocity(scope, [0], (0.6, 0.0, 0.0), ramp=2e-3),  # push, m/s
            LineConstraint(scope, (-0.1, 0.0, -0.01), (1.0, 0.0, 0.0), extent=(-1.0, 0.09)),  # sheath
        ],
        damping=20.0,  # 1/s, mass-proportional
    )
    history = sim.run(5e-3, record_interval=1e-3, record_positions=["colon"])
    push_force = history.reactions[1][:, 0]  # N, force the driver applies to the proximal end
    contact_force = history.contacts[0]["normal_force"]  # N
"""

import math

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.body_state import BodyState, step_body
from colonsim.insertion.engine.history import History


class ExplicitSolver:
    """Explicit dynamics of bodies (rod, shell) with contact, constraints and loads.

    Parameters
    ----------
    bodies : list of body objects
        Each with ``name``, ``x0``, ``mass``, ``internal_forces(x, f)``, ``critical_time_step(x)``.
    contacts : list
        Contact objects (:class:`colonsim.insertion.engine.contact.RodShellContact`).
    constraints : list
        :class:`~colonsim.insertion.engine.constraints.Constraint` objects (fixed nodes, prescribed
        velocity, line).
    loads : list
        :class:`~colonsim.insertion.engine.constraints.NodalLoad` objects.
    resistances : list
        :class:`~colonsim.insertion.engine.tip_resistance.TipResistance` objects (a resisted tip),
        taken implicitly with their body's velocity update.
    damping : float or dict
        Mass-proportional damping coefficient alpha (1/s), one for all bodies or per body name.
        Critical damping of a mode of angular frequency w is alpha = 2 w.
    time_step : float or None
        Fixed time step, s; None = ``time_step_factor`` times the stable estimate, updated every
        ``time_step_interval`` steps.
    time_step_factor : float
        Safety factor on the stable time step estimate (bodies and contact penalty).
    time_step_interval : int
        Steps between time step updates.
    time_step_growth : float
        Largest factor by which an update may raise the time step (a decrease applies at once).
        A wall that goes slack (a scope snapping past a bend) lets the stable step double within
        a few milliseconds; if it stiffens again before the next update, a step raised all the way
        is unstable for up to ``time_step_interval`` steps (a THF run diverged so).
    mass_scaling : float or None
        Target time step, s: bodies whose stable step is smaller get their masses scaled uniformly
        by (target / dt_body)^2 (the added mass is reported in ``added_mass``).
    initial_velocity : dict or None
        ``{body name: (n, 3) array}``, m/s.
    energy_growth_limit : float
        Divergence guard factor (see module docstring).
    parallel_min_nodes : int
        Bodies with at least this many nodes get threaded nodal updates (smaller ones run
        serially: starting threads costs more than the work, and much more on a loaded machine).
    global_estimate : GlobalTimeStep or None
        None: the step rests on the bounds alone. Given
        (:class:`colonsim.insertion.engine.global_time_step.GlobalTimeStep`): the largest frequency
        of the coupled system by power iteration, never below that of a body whose own value is
        exact (a rod), and the step never below the bounds' (:meth:`stable_time_step`).
    """

    def __init__(self, bodies, contacts=(), constraints=(), loads=(), damping=0.0, time_step=None,
                 time_step_factor=0.9, time_step_interval=100, time_step_growth=1.05, mass_scaling=None, initial_velocity=None,
                 energy_growth_limit=10.0, parallel_min_nodes=50_000, resistances=(), global_estimate=None):
        names = [b.name for b in bodies]
        if len(set(names)) != len(names):
            raise ColonsimError(f"body names must be unique, got {names}; rename the bodies.")
        if not 0.0 < time_step_factor <= 1.0:
            raise ColonsimError(f"time_step_factor = {time_step_factor} must lie in (0, 1]; fix it.")
        if time_step is not None and not time_step > 0.0:
            raise ColonsimError(f"time_step = {time_step} s must be positive; fix it.")
        self.bodies = list(bodies)
        self.contacts = list(contacts)
        self.constraints = list(constraints)
        self.loads = list(loads)
        self.resistances = list(resistances)
        for item in self.constraints + self.loads + self.resistances:
            if item.body not in self.bodies:
                raise ColonsimError(
                    f"a constraint or load acts on body '{item.body.name}', which is not in the solver; add the body."
                )
        if isinstance(damping, dict):
            unknown = set(damping) - set(names)
            if unknown:
                raise ColonsimError(f"damping given for unknown bodies {sorted(unknown)}; use the names {names}.")
            self.damping = {n: float(damping.get(n, 0.0)) for n in names}
        else:
            self.damping = {n: float(damping) for n in names}
        if any(a < 0.0 for a in self.damping.values()):
            raise ColonsimError("damping coefficients must be >= 0 1/s; fix them.")
        initial_velocity = initial_velocity or {}
        self.state = {b.name: BodyState(b, initial_velocity.get(b.name), parallel_min_nodes) for b in self.bodies}
        self.fixed_time_step = time_step
        self.time_step_factor = float(time_step_factor)
        self.time_step_interval = int(time_step_interval)
        if not time_step_growth >= 1.0:
            raise ColonsimError(f"time_step_growth = {time_step_growth} must be >= 1; fix it.")
        self.time_step_growth = float(time_step_growth)
        self.energy_growth_limit = float(energy_growth_limit)
        self.global_estimate = global_estimate
        self.time = 0.0
        self.step = 0
        self.added_mass = {n: 0.0 for n in names}
        if mass_scaling is not None:
            self._scale_masses(float(mass_scaling))
        self.dt = None
        self._dt_prev = None
        self._fixed_key = None
        self._held_key = None
        self._quiet_key = None
        self._rest_key = ()
        self._rest_key_since = self._rest_key_until = -math.inf  # an empty window: asked at the first step
        self._rest_key_count = 0
        self._per_body = None
        self._energy0 = None
        self._work_in = 0.0

    # -- time step --------------------------------------------------------------------------

    def _scale_masses(self, target):
        for b in self.bodies:
            dt_b = b.critical_time_step(self.state[b.name].x)
            if dt_b < target:
                m0 = b.mass.sum()
                b.mass[:] = b.mass * (target / dt_b) ** 2
                self.added_mass[b.name] = float(b.mass.sum() - m0)

    def stable_time_step(self, bounds_only=False):
        """Stable time step estimate of the current state (before the safety factor), s.

        Per body omega^2 = (2 / dt_body)^2 plus the contact penalty's contribution on that body
        (Gershgorin: the stiffness rows add; a contact reports its damped springs as equivalent
        undamped ones). Contacts first adapt their penalty to the bodies' current frequencies (from
        the bounds, whichever estimate sets the step). With a ``global_estimate``, the step of the
        coupled system's largest frequency instead, when it is the longer; ``bounds_only`` keeps the
        bounds' (a run's budget, sized before the run, does not run the power iteration).
        """
        omega2 = {b.name: (2.0 / b.critical_time_step(self.state[b.name].x)) ** 2 for b in self.bodies}
        floor = [omega2[b.name] for b in self.bodies if hasattr(b, "max_frequency")]  # a rod's is its eigenvalue
        for c in self.contacts:
            c.follow_wall(omega2)
            for name, w2 in c.frequency_squared().items():
                omega2[name] += w2
                floor.append(w2)
        bound = 2.0 / math.sqrt(max(omega2.values()))
        if self.global_estimate is None or bounds_only:
            return bound
        # The power iteration sees the springs active at its last evaluation; a contact that appears
        # between two updates it cannot see. Each contact's own frequency as the bounds count it
        # (doubled for contacts appearing before the next update) floors the estimate: without it a
        # scope snapping along a coarse wall diverged (docs/quasi_static.md, "The time step").
        return max(bound, 2.0 / math.sqrt(self.global_estimate.omega2(self, floor=max(floor, default=0.0))))

    def _update_time_step(self):
        if self.fixed_time_step is not None:
            self.dt = self.fixed_time_step
        else:
            dt = self.time_step_factor * self.stable_time_step()
            self.dt = dt if self.dt is None else min(dt, self.time_step_growth * self.dt)

    # -- one step ---------------------------------------------------------------------------

    def _holding_at_rest(self, t):
        """Which constraints hold their nodes at rest at ``t`` (a tuple of flags, the solver's order).
        The flags change only where a constraint's window starts or ends, so between two such times
        the last tuple is returned without asking every constraint again (time only moves forward)."""
        added = self._rest_key_count != len(self.constraints)  # a constraint added after construction
        if added or not self._rest_key_since <= t < self._rest_key_until:
            self._rest_key = tuple(c.holds_at_rest and c.active(t) for c in self.constraints)
            self._rest_key_since = t
            bounds = [b for c in self.constraints if c.holds_at_rest for b in (c.start, c.end) if b > t]
            self._rest_key_until = min(bounds, default=math.inf)
            self._rest_key_count = len(self.constraints)
        return self._rest_key

    def _by_body(self):
        """Per body state: its constraints and resistances (in the solver's order), and whether
        anything writes its external forces (loads, resistances); rebuilt when constraints are added."""
        key = (len(self.constraints), len(self.loads), len(self.resistances))
        if self._per_body is None or self._per_body[0] != key:
            self._per_body = (key, [
                (self.state[b.name], [c for c in self.constraints if c.body is b],
                 [r for r in self.resistances if r.body is b],
                 any(item.body is b for item in self.loads + self.resistances)) for b in self.bodies])
        return self._per_body[1]

    def _refresh_fixed(self, t):
        active = self._holding_at_rest(t)
        if active == self._fixed_key:
            return
        self._fixed_key = active
        for s in self.state.values():
            s.fixed[:] = 0
        for c, on in zip(self.constraints, active):
            if on:
                self.state[c.body.name].fixed[c.nodes] = 1

    def _leave_out_quiet(self, bodies):
        """Tell each body which nodes its explicit update may leave out (:meth:`BodyState.leave_out_quiet`):
        held, at rest, on no element that is not all held, on no contact's candidate and on a body
        no load or resistance acts on. Asked again whenever the held nodes change, a constraint,
        load or resistance is added, or a contact revises the nodes it may reach (its
        ``revision``); a body or contact that cannot say
        (no ``force_nodes`` / ``nodes_on``) leaves nothing out."""
        key = (self._fixed_key, self._per_body[0], tuple(getattr(c, "revision", None) for c in self.contacts))
        if key == self._quiet_key and None not in key[2]:
            return
        self._quiet_key = key
        for s, _, _, written in bodies:
            quiet = None
            if not (s.implicit or written or s.parallel) and hasattr(s.body, "force_nodes"):
                quiet = (s.fixed != 0) & ~(s.v != 0.0).any(axis=1)
                quiet[s.body.force_nodes()] = False
                for c in self.contacts:
                    reach = c.nodes_on(s.body) if hasattr(c, "nodes_on") else None
                    if reach is None:
                        quiet = None
                        break
                    quiet[reach] = False
            s.leave_out_quiet(quiet)

    def _hold_elements(self, t):
        """Tell bodies that leave held elements out (a shell: :meth:`Shell.hold`) which of their
        nodes the constraints active at ``t`` hold, whenever that set changes (before the step's
        forces, so a node released at ``t`` gets its elements' forces from this step on)."""
        key = self._holding_at_rest(t)
        if key == self._held_key:
            return
        self._held_key = key
        for b in self.bodies:
            if hasattr(b, "hold"):
                held = np.zeros(len(b.x0), dtype=bool)
                for c, on in zip(self.constraints, key):
                    if on and c.body is b:
                        held[c.nodes] = True
                b.hold(held)

    def _diverged(self, why):
        return ColonsimError(
            f"simulation diverged at t = {self.time:.6g} s (step {self.step}): {why}; "
            f"reduce time_step_factor (now {self.time_step_factor}) or the time step, or add damping."
        )

    def advance(self, max_step=math.inf):
        """Advance the state by one time step (at most ``max_step`` seconds)."""
        if self.dt is None or (self.fixed_time_step is None and self.step % self.time_step_interval == 0):
            try:
                self._update_time_step()
            except ColonsimError as err:
                raise self._diverged(str(err)) from err
        dt = min(self.dt, max_step)
        dt_mid = dt if self._dt_prev is None else 0.5 * (dt + self._dt_prev)
        t = self.time
        self._hold_elements(t)
        bodies = self._by_body()
        try:
            for s, _, _, written in bodies:
                s.clear_forces(written)  # nothing but loads and resistances writes f_ext: it stays zero
                s.internal = s.body.internal_forces(s.x, s.f_int)
            for c in self.contacts:
                c.compute(self.state, dt_mid)
        except ColonsimError as err:
            raise self._diverged(str(err)) from err
        for load in self.loads:
            if load.active(t):
                load.add_forces(t, self.state[load.body.name].f_ext)
        self._refresh_fixed(t)
        self._leave_out_quiet(bodies)
        energy = 0.0
        work_in = 0.0
        for s, constraints, resistances, _ in bodies:
            w_int, w_con, w_ext, w_damp, w_react, kinetic = step_body(
                s, constraints, self.damping[s.body.name], t, t + 0.5 * dt, dt_mid, dt, resistances)
            s.kinetic = kinetic
            s.work_internal += w_int
            s.work_contact += w_con
            s.work_external += w_ext
            s.work_reaction += w_react
            s.dissipated_damping -= w_damp
            energy += kinetic + s.internal
            work_in += abs(w_ext) + abs(w_react)
        for c in self.contacts:
            c.finish_step(self.state, dt_mid)
            energy += c.energy
        self._work_in += work_in
        if self._energy0 is None:
            self._energy0 = energy
        self.time = t + dt
        self.step += 1
        self._dt_prev = dt
        if not math.isfinite(energy):
            raise self._diverged("the state is no longer finite (NaN or overflow)")
        limit = self.energy_growth_limit * (abs(self._energy0) + self._work_in) + 1e-12
        if energy > limit:
            raise self._diverged(
                f"mechanical energy {energy:.3g} J exceeds {self.energy_growth_limit:g} x the initial energy "
                f"plus the work put in ({limit:.3g} J)"
            )

    # -- run --------------------------------------------------------------------------------

    def _row(self, positions):
        bodies = {}
        for b in self.bodies:
            s = self.state[b.name]
            d = {
                "kinetic": s.kinetic,
                "internal": s.internal,
                "dissipated": s.dissipated_damping,
                "external_work": s.work_external + s.work_reaction,
                "contact_work": s.work_contact,
            }
            if b.name in positions:
                d["positions"] = s.x.copy()
            bodies[b.name] = d
        return {
            "time": self.time,
            "step": self.step,
            "bodies": bodies,
            "contacts": [c.record() for c in self.contacts],
            "reactions": [np.asarray(c.reaction, dtype=np.float64).copy() for c in self.constraints],
        }

    def run(self, duration, record_interval=None, record_positions=(), callbacks=(), exact_end=True):
        """Integrate for ``duration`` seconds and return the recorded :class:`History`.

        Parameters
        ----------
        duration : float
            Simulated time, s.
        record_interval : float or None
            Simulated time between records, s (None = every step).
        record_positions : iterable of str
            Names of bodies whose positions are recorded.
        callbacks : iterable of callables
            Called as ``callback(solver)`` at every record.
        exact_end : bool
            True: the last step is shortened to end on the requested time. False: the run stops at
            the first step that reaches it (up to one step later). A caller that runs in chunks
            should pass False: a shortened step followed by a full one kicks the stiffest mode,
            and repeated every chunk near the stability limit this pumps energy into it (an RSJ
            scope on a 7.5 mm wall mesh diverged in its sheath so, chunks of 10 ms at 0.9 of the
            rod's exact critical step).
        """
        if not duration > 0.0:
            raise ColonsimError(f"duration = {duration} s must be positive; fix it.")
        positions = set(record_positions)
        history = History()
        t_end = self.time + duration
        next_record = self.time
        # central differences allow a varying step
        while t_end - self.time > 1e-6 * (self.dt or 0.0):
            self.advance(max_step=t_end - self.time if exact_end else math.inf)
            if record_interval is None or self.time >= next_record - 1e-12:
                history._append(self._row(positions))
                for cb in callbacks:
                    cb(self)
                if record_interval is not None:
                    while next_record <= self.time + 1e-12:
                        next_record += record_interval
        return history._finish([b.name for b in self.bodies], len(self.contacts), len(self.constraints))
