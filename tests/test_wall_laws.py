"""Every calibrated wall law runs in the shell: dispatched by the kernels, with derivatives equal to
the law's own, and usable end to end from a file (uniaxial tension and inflation of every law are rows
of the verification table, group "law")."""

import json

import numpy as np
import pytest

from colonsim.catalog import SMOKE_PUSH_SPEED
from colonsim.errors import ColonsimError
from colonsim.insertion.case.scenario import InsertionCase, run_insertion
from colonsim.insertion.engine.material import load_material
from colonsim.insertion.engine.shell_membrane import check_dispatched, law_derivatives
from colonsim.insertion.study.law_checks import CHECK_MATERIALS
from colonsim.laws import LAWS, WALL_LAWS, Law

RNG = np.random.default_rng(11)


def _invariants(n):
    """Invariants of random incompressible states (principal stretches 0.6-1.8, J = 1)."""
    l1, l2 = RNG.uniform(0.6, 1.8, (2, n))
    l3 = 1.0 / (l1 * l2)
    return l1**2 + l2**2 + l3**2, (l1 * l2) ** 2 + (l2 * l3) ** 2 + (l1 * l3) ** 2


def test_check_materials_cover_every_law():
    assert set(CHECK_MATERIALS) == set(WALL_LAWS)
    assert all(m.law == name for name, m in CHECK_MATERIALS.items())


@pytest.mark.parametrize("name", sorted(LAWS))
def test_every_law_is_dispatched_with_its_own_derivatives(name):
    """The compiled dispatch returns, for each registered law, the same six numbers as the law's
    numpy evaluation at random invariants and parameters: the same arithmetic, so equal to a
    few ulps (1e-14; numba may evaluate an integer power by multiplication where numpy calls pow)."""
    law = LAWS[name]
    i1, i2 = _invariants(50)
    for _ in range(3):
        params = RNG.uniform(1e3, 3e5, len(law.parameter_names))
        expected = law(i1, i2, params)
        got = np.array([law_derivatives(law.index, params, a, b) for a, b in zip(i1, i2)]).T
        for k, field in enumerate(expected._fields):
            np.testing.assert_allclose(got[k], getattr(expected, field), rtol=1e-14, atol=1e-14 * np.abs(params).max(),
                                       err_msg=f"{name} {field}")
    check_dispatched(law, params)


def test_a_law_without_a_branch_is_reported():
    stray = Law("stray", max(law.index for law in WALL_LAWS.values()) + 1, LAWS["neo_hookean"].energy, ("C10",))
    assert np.isnan(law_derivatives(stray.index, np.array([1.0]), 3.0, 3.0)[0])
    with pytest.raises(ColonsimError, match="do not dispatch law stray.*law_derivatives"):
        check_dispatched(stray, np.array([1.0]))


@pytest.mark.parametrize("name", sorted(LAWS))
def test_law_derivatives_are_consistent(name):
    """W1, W2 are the partial derivatives of W, and W11, W12, W22 those of W1, W2 (the membrane
    stress and the time-step tangent use them): central differences, step 1e-5 on invariants of
    order 4, truncation ~1e-10 and round-off ~1e-16 W / 1e-5, so 1e-7 relative to the scale."""
    law = LAWS[name]
    params = RNG.uniform(1e3, 3e5, len(law.parameter_names))
    i1, i2 = _invariants(20)
    d = law(i1, i2, params)
    h = 1e-5

    def diff(field, which):
        plus = law(i1 + h * (which == 1), i2 + h * (which == 2), params)
        minus = law(i1 - h * (which == 1), i2 - h * (which == 2), params)
        return (getattr(plus, field) - getattr(minus, field)) / (2 * h)

    scale = np.abs(params).max() * 10.0
    for analytic, (field, which) in ((d.W1, ("W", 1)), (d.W2, ("W", 2)), (d.W11, ("W1", 1)), (d.W12, ("W1", 2)),
                                     (d.W12, ("W2", 1)), (d.W22, ("W2", 2))):
        np.testing.assert_allclose(analytic, diff(field, which), rtol=0, atol=1e-7 * scale)


@pytest.mark.parametrize("name, last", [("yeoh", "C30"), ("ogden_3", "alpha3")])
def test_material_file_runs_an_insertion(tmp_path, name, last):
    """What ``colonsim calibrate --law yeoh`` (or ``ogden_3``) writes, ``colonsim insert --material``
    runs: the file loads, and a straight push on a coarse mesh, at the smoke push speed, reaches the
    far end."""
    law = WALL_LAWS[name]
    path = tmp_path / "material.json"
    params = dict(zip(law.parameter_names, CHECK_MATERIALS[name].parameters))
    path.write_text(json.dumps({"law": name, "units": "Pa", "parameters": params}))
    assert load_material(path) == CHECK_MATERIALS[name]
    result = run_insertion(InsertionCase(segment="straight", scope="pdc", element_size_mm=8.0, material=str(path),
                                         push_speed=SMOKE_PUSH_SPEED))
    s = result.summary
    assert s["ended_by"] == "far_end" and s["material"]["law"] == name and s["material"][last] == params[last]
    assert result.model.shell.material.law == name
