"""The numba cache guard of railadhesion._jit (used by the braking kernels only, until they
are built with railadhesion.numerics.jit): kernels that inline njit helpers of another module
must not keep cached machine code built against an older version of that module."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

from railadhesion import _jit

GUARDED = '''
import helper
from numba import njit
from railadhesion import _jit

FINGERPRINT = _jit.source_checksum(helper)


@njit(cache=True)
def _fingerprint():
    return FINGERPRINT


GONE = _jit.guard_cache(_fingerprint, __file__, FINGERPRINT)


@njit(cache=True)
def kernel(x):
    return helper.twice(x)
'''


def _run(tmp_path, code: str) -> str:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               PYTHONPATH=os.pathsep.join([str(tmp_path), *sys.path]))  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=300, check=True)  # fmt: skip
    return out.stdout.strip()


def test_cached_kernel_is_dropped_when_an_inlined_helper_changes(tmp_path):
    (tmp_path / "guarded.py").write_text(GUARDED)
    helper = tmp_path / "helper.py"
    helper.write_text("from numba import njit\n\n@njit(inline='always')\ndef twice(x):\n"
                      "    return 2.0 * x\n")  # fmt: skip
    probe = "import guarded; print(len(guarded.GONE), guarded.kernel(3.0))"
    assert _run(tmp_path, probe) == "0 6.0"  # compiled and cached
    assert _run(tmp_path, probe) == "0 6.0"  # loaded from the cache, nothing dropped
    helper.write_text(helper.read_text().replace("2.0 * x", "3.0 * x"))
    # numba alone would serve the cached kernel (6.0); the guard drops guarded's cache files
    dropped, value = _run(tmp_path, probe).split()
    assert int(dropped) >= 2 and value == "9.0"
    assert _run(tmp_path, probe) == "0 9.0"


def test_purge_touches_only_the_module_files(tmp_path):
    names = ["table._lookup_chunks-410.py311.nbi", "table._lookup_chunks-410.py311.1.nbc",
             "exact._solve-20.py311.nbi", "table.cpython-311.pyc"]  # fmt: skip
    for name in names:
        (tmp_path / name).write_text("x")
    assert _jit.purge_module_cache(tmp_path, "table", 5, 5) == []
    gone = _jit.purge_module_cache(tmp_path, "table", 5, 6)
    assert sorted(p.name for p in gone) == sorted(names[:2])
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names[2:])




def test_source_checksum_changes_with_the_source(tmp_path):
    mod = tmp_path / "m.py"
    mod.write_text("x = 1\n")
    module = type(sys)("m")
    module.__file__ = str(mod)
    before = _jit.source_checksum(module)
    mod.write_text(textwrap.dedent("x = 2\n"))
    assert _jit.source_checksum(module) != before


def test_kernel_entry_calls_the_compiled_code():
    from numba import njit

    from railadhesion._jit import kernel_entry

    @njit
    def add(a, b):
        return a + b

    entry = kernel_entry(add, (1.0, 2.0))
    assert entry(3.0, 4.0) == 7.0
    # fails loudly when numba's internals change: kernel_entry's fallback would keep the
    # package working (through the dispatcher, a few hundred ns slower a call), unnoticed
    assert entry is not add, "numba's overloads[...].entry_point is gone: see _jit.kernel_entry"


def test_guard_cache_finds_numbas_cache_directory():
    """guard_cache reads numba's private ``dispatcher._cache._cache_path``: fail loudly if
    numba moves it."""
    from numba import njit

    @njit(cache=True)
    def cached():
        return 1

    assert cached() == 1
    assert isinstance(cached._cache._cache_path, str), "see _jit.guard_cache"
