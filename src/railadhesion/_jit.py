"""The package's only uses of numba's private internals, isolated here on purpose.

Two remain, for ``monitor.kernel`` and ``monitor.estimator``, and the second also for the
braking simulator's stepping call ``BrakingSimulator.advance`` (every other kernel is built
with :func:`railadhesion.numerics.jit`, whose cache directory is keyed by the kernel sources and
needs no guard, and called through numba's public dispatcher):

* :func:`guard_cache` reads ``Dispatcher._cache._cache_path``: numba has no public way to say
  where it keeps a function's cache files (``__pycache__`` beside the source, or a user-wide
  directory when that is not writable), and the guard must delete them there. Moving the
  monitor's kernels to :func:`railadhesion.numerics.jit` makes the guard unnecessary.
* :func:`kernel_entry` reads ``Dispatcher.overloads[types].entry_point``: calling the compiled
  entry point skips the dispatcher's type resolution of every argument on every call (numba
  has no public equivalent short of a ``cfunc`` with a C signature for the monitor's records,
  or for the buffer of ``advance``).

``tests/test_jit.py`` reads both internals from the installed numba directly and fails when
numba changes them (the declared upper bounds on numba and llvmlite, checked by
``tests/test_numerics.py``, keep an untested numba out).
"""

from __future__ import annotations

__all__ = ["cache_path", "compiled_entry", "guard_cache", "kernel_entry", "purge_module_cache",
           "source_checksum"]

# numba keys a cached kernel on its own source file only. A kernel that calls (and inlines)
# njit helpers of another module keeps its cached machine code when that module changes; the
# guard below compiles a checksum of those modules' sources into a tiny cached function of the
# guarded module and, when the cached checksum differs from the current one, deletes every
# cache file of the guarded module so that its kernels compile afresh.


def source_checksum(*modules) -> int:
    """CRC-32 of the source files of ``modules`` (module objects), in the order given."""
    import zlib
    from pathlib import Path

    crc = 0
    for module in modules:
        crc = zlib.crc32(Path(module.__file__).read_bytes(), crc)
    return crc


def purge_module_cache(cache_dir, module_stem: str, compiled: int, current: int) -> list:
    """Delete the numba cache files of module ``module_stem`` (``<stem>.*.nbi``/``.nbc``) in
    ``cache_dir`` if ``compiled`` (the checksum the cached code was built with) differs from
    ``current``; return the deleted paths."""
    from pathlib import Path

    if compiled == current:
        return []
    gone = []
    for path in Path(cache_dir).glob(f"{module_stem}.*.nb[ic]"):
        path.unlink(missing_ok=True)
        gone.append(path)
    return gone


def cache_path(dispatcher) -> str:
    """The directory of the cache files of an ``@njit(cache=True)`` ``dispatcher``
    (``Dispatcher._cache._cache_path``, numba internals). Raises ``RuntimeError`` naming
    numba's version if numba no longer gives it."""
    import numba

    try:
        path = dispatcher._cache._cache_path
    except AttributeError as exc:
        raise RuntimeError(f"numba {numba.__version__} no longer gives a function's cache "
                           f"directory (Dispatcher._cache._cache_path): {exc!r}") from exc
    if not isinstance(path, str):
        raise RuntimeError(f"numba {numba.__version__}: Dispatcher._cache._cache_path is "
                           f"{type(path).__name__}, not a directory name")
    return path


def guard_cache(fingerprint_dispatcher, module_file: str, current: int) -> list:
    """Run the guard: ``fingerprint_dispatcher`` is an ``@njit(cache=True)`` function of the
    guarded module (``module_file``) returning the checksum global it was compiled with."""
    from pathlib import Path

    cache_dir = cache_path(fingerprint_dispatcher)
    gone = purge_module_cache(cache_dir, Path(module_file).stem, fingerprint_dispatcher(), current)
    if gone:
        fingerprint_dispatcher.recompile()
    return gone


def compiled_entry(dispatcher, args):
    """``dispatcher.overloads[types of args].entry_point`` (numba internals): the compiled
    entry point for the types of ``args``, which must already be compiled. Raises
    ``RuntimeError`` naming numba's version if numba no longer gives it."""
    import numba

    try:
        entry = dispatcher.overloads[tuple(numba.typeof(a) for a in args)].entry_point
    except (AttributeError, KeyError, TypeError) as exc:
        raise RuntimeError(f"numba {numba.__version__} no longer gives a kernel's entry point "
                           f"(Dispatcher.overloads[...].entry_point): {exc!r}") from exc
    if not callable(entry):
        raise RuntimeError(f"numba {numba.__version__}: Dispatcher.overloads[...].entry_point "
                           f"is not callable ({type(entry).__name__})")
    return entry


def kernel_entry(dispatcher, args):
    """The compiled entry point of the numba ``dispatcher`` for the types of ``args``
    (:func:`compiled_entry`): calling it skips the dispatcher's type resolution. ``args`` must
    make a call without harm (it compiles the kernel, or loads it from the cache). If numba's
    internals do not give the entry point, warns (``RuntimeWarning``) and returns the
    dispatcher: the results are the same, each call is slower. ``tests/test_jit.py`` fails in
    that case."""
    dispatcher(*args)
    try:
        return compiled_entry(dispatcher, args)
    except RuntimeError as exc:  # pragma: no cover - numba changed: tests/test_jit.py fails
        import warnings

        warnings.warn(f"{exc}; calling the kernel through its dispatcher (slower)",
                      RuntimeWarning, stacklevel=2)  # fmt: skip
        return dispatcher
