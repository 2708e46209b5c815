"""The public Python API (colonsim.api, re-exported by colonsim): every function's docstring example
runs, in the order a user would (calibrate, insert, sweep, fit a surrogate, predict, recommend), at
the smoke size; bad inputs are one-line errors."""

import doctest

import pytest

import colonsim
from colonsim import api

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


def test_docstring_examples_run(examples, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
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
