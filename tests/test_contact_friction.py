"""Regularised Coulomb friction: a rod on a wall sticks below mu N and slides above it
(the problem is built in :func:`colonsim.insertion.study.verification.friction_slide`)."""

import pytest

from colonsim.insertion.study.verification import friction_slide

MU = 0.3
N = 1.0  # total normal load, N


def test_sticks_below_mu_n():
    # Below mu N the regularised law holds the rod at the creep speed v_reg F_t / (mu N)
    # (reached after M v_reg / (mu N) = 0.07 ms). Tolerance 1 %: the creep is steady, the only
    # deviation is the O(mu f_n dt / m) lag of the explicit viscous update.
    s = friction_slide(0.5 * MU * N, MU, N)
    assert s.v5 == pytest.approx(s.creep_speed, rel=0.01)
    assert s.v2 == pytest.approx(s.creep_speed, rel=0.01)
    assert s.slid < 1.1 * s.creep_speed * 5e-3  # a few micrometres: stuck for practical purposes


def test_slides_above_mu_n():
    # Above mu N the rod accelerates at (F_t - mu N) / M and friction dissipates mu N per unit
    # slid distance. Tolerance 1 %: friction is saturated once |v| > v_reg (after ~0.1 ms, before
    # the 2 ms measuring start), the normal force stays N to 1e-4 and the part of the slide below
    # v_reg is ~1e-8 m of 2e-4 m.
    ft = 2.0 * MU * N
    s = friction_slide(ft, MU, N)
    assert (s.v5 - s.v2) / s.interval == pytest.approx((ft - MU * N) / s.mass, rel=0.01)
    assert s.dissipated == pytest.approx(MU * N * s.slid, rel=0.01)
