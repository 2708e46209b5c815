"""Shared test fixtures."""

import os
import re
import subprocess
import sys

import numba
import numpy as np
import pytest


@pytest.fixture
def serial_kernels():
    """Run the kernels on one thread: checks that call them hundreds of times on tiny meshes,
    where waking a second thread on a loaded machine costs more than the work itself."""
    previous = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(previous)


@pytest.fixture
def two_threads(request):
    """Checks of the threaded kernels against the serial ones run on two Numba threads: here when
    this process has them (the test gets True and runs), else the same test again in a child
    pytest process started with ``NUMBA_NUM_THREADS=2`` (the test gets False and returns). Under
    the README's test command every process has one thread (conftest.py at the root), on which
    a threaded kernel runs serially and its check could not fail on a race or a lost sum."""
    if numba.config.NUMBA_NUM_THREADS >= 2:
        previous = numba.get_num_threads()
        numba.set_num_threads(2)
        yield True
        numba.set_num_threads(previous)
        return
    child = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", request.node.nodeid],
                           cwd=request.config.rootpath, env={**os.environ, "NUMBA_NUM_THREADS": "2"},
                           capture_output=True, text=True, timeout=600)
    assert child.returncode == 0 and re.search(r"^1 passed", child.stdout, re.M), child.stdout[-3000:] + child.stderr[-3000:]
    yield False


@pytest.fixture
def energy_gradient():
    """Central-difference gradient of ``energy(x)`` (a scalar function of positions (n, 3)),
    step ``h`` in m: the reference the force kernels are checked against (forces = -gradient)."""

    def gradient(energy, x, h=1e-7):
        g = np.empty_like(x)
        for i in range(len(x)):
            for k in range(3):
                xp = x.copy()
                xp[i, k] += h
                xm = x.copy()
                xm[i, k] -= h
                g[i, k] = (energy(xp) - energy(xm)) / (2.0 * h)
        return g

    return gradient


@pytest.fixture
def without_run_figures(monkeypatch):
    """Sweeps of stand-in runs (a few synthetic samples each) write every run's files but its PNG:
    the adaptive-sweep tests check the loop, not the figure (test_insertion_straight.py and
    test_demo.py check the run figures); measured on the budget/resume test, 66 -> 58 s."""
    from colonsim.insertion.case import results

    monkeypatch.setattr(results, "save_figure", lambda fig, path, dpi=150: None)
