"""The package's only uses of numba internals, isolated here: the cache guard of the kernels
that still use numba's in-tree cache (``braking._kernels``, ``monitor.kernel``; every other
kernel is built with :func:`railadhesion.numerics.jit`, whose cache directory is keyed by the
kernel sources and needs no guard) and :func:`kernel_entry` (with a fallback).
``tests/test_jit.py`` checks both against the installed numba.
"""

from __future__ import annotations

__all__ = ["guard_cache", "kernel_entry", "purge_module_cache", "source_checksum"]

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


def guard_cache(fingerprint_dispatcher, module_file: str, current: int) -> list:
    """Run the guard: ``fingerprint_dispatcher`` is an ``@njit(cache=True)`` function of the
    guarded module (``module_file``) returning the checksum global it was compiled with."""
    from pathlib import Path

    cache_dir = fingerprint_dispatcher._cache._cache_path
    gone = purge_module_cache(cache_dir, Path(module_file).stem, fingerprint_dispatcher(), current)
    if gone:
        fingerprint_dispatcher.recompile()
    return gone


def kernel_entry(dispatcher, args):
    """The compiled entry point of the numba ``dispatcher`` for the types of ``args``: calling
    it skips the dispatcher's type resolution (a few hundred ns a call). ``args`` must make a
    call without harm (it compiles the kernel, or loads it from the cache); falls back to the
    dispatcher if numba's internals do not give the entry point."""
    dispatcher(*args)
    try:
        from numba import typeof

        entry = dispatcher.overloads[tuple(typeof(a) for a in args)].entry_point
    except Exception:  # pragma: no cover - numba internals changed: use the dispatcher
        entry = None
    return entry if callable(entry) else dispatcher
