"""Frictional penalty contact between a rod (the scope) and a shell (the colon wall).

The scope surface is the union of capsules of radius ``rod.radius`` around its segments; the
end caps are spheres, so the distal one is the hemispherical tip. The wall is a set of contact
points, its nodes or points spread over its triangles (``surface``,
:mod:`colonsim.insertion.engine.contact_points`), offset by half the wall thickness (the
mid-surface carries the nodes, the lumen is ``offset`` inside it). Each point in contact takes
the closest point of the scope surface (the minimum over capsules, so a point near a joint
between two segments is counted once):

    gap g = |p - c| - radius - offset,   n = (p - c) / |p - c|
    normal force  f_n = max(k (-g) - c_n v_n, 0),   c_n = 2 zeta sqrt(k m_eff)
    friction      f_t = -mu f_n v_t / max(|v_t|, v_reg)

with c the closest point on the segment axis, v_n, v_t the normal and tangential relative
velocity, m_eff the reduced mass of the wall point (infinite when held) and the rod point, and k
the penalty of a free wall node, or the stiffer one of a held node (whose spring loads only the
rod, so the wall's light nodes do not limit it), each times the point's share of a node (1 for
nodes). Given ``held_normals``, a held point's n is the fixed wall's rest normal instead: the
fixed colon acts as a rigid smooth tube (docs/model.md, "Contact"), which pushes the scope across
its axis but never back along it.
Friction is Coulomb, regularised by a slip velocity v_reg: below mu f_n the contact "sticks"
by creeping at |v_t| = v_reg |F_t| / (mu f_n); v_reg is raised where needed to mu f_n dt / m_eff
so that the viscous friction stays stable in explicit time stepping. The reaction on the rod is
split linearly between the segment's two nodes, the force on the wall onto the point's nodes by
their weights.

The broad phase (candidate pairs) is :mod:`.contact_broad_phase`, the narrow phase (forces per
candidate) :mod:`.contact_kernel`; this module holds the contact object the solver calls.
"""

import math

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.contact_broad_phase import (candidate_counts, candidate_fill, max_displacement,
                                                           max_displacement_at, segment_cell_table)
from colonsim.insertion.engine.contact_kernel import (contact_kernel, contact_kernel_serial, contact_spring_action,
                                                      dissipation_rates, rod_reactions, wall_reactions)
from colonsim.insertion.engine.contact_points import WALL_SAMPLINGS, face_points, node_points


def damped_step_reduction(zeta):
    """Factor sqrt(1 + zeta^2) - zeta on the stable step of a spring damped at the fraction zeta of
    critical (damping force from the previous half-step velocity)."""
    return math.sqrt(1.0 + zeta * zeta) - zeta


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
    surface : str
        Where the contact samples the wall: ``"nodes"`` (its nodes) or ``"faces"`` (points spread
        over its triangles, :func:`colonsim.insertion.engine.contact_points.face_points`).
    face_subdivision : int
        With ``surface="faces"``: L, the points per triangle being L^2 (spaced about h / L).
    """

    def __init__(self, rod, shell, stiffness=None, damping_ratio=0.5, friction=0.0, slip_velocity=1e-3,
                 offset=None, skin=None, held_stiffness=None, held_normals=None, surface="nodes", face_subdivision=2):
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
        if held_normals is None:  # zeros: the kernel's flag to push along the axis-to-point line
            held_normal = np.zeros_like(shell.x0)
        else:
            held_normal = np.ascontiguousarray(held_normals, dtype=np.float64)
            if held_normal.shape != shell.x0.shape or not np.all(np.isfinite(held_normal)):
                raise ColonsimError(f"held_normals must be finite unit vectors of shape {shell.x0.shape}; fix them.")
        if surface not in WALL_SAMPLINGS:
            raise ColonsimError(f"contact surface = {surface!r} is not one of {', '.join(WALL_SAMPLINGS)}; fix it.")
        if surface == "nodes":
            self.points = node_points(len(shell.x0), held_normal)
        else:
            self.points = face_points(shell.x0, shell.triangles, face_subdivision, held_normal)
        self._xr_build = None
        self._xs_build = None
        self.n_rebuilds = 0
        self._still = (None, -1, 0.0)  # (moving nodes, build, the other nodes' largest displacement)
        # below this many candidate wall nodes the narrow phase runs serially (cheaper than threads)
        self.parallel_min_candidates = 20_000
        self._points = np.zeros(0, dtype=np.int64)
        self._ptr = np.zeros(1, dtype=np.int64)
        self._cand = np.zeros(0, dtype=np.int64)
        self._counts = np.zeros(len(self.points), dtype=np.int64)
        self._load = np.zeros(len(rod.x0))
        self._rod_weight = 0.0
        self.energy = 0.0
        self.dissipated = 0.0
        self.friction_dissipated = 0.0
        self.n_active = 0
        self.normal_force = 0.0
        self._force_on_rod = (0.0, 0.0, 0.0)
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
    def revision(self):
        """Changes whenever the candidates change (what :meth:`nodes_on` returns)."""
        return self.n_rebuilds

    def nodes_on(self, body):
        """The nodes of ``body`` this contact may put a force on until its candidates are rebuilt
        (None: any of them)."""
        if body is self.shell:
            return self.points.nodes[self._points].ravel()
        return None

    @property
    def n_candidates(self):
        """Candidate (contact point, segment) pairs of the current list."""
        return len(self._cand)

    def _needs_rebuild(self, xr, xs, moving=None):
        """Have the rod and the wall moved farther than the skin since the last build? ``moving``:
        the wall nodes the solver updates (None, or every node: all); the others stand still, so
        their part of the largest displacement is kept until the list or the build changes (a
        maximum split in two: the same number)."""
        if self._xr_build is None:
            return True
        if moving is None or len(moving) == len(xs):
            wall = max_displacement(xs, self._xs_build)
        else:
            if self._still[0] is not moving or self._still[1] != self.n_rebuilds:
                still = np.ones(len(xs), dtype=bool)
                still[moving] = False
                self._still = (moving, self.n_rebuilds,
                               max_displacement_at(xs, self._xs_build, np.flatnonzero(still)))
            wall = max(self._still[2], max_displacement_at(xs, self._xs_build, moving))
        return max_displacement(xr, self._xr_build) + wall > self.skin

    def build_candidates(self, xr, xs):
        """Rebuild the candidate pairs for rod positions xr and wall positions xs (the points move no
        farther than their nodes, so the nodes' displacement decides when to rebuild)."""
        seg = self.rod.segments
        keys, ids = segment_cell_table(xr, seg, self.cutoff, self.cell)
        xp = self.points.positions(xs)
        candidate_counts(xp, xr, seg, keys, ids, self.cutoff, self.cell, self._counts)
        points = np.flatnonzero(self._counts).astype(np.int64)
        ptr = np.zeros(len(points) + 1, dtype=np.int64)
        np.cumsum(self._counts[points], out=ptr[1:])
        cand = np.empty(ptr[-1], dtype=np.int64)
        candidate_fill(xp, xr, seg, keys, ids, self.cutoff, self.cell, points, ptr, cand)
        self._points, self._ptr, self._cand = points, ptr, cand
        self._rod_seg = np.full(len(points), -1, dtype=np.int64)
        self._rod_t = np.zeros(len(points))
        self._rod_k = np.zeros(len(points))
        self._rod_f = np.zeros((len(points), 3))
        self._damp_f = np.zeros((len(points), 3))
        self._fric_f = np.zeros((len(points), 3))
        self._xr_build = xr.copy()
        self._xs_build = xs.copy()
        self.n_rebuilds += 1

    # -- solver interface --------------------------------------------------------------------

    def compute(self, state, dt):
        """Add contact forces at the current state into the bodies' ``f_con`` buffers."""
        r = state[self.rod.name]
        s = state[self.shell.name]
        if self._needs_rebuild(r.x, s.x, getattr(s, "moving", None)):
            self.build_candidates(r.x, s.x)
        kernel = contact_kernel if len(self._points) >= self.parallel_min_candidates else contact_kernel_serial
        pts = self.points
        energy, p_damp, p_fric, n_active, normal = kernel(
            s.x, s.v, self.shell.mass, s.fixed, pts.nodes, pts.weights, pts.share, pts.held_normal, r.x, r.v,
            self.rod.mass, self.rod.segments, self._points, self._ptr, self._cand, self.rod.radius, self.offset,
            self.stiffness, self.held_stiffness, self.damping_ratio, self.friction, self.slip_velocity, dt,
            self._rod_seg, self._rod_t, self._rod_k, self._rod_f, self._damp_f, self._fric_f,
        )
        wall_reactions(self._points, pts.nodes, pts.weights, self._rod_seg, self._rod_f, s.f_con)
        f0, f1, f2, weight = rod_reactions(self.rod.segments, self._rod_seg, self._rod_t, self._rod_k, self._rod_f,
                                           self.rod.mass, r.f_con, self._load)
        self.energy = energy
        self._p_damp = p_damp
        self._p_fric = p_fric
        self.n_active = n_active
        self.normal_force = normal
        self._force_on_rod = (f0, f1, f2)
        self._rod_weight = weight

    @property
    def force_on_rod(self):
        """The contact's total force on the rod at the last evaluation, N (3,)."""
        return np.array(self._force_on_rod)

    def finish_step(self, state, dt):
        """Accumulate the energy dissipated during the step: the forces of the step times the
        relative velocity averaged over the old and new half-step velocities (as the solver
        sums the work on the bodies)."""
        if len(self._points) == 0:
            return
        p_damp, p_fric = dissipation_rates(state[self.shell.name].v, state[self.rod.name].v, self.rod.segments,
                                           self._points, self.points.nodes, self.points.weights, self._rod_seg,
                                           self._rod_t, self._damp_f, self._fric_f)
        self.dissipated += 0.5 * (self._p_damp + p_damp + self._p_fric + p_fric) * dt
        self.friction_dissipated += 0.5 * (self._p_fric + p_fric) * dt

    def record(self):
        """Scalars of the current step for the history."""
        return {
            "energy": self.energy,
            "dissipated": self.dissipated,
            "friction_dissipated": self.friction_dissipated,
            "normal_force": self.normal_force,
            "force_on_rod": self.force_on_rod,
            "n_active": self.n_active,
            "n_candidates": self.n_candidates,
        }

    # -- time step ---------------------------------------------------------------------------

    def frequency_squared(self):
        """Squared frequency the penalty springs add to each body (Gershgorin rows), rad^2/s^2.

        Wall: one free spring per node, k / m (with points on the faces: the largest of the
        penalty the points put on a node, over its mass). Rod: the largest penalty stiffness per unit mass
        on a rod node of the last evaluation, doubled for contacts appearing before the next
        update, and at least that of four full held-node contacts on the lightest rod node. Both
        are divided by the square of :meth:`damping_reduction` (a damped spring counts as a
        stiffer undamped one).
        """
        reduction = self.damping_reduction() ** 2
        rod_w2 = max(2.0 * self._rod_weight, 4.0 * self.held_stiffness / float(self.rod.mass.min()))
        wall_mass = float((self.shell.mass / self.points.node_share).min())  # the lightest node's, for nodes
        return {self.shell.name: self.stiffness / wall_mass / reduction,
                self.rod.name: rod_w2 / reduction}

    def spring_action(self, state, u, ku):
        """Add K u of the penalty springs active at the last evaluation into ``ku`` (per body
        name, (n, 3) arrays; ``u`` the displacements), each counted as k / r^2 for its damping
        (:meth:`damping_reduction`), as the bounds count it
        (:class:`colonsim.insertion.engine.global_time_step.GlobalTimeStep`)."""
        if len(self._points) == 0:
            return
        s = state[self.shell.name]
        pts = self.points
        contact_spring_action(s.x, state[self.rod.name].x, self.rod.segments, self._points, pts.nodes, pts.weights,
                              self._rod_seg, self._rod_t, self._rod_k, s.fixed, pts.held_normal,
                              1.0 / self.damping_reduction() ** 2, u[self.shell.name], u[self.rod.name],
                              ku[self.shell.name], ku[self.rod.name])

    def damping_reduction(self):
        """:func:`damped_step_reduction` of this contact's springs."""
        return damped_step_reduction(self.damping_ratio)

    def critical_time_step(self):
        """Stable step of the contact springs alone, s."""
        return 2.0 / math.sqrt(max(self.frequency_squared().values()))
