"""Inflation of a thin incompressible Mooney-Rivlin tube against thin-wall theory.

Closed form (axial stretch held at 1, i.e. ends fixed axially: plane strain along the tube).
A tube of mid-surface radius R and wall thickness t inflates to radius r = l R. The principal
stretches are l (hoop), 1 (axial) and 1/l (thickness), so I1 = I2 = I = l^2 + 1 + l^-2 and
W(l) = (C10 + C01)(I - 3) + C11 (I - 3)^2. Per unit length the strain energy is 2 pi R t W(l) and
the enclosed volume pi R^2 l^2; equilibrium p dV = dE gives

    p(l) = t W'(l) / (l R) = (2 t / R) (1 - l^-4) [C10 + C01 + 2 C11 (l^2 + l^-2 - 2)],

the same as Laplace's law p r = sigma_theta t / l with the plane-stress Cauchy hoop stress
sigma_theta = l W'(l).

Discrete correction (exact, not fitted): the mesh's rings are m-gons inscribed in the circle. Under
uniform inflation each triangle's hoop stretch is exactly l, but the reference area is the
polygon's (perimeter 2 m R sin(pi/m)) and so is the volume ((m/2) r^2 sin(2 pi/m) per length), so
the discrete relation is p(l) / cos(pi / m) (+0.34 % for m = 38).
"""

import os

import numpy as np
import pytest

from colonsim.insertion.study.verification import (TUBE_RADIUS, WALL_T, inflate_clamped_tube, inflate_section, inflation_tube,
                                    reference_material, thin_wall_pressure)

FULL = os.environ.get("COLONSIM_FULL") == "1"


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


@pytest.mark.parametrize("stretch", [1.05, 1.2, 1.4, 1.6])
def test_plane_strain_section_follows_thin_wall_theory(stretch, serial_kernels):
    """A tube section with every node's axial coordinate fixed (axial stretch 1, ends free to
    expand: a periodic slice of an infinitely long tube) under p(l) / cos(pi/m).

    Static solve of the membrane + hinge energy minus p V. The section must expand uniformly to
    l within 1e-3 (measured: 3e-5 at l = 1.05 up to 3.5e-4 at l = 1.6, the remainder from the
    ring-to-ring triangles tilting slightly out of the hoop plane; hinges stay unbent under
    uniform inflation because the dihedral angles of the inscribed polygon do not change).
    """
    stretch_check, spread = inflate_section(stretch)
    assert stretch_check.measured == pytest.approx(stretch, rel=1e-3)
    assert spread < 1e-3


@pytest.mark.slow
def test_tube_with_fixed_ends_follows_thin_wall_theory_in_the_middle():
    """A tube with both end rings clamped and every axial coordinate fixed; away from the ends
    the wall must reach the plane-strain thin-wall stretch. The clamped rings hold the wall back
    over a boundary layer a few radii long, so the middle ring is checked: reduced size L = 6 R at
    l = 1.2, full size L = 10 R at l = 1.1, 1.2, 1.3, both to 1e-3 on the stretch (measured
    5e-5 reduced, at most 1e-4 full).
    """
    checks = inflate_clamped_tube((1.1, 1.2, 1.3) if FULL else (1.2,), 10.0 if FULL else 6.0)
    for c in checks:
        assert c.measured == pytest.approx(c.analytic, rel=1e-3)


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
