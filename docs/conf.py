"""Sphinx configuration of colonsim's documentation site (MyST Markdown, furo, myst-nb).

Build: ``sphinx-build -W docs docs/_build`` (``pip install -e ".[docs]"``). The notebooks are
rendered with the outputs stored in them (one run at reduced size, docs/tutorials/index.md), never
executed here (the test command executes them at reduced size); the command-line reference is
generated from the argparse parser, the results columns and the model parameters from the code
(``_ext/colonsim_docs.py``).
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent / "_ext"))

from colonsim import __version__  # noqa: E402

project = "colonsim"
author = "the colonsim developers"
copyright = "2026, the colonsim developers"
release = version = __version__

extensions = [
    "myst_nb",  # MyST Markdown pages and the notebooks
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinxarg.ext",
    "colonsim_docs",
]

myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
myst_heading_anchors = 3
nb_execution_mode = "off"  # stored outputs only
nb_merge_streams = True

exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "**.ipynb_checkpoints"]

# Pages written in other changes, listed in the toctrees as "../NAME": until such a page exists,
# its toctree line is dropped when the index is read (a missing page is otherwise a warning).
OPTIONAL_PAGES = ("cards", "visualisation")


def _drop_absent_optional_pages(app, docname, source):
    for page in OPTIONAL_PAGES:
        if not (Path(app.srcdir) / f"{page}.md").is_file():
            source[0] = source[0].replace(f"\n../{page}\n", "\n")


def setup(app):
    app.connect("source-read", _drop_absent_optional_pages)

autodoc_member_order = "bysource"
autodoc_typehints = "description"
napoleon_numpy_docstring = True

html_theme = "furo"
html_title = f"colonsim {release}"
