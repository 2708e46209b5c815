"""Dynamic Euler buckling: a clamped-free rod under a dead axial load just below and just above
pi^2 EI / (4 L^2) (the load-deflection counterpart of the tangent-stiffness test)."""

import math
import os

import pytest

from colonsim.insertion.study.verification import beam_column_tip_deflection, buckling_tip_deflection, elastica_tip_deflection

FULL = os.environ.get("COLONSIM_FULL") == "1"


@pytest.mark.slow
def test_buckles_within_five_percent_of_euler_load():
    # 5 % below the Euler load the straight rod is stable: the imperfection's linear tip
    # deflection (1e-3 pi^2/12 L = 8e-4 L) is amplified about 1 / (1 - 0.95) = 20 times, to
    # ~0.02 L (bound 0.03 L). 5 % above, it buckles: the elastica at P / P_cr = 1.05 has a tip
    # rotation of ~0.6 rad and a lateral tip deflection of ~0.35 L (bound 0.15 L). Reduced size:
    # 15 cm rod with 20 segments (the discrete critical load is within 0.1 % of Euler's).
    length, spacing = (0.3, 0.01) if FULL else (0.15, 0.0075)
    below = buckling_tip_deflection(0.95, length, spacing)
    above = buckling_tip_deflection(1.05, length, spacing)
    assert 0.0 < below < 0.03
    assert above > 0.15


def test_closed_forms_of_the_buckling_figure():
    """The curves the validation report draws the dynamic runs against: linear beam-column
    theory tends to the unamplified cantilever deflection (1e-3 pi^2/12 at small loads) and
    diverges at the Euler load; the elastica starts at zero and gives 2 p / K(p)."""
    unamplified = 1e-3 * math.pi**2 / 12  # Q L^3 / (3 EI) / L per unit load ratio, Q = 1e-3 P
    assert beam_column_tip_deflection(1e-6) == pytest.approx(1e-6 * unamplified, rel=1e-4)
    # Timoshenko's amplification 1 / (1 - P / P_cr) holds to a few percent (1.3 % here)
    assert beam_column_tip_deflection(0.95) == pytest.approx(0.95 * unamplified / 0.05, rel=0.03)
    assert beam_column_tip_deflection(0.999) > 100 * beam_column_tip_deflection(0.5)
    assert elastica_tip_deflection(1.0) == 0.0
    # small post-buckling: P / P_cr = 1 + p^2 / 2 + ..., tip deflection 2 p / K(p) ~ 4 p / pi
    ratio = 1.0 + 0.5 * 0.05**2
    assert elastica_tip_deflection(ratio) == pytest.approx(4 * 0.05 / math.pi, rel=0.01)
    assert 0.3 < elastica_tip_deflection(1.05) < 0.45
