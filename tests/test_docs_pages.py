"""The site's pages name no commit and no build machine's path (docs/notes/ holds the dated history
and is exempt). Scanned: every Markdown page and notebook the site builds from docs/ (the tutorials
are the notebooks, their stored outputs included, images left out), the generated validation report
among them. A commit-like token is 7-40 hex digits with at least one digit and one letter a-f, not
part of a number (the digits of ``4.14917562129292e-05`` are none).

Timings are checked by reading, not here: a page that gives a time names the machine and the date
it was measured on (the stored outputs of the tutorials: docs/tutorials/index.md)."""

import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
EXEMPT = ("notes", "_build")
COMMIT = re.compile(r"(?<![0-9A-Za-z_.])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*[0-9])[0-9a-f]{7,40}(?![0-9A-Za-z_])")
MACHINE_PATH = re.compile(r"(?<![\w.])/(?:work|home|tmp)/")
TEXT_OUTPUTS = ("text/plain", "text/markdown", "text/html", "text/latex")


def site_pages():
    """The Markdown pages and notebooks under docs/ that the site builds, outside the notes."""
    return sorted(p for p in DOCS.rglob("*") if p.suffix in (".md", ".ipynb")
                  and p.relative_to(DOCS).parts[0] not in EXEMPT)


def page_lines(path):
    """(where, line) of a page: a Markdown file's lines; a notebook's cells and text outputs."""
    if path.suffix == ".md":
        yield from ((f"line {n}", line) for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1))
        return
    for k, cell in enumerate(json.loads(path.read_text(encoding="utf-8"))["cells"]):
        texts = [("source", cell["source"])]
        for output in cell.get("outputs", []):
            texts.append(("output", output.get("text", "")))
            texts += [(f"output {kind}", output.get("data", {}).get(kind, "")) for kind in TEXT_OUTPUTS]
        for what, text in texts:
            text = "".join(text) if isinstance(text, list) else text
            yield from ((f"cell {k} {what} line {n}", line) for n, line in enumerate(text.splitlines(), 1))


def offences(path):
    """One line per commit-like token or machine path of ``path``: the page, where, what, the line."""
    name = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path.name
    out = []
    for where, line in page_lines(path):
        for pattern, what in ((COMMIT, "a commit-like token"), (MACHINE_PATH, "a machine's path")):
            found = pattern.search(line)
            if found:
                out.append(f"{name}: {where}: {what} {found.group(0)!r}: {line.strip()[:160]}")
    return out


def test_the_scan_finds_what_it_looks_for(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("made at 45b48b5 on a laptop\nrun `colonsim demo --out out`\nread /work/runs/thesis\n"
                    "C10 8395.8 Pa, 1e-3, 4.14917562129292e-05, 2026-12-07, 20261207, `a1b2c3d4e5f6`\n",
                    encoding="utf-8")
    assert len(offences(page)) == 3
    found = "\n".join(offences(page))
    assert "line 1: a commit-like token '45b48b5'" in found and "line 3: a machine's path" in found
    assert "line 4: a commit-like token 'a1b2c3d4e5f6'" in found
    notebook = tmp_path / "nb.ipynb"
    notebook.write_text(json.dumps({"cells": [
        {"cell_type": "markdown", "source": ["# fine\n"]},
        {"cell_type": "code", "source": ["x = 1\n"], "outputs": [
            {"output_type": "stream", "text": ["outputs in /tmp/colonsim-notebooks-x\n"]},
            {"output_type": "display_data", "data": {"image/png": "iVBORw0KGgo/tmp/abc123def", "text/plain": ["ok"]}}]}]}),
        encoding="utf-8")
    assert [f.split(": ")[1] for f in offences(notebook)] == ["cell 1 output line 1"]  # the image is not read


def test_the_site_has_pages_to_scan():
    names = {p.relative_to(DOCS).as_posix() for p in site_pages()}
    assert {"index.md", "validation/report.md", "tutorials/02_insertion.ipynb"} <= names
    assert not any(n.startswith("notes/") for n in names)


@pytest.mark.parametrize("page", site_pages(), ids=lambda p: p.relative_to(DOCS).as_posix())
def test_no_page_names_a_commit_or_a_machine_path(page):
    found = offences(page)
    assert not found, ("name commits and the build machine's paths in docs/notes/ or a record, not on a page:\n"
                       + "\n".join(found))


NOTEBOOK_BYTES = 400_000  # a stored notebook's size at most (the site embeds its figures)


def test_the_stored_notebooks_stay_small():
    sizes = {p.name: p.stat().st_size for p in (ROOT / "notebooks").glob("*.ipynb")}
    assert len(sizes) == 5 and all(size <= NOTEBOOK_BYTES for size in sizes.values()), sizes


def test_storing_outputs_shrinks_figures_and_drops_timestamps():
    """notebooks/store_outputs.py: a figure becomes a smaller 256-colour PNG of the same size in
    pixels, the execution timestamps go."""
    import base64
    import io
    import sys

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import nbformat
    import numpy as np
    from PIL import Image

    sys.path.insert(0, str(ROOT / "notebooks"))
    try:
        import store_outputs
    finally:
        sys.path.remove(str(ROOT / "notebooks"))
    fig, ax = plt.subplots(figsize=(4, 3))
    ax.tripcolor(*np.random.default_rng(0).random((3, 200)), cmap="magma_r")
    png = io.BytesIO()
    fig.savefig(png, format="png")
    plt.close(fig)
    data = base64.b64encode(png.getvalue()).decode("ascii")
    cell = nbformat.v4.new_code_cell("x", metadata={"execution": {"iopub.status.idle": "2026-12-07T03:40:00Z"}},
                                     outputs=[nbformat.v4.new_output("display_data", data={"image/png": data})])
    notebook = nbformat.v4.new_notebook(cells=[cell])
    store_outputs.tidy(notebook)
    small = notebook.cells[0].outputs[0]["data"]["image/png"]
    assert "execution" not in notebook.cells[0].metadata and len(small) < 0.8 * len(data)
    before, after = (Image.open(io.BytesIO(base64.b64decode(d))) for d in (data, small))
    assert after.size == before.size and after.mode == "P"
