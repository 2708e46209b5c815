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
