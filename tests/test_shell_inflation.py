"""Inflation of a thin incompressible Mooney-Rivlin tube: the pressure load and the closed form.

The thin-wall closed form p(l) and the inscribed-polygon correction are derived in
:mod:`colonsim.insertion.study.verification_shell`; the inflated sections and the clamped tube
against it are rows of the verification table (tests/test_verification_table.py).
"""

import numpy as np
import pytest

from colonsim.insertion.study.verification import WALL_T, reference_material
from colonsim.insertion.study.verification_shell import TUBE_RADIUS, inflation_tube, thin_wall_pressure


def test_pressure_load_is_volume_gradient(serial_kernels):
    """On nodes away from the open ends the follower pressure load per pascal equals the gradient
    of ``enclosed_volume`` (what makes -p V the pressure's potential); central differences,
    tolerance 1e-6 of the largest load (round-off ~ 1e-16 V / 1e-7 m)."""
    shell, ring, _ = inflation_tube(0.02)
    x = np.ascontiguousarray(shell.x0 * [1.0, 1.1, 1.1] + 3e-4 * np.random.default_rng(2).standard_normal(shell.x0.shape))
    f = np.zeros_like(x)
    shell.pressure_forces(x, 1.0, f)
    inner = np.flatnonzero((ring > 0) & (ring < ring.max()))
    h = 1e-7
    for i in inner[::7]:
        for k in range(3):
            xp = x.copy()
            xp[i, k] += h
            xm = x.copy()
            xm[i, k] -= h
            grad = (shell.enclosed_volume(xp) - shell.enclosed_volume(xm)) / (2.0 * h)
            assert grad == pytest.approx(f[i, k], abs=1e-6 * np.max(np.abs(f)))


def test_thin_wall_pressure_is_laplace_law():
    """p r = sigma_theta t / l with the plane-stress hoop stress sigma_theta = l dW/dl of the
    strain energy W(l) = (C10 + C01)(I - 3) + C11 (I - 3)^2, I = l^2 + 1 + l^-2 (central
    differences of W; 1e-7 relative)."""
    c = reference_material().named_parameters

    def energy(l):
        i = l**2 + 1 + l**-2
        return (c["C10"] + c["C01"]) * (i - 3) + c["C11"] * (i - 3) ** 2

    for l in (1.05, 1.3, 1.6):
        h = 1e-6
        sigma = l * (energy(l + h) - energy(l - h)) / (2 * h)
        assert thin_wall_pressure(l) * l * TUBE_RADIUS == pytest.approx(sigma * WALL_T / l, rel=1e-7)
