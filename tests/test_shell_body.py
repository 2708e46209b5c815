"""The shell as a solver body: protocol attributes, masses, normals, rest state, input errors."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material
from colonsim.insertion.engine.sheet_mesh import straight_tube
from colonsim.insertion.engine.shell import Shell

MATERIAL = load_material(REFERENCE_MATERIAL_PATH)
RADIUS, THICKNESS, LENGTH, H = 0.018, 0.002, 0.03, 0.003


@pytest.fixture(scope="module")
def tube():
    nodes, tri, _ = straight_tube(LENGTH, 2 * RADIUS, H)
    return Shell(nodes, tri, THICKNESS, MATERIAL, density=1040.0, name="colon")


def test_protocol_attributes(tube):
    assert tube.name == "colon"
    assert tube.x0.shape == (tube.mass.shape[0], 3) and tube.x0.dtype == np.float64
    assert tube.triangles.dtype == np.int64 and tube.triangles.shape[1] == 3
    assert tube.hinges.dtype == np.int64 and tube.hinges.shape[1] == 4
    assert tube.thickness == THICKNESS


def test_lumped_mass_is_wall_mass(tube):
    """Total lumped mass = density t (sum of triangle areas) to round-off; that area is the
    cylinder's 2 pi R L within 0.5 % (inscribed polygons: -(pi/m)^2/6 = -0.1 % for m = 38, and
    ring-to-ring triangles tilted slightly outward, measured -0.08 % in all)."""
    assert tube.mass.sum() == pytest.approx(1040.0 * THICKNESS * tube.area0.sum(), rel=1e-12)
    assert tube.area0.sum() == pytest.approx(2 * np.pi * RADIUS * LENGTH, rel=5e-3)
    assert np.all(tube.mass > 0)


def test_rest_state_is_stress_free(tube):
    """Energy and forces vanish to round-off (1e-12 of the scales mu0 t A and mu0 t h)."""
    f = np.zeros_like(tube.x0)
    volume = THICKNESS * tube.area0.sum()
    assert tube.internal_forces(tube.x0.copy(), f) == pytest.approx(0.0, abs=1e-12 * MATERIAL.mu0 * volume)
    assert np.max(np.abs(f)) < 1e-12 * MATERIAL.mu0 * THICKNESS * H


def test_node_normals_point_out_of_the_lumen(tube):
    """Unit length; on the cylinder they are radial up to O(h / R) tilt on the end rings, where
    the incident triangles lie on one side only (measured < 1 degree inside, < 5 deg at the ends)."""
    n = tube.node_normals(tube.x0)
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    radial = tube.x0.copy()
    radial[:, 0] = 0.0
    radial /= np.linalg.norm(radial, axis=1)[:, None]
    cos = np.einsum("ij,ij->i", n, radial)
    assert np.all(cos > np.cos(np.radians(5.0)))
    inner = (tube.x0[:, 0] > 1e-9) & (tube.x0[:, 0] < LENGTH - 1e-9)
    assert np.all(cos[inner] > np.cos(np.radians(1.0)))


def test_rigid_motion_is_force_free(tube):
    """A rotation plus translation leaves energy and forces at zero (objectivity of both kernels)."""
    q, _ = np.linalg.qr(np.random.default_rng(4).standard_normal((3, 3)))
    x = np.ascontiguousarray(tube.x0 @ q.T + [0.01, -0.02, 0.03])
    f = np.zeros_like(x)
    volume = THICKNESS * tube.area0.sum()
    assert tube.internal_forces(x, f) == pytest.approx(0.0, abs=1e-12 * MATERIAL.mu0 * volume)
    assert np.max(np.abs(f)) < 1e-10 * MATERIAL.mu0 * THICKNESS * H


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"thickness": 0.0}, "thickness"),
        ({"density": -1.0}, "density"),
        ({"triangles": np.array([[0, 1, 99999]])}, "do not exist"),
    ],
)
def test_bad_input_raises(tube, kwargs, message):
    args = {"nodes": tube.x0, "triangles": tube.triangles, "thickness": THICKNESS, "material": MATERIAL}
    args.update(kwargs)
    with pytest.raises(ColonsimError, match=message):
        Shell(**args)


def test_wrong_position_array_raises(tube):
    with pytest.raises(ColonsimError, match="C-contiguous float64"):
        tube.internal_forces(tube.x0.astype(np.float32), np.zeros_like(tube.x0))
