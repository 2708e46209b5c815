"""Shared test fixtures."""

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
