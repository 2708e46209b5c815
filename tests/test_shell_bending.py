"""Hinge bending of the shell against plate theory.

A flat near-equilateral sheet (built, with the maps, in
:mod:`colonsim.insertion.study.verification_shell`) is mapped isometrically onto a cylinder of
radius R: the hinge energy per unit area must be the plate value D / (2 R^2) with D = E0 t^3 / 9
(nu = 1/2), whatever the cylinder's direction relative to the mesh. The interior density on
cylinders and on a sphere are rows of the verification table (tests/test_verification_table.py);
here the stiffness, the whole sheet with its edges and the forces.
"""

import numpy as np
import pytest
from shell_reference import bending_forces

from colonsim.insertion.engine.sheet_mesh import straight_tube
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.study.verification import WALL_T, reference_material
from colonsim.insertion.study.verification_shell import bending_sheet, onto_cylinder

MATERIAL = reference_material()
THICKNESS = WALL_T


def _bending(shell, x):
    f = np.zeros_like(x)
    return bending_forces(shell, x, f), f


def test_bending_stiffness_is_plate_value():
    assert bending_sheet().bending_stiffness == pytest.approx(MATERIAL.E0 * THICKNESS**3 / (12 * (1 - 0.25)), rel=1e-12)


def test_whole_sheet_cylinder_energy():
    """The total hinge energy of the whole sheet, edges included, over the hinge area is the plate
    value within 3 % (measured <= 2.8 % for h/side = 1/20: boundary rows, O(h / side))."""
    shell = bending_sheet()
    nodes, hinge = shell.x0, shell.hinges
    edge = nodes[hinge[:, 1]] - nodes[hinge[:, 0]]
    hinge_area = (
        np.linalg.norm(np.cross(edge, nodes[hinge[:, 2]] - nodes[hinge[:, 0]]), axis=1)
        + np.linalg.norm(np.cross(nodes[hinge[:, 3]] - nodes[hinge[:, 0]], edge), axis=1)
    ).sum() / 6.0
    radius = 0.05
    for angle in np.radians([0, 30, 45, 90]):
        energy, _ = _bending(shell, onto_cylinder(nodes, radius, angle))
        assert energy == pytest.approx(shell.bending_stiffness / (2 * radius**2) * hinge_area, rel=3e-2)


def test_hinge_forces_are_minus_energy_gradient(serial_kernels, energy_gradient):
    """Central differences of the hinge energy on a randomly perturbed tube (curved reference,
    theta0 != 0); step 1e-7 m, tolerance 1e-6 of the largest force (measured ~1e-9)."""
    nodes, tri, _ = straight_tube(0.03, 0.02, 0.006)
    shell = Shell(nodes, tri, THICKNESS, MATERIAL)
    e0, f0 = _bending(shell, shell.x0)
    assert e0 == pytest.approx(0.0, abs=1e-20) and np.max(np.abs(f0)) < 1e-15
    x = nodes + 5e-4 * np.random.default_rng(3).standard_normal(nodes.shape)
    _, f = _bending(shell, x)
    fd = -energy_gradient(lambda y: _bending(shell, y)[0], x, h=1e-7)
    assert np.max(np.abs(fd - f)) < 1e-6 * np.max(np.abs(f))
