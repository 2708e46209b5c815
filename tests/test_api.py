"""The public Python API (colonsim.api, re-exported by colonsim): every function's docstring example
runs, in the order a user would (calibrate, insert, sweep, fit a surrogate, predict, recommend), at
the smoke size; bad inputs are one-line errors."""

import doctest

import pytest

import colonsim
from colonsim import api
from colonsim.surrogate import predictor

from predictor_fixture import synthetic_patient_table

ORDER = ("calibrate", "insert", "sweep", "fit_surrogate", "predict", "recommend")


@pytest.fixture(scope="module")
def examples():
    found = {t.name.rsplit(".", 1)[-1]: t for t in doctest.DocTestFinder().find(api) if t.examples}
    assert set(ORDER) <= set(found), f"functions without a docstring example: {sorted(set(ORDER) - set(found))}"
    return found


def test_every_public_function_is_exported():
    assert set(ORDER) <= set(colonsim.__all__)
    assert all(getattr(colonsim, name) is getattr(api, name) for name in ORDER)
    with pytest.raises(AttributeError):
        colonsim.no_such_function


def tiny_predictor(folder):
    """A predictor fitted on a SYNTHETIC RSF table (tests/predictor_fixture.py), saved as the package does."""
    from colonsim.surrogate.predictor_fit import fit_predictor, save_predictor

    model = fit_predictor({"patient_space_rsf": synthetic_patient_table(n=72)}, targets=("max_deformation_cm",),
                          n_restarts=0, hyperparameter_draws=0)
    return save_predictor(model, folder / "patient_space")[0]


def test_docstring_examples_run(examples, tmp_path, monkeypatch):
    """Every example, the shipped predictor's answered by a tiny SYNTHETIC one in its place."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv(predictor.OVERRIDE, str(tiny_predictor(tmp_path)))
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for name in ORDER:
        runner.run(examples[name])
    failed, attempted = runner.summarize(verbose=False)
    assert attempted > 0 and failed == 0, f"{failed} of {attempted} docstring examples of colonsim.api failed"


def test_bad_inputs_are_one_line_errors(tmp_path):
    with pytest.raises(colonsim.ColonsimError, match="at least one scope"):
        colonsim.insert("rsj", [], out=tmp_path / "x")
    with pytest.raises(colonsim.ColonsimError, match="InsertionCase's fields"):
        colonsim.insert("rsj", "sdc", no_such_input=1, out=tmp_path / "x")
    assert not (tmp_path / "x").exists()


@pytest.mark.skipif(not predictor.shipped_exists(), reason="no predictor is shipped yet (the patient-space sweeps "
                    "have not been run): test_docstring_examples_run runs the example on a synthetic one")
def test_the_shipped_predictor_answers_the_example(examples, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv(predictor.OVERRIDE, raising=False)
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for name in ("fit_surrogate", "predict"):  # the predict example's second half asks fit_surrogate's model
        runner.run(examples[name])
    failed, attempted = runner.summarize(verbose=False)
    assert attempted > 0 and failed == 0


def test_without_a_shipped_model_the_call_says_so(tmp_path, monkeypatch):
    monkeypatch.setattr(predictor, "SHIPPED", tmp_path / "none")
    monkeypatch.delenv(predictor.OVERRIDE, raising=False)
    with pytest.raises(colonsim.ColonsimError, match="ships no fitted predictor"):
        colonsim.predict(segment="rsf", scope="pdc", angle_deg=45, diameter_mm=36)
    with pytest.raises(colonsim.ColonsimError, match="ships no fitted predictor"):
        colonsim.recommend(segment="rsf", angle_deg=45, diameter_mm=36)


def test_the_shipped_predictor_refuses_outside_its_domain_a_users_model_warns(tmp_path, monkeypatch):
    monkeypatch.setenv(predictor.OVERRIDE, str(tiny_predictor(tmp_path)))
    with pytest.raises(colonsim.ColonsimError, match="angle_deg 75 outside"):
        colonsim.predict(segment="rsf", scope="pdc", angle_deg=75, diameter_mm=36)
    with pytest.raises(colonsim.ColonsimError, match="angle_deg 75 outside"):
        colonsim.recommend(segment="rsf", angle_deg=75, diameter_mm=36)
    with pytest.warns(colonsim.surrogate.OutOfDomainWarning):
        frame = colonsim.predict(tmp_path / "patient_space.json", "rsf", scope="pdc", angle_deg=75, diameter_mm=36)
    assert not frame["in_domain"].any()
    ranked = colonsim.recommend(segment="rsf", angle_deg=30, diameter_mm=36, scopes=["utc", "sdc"])
    assert sorted(s["scope"] for s in ranked["scopes"]) == ["sdc", "utc"]
    with pytest.raises(colonsim.ColonsimError, match="give the colon model"):
        colonsim.predict(scope="pdc")
