"""Membrane of the shell: forces are the energy gradient, and homogeneous uniaxial tension of a
flat triangulated sheet reproduces the closed-form incompressible Mooney-Rivlin nominal stress."""

import numpy as np
import pytest

from shell_reference import membrane_forces

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, WallMaterial, load_material
from colonsim.insertion.engine.sheet_mesh import flat_sheet
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.statics import minimize_energy

REFERENCE = load_material(REFERENCE_MATERIAL_PATH)
MATERIALS = {
    "reference": REFERENCE,
    "neo_hookean": WallMaterial("neo_hookean", (20e3,)),
    "mooney_rivlin_2": WallMaterial("mooney_rivlin_2", (15e3, 5e3)),
}
LENGTH, WIDTH, THICKNESS, H = 0.10, 0.025, 0.002, 0.005


def _sheet(material):
    nodes, tri = flat_sheet(LENGTH, WIDTH, H)
    return Shell(nodes, tri, THICKNESS, material)


def _membrane(shell, x):
    f = np.zeros_like(x)
    energy = membrane_forces(shell, x, f)
    return energy, f


def test_membrane_forces_are_minus_energy_gradient(serial_kernels, energy_gradient):
    """Central differences of the energy on a randomly deformed sheet (strains up to ~30 %).

    Step 1e-7 m: truncation error ~ h^2 |E'''| and round-off ~ 1e-16 E / h are both far below
    1e-6 of the largest force, the tolerance (measured: ~1e-8).
    """
    shell = _sheet(REFERENCE)
    rng = np.random.default_rng(1)
    x = shell.x0 * [1.2, 0.9, 1.0] + 4e-4 * rng.standard_normal(shell.x0.shape)
    _, f = _membrane(shell, x)
    fd = -energy_gradient(lambda y: _membrane(shell, y)[0], x, h=1e-7)
    assert np.max(np.abs(fd - f)) < 1e-6 * np.max(np.abs(f))


def _rotation(seed):
    q, _ = np.linalg.qr(np.random.default_rng(seed).standard_normal((3, 3)))
    return q * np.sign(np.linalg.det(q))


@pytest.mark.parametrize("name", sorted(MATERIALS))
@pytest.mark.parametrize("rotated", [False, True])
def test_uniaxial_stretch_matches_closed_form(name, rotated):
    """Impose the homogeneous incompressible uniaxial state (stretch l along x, 1/sqrt(l) across)
    on every node and read the reactions.

    Constant-strain triangles represent a homogeneous deformation exactly, so the closed form must
    hold to round-off: the axial grip force equals P(l) W t with P from
    ``colonsim.laws.Law.uniaxial_nominal_stress`` (independent code), every node off the grips is in
    equilibrium, and no node carries a lateral force (plane stress, free lateral contraction), all
    to 1e-9 of the grip force; the energy equals W(l) L W t. ``rotated`` puts the sheet at an
    arbitrary orientation in space (frame invariance).
    """
    material = MATERIALS[name]
    law, params = material.law_model, material.parameters
    shell = _sheet(material)
    q = _rotation(7) if rotated else np.eye(3)
    shell_r = Shell(shell.x0 @ q.T, shell.triangles, THICKNESS, material)
    grip = np.isclose(shell.x0[:, 0], LENGTH)
    fixed = np.isclose(shell.x0[:, 0], 0.0)
    others = ~(grip | fixed)
    for stretch in (1.05, 1.2, 1.4, 1.6):
        x = shell.x0 * [stretch, stretch**-0.5, 1.0]
        energy, f = _membrane(shell_r, np.ascontiguousarray(x @ q.T))
        f = f @ q  # back to the sheet's own axes
        force = -f[grip, 0].sum()
        expected = law.uniaxial_nominal_stress(stretch, params) * WIDTH * THICKNESS
        assert force == pytest.approx(expected, rel=1e-9)
        assert np.max(np.abs(f[others])) < 1e-9 * force
        assert np.max(np.abs(f[:, 1:])) < 1e-9 * force
        assert -f[fixed, 0].sum() == pytest.approx(-expected, rel=1e-9)
        i1, i2 = stretch**2 + 2.0 / stretch, 2.0 * stretch + stretch**-2
        w = law(i1, i2, params).W
        assert energy == pytest.approx(w * LENGTH * WIDTH * THICKNESS, rel=1e-9)


def test_small_strain_modulus_is_E0():
    """At 0.1 % stretch the uniaxial stress is E0 * strain to within the curve's own nonlinearity
    (relative curvature ~ 3 * strain, so 1 %)."""
    shell = _sheet(REFERENCE)
    grip = np.isclose(shell.x0[:, 0], LENGTH)
    eps = 1e-3
    x = shell.x0 * [1.0 + eps, (1.0 + eps) ** -0.5, 1.0]
    _, f = _membrane(shell, x)
    stress = -f[grip, 0].sum() / (WIDTH * THICKNESS)
    assert stress == pytest.approx(REFERENCE.E0 * eps, rel=1e-2)


def test_inverted_triangle_is_reported():
    """A folded-over triangle makes the membrane raise a ColonsimError naming the divergence."""
    shell = _sheet(REFERENCE)
    x = shell.x0.copy()
    i = shell.triangles[0, 0]
    x[i] = x[shell.triangles[0, 1]]  # collapse a triangle onto an edge
    with pytest.raises(ColonsimError, match="inverted or collapsed"):
        _membrane(shell, x)


def test_free_lateral_contraction_found_by_static_solve(serial_kernels):
    """Grips that hold only the axial coordinate (sliding grips): the static solve must find the
    homogeneous state by itself, lateral stretch 1/sqrt(l), and the closed-form grip force.
    Tolerance 1e-5: the solve stops at nodal forces below 1e-7 of the grip force (near the
    energy's round-off floor), which leaves the lateral stretch 1e-6 and the grip force 2e-7 off
    (measured)."""
    material = REFERENCE
    shell = _sheet(material)
    stretch = 1.4
    grip = np.isclose(shell.x0[:, 0], LENGTH)
    fixed = np.isclose(shell.x0[:, 0], 0.0)
    free = np.ones(shell.x0.shape, dtype=bool)
    free[grip | fixed, 0] = False
    free[:, 2] = False  # in-plane problem
    free[np.argmin(shell.x0[:, 0] + shell.x0[:, 1]), 1] = False  # no rigid sliding across
    start = shell.x0.copy()
    start[:, 0] = shell.x0[:, 0] * stretch
    expected = material.uniaxial_nominal_stress(stretch) * WIDTH * THICKNESS
    x, _ = minimize_energy(start, free, lambda y, f: membrane_forces(shell, y, f), force_tol=1e-7 * expected)
    assert np.ptp(x[:, 1]) / WIDTH == pytest.approx(stretch**-0.5, rel=1e-5)
    assert np.allclose(x[:, 0], shell.x0[:, 0] * stretch, rtol=0, atol=1e-5 * LENGTH)
    f = np.zeros_like(x)
    membrane_forces(shell, x, f)
    assert -f[grip, 0].sum() == pytest.approx(expected, rel=1e-5)
