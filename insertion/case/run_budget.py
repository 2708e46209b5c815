"""How long an insertion will take, estimated before it starts.

An explicit solver takes steps no longer than the stable step of its stiffest, lightest part. A
wall material in the wrong unit (MPa written as Pa: 1e6 times too stiff) shrinks the step by
sqrt(1e6) = 1000, and a run of seconds becomes one of hours that looks like a hang.
:func:`estimate_run` builds the model (``colonsim.insertion.case.scenario.build_insertion``, ~0.1-0.5 s), reads
the solver's stable time step at the start and the push duration, and estimates the steps and
the wall time; :func:`check_run_budget` refuses a run over a step limit, naming the likely cause.

The estimate is of the start: contact later shortens the step a little (RSJ, D 36 mm, 13.3 mm
scope: 35,961 steps estimated, 41,326 taken), a run may end before the push does (the tip passed
the end), and the closing hold is counted at its shortest (``settle_s``; a run that takes long to
come to rest holds up to ``settle_max_s``), and so is the relax of RSF/THF (``relax_s``; held until
at rest it can last up to ``relax_max_s``). The push behind a held tip (``held_push_share``) is
counted from the pushed depth at which the tip would reach the exit along the centerline, without
its speed ramp.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from colonsim.errors import ColonsimError

DEFAULT_MAX_STEPS = 2_000_000  # 20-70 x a default run (28,000-99,000 steps, thesis sweep); ~15 min on one core
# Wall time of one solver step on one core, a + b * (nodes not held at the start: the scope's and
# the free wall's; a held wall costs next to nothing, docs/notes/2026-11-model-studies.md "Cost"), fitted to the 39 runs
# of the thesis sweep (2026-11-25, 2 workers on an idle 2-core machine, one Numba thread each):
# within 22 % for every run, 0.20 ms/step at 101 such nodes (fixed THF) to 0.62 at 4141 (THF);
# the count of all nodes was off by up to 135 %. Machines differ (the same runs have taken up to
# 3 times longer on other days): this sizes a run, it does not time it.
STEP_COST_S = (1.52e-4, 1.13e-7)
STIFF_RATIO = 100.0  # a wall this many times stiffer than the reference tissue is named as the cause


def human_duration(seconds: float) -> str:
    """``seconds`` in the largest unit that keeps the number readable (s, min, h, days, years)."""
    for unit, size in (("years", 365.25 * 86400), ("days", 86400), ("h", 3600), ("min", 60)):
        if seconds >= 2 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.2g} s"


@dataclass
class RunBudget:
    """The estimated cost of one insertion (at its start)."""

    case: object  # InsertionCase
    time_step_s: float  # the solver's step: safety factor x stable step
    limited_by: str  # the body with the smallest stable step (colon wall or scope)
    simulated_s: float  # duration of the push
    steps: float
    nodes: int  # the scope's and the wall's nodes not held at the start (what a step costs)
    wall_time_s: float
    wall_mu0_Pa: float
    reference_mu0_Pa: float

    def describe(self) -> str:
        return (f"about {self.steps:,.0f} time steps of {self.time_step_s:.3g} s for {self.simulated_s:.3g} s of push "
                f"(roughly {human_duration(self.wall_time_s)} on one core)")

    def likely_causes(self) -> list:
        """What in the case makes the run long, compared with the defaults (most likely first)."""
        from colonsim.insertion.case.scenario import InsertionCase

        default, case, causes = InsertionCase(), self.case, []
        ratio = self.wall_mu0_Pa / self.reference_mu0_Pa
        if self.limited_by == "colon" and ratio >= STIFF_RATIO:
            causes.append(f"the wall material is {ratio:.3g} times stiffer than the reference tissue (shear modulus "
                          f"{self.wall_mu0_Pa:.3g} Pa vs {self.reference_mu0_Pa:.3g} Pa): parameters in kPa or MPa "
                          "written as Pa?")
        if case.element_size_mm < 0.5 * default.element_size_mm:
            causes.append(f"the fine wall mesh (--element-size {case.element_size_mm:g} mm, default "
                          f"{default.element_size_mm:g})")
        if case.push_speed < 0.2 * default.push_speed:
            causes.append(f"the slow push ({case.push_speed:g} m/s, default {default.push_speed:g}) lasting "
                          f"{self.simulated_s:.3g} s")
        if case.time_step_factor < 0.5 * default.time_step_factor:
            causes.append(f"the small time step factor {case.time_step_factor:g} (default {default.time_step_factor:g})")
        if not causes:
            causes.append(f"the stiffness and mass of the {'colon wall' if self.limited_by == 'colon' else 'scope'}, "
                          "which set the stable time step")
        return causes


def estimate_run(case) -> RunBudget:
    """Build ``case``'s model and estimate its time step, steps and wall time (see module docstring)."""
    from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
    from colonsim.insertion.case.scenario import build_insertion

    model = build_insertion(case)
    solver = model.solver
    stable = {b.name: b.critical_time_step(solver.state[b.name].x) for b in solver.bodies}
    # the bounds' step (bodies and contact): a budget errs on the long side, and the global estimate's
    # power iteration is not run on a model that may be absurd (a wall 1e10 times too stiff)
    dt = solver.time_step_factor * solver.stable_time_step(bounds_only=True)
    if not (math.isfinite(dt) and dt > 0.0):
        raise ColonsimError(f"{case.segment} {case.scope}: no stable time step exists for this model ({dt!r} s); "
                            "check the wall material and mesh")
    duration = float(model.push.duration)
    if model.push.settle_start is not None:  # the closing hold at its shortest: most runs come to rest early
        duration -= case.settle_max_s - case.settle_s
    if model.resistance is not None:  # the push behind a held tip, from the exit (less the lead) on, is slower
        held = max(model.total_depth - model.geometry.exit_start + case.held_push_lead_mm * 1e-3, 0.0)
        duration += held / case.push_speed * (1.0 / case.held_push_share - 1.0)
    steps = duration / dt
    nodes = sum(len(solver.state[b.name].x) for b in solver.bodies) - len(model.fixed_nodes)
    a, b = STEP_COST_S
    return RunBudget(case=case, time_step_s=dt, limited_by=min(stable, key=stable.get), simulated_s=duration,
                     steps=steps, nodes=nodes, wall_time_s=steps * (a + b * nodes),
                     wall_mu0_Pa=model.shell.material.mu0, reference_mu0_Pa=load_material(REFERENCE_MATERIAL_PATH).mu0)


def check_run_budget(case, max_steps=DEFAULT_MAX_STEPS, option="--max-steps") -> RunBudget:
    """The estimate of ``case``; a :class:`ColonsimError` naming the likely cause when it needs
    more than ``max_steps`` time steps."""
    budget = estimate_run(case)
    if budget.steps > max_steps:
        raise ColonsimError(f"{case.segment} {case.scope}: {budget.describe()}, over the limit of {max_steps:,} steps; "
                            f"likely cause: {'; '.join(budget.likely_causes())}; if the run is meant to be this long, "
                            f"raise {option}")
    return budget


def check_sweep_budget(cases, max_steps=DEFAULT_MAX_STEPS, option="--max-steps"):
    """:func:`check_run_budget` of one case per wall material, the one on the finest mesh with
    the slowest push (the longest run of that material, as far as the inputs tell).

    Checking every case would build every model (~0.1-0.5 s each, minutes for a large sweep);
    the stiff-material slip this guards against shows in any case of that material."""
    by_material = {}
    for case in cases:
        longest = by_material.get(case.material)
        if longest is None or (case.element_size_mm, case.push_speed) < (longest.element_size_mm, longest.push_speed):
            by_material[case.material] = case
    for case in by_material.values():
        check_run_budget(case, max_steps, option)
