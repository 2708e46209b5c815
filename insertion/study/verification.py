"""Verification problems of the explicit solver: each builds a small model with a closed-form
answer, solves it, and returns the analytic and the measured number.

The test-suite asserts on these numbers (``tests/test_rod_*.py``, ``test_shell_inflation.py``,
``test_shell_bending.py``, ``test_energy_balance.py``, ``test_contact_*.py``) and the validation
report (``benchmarks/validation_report.py``) tabulates them; the derivations and the reasons for
the tolerances are in those tests' docstrings. SI units throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipk

from colonsim.insertion.engine.contact import RodShellContact
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.sheet_mesh import flat_sheet, straight_tube
from colonsim.insertion.engine.constraints import FixedNodes, LineConstraint, NodalLoad, PrescribedVelocity
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.shell_hinges import dihedral_angles
from colonsim.insertion.engine.solver import ExplicitSolver
from colonsim.insertion.engine.statics import minimize_energy

# The standard scope (catalogue diameter).
SCOPE_E = 16e6  # Pa
SCOPE_RHO = 2944.0  # kg/m^3
SCOPE_D = 12.8e-3  # m
WALL_T = 2e-3  # m, wall thickness (an assumption, docs/model.md)


@dataclass(frozen=True)
class Comparison:
    """An analytic value and what the model gives for it."""

    quantity: str
    analytic: float
    measured: float
    unit: str = ""

    @property
    def relative_error(self) -> float:
        """(measured - analytic) / |analytic|; NaN when the analytic value is zero."""
        return (self.measured - self.analytic) / abs(self.analytic) if self.analytic != 0.0 else math.nan

    def to_dict(self) -> dict:
        return {"quantity": self.quantity, "analytic": self.analytic, "measured": self.measured, "unit": self.unit,
                "relative_error": self.relative_error}


def reference_material():
    return load_material(REFERENCE_MATERIAL_PATH)


# --- rod: cantilever, Euler buckling, axial waves -------------------------------------------

def cantilever(length, spacing):
    """Rod whose clamp (middle of segment 0) lies at x = 0 and whose tip is at x = length.

    The rod's hinge at the first free node owns the half cell behind it, so a rod whose first two
    nodes are fixed is clamped at the middle of its first segment.
    """
    n_seg = int(round(length / spacing))
    h = length / (n_seg + 0.5)
    x = (np.arange(n_seg + 2) - 0.5) * h
    nodes = np.column_stack((x, np.zeros_like(x), np.zeros_like(x)))
    return Rod(nodes, SCOPE_D, SCOPE_E, SCOPE_RHO)


def _first_mode(rod, length):
    return 1.875**2 * math.sqrt(rod.flexural_rigidity / (SCOPE_RHO * rod.area * length**4))


def cantilever_tip_deflection(length=0.3, spacing=0.01, deflection_ratio=0.005) -> Comparison:
    """Static tip deflection under a tip load P = 3 EI delta / L^3 (beam theory: delta), by
    dynamic relaxation (critical damping of the first mode, 16 time constants)."""
    rod = cantilever(length, spacing)
    EI = rod.flexural_rigidity
    delta = deflection_ratio * length
    P = 3.0 * EI * delta / length**3
    omega1 = _first_mode(rod, length)
    sim = ExplicitSolver([rod], constraints=[FixedNodes(rod, [0, 1])],
                         loads=[NodalLoad(rod, [rod.tip_node], (0.0, 0.0, -P))], damping=2.0 * omega1)
    sim.run(16.0 / omega1, record_interval=0.1)
    tip = sim.state["scope"].x[rod.tip_node]
    return Comparison("cantilever tip deflection P L^3 / (3 EI)", P * length**3 / (3.0 * EI), float(-tip[2]), "m")


def euler_load(rod, length) -> float:
    """Critical load of a clamped-free column, pi^2 EI / (4 L^2), N."""
    return math.pi**2 * rod.flexural_rigidity / (4.0 * length**2)


def compressed_min_eigenvalue(rod, load, eps=1e-7) -> float:
    """Smallest eigenvalue of the lateral tangent stiffness of the straight cantilever under an
    axial dead load ``load`` (N), by central differences of the rod's own forces, N/m."""
    free = np.arange(2, rod.n_nodes)
    x = rod.x0.copy()
    shortened = rod.rest_length[1:] - load / rod.axial_stiffness[1:]
    x[2:, 0] = x[1, 0] + np.cumsum(shortened)
    k = np.zeros((len(free), len(free)))
    for j, node in enumerate(free):
        fp = np.zeros_like(x)
        fm = np.zeros_like(x)
        xp = x.copy()
        xp[node, 1] += eps
        xm = x.copy()
        xm[node, 1] -= eps
        rod.internal_forces(xp, fp)
        rod.internal_forces(xm, fm)
        k[:, j] = -(fp[free, 1] - fm[free, 1]) / (2 * eps)
    return float(np.linalg.eigvalsh(0.5 * (k + k.T)).min())


def euler_buckling_load(length=0.3, spacing=0.01) -> Comparison:
    """The load where the straight rod's tangent stiffness first loses positive definiteness
    against pi^2 EI / (4 L^2)."""
    rod = cantilever(length, spacing)
    p_euler = euler_load(rod, length)
    p_cr = brentq(lambda p: compressed_min_eigenvalue(rod, p), 0.5 * p_euler, 1.5 * p_euler, xtol=1e-6 * p_euler)
    return Comparison("Euler load pi^2 EI / (4 L^2), clamped-free", p_euler, float(p_cr), "N")


def buckling_tip_deflection(load_ratio, length, spacing, imperfection=1e-3) -> float:
    """Lateral tip deflection / L after relaxing (120 first-mode time constants) under an axial
    dead load P = load_ratio * P_Euler plus a lateral imperfection load ``imperfection`` * P."""
    rod = cantilever(length, spacing)
    P = load_ratio * euler_load(rod, length)
    omega1 = _first_mode(rod, length)
    sim = ExplicitSolver([rod], constraints=[FixedNodes(rod, [0, 1])],
                         loads=[NodalLoad(rod, [rod.tip_node], (-P, imperfection * P, 0.0))], damping=0.5 * omega1)
    sim.run(120.0 / omega1, record_interval=1.0)
    return float(sim.state["scope"].x[rod.tip_node, 1] / length)


def beam_column_tip_deflection(load_ratio, imperfection=1e-3) -> float:
    """Linear theory below the Euler load: tip deflection / L of a cantilever under axial P and
    a lateral tip load Q = imperfection * P, delta = Q (tan kL - kL) / (P k), kL = pi/2 sqrt(ratio)."""
    if not 0.0 < load_ratio < 1.0:
        raise ValueError("linear beam-column theory holds below the Euler load only")
    kl = 0.5 * math.pi * math.sqrt(load_ratio)
    return imperfection * (math.tan(kl) - kl) / kl


def elastica_tip_deflection(load_ratio) -> float:
    """Post-buckled perfect cantilever (Euler elastica): tip deflection / L = 2 p / K(p) with
    K(p) = (pi/2) sqrt(P / P_Euler), p = sin(tip rotation / 2); 0 below the Euler load."""
    if load_ratio <= 1.0:
        return 0.0
    target = 0.5 * math.pi * math.sqrt(load_ratio)
    p = brentq(lambda q: ellipk(q * q) - target, 1e-12, 1.0 - 1e-12)
    return 2.0 * p / target


def axial_wave(length=1.0, spacing=5e-3, speed=0.01, probe=100) -> tuple[Comparison, Comparison]:
    """Velocity step at the free end of a long rod: the front's arrival at node ``probe`` gives
    the wave speed (analytic sqrt(E / rho)), the mean push force after 0.3 of the transit the
    impedance force rho c A v0."""
    rod = Rod.straight(length, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=spacing)
    c = math.sqrt(SCOPE_E / SCOPE_RHO)
    push = PrescribedVelocity(rod, [0], (speed, 0.0, 0.0))
    sim = ExplicitSolver([rod], constraints=[push])
    d = rod.x0[probe, 0]
    arrival = None
    force = []
    while sim.time < 1.2 * d / c:
        v_before = sim.state["scope"].v[probe, 0]
        t_before = sim.time
        sim.advance()
        v_after = sim.state["scope"].v[probe, 0]
        # velocities live at mid-steps
        if arrival is None and v_after >= 0.5 * speed:
            frac = (0.5 * speed - v_before) / (v_after - v_before)
            arrival = t_before - 0.5 * sim.dt + frac * sim.dt if t_before > 0 else t_before
        if sim.time > 0.3 * d / c:
            force.append(push.reaction[0])
    return (Comparison("axial wave speed sqrt(E / rho)", c, float(d / arrival), "m/s"),
            Comparison("push force rho c A v0 (impedance)", SCOPE_RHO * c * rod.area * speed, float(np.mean(force)), "N"))


# --- shell: inflation against thin-wall theory, bending against plate theory ----------------

TUBE_RADIUS, TUBE_H = 0.018, 0.003  # m: mid-surface radius and mesh size of the inflated tube


def thin_wall_pressure(stretch, material=None, radius=TUBE_RADIUS, thickness=WALL_T):
    """Closed-form inflation pressure of a thin incompressible Mooney-Rivlin tube in plane strain
    (axial stretch 1) at hoop stretch ``stretch``, Pa (derivation: tests/test_shell_inflation.py):

        p(l) = (2 t / R) (1 - l^-4) [C10 + C01 + 2 C11 (l^2 + l^-2 - 2)]
    """
    c = (material or reference_material()).named_parameters
    l = np.asarray(stretch, dtype=float)
    return 2.0 * thickness / radius * (1.0 - l**-4) * (c["C10"] + c["C01"] + 2.0 * c["C11"] * (l**2 + l**-2 - 2.0))


def inflation_tube(length, material=None):
    """Straight tube of radius TUBE_RADIUS; returns (shell, ring index per node, cos(pi / m)), the
    last being the exact correction of a ring of m chords inscribed in the circle."""
    nodes, tri, ring = straight_tube(length, 2.0 * TUBE_RADIUS, TUBE_H)
    shell = Shell(nodes, tri, WALL_T, material or reference_material())
    per_ring = int(np.sum(ring == 0))
    return shell, ring, np.cos(np.pi / per_ring)


def _closed_volume(shell, x, last_ring, length):
    """Volume enclosed by the tube and two flat end caps (axial coordinates held), m^3."""
    p = x[last_ring]
    order = np.argsort(np.arctan2(p[:, 2], p[:, 1]))
    y, z = p[order, 1], p[order, 2]
    cap_area = 0.5 * np.sum(y * np.roll(z, -1) - np.roll(y, -1) * z)
    return shell.enclosed_volume(x) + length * cap_area / 3.0


def inflate_section(stretch, length=0.02) -> tuple[Comparison, float]:
    """A periodic tube section (every axial coordinate fixed) under p(l) / cos(pi/m), solved
    statically. Returns the mean radius / R against ``stretch`` and the relative spread of the
    nodal radii (std / stretch)."""
    shell, ring, cos_factor = inflation_tube(length)
    last = np.flatnonzero(ring == ring.max())
    free = np.ones(shell.x0.shape, dtype=bool)
    free[:, 0] = False
    pressure = float(thin_wall_pressure(stretch)) / cos_factor

    def potential(x, f):
        energy = shell.internal_forces(x, f)
        shell.pressure_forces(x, pressure, f)
        return energy - pressure * _closed_volume(shell, x, last, length)

    x, _ = minimize_energy(shell.x0, free, potential, force_tol=1e-5 * pressure * TUBE_H**2)
    r = np.hypot(x[:, 1], x[:, 2]) / TUBE_RADIUS
    return (Comparison(f"hoop stretch of a plane-strain section at p(l = {stretch:g})", float(stretch), float(r.mean())),
            float(r.std() / stretch))


def inflate_clamped_tube(stretches, length_radii) -> list[Comparison]:
    """A tube of ``length_radii`` radii with clamped end rings and fixed axial coordinates,
    inflated successively to each of ``stretches``; the middle ring's mean stretch against the
    plane-strain thin-wall value."""
    length = length_radii * TUBE_RADIUS
    shell, ring, cos_factor = inflation_tube(length)
    free = np.ones(shell.x0.shape, dtype=bool)
    free[:, 0] = False
    free[(ring == 0) | (ring == ring.max())] = False
    middle = ring == ring.max() // 2
    x = shell.x0
    out = []
    for stretch in stretches:
        pressure = float(thin_wall_pressure(stretch)) / cos_factor

        def potential(x, f, pressure=pressure):
            energy = shell.internal_forces(x, f)
            shell.pressure_forces(x, pressure, f)
            # End rings fixed: the open tube's signed volume is a valid potential.
            return energy - pressure * shell.enclosed_volume(x)

        x, _ = minimize_energy(x, free, potential, force_tol=1e-5 * pressure * TUBE_H**2)
        r = np.hypot(x[middle, 1], x[middle, 2]) / TUBE_RADIUS
        out.append(Comparison(f"middle-ring hoop stretch, clamped tube L = {length_radii:g} R, p(l = {stretch:g})",
                              float(stretch), float(r.mean())))
    return out


SHEET_SIDE, SHEET_H = 0.06, 0.003  # m: 516 nodes; the interior (2 h from the edges) holds ~900 hinges


def bending_sheet(material=None):
    """The flat near-equilateral sheet of the bending checks."""
    nodes, tri = flat_sheet(SHEET_SIDE, SHEET_SIDE, SHEET_H)
    return Shell(nodes, tri, WALL_T, material or reference_material())


def onto_cylinder(nodes, radius, angle):
    """Isometric map of the z = 0 sheet onto a cylinder whose axis makes ``angle`` (rad) with x."""
    axis = np.array([np.cos(angle), np.sin(angle), 0.0])
    across = np.array([-np.sin(angle), np.cos(angle), 0.0])
    p = nodes - [SHEET_SIDE / 2, SHEET_SIDE / 2, 0.0]
    s, a = p @ across, p @ axis
    x = a[:, None] * axis + (radius * np.sin(s / radius))[:, None] * across
    x[:, 2] = radius * (1.0 - np.cos(s / radius))
    return np.ascontiguousarray(x)


def onto_sphere(nodes, radius):
    """Map of the sheet onto a spherical cap (radial distances kept as arc lengths)."""
    p = nodes - [SHEET_SIDE / 2, SHEET_SIDE / 2, 0.0]
    rho = np.hypot(p[:, 0], p[:, 1])
    scale = np.where(rho > 0, radius * np.sin(rho / radius) / np.where(rho > 0, rho, 1.0), 1.0)
    return np.ascontiguousarray(np.column_stack((p[:, 0] * scale, p[:, 1] * scale, radius * (1 - np.cos(rho / radius)))))


def interior_energy_density(shell, x):
    """Hinge energy per unit area away from the sheet's edges, J/m^2.

    Each hinge stands for (A_1 + A_2)/3 of area. A rectangular window cuts the three edge
    directions of the mesh unequally, and for a cylinder the hinge angle depends on the edge
    direction, so the density is summed per direction class (mean energy of the class over the
    mean hinge area), which is what an unbounded mesh gives.
    """
    nodes, hinge = shell.x0, shell.hinges
    edge = nodes[hinge[:, 1]] - nodes[hinge[:, 0]]
    area_pair = 0.5 * (
        np.linalg.norm(np.cross(edge, nodes[hinge[:, 2]] - nodes[hinge[:, 0]]), axis=1)
        + np.linalg.norm(np.cross(nodes[hinge[:, 3]] - nodes[hinge[:, 0]], edge), axis=1)
    )
    direction = np.round(np.degrees(np.arctan2(edge[:, 1], edge[:, 0])) % 180.0 / 60.0).astype(int) % 3
    centre = nodes[hinge].mean(axis=1)
    inside = np.all((centre[:, :2] > 2 * SHEET_H) & (centre[:, :2] < SHEET_SIDE - 2 * SHEET_H), axis=1)
    energy = shell.hinge_stiffness * dihedral_angles(x, hinge) ** 2
    return sum(energy[inside & (direction == k)].mean() for k in range(3)) / area_pair[inside].mean()


def cylinder_bending(radius, angle_deg) -> Comparison:
    """Interior hinge energy density of the sheet rolled onto a cylinder against D / (2 R^2)."""
    shell = bending_sheet()
    x = onto_cylinder(shell.x0, radius, np.radians(angle_deg))
    return Comparison(f"bending energy density D / (2 R^2), cylinder R = {radius * 100:g} cm, axis at {angle_deg:g} deg",
                      shell.bending_stiffness / (2.0 * radius**2), float(interior_energy_density(shell, x)), "J/m^2")


def sphere_bending(radius) -> Comparison:
    """Interior hinge energy density on a spherical cap against the hinge model's own value
    (2/3) D / R^2 (intrinsic Poisson ratio -1/3, documented in insertion/shell.py)."""
    shell = bending_sheet()
    x = onto_sphere(shell.x0, radius)
    return Comparison(f"bending energy density (2/3) D / R^2 of the hinge model, sphere R = {radius * 100:g} cm",
                      2.0 / 3.0 * shell.bending_stiffness / radius**2, float(interior_energy_density(shell, x)), "J/m^2")


# --- energy accounting ------------------------------------------------------------------------

def free_vibration_energy_drift() -> dict:
    """Cantilever rod and a clamped wall patch vibrating freely for 5 periods of the rod's first
    mode (no damping, no loads). Returns per body the largest |E(t) - E(0)| / E(0) of kinetic +
    strain energy, and the largest |external work| (must be exactly 0)."""
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
    omega1 = _first_mode(rod, 0.1)
    hist = sim.run(5 * 2 * math.pi / omega1, record_interval=1e-3)
    out = {}
    for name in ("scope", "wall"):
        b = hist.bodies[name]
        total = b["kinetic"] + b["internal"]
        out[name] = {"drift": float(np.max(np.abs(total - total[0])) / total[0]),
                     "external_work": float(np.max(np.abs(b["external_work"])))}
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


@dataclass
class RestingRod:
    """Outcome of :func:`rod_resting_on_wall`."""

    penetration: Comparison
    normal_force: float
    force_on_rod_z: float
    n_active: int
    n_under: int
    energy_residual: float
    work: float
    contact_energy: float


def rod_resting_on_wall(load=1.0) -> RestingRod:
    """A load spread over the rod like its weight pressing it on a rigid wall: the mean
    penetration is F / (n k) with n contact springs of stiffness k in parallel."""
    wall, rod, contact, under = rod_on_sheet()
    per_node = load * rod.mass / rod.mass.sum()
    nodal = NodalLoad(rod, np.arange(rod.n_nodes), np.column_stack((0 * per_node, 0 * per_node, -per_node)))
    sim = ExplicitSolver([rod, wall], contacts=[contact], constraints=[FixedNodes(wall, np.arange(wall.n_nodes))],
                         loads=[nodal], damping={"scope": 0.0})
    omega = math.sqrt(len(under) * contact.held_stiffness / rod.mass.sum())
    hist = sim.run(30.0 / omega, record_interval=1.0 / omega)
    pen = 0.5 * SCOPE_D + 0.5 * WALL_T - sim.state["scope"].x[:, 2].mean()
    expected = load / (len(under) * contact.held_stiffness)
    return RestingRod(Comparison("penetration F / (n k) of a rod resting on n wall nodes", expected, float(pen), "m"),
                      float(contact.normal_force), float(contact.force_on_rod[2]), int(contact.n_active), len(under),
                      float(np.max(np.abs(hist.total_energy_balance()))), float(hist.bodies["scope"]["external_work"][-1]),
                      float(hist.contacts[0]["energy"][-1]))


def tip_on_node(load=0.2) -> tuple[Comparison, int]:
    """A rod guided along its axis pressed tip-down on one wall node: penetration F / k.
    Returns the comparison and the number of active contacts (must be 1)."""
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
    return (Comparison("penetration F / k of the hemispherical tip on one node", load / contact.held_stiffness,
                       float(reach - (tip[2] - nodes[below, 2])), "m"), int(contact.n_active))


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
    """Pulled with half of mu N the rod creeps at the regularised stick speed."""
    s = friction_slide(0.5 * friction * normal, friction, normal)
    return Comparison("stick: creep speed v_reg F_t / (mu N) at F_t = mu N / 2", s.creep_speed, s.v5, "m/s")


def friction_sliding(friction=0.3, normal=1.0) -> tuple[Comparison, Comparison]:
    """Pulled with twice mu N the rod accelerates at (F_t - mu N) / M and friction dissipates
    mu N per unit slid distance."""
    ft = 2.0 * friction * normal
    s = friction_slide(ft, friction, normal)
    return (Comparison("slide: acceleration (F_t - mu N) / M at F_t = 2 mu N", (ft - friction * normal) / s.mass,
                       (s.v5 - s.v2) / s.interval, "m/s^2"),
            Comparison("slide: friction work mu N x slid distance", friction * normal * s.slid, s.dissipated, "J"))
