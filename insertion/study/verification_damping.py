"""Verification problems of the quasi-static devices (docs/model.md, "Time integration and
damping"): the scope's implicit damping against the decay rates of damped free vibration, a
sliding scope that the damping must not drag, and the sheath's lip against a cantilever. SI units.
"""

from __future__ import annotations

import math

import numpy as np

from colonsim.insertion.engine.constraints import FixedNodes, LineConstraint, NodalLoad, PrescribedVelocity
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.sheath_lip import SheathLip
from colonsim.insertion.engine.solver import ExplicitSolver
from colonsim.insertion.study.verification import SCOPE_D, SCOPE_E, SCOPE_RHO, Comparison
from colonsim.insertion.study.verification_rod import cantilever, first_mode


def _damping_ratio_from_peaks(signal) -> float:
    """Damping ratio from the logarithmic decrement between the first and the last positive peaks
    of a decaying oscillation sampled every step: delta = ln(a_0 / a_k) / k = 2 pi z / sqrt(1 - z^2)."""
    s = np.asarray(signal)
    peaks = [i for i in range(1, len(s) - 1) if s[i] > s[i - 1] and s[i] >= s[i + 1] and s[i] > 0.0]
    if len(peaks) < 3:
        raise RuntimeError("fewer than three peaks: the record is too short for a decrement")
    delta = math.log(s[peaks[0]] / s[peaks[-1]]) / (len(peaks) - 1)
    return delta / math.sqrt(4.0 * math.pi**2 + delta**2)


def axial_damping_decay(length=0.3, spacing=0.01, damping_time=2e-4) -> Comparison:
    """Free axial vibration of a fixed-free rod with Kelvin-Voigt axial dashpots tau EA / L0:
    the damping matrix is tau times the axial stiffness, so each axial mode decays with the
    damping ratio tau omega / 2, omega its undamped frequency (here the discrete chain's lowest,
    from its eigenvalues). The rod starts in that mode; the ratio is read from the logarithmic
    decrement of the tip's axial displacement."""
    rod = Rod.straight(length, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=spacing, damping_time=damping_time)
    n = rod.n_nodes
    k = rod.axial_stiffness
    stiffness = np.zeros((n - 1, n - 1))  # free nodes 1..n-1, node 0 fixed
    for e in range(n - 1):
        for a in (e, e + 1):
            for b in (e, e + 1):
                if a > 0 and b > 0:
                    stiffness[a - 1, b - 1] += k[e] * (1.0 if a == b else -1.0)
    m = rod.mass[1:]
    w2, modes = np.linalg.eigh(stiffness / np.sqrt(np.outer(m, m)))
    omega = math.sqrt(w2[0])
    shape = modes[:, 0] / np.sqrt(m)
    amplitude = 1e-4 * length / np.abs(shape).max()
    sim = ExplicitSolver([rod], constraints=[FixedNodes(rod, [0])], time_step_factor=0.5)
    x0 = rod.x0
    sim.state[rod.name].x[1:, 0] += amplitude * shape  # displaced in the mode, at rest
    tip = []
    period = 2.0 * math.pi / omega
    while sim.time < 6.0 * period:
        sim.advance()
        tip.append(sim.state["scope"].x[rod.tip_node, 0] - x0[rod.tip_node, 0])
    return Comparison("axial Kelvin-Voigt damping: damping ratio tau omega / 2 of the first axial mode",
                      0.5 * damping_time * omega, _damping_ratio_from_peaks(tip), "",
                      extra={"omega_rad_s": omega, "omega_dt": omega * sim.dt})


def lateral_damping_decay(length=0.3, spacing=0.01, ratio=0.05) -> Comparison:
    """Free bending vibration of a cantilever with lateral damping alpha (mass-proportional across
    the rod): a straight rod's bending modes move across it only, so every mode's amplitude decays
    as exp(-alpha t / 2), and the first mode's damping ratio is alpha / (2 omega_1), omega_1 the
    cantilever's first frequency. Started with the beam's first mode shape as velocity."""
    probe = cantilever(length, spacing)
    omega = first_mode(probe, length)
    alpha = 2.0 * ratio * omega
    rod = Rod(probe.x0, SCOPE_D, SCOPE_E, SCOPE_RHO, lateral_damping=alpha)
    s = np.clip(rod.x0[:, 0], 0.0, None) / length
    b, sigma = 1.875104, 0.734096  # the clamped-free beam's first mode
    shape = np.cosh(b * s) - np.cos(b * s) - sigma * (np.sinh(b * s) - np.sin(b * s))
    velocity = np.zeros_like(rod.x0)
    velocity[:, 2] = 1e-3 * length * omega * shape / np.abs(shape).max()
    sim = ExplicitSolver([rod], constraints=[FixedNodes(rod, [0, 1])], initial_velocity={rod.name: velocity})
    tip = []
    while sim.time < 8.0 * 2.0 * math.pi / omega:
        sim.advance()
        tip.append(sim.state[rod.name].x[rod.tip_node, 2])
    return Comparison("lateral damping: damping ratio alpha / (2 omega_1) of the cantilever's first mode", ratio,
                      _damping_ratio_from_peaks(tip), "", extra={"alpha_per_s": alpha})


def sliding_push_force(length=0.5, spacing=5e-3, speed=0.3, ramp=0.2) -> tuple[Comparison, Comparison]:
    """A scope pushed through a straight rigid sheath along its whole length, with the insertion's
    damping (axial dashpots, lateral damping, no mass damping) and speed ramp: the drive needs
    the force that accelerates the rod's mass during the (1 - cos) ramp, M pi v / (2 T) at its
    middle (the ramp is 40 times the rod's first axial period: the rod follows as a rigid body,
    within the ramp's inertial wave), and none at the constant speed after it (the damping
    resists strain rate and motion across the rod, neither of which a sliding rod has)."""
    from colonsim.insertion.case.insertion_case import InsertionCase

    defaults = InsertionCase()
    rod = Rod.straight(length, SCOPE_D, SCOPE_E, SCOPE_RHO, spacing=spacing,
                       damping_time=defaults.scope_axial_damping_s, lateral_damping=defaults.scope_lateral_damping)
    drive = PrescribedVelocity(rod, [0], (speed, 0.0, 0.0), ramp=ramp)
    sheath = LineConstraint(rod, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    sim = ExplicitSolver([rod], constraints=[drive, sheath], damping=defaults.scope_damping)
    at_mid = None
    plateau = []
    while sim.time < 2.0 * ramp:
        sim.advance()
        if at_mid is None and sim.time >= 0.5 * ramp:
            at_mid = drive.reaction[0]
        if sim.time > 1.25 * ramp:
            plateau.append(abs(drive.reaction[0]))
    mass = rod.mass.sum()
    return (Comparison("push force at the middle of the ramp, M pi v / (2 T)", mass * math.pi * speed / (2.0 * ramp),
                       float(at_mid), "N"),
            Comparison("push force at constant speed (no drag)", 0.0, float(max(plateau)), "N"))


def lip_cantilever(length=0.15, spacing=5e-3, positions=5) -> tuple[Comparison, Comparison]:
    """A scope held in a sheath and bent by a tip load P: a cantilever clamped at the sheath's lip,
    tip deflection P L^3 / (3 EI) with L from the lip to the tip. The lip is put at ``positions``
    places between two nodes. A discrete rod cannot bend inside a segment, so its clamp sits
    between the lip and the last node behind it (up to one node spacing h further back: a
    deflection up to 3 h / L larger); what the lip must give is a deflection that changes little
    as the lip moves between nodes, as the scope's advance moves it. Returns the mean deflection
    ratio (measured / beam) and the spread of the ratio over the lip positions (for the sheath
    held node by node, in ``extra``)."""
    ratios = {"lip": [], "nodes": []}
    for offset in np.linspace(0.0, spacing, positions, endpoint=False):
        n = int(round((length + 0.1) / spacing))
        x = length - spacing * np.arange(n + 1)[::-1]
        nodes = np.column_stack((x, np.zeros_like(x), np.zeros_like(x)))
        lip = -offset
        for mode in ratios:
            rod = Rod(nodes, SCOPE_D, SCOPE_E, SCOPE_RHO)
            EI = rod.flexural_rigidity
            free = length - lip
            P = 3.0 * EI * 0.005 * free / free**3  # a tip deflection of 0.5 % of the free length
            omega = 1.875**2 * math.sqrt(EI / (SCOPE_RHO * rod.area * free**4))
            constraints = [PrescribedVelocity(rod, [0], (0.0, 0.0, 0.0)),
                           LineConstraint(rod, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), extent=(-math.inf, lip))]
            contacts = [SheathLip(rod, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), lip)] if mode == "lip" else []
            sim = ExplicitSolver([rod], contacts=contacts, constraints=constraints,
                                 loads=[NodalLoad(rod, [rod.tip_node], (0.0, 0.0, -P))], damping=2.0 * omega)
            sim.run(16.0 / omega, record_interval=1.0, exact_end=False)
            deflection = -sim.state[rod.name].x[rod.tip_node, 2]
            ratios[mode].append(deflection / (P * free**3 / (3.0 * EI)))
    lip, held = np.array(ratios["lip"]), np.array(ratios["nodes"])
    return (Comparison("tip deflection of a scope bent out of the sheath's lip / P L^3 (3 EI)", 1.0, float(lip.mean()),
                       extra={"bound": 1.0 + 3.0 * spacing / length}),
            Comparison("spread of that ratio over lip positions between two nodes", 0.0, float(lip.max() - lip.min()),
                       extra={"node_by_node": float(held.max() - held.min())}))
