"""Compile one kernel source several ways: threaded and serial, or once per value of a constant.

Bodies and candidate lists below a size threshold run serially (starting threads costs more than
their work, and much more on a loaded machine), larger ones on threads. Both variants come from
one Python function. Numba keys its on-disk cache by module, qualified name and source line, not
by compile options: the same function jitted with ``parallel=True`` and without shares one cache
entry, and a process then loads the other variant's machine code (checked: the serial dispatcher
reported a cache hit on the entry the threaded one wrote). The serial variant is therefore
compiled from a copy of the function whose qualified name ends in ``_serial``: one source, two
cache entries. A kernel specialised to a constant (one per wall law, say) is made the same way:
a copy per value, whose globals bind the constant, under a qualified name of its own.
"""

import types

import numba


def _renamed_copy(py_func, suffix, module_globals):
    """A copy of ``py_func`` reading ``module_globals``, named ``py_func``'s name + ``suffix``
    (its own cache entry)."""
    copy = types.FunctionType(py_func.__code__, module_globals, py_func.__name__ + suffix, py_func.__defaults__,
                              py_func.__closure__)
    copy.__qualname__ = py_func.__qualname__ + suffix
    copy.__doc__ = py_func.__doc__
    return copy


def threaded_and_serial(py_func):
    """(threaded, serial) dispatchers of ``py_func``, a kernel whose main loop is ``numba.prange``
    (a plain ``range`` when compiled serially), both cached."""
    serial = _renamed_copy(py_func, "_serial", py_func.__globals__)
    return numba.njit(parallel=True, cache=True)(py_func), numba.njit(cache=True)(serial)


def with_constant(py_func, suffix, **constants):
    """A copy of ``py_func`` whose module globals also bind ``constants`` (which Numba freezes
    into the machine code), named ``py_func``'s name + ``suffix`` so that each copy has its own
    cache entry; jit it as the original would be."""
    return _renamed_copy(py_func, suffix, {**py_func.__globals__, **constants})
