"""Shared test fixtures."""

import numba
import pytest


@pytest.fixture
def serial_kernels():
    """Run the kernels on one thread: checks that call them hundreds of times on tiny meshes,
    where waking a second thread on a loaded machine costs more than the work itself."""
    previous = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(previous)
