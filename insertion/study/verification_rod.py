"""Verification problems of the rod (the scope) against beam theory: a cantilever's tip
deflection, the Euler buckling load, buckling under a dead load and axial waves. SI units.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipk

from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.constraints import FixedNodes, NodalLoad, PrescribedVelocity
from colonsim.insertion.engine.solver import ExplicitSolver
from colonsim.insertion.study.verification import SCOPE_D, SCOPE_E, SCOPE_RHO, Comparison

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


def first_mode(rod, length):
    """Angular frequency of the first bending mode of a clamped-free rod of ``length``, rad/s."""
    return 1.875**2 * math.sqrt(rod.flexural_rigidity / (SCOPE_RHO * rod.area * length**4))


def cantilever_tip_deflection(length=0.3, spacing=0.01, deflection_ratio=0.005) -> Comparison:
    """Static tip deflection under a tip load P = 3 EI delta / L^3 (beam theory: delta), by
    dynamic relaxation (critical damping of the first mode, 16 time constants)."""
    rod = cantilever(length, spacing)
    EI = rod.flexural_rigidity
    delta = deflection_ratio * length
    P = 3.0 * EI * delta / length**3
    omega1 = first_mode(rod, length)
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
    omega1 = first_mode(rod, length)
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


def buckling_check(load_ratio, length, spacing) -> Comparison:
    """Tip deflection / L of :func:`buckling_tip_deflection` against linear beam-column theory below
    the Euler load and the perfect elastica above it."""
    theory, name = ((beam_column_tip_deflection(load_ratio), "beam-column theory") if load_ratio < 1.0
                    else (elastica_tip_deflection(load_ratio), "elastica"))
    return Comparison(f"tip deflection / L at P = {load_ratio:g} P_E (L = {length * 100:g} cm), {name}", theory,
                      buckling_tip_deflection(load_ratio, length, spacing))


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

