"""The closed forms of dynamic Euler buckling (a clamped-free rod under a dead axial load just
below and just above pi^2 EI / (4 L^2)); the dynamic runs are rows of the verification table."""

import math

import pytest

from colonsim.insertion.study.verification_rod import beam_column_tip_deflection, elastica_tip_deflection


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
