"""Dynamic Euler buckling: a clamped-free rod under a dead axial load just below and just above
pi^2 EI / (4 L^2) (the load-deflection counterpart of the tangent-stiffness test)."""

import math
import os

import numpy as np
import pytest

from insertion.solver import ExplicitSolver, FixedNodes, NodalLoad
from test_rod_beam import RHO, cantilever

FULL = os.environ.get("COLONSIM_FULL") == "1"


def tip_deflection(load_ratio, length, spacing):
    """Lateral tip deflection / L after relaxing under P = load_ratio * P_Euler plus a lateral
    imperfection load of 1e-3 P."""
    rod = cantilever(length, spacing)
    EI = rod.flexural_rigidity
    p_euler = math.pi**2 * EI / (4.0 * length**2)
    P = load_ratio * p_euler
    omega1 = 1.875**2 * math.sqrt(EI / (RHO * rod.area * length**4))
    sim = ExplicitSolver(
        [rod],
        constraints=[FixedNodes(rod, [0, 1])],
        loads=[NodalLoad(rod, [rod.tip_node], (-P, 1e-3 * P, 0.0))],
        damping=0.5 * omega1,
    )
    sim.run(120.0 / omega1, record_interval=1.0)
    return sim.state["scope"].x[rod.tip_node, 1] / length


@pytest.mark.slow
def test_buckles_within_five_percent_of_euler_load():
    # 5 % below the Euler load the straight rod is stable: the imperfection's linear tip
    # deflection (1e-3 pi^2/12 L = 8e-4 L) is amplified about 1 / (1 - 0.95) = 20 times, to
    # ~0.02 L (bound 0.03 L). 5 % above, it buckles: the elastica at P / P_cr = 1.05 has a tip
    # rotation of ~0.6 rad and a lateral tip deflection of ~0.35 L (bound 0.15 L). Reduced size:
    # 15 cm rod with 20 segments (the discrete critical load is within 0.1 % of Euler's).
    length, spacing = (0.3, 0.01) if FULL else (0.15, 0.0075)
    below = tip_deflection(0.95, length, spacing)
    above = tip_deflection(1.05, length, spacing)
    assert 0.0 < below < 0.03
    assert above > 0.15
