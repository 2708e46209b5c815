"""The documentation site (docs/, Sphinx with MyST, myst-nb and sphinx-argparse) builds with every
warning an error, as CI builds it: a broken link, a page outside every toctree, a notebook that no
longer parses, an option whose help text breaks the generated CLI reference, or a catalog column or
InsertionCase field the generated reference tables cannot place fails here."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytest.importorskip("sphinx", reason="the docs extra (pip install -e '.[docs]') builds the site")


def test_site_builds_without_warnings(tmp_path):
    done = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-E", "-b", "html",
                           "-d", str(tmp_path / "doctrees"), str(ROOT / "docs"), str(tmp_path / "html")],
                          capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert done.returncode == 0, f"sphinx-build failed:\n{done.stderr[-4000:]}"
    html = tmp_path / "html"
    for page in ("index", "reference/cli", "reference/parameters", "reference/results_columns", "reference/api",
                 "tutorials/02_insertion", "validation/report", "faq"):
        assert (html / f"{page}.html").is_file(), page
    # the generated tables hold every catalog column and every case field
    from dataclasses import fields

    from colonsim.catalog import COLUMNS
    from colonsim.insertion.case.insertion_case import InsertionCase

    columns = (html / "reference" / "results_columns.html").read_text(encoding="utf-8")
    parameters = (html / "reference" / "parameters.html").read_text(encoding="utf-8")
    assert all(f">{name}<" in columns for name in COLUMNS)
    assert all(f">{f.name}<" in parameters for f in fields(InsertionCase))
    assert "--distal-resistance" in (html / "reference" / "cli.html").read_text(encoding="utf-8")


def test_every_case_field_needs_a_kind(monkeypatch):
    """The parameters reference refuses a field it cannot classify, and a stale classification."""
    sys.path.insert(0, str(ROOT / "docs" / "_ext"))
    try:
        import colonsim_docs
    finally:
        sys.path.remove(str(ROOT / "docs" / "_ext"))
    from sphinx.errors import ExtensionError

    rows = colonsim_docs.parameter_rows()
    by_name = {r[0]: r for r in rows}
    assert by_name["distal_resistance_N"][1:4] == ("5.0", "N", "assumption")
    assert by_name["push_speed"][3] == "numerical" and by_name["push_speed"][4]  # its docstring's description
    table = dict(colonsim_docs.PARAMETERS)
    del table["push_speed"]
    monkeypatch.setattr(colonsim_docs, "PARAMETERS", table)
    with pytest.raises(ExtensionError, match="push_speed"):
        colonsim_docs.parameter_rows()
    monkeypatch.setattr(colonsim_docs, "PARAMETERS", {**dict(colonsim_docs.PARAMETERS), "push_speed": ("m/s", "numerical"),
                                                      "no_such_field": ("", "numerical")})
    with pytest.raises(ExtensionError, match="no_such_field"):
        colonsim_docs.parameter_rows()
