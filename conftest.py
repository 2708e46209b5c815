"""Repository-wide pytest set-up.

``python -m pytest`` also executes the notebooks (nbmake, ``--nbmake`` in pyproject.toml). Under
pytest they run at reduced size (coarse meshes, tiny budgets; every notebook prints what it
reduced) and write into a fresh temporary folder, removed at the end, so that a sweep left in
``notebooks/output/`` by an earlier run is never resumed instead of run. The notebook kernels
inherit this process's environment. Set either variable beforehand to override.
"""

import os
import shutil
import tempfile

# Under pytest-xdist (the README's test command runs one pytest process per core) every process,
# and the notebook kernels and sweep workers it starts, runs one Numba thread: two processes of two
# threads each on two cores wait on each other's threads (measured with a 2-process sweep also
# running: the insertion fixtures took 10 times longer).
if "PYTEST_XDIST_WORKER" in os.environ:
    os.environ.setdefault("NUMBA_NUM_THREADS", "1")
os.environ.setdefault("COLONSIM_NOTEBOOK_SIZE", "reduced")
_TEMPORARY_OUTPUT = None
if "COLONSIM_NOTEBOOK_OUTPUT" not in os.environ:
    _TEMPORARY_OUTPUT = tempfile.mkdtemp(prefix="colonsim-notebooks-")
    os.environ["COLONSIM_NOTEBOOK_OUTPUT"] = _TEMPORARY_OUTPUT


def pytest_sessionfinish(session, exitstatus):
    if _TEMPORARY_OUTPUT is not None:
        shutil.rmtree(_TEMPORARY_OUTPUT, ignore_errors=True)


# The files that take longest under the README's test command (measured: `--durations=0`, summed
# per file, on a 2-core machine; 2026-11-29), longest first. pytest-xdist hands whole files to the
# two processes in collection order (`--no-loadscope-reorder` in pyproject.toml; its default orders
# by the number of tests, which puts a file of one long test, like the demo's, last), so starting
# the long files first leaves the short ones to even out the two processes' ends. Only the order
# of the run depends on this list: a file missing from it runs later, a stale entry matches nothing.
LONG_FIRST = ("tests/test_demo.py", "tests/test_insertion_rsj.py", "tests/test_sweep.py",
              "tests/test_adaptive_sweep.py", "notebooks/03_sweep_and_surrogate.ipynb",
              "notebooks/02_insertion.ipynb", "tests/test_relax_until_rest.py",
              "tests/test_tissue_uncertainty.py", "tests/test_distal_resistance.py", "tests/test_verification_table.py",
              "notebooks/04_patient_anatomy.ipynb", "tests/test_docs_snippets.py", "tests/test_api.py",
              "tests/test_docs_site.py")


def pytest_collection_modifyitems(config, items):
    rank = {path: k for k, path in enumerate(LONG_FIRST)}
    items.sort(key=lambda item: rank.get(item.nodeid.split("::")[0], len(LONG_FIRST)))  # stable: files stay whole
