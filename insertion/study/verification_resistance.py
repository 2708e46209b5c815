"""Verification problems of the distal resistance (docs/model.md, "Loading"): a scope pushed out
of its sheath against a resisted tip, below and above the Euler load of its free span, and the
creep of a tip loaded below the resistance. SI units.

The scope leaves a rigid sheath (its nodes behind the lip held on the axis, the lip's support
where it leaves: the insertion's own) into a free span of length ``L`` whose tip is resisted
along the axis, a dead load in a fixed direction like the lumen's. Until the push force reaches
the resistance the tip is held (it creeps at the regularisation speed), so the span is a column
clamped at the lip and loaded at its free tip: below its Euler load ``pi^2 EI / (4 L^2)`` the
push force rises to the resistance and the scope slides straight; above it, the span buckles at
that load. A lateral imperfection load of 1e-3 times the resistance gives the buckle its side. The span's
lateral damping is critical for its first bending mode (the insertion's 200 1/s, meant for the
colon's spans of a few centimetres between contacts, would make a free 15 cm span relax over
seconds, and the test would measure that delay instead of the load).
A straight tube around the span would first be touched after the onset (the clearance of a
12.8 mm scope in a 36 mm lumen is 8 % of a 15 cm span; the onset is at 1 %), so the span is left free: the onset is
what is checked; contact after it is the contact rows' subject.
"""

from __future__ import annotations

import math

import numpy as np

from colonsim.insertion.engine.constraints import LineConstraint, NodalLoad, PrescribedVelocity
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.sheath_lip import SheathLip
from colonsim.insertion.engine.solver import ExplicitSolver
from colonsim.insertion.engine.tip_resistance import TipResistance
from colonsim.insertion.study.verification import SCOPE_D, SCOPE_E, SCOPE_RHO, Comparison

SHEATH = 0.1  # m of scope inside the sheath at the start
SPEED = 2e-3  # m/s: the push, slow against the span's bending (a period of 0.17 s at L = 15 cm)
RAMP = 0.05  # s
CREEP_SHARE = 0.01  # creep speed / push speed, as in the insertion


def _scope(length, spacing, lateral_damping=None):
    """Scope with the insertion's axial damping, its tip at x = length (the lip at x = 0), and a
    lateral damping critical for the first bending mode of the span (None: that value)."""
    from colonsim.insertion.case.insertion_case import InsertionCase

    n = int(round((length + SHEATH) / spacing))
    x = length - spacing * np.arange(n + 1)[::-1]
    nodes = np.column_stack((x, np.zeros_like(x), np.zeros_like(x)))
    probe = Rod(nodes, SCOPE_D, SCOPE_E, SCOPE_RHO)
    if lateral_damping is None:
        lateral_damping = 2.0 * 1.875**2 * math.sqrt(probe.flexural_rigidity / (SCOPE_RHO * probe.area * length**4))
    return Rod(nodes, SCOPE_D, SCOPE_E, SCOPE_RHO, damping_time=InsertionCase().scope_axial_damping_s,
               lateral_damping=lateral_damping)


def euler_span_load(rod, length) -> float:
    """Euler load of a span ``length`` clamped at one end, loaded at the free one, N."""
    return math.pi**2 * rod.flexural_rigidity / (4.0 * length**2)


def resisted_push(load_ratio, length=0.15, spacing=5e-3, push=1e-3) -> dict:
    """Push the scope ``push`` (m) out of the sheath against a tip resistance ``load_ratio`` times
    the Euler load of its initial span. Returns the resistance and Euler load (N), the mean push
    force over the last fifth of the push (N), the tip's lateral deflection / L and its advance (m)."""
    rod = _scope(length, spacing)
    p_euler = euler_span_load(rod, length)
    resistance = load_ratio * p_euler
    axis = np.array([1.0, 0.0, 0.0])
    tip = rod.tip_node
    resisted = TipResistance(rod, tip, axis, resistance, creep_speed=CREEP_SHARE * SPEED)
    drive = PrescribedVelocity(rod, [0], SPEED * axis, ramp=RAMP)
    sheath = LineConstraint(rod, (0.0, 0.0, 0.0), axis, extent=(-math.inf, 0.0))
    lip = SheathLip(rod, (0.0, 0.0, 0.0), axis, 0.0)
    imperfection = NodalLoad(rod, [tip], (0.0, 1e-3 * resistance, 0.0))
    sim = ExplicitSolver([rod], contacts=[lip], constraints=[drive, sheath], loads=[imperfection],
                         resistances=[resisted])
    duration = RAMP / 2 + push / SPEED
    force, deflection = [], 0.0
    while sim.time < duration:
        sim.advance()
        if sim.time > RAMP / 2 + 0.8 * push / SPEED:
            force.append(drive.reaction[0])
    x = sim.state[rod.name].x
    deflection = float(np.hypot(x[tip, 1], x[tip, 2]) / length)
    return {"resistance_N": resistance, "euler_N": p_euler, "push_N": float(np.mean(force)),
            "deflection": deflection, "advance_m": float(x[tip, 0] - rod.x0[tip, 0]),
            "resisting_N": float(resisted.force)}


def below_euler(load_ratio=0.5, length=0.15, spacing=5e-3) -> tuple[Comparison, Comparison]:
    """Below the Euler load: push force against the resistance, and the tip deflection against
    linear beam-column theory for the imperfection, Q (tan kL - kL) / (P k L)."""
    r = resisted_push(load_ratio, length, spacing)
    kl = 0.5 * math.pi * math.sqrt(load_ratio)
    straight = 1e-3 * (math.tan(kl) - kl) / kl
    extra = {"advance_m": r["advance_m"], "euler_N": r["euler_N"]}
    return (Comparison(f"push force against a tip resistance of {load_ratio:g} P_E", r["resistance_N"], r["push_N"],
                       "N", extra=extra),
            Comparison("tip deflection / L (beam-column theory, imperfection 1e-3)", straight, r["deflection"], "",
                       extra=extra))


def above_euler(load_ratio=2.0, length=0.15, spacing=5e-3) -> Comparison:
    """Above the Euler load: the push force where the held span has buckled, against the Euler load
    (the elastica's load rises by under 0.1 % up to a deflection of 5 % of L)."""
    r = resisted_push(load_ratio, length, spacing)
    return Comparison(f"push force of a span buckling under a tip resistance of {load_ratio:g} P_E, "
                      "pi^2 EI / (4 L^2)", r["euler_N"], r["push_N"], "N",
                      extra={"deflection": r["deflection"], "advance_m": r["advance_m"],
                             "resistance_N": r["resistance_N"], "node_spacing_over_L": spacing / length})


def creep(length=0.3, spacing=5e-3, resistance=5.0, creep_speed=3e-3, load_share=0.5, duration=0.1) -> Comparison:
    """A free scope pushed along its axis by a load of ``load_share`` times its tip's resistance:
    under the regularised law it creeps at ``load_share`` times the creep speed (mean over the
    last half of the run)."""
    rod = _scope(length, spacing)
    axis = np.array([1.0, 0.0, 0.0])
    tip = rod.tip_node
    resisted = TipResistance(rod, tip, axis, resistance, creep_speed=creep_speed)
    sim = ExplicitSolver([rod], loads=[NodalLoad(rod, [0], load_share * resistance * axis)], resistances=[resisted])
    speed = []
    while sim.time < duration:
        sim.advance()
        if sim.time > 0.5 * duration:
            speed.append(sim.state[rod.name].v[tip, 0])
    return Comparison(f"creep speed of a tip loaded at {load_share:g} of its resistance, {load_share:g} v_c",
                      load_share * creep_speed, float(np.mean(speed)), "m/s")
