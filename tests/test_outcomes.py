"""Characteristic points and the quasi-static check on synthetic curves with known answers."""

import numpy as np
import pytest

from insertion.outcomes import characteristic_points, principal_stretches, quasi_static_fraction, sliding_kinetic_energy


def rsj_like(noise=0.0, seed=0):
    """A rise to A = 2 cm at t = 0.3, a dip to B = 1.2 cm at t = 0.5, a rise to C = 3.8 cm at 0.9."""
    t = np.linspace(0.0, 1.0, 501)
    u = np.interp(t, [0.0, 0.3, 0.5, 0.9, 1.0], [0.0, 0.02, 0.012, 0.038, 0.036])
    u = u + noise * np.random.default_rng(seed).standard_normal(t.size)
    return t, 0.6 * t, u


def test_points_a_b_c_found():
    t, z, u = rsj_like()
    p = characteristic_points(t, z, u)
    assert p["A"]["time_s"] == pytest.approx(0.3) and p["A"]["deformation_m"] == pytest.approx(0.02)
    assert p["B"]["time_s"] == pytest.approx(0.5) and p["B"]["deformation_m"] == pytest.approx(0.012)
    assert p["C"]["time_s"] == pytest.approx(0.9) and p["C"]["deformation_m"] == pytest.approx(0.038)
    assert p["C"]["depth_m"] == pytest.approx(0.54)


def test_recording_noise_is_not_taken_for_a():
    """Noise of 0.1 mm (0.3 % of the maximum) stays below the 5 % prominence threshold."""
    t, z, u = rsj_like(noise=1e-4)
    p = characteristic_points(t, z, u)
    assert p["A"]["time_s"] == pytest.approx(0.3, abs=0.02)
    assert p["C"]["time_s"] == pytest.approx(0.9, abs=0.02)


def test_monotone_curve_has_only_c():
    t = np.linspace(0, 1, 50)
    p = characteristic_points(t, t, t**2)
    assert p["A"] is None and p["B"] is None and p["C"]["time_s"] == pytest.approx(1.0)


def test_quasi_static_fraction():
    internal = np.r_[0.0, np.ones(9)]
    kinetic = np.r_[0.5, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.5, 0.5]
    # the first sample (no strain energy yet) is left out: 7 of the 9 others are below 10 %
    assert quasi_static_fraction(kinetic, internal) == pytest.approx(7 / 9)


def test_principal_stretch_of_a_stretched_and_rotated_triangle():
    from insertion.shell import reference_frames

    nodes = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    tri = np.array([[0, 1, 2]])
    dm_inv, _ = reference_frames(nodes, tri)
    stretch = np.diag([1.3, 0.9, 1.0])  # 1.3 along x, 0.9 along y
    c, s = np.cos(0.7), np.sin(0.7)
    rotation = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    x = nodes @ stretch.T @ rotation.T
    assert principal_stretches(x, tri, dm_inv)[0] == pytest.approx(1.3, rel=1e-12)


def test_sliding_kinetic_energy_removes_only_the_tank_tread_motion():
    # nodes on a quarter circle moving along the tangent at the push speed: nothing left
    phi = np.linspace(0.0, np.pi / 2, 40)
    x = np.column_stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)])
    tangent = np.column_stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
    mass = np.full(40, 0.01)
    assert sliding_kinetic_energy(x, 0.6 * tangent, mass, 0.6) == pytest.approx(0.0, abs=1e-5)  # one-sided ends
    # a sideways velocity w on top of the sliding: 1/2 m w^2 exactly
    w = np.array([0.0, 0.0, 0.2])
    assert sliding_kinetic_energy(x, 0.6 * tangent + w, mass, 0.6) == pytest.approx(0.5 * 0.4 * 0.04, rel=1e-3)
