"""The public API beside colonsim.api (colonsim.api_calibration, colonsim.api_insertion): every
function is exported by colonsim, its docstring example runs (reduced meshes and budgets, the smoke
size), and bad inputs are one-line errors raised before anything is fitted, run or written."""

import doctest

import pytest

import colonsim
from colonsim import api_calibration, api_insertion
from colonsim.data import TRELOAR_MANIFEST

# in the order a user would run them: export_cards reads calibrate_multimode's material.json
ORDER = ((api_calibration, "calibrate_strip"), (api_calibration, "calibrate_multimode"),
         (api_calibration, "export_cards"), (api_insertion, "simulate"))


def test_every_function_is_exported():
    for module, name in ORDER:
        assert name in colonsim.__all__ and name in dir(colonsim)
        assert getattr(colonsim, name) is getattr(module, name)
        assert name in module.__all__


def test_docstring_examples_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for module, name in ORDER:
        found = [t for t in doctest.DocTestFinder().find(module) if t.name.endswith(f".{name}") and t.examples]
        assert found, f"{module.__name__}.{name} has no docstring example"
        runner.run(found[0])
    failed, attempted = runner.summarize(verbose=False)
    assert attempted > 0 and failed == 0, f"{failed} of {attempted} docstring examples failed"
    # the cards export the material written (the example above), read back as the same law
    from colonsim.identification.card_readers import initial_shear_modulus, read_card
    from colonsim.identification.cards import read_material
    from colonsim.identification.hyperelastic import calibration_law

    law, params = read_material(tmp_path / "treloar" / "material.json")
    model = calibration_law(law)
    mu0 = model.initial_shear_modulus([params[n] for n in model.parameter_names])
    card_mu0 = initial_shear_modulus(read_card("febio", tmp_path / "treloar" / "material_febio.xml"))
    assert card_mu0 == pytest.approx(mu0, rel=1e-5)


@pytest.mark.parametrize("call, words", [
    (lambda out: colonsim.calibrate_strip(mesh=(4,), out=out), "two whole numbers"),
    (lambda out: colonsim.calibrate_strip(mesh=(100, 2), out=out), "outside 1x1-64x24"),
    (lambda out: colonsim.calibrate_strip(budget="fast", out=out), "give 'full', 'quick' or a dict"),
    (lambda out: colonsim.calibrate_strip(budget={"design": 5}, out=out), "budget key 'design' is unknown"),
    (lambda out: colonsim.calibrate_strip(budget={"designs": 0}, out=out), "budget designs 0 is outside 1-100,000"),
    (lambda out: colonsim.calibrate_strip(budget={"cma_sigma0": 2.0}, out=out), "cma_sigma0 2.0"),
    (lambda out: colonsim.calibrate_strip(points=2, out=out), "too few to fit 3 parameters"),
    (lambda out: colonsim.calibrate_multimode(modes=["shear"], out=out), "give some of uniaxial, equibiaxial, planar"),
    (lambda out: colonsim.calibrate_multimode(out=out), "give a mode manifest"),
    (lambda out: colonsim.calibrate_multimode(TRELOAR_MANIFEST, residuals="squared", out=out), "'relative' or 'absolute'"),
    (lambda out: colonsim.calibrate_multimode(TRELOAR_MANIFEST, law="hooke", out=out), "hooke"),
    (lambda out: colonsim.export_cards(out / "material.json", ["nastran"]), "card format 'nastran'"),
    (lambda out: colonsim.export_cards(out / "material.json", "febio", bulk_ratio=100, poisson=0.49), "not both"),
    (lambda out: colonsim.export_cards(out / "material.json", "febio", material_id=0), "material id 0"),
    (lambda out: colonsim.simulate("straight", snapshot_interval_s=0.0, out=out), "outside 0.001-10"),
    (lambda out: colonsim.simulate("straight", ["utc", "sdc"], out=out), "colonsim.insert runs several"),
    (lambda out: colonsim.simulate("straight", no_such_input=1, out=out), "InsertionCase's fields"),
])
def test_bad_inputs_are_one_line_errors(tmp_path, call, words):
    out = tmp_path / "out"
    with pytest.raises(colonsim.ColonsimError, match=words) as caught:
        call(out)
    assert "\n" not in str(caught.value)
    assert not out.exists() or not any(out.iterdir())  # nothing written

