"""Helpers for the numba kernels (imported only by the kernel modules: importing it does not
import numba until :func:`serial_and_parallel` is called)."""

from __future__ import annotations

import types

__all__ = ["serial_and_parallel"]


def _renamed(py_func, suffix: str):
    """A copy of ``py_func`` (same code, globals and defaults) named ``<name><suffix>``."""
    func = types.FunctionType(py_func.__code__, py_func.__globals__, py_func.__name__ + suffix,
                              py_func.__defaults__, py_func.__closure__)  # fmt: skip
    func.__qualname__ = py_func.__qualname__ + suffix
    func.__module__ = py_func.__module__
    func.__doc__ = py_func.__doc__
    return func


def serial_and_parallel(py_func, **flags):
    """(parallel, serial) ``@njit(cache=True)`` compilations of one Python function.

    numba's on-disk cache is keyed by the function's qualified name, its line and the
    signature, not by the compile flags: two dispatchers of the same function, one with
    ``parallel=True`` and one without, would share one cache entry, and whichever compiled
    first would be loaded by both (a "parallel" kernel then runs serially, or the reverse).
    Each twin is therefore compiled from a renamed copy (``<name>_par``, ``<name>_ser``),
    which gives it a cache file of its own.
    """
    from numba import njit

    par = njit(cache=True, parallel=True, **flags)(_renamed(py_func, "_par"))
    ser = njit(cache=True, **flags)(_renamed(py_func, "_ser"))
    return par, ser
