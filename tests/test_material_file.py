"""Reading the wall material file, and every way it can be wrong."""

import json

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, SoftWallWarning, WallMaterial, load_material
from colonsim.laws import LAWS, OGDEN_LAWS


def write(tmp_path, data, name="mat.json"):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else json.dumps(data))
    return path


def good(**overrides):
    data = {"law": "mooney_rivlin_3", "units": "Pa",
            "parameters": {"C10": 652.01, "C01": 42835.25, "C11": 219120.3}}
    data.update(overrides)
    return data


def test_reference_file_holds_source_parameters():
    mat = load_material(REFERENCE_MATERIAL_PATH)
    assert mat.law == "mooney_rivlin_3" and mat.parameters == (652.01, 42835.25, 219120.3)
    assert mat.named_parameters == {"C10": 652.01, "C01": 42835.25, "C11": 219120.3}
    assert mat.mu0 == pytest.approx(2 * (652.01 + 42835.25), rel=1e-15)
    assert mat.E0 == pytest.approx(6 * (652.01 + 42835.25), rel=1e-15)


def test_reference_path_is_the_repo_data_file():
    assert REFERENCE_MATERIAL_PATH.name == "material_reference.json"
    assert REFERENCE_MATERIAL_PATH.parent.name == "data"
    assert REFERENCE_MATERIAL_PATH.is_file()


def test_load_accepts_str_path(tmp_path):
    mat = load_material(str(write(tmp_path, good())))
    assert isinstance(mat, WallMaterial)


def test_material_is_frozen():
    mat = WallMaterial("mooney_rivlin_3", (1.0, 2.0, 3.0))
    with pytest.raises(AttributeError):
        mat.parameters = (5.0, 2.0, 3.0)


@pytest.mark.parametrize("law", sorted(LAWS))
def test_every_law_loads(tmp_path, law):
    """A material file of each law the calibration offers loads, with mu0 from the law."""
    names = LAWS[law].parameter_names
    params = {name: 1e4 * (i + 1) for i, name in enumerate(names)}
    mat = load_material(write(tmp_path, good(law=law, parameters=params)))
    assert mat.law == law and mat.parameters == tuple(params.values())
    assert mat.mu0 == pytest.approx(LAWS[law].initial_shear_modulus(mat.parameters), rel=1e-15)
    assert mat.E0 == pytest.approx(3.0 * mat.mu0, rel=1e-15)


OGDEN_3 = {"mu1": 20e3, "alpha1": 2.0, "mu2": 2e3, "alpha2": 10.0, "mu3": -10e3, "alpha3": -2.0}


@pytest.mark.parametrize("law", sorted(OGDEN_LAWS))
def test_ogden_files_load(tmp_path, law):
    """An Ogden file (mu_p in Pa of either sign, alpha_p dimensionless) loads for the insertion,
    with mu0 = 1/2 sum mu_p alpha_p (Ogden's own convention, the calibration's)."""
    terms = OGDEN_LAWS[law].terms
    params = dict(list(OGDEN_3.items())[:2 * terms])
    mat = load_material(write(tmp_path, good(law=law, parameters=params)))
    assert mat.law == law and mat.named_parameters == params
    expected = {1: 20e3, 2: 30e3, 3: 40e3}[terms]  # 20e3 * 2/2, + 2e3 * 10/2, + (-10e3)(-2)/2
    assert mat.mu0 == pytest.approx(expected, rel=1e-15) and mat.E0 == pytest.approx(3 * expected, rel=1e-15)


def test_ogden_file_errors(tmp_path):
    ogden_3 = good(law="ogden_3", parameters=OGDEN_3)
    with pytest.raises(ColonsimError, match="misses parameter.*alpha3; give mu1, alpha1, mu2, alpha2, mu3, alpha3"):
        load_material(write(tmp_path, {**ogden_3, "parameters": {k: v for k, v in OGDEN_3.items() if k != "alpha3"}}))
    with pytest.raises(ColonsimError, match="C10 do not belong to law ogden_3"):
        load_material(write(tmp_path, {**ogden_3, "parameters": {**OGDEN_3, "C10": 1.0}}))
    with pytest.raises(ColonsimError, match="ogden_3 exponent alpha2 = 0 leaves its term undefined"):
        load_material(write(tmp_path, {**ogden_3, "parameters": {**OGDEN_3, "alpha2": 0.0}}))
    with pytest.raises(ColonsimError, match="ogden_3 parameter mu1 = inf must be finite"):
        WallMaterial("ogden_3", (np.inf, 2.0, 2e3, 10.0, -10e3, -2.0))
    with pytest.raises(ColonsimError, match="mu0 = -1000.0 Pa must be > 0"):
        WallMaterial("ogden_1", (-1e3, 2.0))
    with pytest.warns(SoftWallWarning, match="mu0 = 40 Pa"):  # the parameters given in kPa
        load_material(write(tmp_path, {**ogden_3, "parameters": {k: v / 1e3 if k.startswith("mu") else v
                                                                 for k, v in OGDEN_3.items()}}))


def test_uniaxial_stress_matches_numerical_derivative_of_energy():
    # Incompressible uniaxial: P = dW/dl with I1 = l^2 + 2/l, I2 = 2l + 1/l^2.
    C10, C01, C11 = 652.01, 42835.25, 219120.3
    mat = WallMaterial("mooney_rivlin_3", (C10, C01, C11))

    def w(lam):
        i1 = lam**2 + 2 / lam
        i2 = 2 * lam + 1 / lam**2
        return C10 * (i1 - 3) + C01 * (i2 - 3) + C11 * (i1 - 3) * (i2 - 3)

    for lam in (0.8, 1.1, 1.6):
        h = 1e-6
        # central difference error ~h^2 W''' ~ 1e-12 relative; rounding ~1e-16 W/h ~ 1e-10
        assert mat.uniaxial_nominal_stress(lam) == pytest.approx(
            (w(lam + h) - w(lam - h)) / (2 * h), rel=1e-7)
    assert mat.uniaxial_nominal_stress(1.0) == 0.0
    # small-strain slope is E0
    eps = 1e-6
    assert mat.uniaxial_nominal_stress(1 + eps) / eps == pytest.approx(mat.E0, rel=1e-4)


def test_missing_file(tmp_path):
    with pytest.raises(ColonsimError, match="not found"):
        load_material(tmp_path / "nope.json")


def test_bad_json(tmp_path):
    with pytest.raises(ColonsimError, match="not valid JSON"):
        load_material(write(tmp_path, "{law: mooney"))


def test_not_an_object(tmp_path):
    with pytest.raises(ColonsimError, match="JSON object"):
        load_material(write(tmp_path, "[1, 2, 3]"))


def test_unknown_law(tmp_path):
    with pytest.raises(ColonsimError, match="law 'ogden'; use one of mooney_rivlin_3, .*yeoh"):
        load_material(write(tmp_path, good(law="ogden")))


def test_parameters_of_another_law(tmp_path):
    with pytest.raises(ColonsimError, match="C01, C11 do not belong to law neo_hookean"):
        load_material(write(tmp_path, good(law="neo_hookean", parameters={"C10": 1.0, "C01": 1.0, "C11": 1.0})))


def test_wrong_parameter_count():
    with pytest.raises(ColonsimError, match="law yeoh takes 3 parameter"):
        WallMaterial("yeoh", (1.0, 2.0))


def test_missing_law(tmp_path):
    data = good()
    del data["law"]
    with pytest.raises(ColonsimError, match="law None"):
        load_material(write(tmp_path, data))


def test_wrong_units(tmp_path):
    with pytest.raises(ColonsimError, match="units 'MPa'"):
        load_material(write(tmp_path, good(units="MPa")))


def test_missing_parameters_object(tmp_path):
    data = good()
    del data["parameters"]
    with pytest.raises(ColonsimError, match="'parameters'"):
        load_material(write(tmp_path, data))


def test_missing_parameter(tmp_path):
    with pytest.raises(ColonsimError, match="misses parameter.*C11"):
        load_material(write(tmp_path, good(parameters={"C10": 1.0, "C01": 2.0})))


@pytest.mark.parametrize("name", ["C10", "C01", "C11"])
def test_negative_parameter(tmp_path, name):
    params = {"C10": 1.0, "C01": 2.0, "C11": 3.0}
    params[name] = -1.0
    with pytest.raises(ColonsimError, match=f"{name} = -1.0"):
        load_material(write(tmp_path, good(parameters=params)))


@pytest.mark.parametrize("value", ["abc", None, True, [1.0]])
def test_non_numeric_parameter(tmp_path, value):
    with pytest.raises(ColonsimError, match="must be a number"):
        load_material(write(tmp_path, good(parameters={"C10": value, "C01": 2.0, "C11": 3.0})))


def test_non_finite_parameter():
    with pytest.raises(ColonsimError, match="finite"):
        WallMaterial("mooney_rivlin_3", (np.inf, 1.0, 1.0))
    with pytest.raises(ColonsimError, match="finite"):
        WallMaterial("mooney_rivlin_3", (np.nan, 1.0, 1.0))


def test_zero_small_strain_stiffness(tmp_path):
    with pytest.raises(ColonsimError, match="small-strain shear modulus mu0 = 0.0 Pa must be > 0"):
        load_material(write(tmp_path, good(parameters={"C10": 0.0, "C01": 0.0, "C11": 3.0})))


def test_integer_parameters_become_floats(tmp_path):
    mat = load_material(write(tmp_path, good(parameters={"C10": 1000, "C01": 2000, "C11": 0})))
    assert all(isinstance(v, float) for v in mat.parameters) and mat.E0 == 18000.0


def test_a_wall_softer_than_any_tissue_is_loaded_with_a_warning(tmp_path, capsys):
    from colonsim.cli import main
    from colonsim.insertion.engine.material import SoftWallWarning

    soft = write(tmp_path, good(parameters={"C10": 1e-6, "C01": 0.0, "C11": 0.0}))
    with pytest.warns(SoftWallWarning, match="2e-06 Pa is softer than any soft tissue"):
        assert load_material(soft).mu0 == pytest.approx(2e-6)
    # on the command line: one warning line, however often the file is read (here per check)
    (tmp_path / "s.toml").write_text(f'[fixed]\nmaterial = "{soft.name}"\n[[grid]]\nscope = ["utc", "sdc"]\n')
    assert main(["sweep", str(tmp_path / "s.toml"), "--dry-run", "--out", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("colonsim: warning: material file") and "softer than any" in err[0]
