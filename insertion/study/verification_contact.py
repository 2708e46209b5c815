"""Verification problems of the explicit integrator's energy accounting, of rod-wall contact and
of regularised Coulomb friction. SI units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.sheet_mesh import flat_sheet
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.constraints import FixedNodes, LineConstraint, NodalLoad, PrescribedVelocity
from colonsim.insertion.engine.solver import ExplicitSolver
from colonsim.insertion.study.verification import SCOPE_D, SCOPE_E, SCOPE_RHO, WALL_T, Comparison, reference_material
from colonsim.insertion.study.verification_rod import first_mode


def free_vibration_energy_drift() -> dict[str, Comparison]:
    """Cantilever rod and a clamped wall patch vibrating freely for 5 periods of the rod's first
    mode (no damping, no loads). Returns per body ("scope", "wall") the largest |E(t) - E(0)| / E(0)
    of kinetic + strain energy against 0, with the largest |external work| (J) as "external work"."""
    rod = Rod.straight(0.1, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=5e-3)
    s = rod.x0[:, 0] / 0.1
    v_rod = np.zeros_like(rod.x0)
    v_rod[:, 2] = 0.05 * s**2
    v_rod[:2] = 0.0
    nodes, tri = flat_sheet(0.04, 0.04, 4e-3)
    wall = Shell(nodes, tri, WALL_T, reference_material(), name="wall")
    on_edge = (np.minimum(nodes[:, 0], 0.04 - nodes[:, 0]) < 1e-9) | (np.minimum(nodes[:, 1], 0.04 - nodes[:, 1]) < 1e-9)
    edge = np.flatnonzero(on_edge)
    r = np.hypot(nodes[:, 0] - 0.02, nodes[:, 1] - 0.02)
    v_wall = np.zeros_like(nodes)
    v_wall[:, 2] = 0.05 * np.clip(1.0 - r / 0.02, 0.0, None)
    v_wall[edge] = 0.0
    sim = ExplicitSolver([rod, wall], constraints=[FixedNodes(rod, [0, 1]), FixedNodes(wall, edge)],
                         initial_velocity={"scope": v_rod, "wall": v_wall})
    omega1 = first_mode(rod, 0.1)
    hist = sim.run(5 * 2 * math.pi / omega1, record_interval=1e-3)
    out = {}
    for name in ("scope", "wall"):
        b = hist.bodies[name]
        total = b["kinetic"] + b["internal"]
        out[name] = Comparison(f"free vibration, {name}: max |E(t) - E(0)| / E(0) over 5 periods", 0.0,
                               float(np.max(np.abs(total - total[0])) / total[0]),
                               extra={"external work": float(np.max(np.abs(b["external_work"])))})
    return out


def damped_push_energy_balance():
    """A damped rod pushed with a ramped velocity, then held, with a switched tip load.

    Returns ``(residual, work, dissipated, history, solver)``: the largest |kinetic + strain +
    dissipated - external work| over the run (J), the largest |external work| (J), the final
    dissipated energy (J), and the run's history and solver for further checks.
    """
    rod = Rod.straight(0.2, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=5e-3)
    push = PrescribedVelocity(rod, [0], (0.5, 0.0, 0.0), ramp=2e-3, end=8e-3)
    hold = FixedNodes(rod, [0], start=8e-3)
    load = NodalLoad(rod, [rod.tip_node], (-20.0, 5.0, 0.0), start=2e-3)
    sim = ExplicitSolver([rod], constraints=[push, hold], loads=[load], damping=200.0)
    hist = sim.run(0.03, record_interval=1e-4)
    b = hist.bodies["scope"]
    return (float(np.max(np.abs(hist.total_energy_balance()))), float(np.max(np.abs(b["external_work"]))),
            float(b["dissipated"][-1]), hist, sim)


def damped_push_balance() -> Comparison:
    """The energy residual of :func:`damped_push_energy_balance` over the work put in, against 0,
    with that work and the energy dissipated (J) as "external work" and "dissipated"."""
    residual, work, dissipated, _, _ = damped_push_energy_balance()
    return Comparison("damped pushed rod: max |kinetic + strain + dissipated - work| / work", 0.0, residual / work,
                      extra={"external work": work, "dissipated": dissipated})



# --- contact ------------------------------------------------------------------------------------

def rod_on_sheet(friction=0.0):
    """A fixed flat wall (rigid support) and a rod lying along one row of its nodes.

    The row has nodes every 5 mm along x; the rod spans x in [22.5, 77.5] mm, so exactly the 11
    row nodes at 25..75 mm lie under it (the neighbour rows are 4.4 mm aside, 1.2 mm clear of
    the capsule, and the row nodes beyond the rod ends 0.4 mm clear of the end caps).
    Returns (wall, rod, contact, indices of the nodes under the rod).
    """
    nodes, tri = flat_sheet(0.1, 0.04, 5e-3)
    wall = Shell(nodes, tri, WALL_T, reference_material(), name="wall")
    y_row = 0.04 * 4 / 9
    under = np.flatnonzero((np.abs(nodes[:, 1] - y_row) < 1e-9) & (nodes[:, 0] > 0.0225) & (nodes[:, 0] < 0.0775))
    z = 0.5 * SCOPE_D + 0.5 * WALL_T
    rod = Rod.straight(0.055, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=5e-3, start=(0.0225, y_row, z))
    contact = RodShellContact(rod, wall, damping_ratio=1.0, friction=friction)
    return wall, rod, contact, under


def rod_resting_on_wall(load=1.0) -> tuple[Comparison, Comparison, Comparison]:
    """A load spread over the rod like its weight pressing it on a rigid wall.

    Returns three comparisons: the mean penetration against F / (n k) with n contact springs of
    stiffness k in parallel (with the "active contacts" and the "nodes under the rod"); the normal
    force over the load against 1 (with the "force on the rod / load"); the largest |energy
    balance| over the work of the load against 0 (with "contact energy / (F pen / 2)", the penalty
    energy against that of a linear spring at the analytic penetration).
    """
    wall, rod, contact, under = rod_on_sheet()
    per_node = load * rod.mass / rod.mass.sum()
    nodal = NodalLoad(rod, np.arange(rod.n_nodes), np.column_stack((0 * per_node, 0 * per_node, -per_node)))
    sim = ExplicitSolver([rod, wall], contacts=[contact], constraints=[FixedNodes(wall, np.arange(wall.n_nodes))],
                         loads=[nodal], damping={"scope": 0.0})
    omega = math.sqrt(len(under) * contact.held_stiffness / rod.mass.sum())
    hist = sim.run(30.0 / omega, record_interval=1.0 / omega)
    pen = 0.5 * SCOPE_D + 0.5 * WALL_T - sim.state["scope"].x[:, 2].mean()
    expected = load / (len(under) * contact.held_stiffness)
    work = float(hist.bodies["scope"]["external_work"][-1])
    return (Comparison("penetration F / (n k) of a rod resting on n wall nodes", expected, float(pen), "m",
                       extra={"active contacts": int(contact.n_active), "nodes under the rod": len(under)}),
            Comparison("resting rod: normal force / applied load", 1.0, float(contact.normal_force) / load,
                       extra={"force on the rod / load": float(contact.force_on_rod[2]) / load}),
            Comparison("resting rod: max |energy balance| / work", 0.0,
                       float(np.max(np.abs(hist.total_energy_balance()))) / work,
                       extra={"contact energy / (F pen / 2)":
                              float(hist.contacts[0]["energy"][-1]) / (0.5 * load * expected)}))


def tip_on_node(load=0.2) -> Comparison:
    """A rod guided along its axis pressed tip-down on one wall node: penetration F / k, with the
    number of "active contacts"."""
    nodes, tri = flat_sheet(0.1, 0.04, 5e-3)
    wall = Shell(nodes, tri, WALL_T, reference_material(), name="wall")
    below = int(np.argmin(np.hypot(nodes[:, 0] - 0.05, nodes[:, 1] - 0.04 * 4 / 9)))
    reach = 0.5 * SCOPE_D + 0.5 * WALL_T
    top = nodes[below] + (0.0, 0.0, reach + 0.03)
    rod = Rod.straight(0.03, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=5e-3, start=top, direction=(0.0, 0.0, -1.0))
    contact = RodShellContact(rod, wall, damping_ratio=1.0)
    sim = ExplicitSolver(
        [rod, wall], contacts=[contact],
        constraints=[FixedNodes(wall, np.arange(wall.n_nodes)), LineConstraint(rod, top, (0.0, 0.0, -1.0))],
        loads=[NodalLoad(rod, [0], (0.0, 0.0, -load))],
    )
    omega = math.sqrt(contact.held_stiffness / rod.mass.sum())
    sim.run(30.0 / omega, record_interval=1.0 / omega)
    tip = sim.state["scope"].x[rod.tip_node]
    return Comparison("penetration F / k of the hemispherical tip on one node", load / contact.held_stiffness,
                      float(reach - (tip[2] - nodes[below, 2])), "m", extra={"active contacts": int(contact.n_active)})


@dataclass
class Slide:
    """Outcome of :func:`friction_slide` (SI units)."""

    v2: float  # mean axial velocity 2 ms after the pull starts
    v5: float  # ... 5 ms after
    interval: float  # time between the two
    slid: float  # distance slid
    dissipated: float  # friction work over the pull
    mass: float
    creep_speed: float  # v_reg F_t / (mu N), the regularised law's stick speed


def friction_slide(tangential, friction=0.3, normal=1.0) -> Slide:
    """Settle the rod of :func:`rod_on_sheet` under a normal load, then pull it along its axis
    with ``tangential`` (N) for 5 ms."""
    wall, rod, contact, under = rod_on_sheet(friction=friction)
    share = rod.mass / rod.mass.sum()
    down = NodalLoad(rod, np.arange(rod.n_nodes), np.column_stack((0 * share, 0 * share, -normal * share)))
    omega = math.sqrt(len(under) * contact.held_stiffness / rod.mass.sum())
    t1 = 30.0 / omega  # contact springs critically damped: settled after 30 time constants
    pull = NodalLoad(rod, np.arange(rod.n_nodes), np.column_stack((tangential * share, 0 * share, 0 * share)), start=t1)
    sim = ExplicitSolver([rod, wall], contacts=[contact], constraints=[FixedNodes(wall, np.arange(wall.n_nodes))],
                         loads=[down, pull])
    sim.run(t1)
    x_start = sim.state["scope"].x[:, 0] @ share
    d0 = contact.friction_dissipated
    sim.run(2e-3)
    v2, t2 = sim.state["scope"].v[:, 0].mean(), sim.time
    sim.run(3e-3)
    v5, t5 = sim.state["scope"].v[:, 0].mean(), sim.time
    # the work sums of a step pair its forces with the mid-step velocity, so they cover the
    # motion up to half a step before the positions: compare with the slide up to there
    slid = sim.state["scope"].x[:, 0] @ share - x_start - 0.5 * sim.dt * v5
    creep = contact.slip_velocity * abs(tangential) / (friction * normal)
    return Slide(float(v2), float(v5), float(t5 - t2), float(slid), float(contact.friction_dissipated - d0),
                 float(rod.mass.sum()), float(creep))


def friction_stick(friction=0.3, normal=1.0) -> Comparison:
    """Pulled with half of mu N the rod creeps at the regularised stick speed: its speed 5 ms after
    the pull starts, with the speed after 2 ms and the distance slid relative to creep."""
    s = friction_slide(0.5 * friction * normal, friction, normal)
    return Comparison("stick: creep speed v_reg F_t / (mu N) at F_t = mu N / 2", s.creep_speed, s.v5, "m/s",
                      extra={"speed after 2 ms / creep speed": s.v2 / s.creep_speed,
                             "slid / (creep speed x 5 ms)": s.slid / (s.creep_speed * 5e-3)})


def friction_sliding(friction=0.3, normal=1.0) -> tuple[Comparison, Comparison]:
    """Pulled with twice mu N the rod accelerates at (F_t - mu N) / M and friction dissipates
    mu N per unit slid distance."""
    ft = 2.0 * friction * normal
    s = friction_slide(ft, friction, normal)
    return (Comparison("slide: acceleration (F_t - mu N) / M at F_t = 2 mu N", (ft - friction * normal) / s.mass,
                       (s.v5 - s.v2) / s.interval, "m/s^2"),
            Comparison("slide: friction work mu N x slid distance", friction * normal * s.slid, s.dissipated, "J"))


# --- where the contact samples the wall: nodes or faces (docs/model.md, "Contact") ----------------

ACROSS_MESH_H = 3e-3  # m, the colon models' wall triangles
ACROSS_MESH_LOAD = 0.5  # N on the tip


def cap_penalty_load(penetration, radius, pressure):
    """Normal force of a sphere of ``radius`` (the tip's, plus the wall's offset) sunk
    ``penetration`` into a flat wall whose every point pushes back with ``pressure`` times its
    gap as the contact law measures it, along the line from the sphere's centre
    (R - sqrt(rho^2 + z^2), z = R - penetration): the penalty spread over the surface, in closed
    form, the integral of that gap over the disc of radius a = sqrt(R^2 - z^2),
    pi R d^2 - 2 pi d^3 / 3 (d the penetration; the cap's volume, measured vertically, is
    pi d^2 (3 R - d) / 3, larger by pi d^3 / 3)."""
    d = penetration
    return pressure * (math.pi * radius * d * d - 2.0 * math.pi * d**3 / 3.0)


def _bisect(force, target, hi):
    """The depth in [0, hi] at which the increasing ``force(depth)`` reaches ``target``."""
    lo = 0.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if force(mid) < target else (lo, mid)
    return 0.5 * (lo + hi)


def _tip_penetrations(surface, subdivision, shifts):
    """Penetration of the tip of :func:`tip_across_wall_mesh` at each of ``shifts`` (m, over the
    wall's plane), with the contact sampling the wall at ``surface``; and the continuous penalty's
    (:func:`cap_penalty_load`)."""
    nodes, tri = flat_sheet(0.03, 0.03, ACROSS_MESH_H)
    wall = Shell(nodes, tri, WALL_T, reference_material(), name="wall")
    down = np.tile((0.0, 0.0, -1.0), (len(nodes), 1))  # the wall's normal, away from the scope
    rod = Rod.straight(0.03, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=5e-3, start=(0.015, 0.015, 0.04),
                       direction=(0.0, 0.0, -1.0))
    free = RodShellContact(rod, wall).stiffness
    contact = RodShellContact(rod, wall, damping_ratio=1.0, held_normals=down, surface=surface,
                              face_subdivision=subdivision, held_stiffness=free)
    sim = ExplicitSolver([rod, wall], contacts=[contact])
    scope, sheet = sim.state["scope"], sim.state["wall"]
    sheet.fixed[:] = 1
    reach = 0.5 * SCOPE_D + 0.5 * WALL_T
    tip = rod.tip_node

    def normal_force(shift, depth):
        scope.x[:] = rod.x0
        scope.x[:, :2] += shift
        scope.x[:, 2] += reach - depth - rod.x0[tip, 2]
        sheet.f_con[:] = 0.0
        scope.f_con[:] = 0.0
        contact.compute(sim.state, 1e-6)
        return contact.normal_force

    sunk = np.array([_bisect(lambda z, s=s: normal_force(s, z), ACROSS_MESH_LOAD, 0.5 * reach) for s in shifts])
    area = 0.5 * np.linalg.norm(np.cross(nodes[tri[:, 1]] - nodes[tri[:, 0]], nodes[tri[:, 2]] - nodes[tri[:, 0]]),
                                axis=1)
    lumped = np.zeros(len(nodes))
    np.add.at(lumped, tri.ravel(), np.repeat(area / 3.0, 3))
    pressure = free / float(np.median(lumped))  # the interior nodes' area (edge nodes have less)
    return sunk, _bisect(lambda z: cap_penalty_load(z, reach, pressure), ACROSS_MESH_LOAD, 0.5 * reach)


def tip_across_wall_mesh(subdivision=2, positions=40, seed=0) -> Comparison:
    """The scope's hemispherical tip pressed with :data:`ACROSS_MESH_LOAD` on a flat wall of 3 mm
    triangles (the colon models' mesh) at ``positions`` random places over one element: its
    penetration at each, found by bisection on the static contact force, with the contact on the
    wall's faces (``subdivision`` L, L^2 points per triangle) and on its nodes. The wall is held,
    its points pushing along its normal, with the penalty of a free wall node (the mobile colon's).

    Returns a :class:`Comparison` of the mean penetration on the faces against that of the same
    penalty spread over the wall's surface (:func:`cap_penalty_load`, the pressure being one
    node's penalty over its lumped area), with the spread of the penetration over the positions
    (m), how far the tip rises and sinks as it slides over the mesh, on the faces ("ripple") and
    on the nodes ("ripple at the nodes"), and the nodes' mean over the closed form ("nodes' mean /
    closed form")."""
    shifts = np.random.default_rng(seed).uniform(0.0, ACROSS_MESH_H, (positions, 2))
    faces, continuous = _tip_penetrations("faces", subdivision, shifts)
    at_nodes, _ = _tip_penetrations("nodes", 1, shifts)
    return Comparison(f"tip across the wall's mesh, contact on its faces ({subdivision ** 2} points per triangle): "
                      f"mean penetration under {ACROSS_MESH_LOAD:g} N", continuous, float(faces.mean()), "m",
                      extra={"ripple": float(np.ptp(faces)), "ripple at the nodes": float(np.ptp(at_nodes)),
                             "nodes' mean / closed form": float(at_nodes.mean()) / continuous})
