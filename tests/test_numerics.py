"""The ground floor of the compiled kernels (railadhesion.numerics): the call-free primitives
against libm, the laws' compatibility with numba.cfunc, the thread pool under concurrent
callers, the on-disk cache keyed by the kernel sources, the declared numba/llvmlite bounds."""

from __future__ import annotations

import ast
import os
import re
import subprocess
import sys
import threading
from importlib import metadata
from pathlib import Path

import numba
import numpy as np
import pytest
from numba import types

import railadhesion
from railadhesion import numerics
from railadhesion.contact.friction import falling_friction_factor
from railadhesion.contact.kalker import kalker_law
from railadhesion.models import kernels  # noqa: F401 - registers the laws with numba
from railadhesion.models.polach import polach_contact_terms, polach_force, polach_law
from railadhesion.models.wilac import wilac_law

PACKAGE = Path(railadhesion.__file__).parent
ROOT = PACKAGE.parent.parent


@numerics.jit
def _exp_all(x, out):
    for k in range(x.size):
        out[k] = numerics.exp(x[k])


@numerics.jit
def _atan_all(x, out):
    for k in range(x.size):
        out[k] = numerics.atan(x[k])


@numerics.jit
def _hypot_all(x, y, out):
    for k in range(x.size):
        out[k] = numerics.hypot(x[k], y[k])


def _ulps(ours, ref):
    """|ours - ref| in units of the last place of ref (subnormals: of the smallest one)."""
    return np.abs(ours - ref) / np.spacing(np.maximum(np.abs(ref), np.finfo(float).tiny))


def test_exp_within_an_ulp_of_libm_everywhere():
    rng = np.random.default_rng(1)
    x = np.concatenate([rng.uniform(-760.0, 720.0, 200_000), rng.uniform(-3.0, 3.0, 50_000),
                        rng.uniform(-745.2, -708.0, 50_000),  # subnormal results
                        [0.0, -0.0, 1e-300, -1e-300, 709.782712893384, 709.7827128933841,
                         -745.1332191019411, -745.1332191019412, 1e308, -1e308]])  # fmt: skip
    out = np.empty_like(x)
    _exp_all(x, out)
    with np.errstate(over="ignore"):
        ref = np.exp(x)
    finite = np.isfinite(ref)
    assert _ulps(out[finite], ref[finite]).max() <= 1.0
    np.testing.assert_array_equal(out[~finite], ref[~finite])  # overflow: inf, as libm
    special = np.array([np.nan, np.inf, -np.inf])
    _exp_all(special, out[:3])
    np.testing.assert_array_equal(out[:3], [np.nan, np.inf, 0.0])
    # the same code run as Python (plain function)
    assert numerics.exp(1.0) == pytest.approx(np.e, rel=1e-16)


def test_atan_within_an_ulp_of_libm():
    rng = np.random.default_rng(2)
    x = np.concatenate([rng.standard_normal(100_000) * 10.0, 10.0 ** rng.uniform(-320, 308, 10_000),
                        -(10.0 ** rng.uniform(-320, 308, 10_000)),
                        [0.0, -0.0, np.inf, -np.inf, 0.66, 2.41421356237309504880]])  # fmt: skip
    out = np.empty_like(x)
    _atan_all(x, out)
    assert _ulps(out, np.arctan(x)).max() <= 1.0
    out = np.empty(1)
    _atan_all(np.array([np.nan]), out)
    assert np.isnan(out[0])


def test_hypot_within_an_ulp_of_libm_without_overflow_or_underflow():
    rng = np.random.default_rng(3)
    n = 100_000
    x = 10.0 ** rng.uniform(-323, 308, n) * rng.choice([-1.0, 1.0], n)
    y = 10.0 ** rng.uniform(-323, 308, n) * rng.choice([-1.0, 1.0], n)
    x[:1000] = rng.standard_normal(1000)
    y[:500] = 0.0
    out = np.empty(n)
    _hypot_all(x, y, out)
    assert _ulps(out, np.hypot(x, y)).max() <= 1.0
    out = np.empty(3)
    _hypot_all(np.array([1e308, 0.0, np.inf]), np.array([1e308, 0.0, 1.0]), out)
    np.testing.assert_array_equal(out, [np.hypot(1e308, 1e308), 0.0, np.inf])


def test_vectorisable_primitives_compile_without_calls():
    """exp, atan and hypot compile to vectorised loops without calls (libm's would be calls);
    compiled afresh here (the inspection of cached code is disabled)."""

    def exp_all(x, out):
        for k in range(x.size):
            out[k] = numerics.exp(x[k])

    def atan_all(x, out):
        for k in range(x.size):
            out[k] = numerics.atan(x[k])

    def hypot_all(x, out):
        for k in range(x.size):
            out[k] = numerics.hypot(x[k], out[k])

    x = np.linspace(-3.0, 3.0, 64)
    for func in (exp_all, atan_all, hypot_all):
        dispatcher = numba.njit(error_model="numpy")(func)
        dispatcher(x, np.ones(64))
        ir = dispatcher.inspect_llvm(dispatcher.signatures[0])
        body = ir[: ir.index("define", ir.index("define") + 1)]  # the kernel, not its wrapper
        assert not re.search(r"call [^@]*@(exp|atan|hypot)\b", body)
        assert "<8 x double>" in body or "<4 x double>" in body or "<2 x double>" in body


F64 = types.float64


@pytest.mark.parametrize(("law", "signature"), [
    (kalker_law, types.UniTuple(F64, 4)(F64, F64, types.boolean)),
    (falling_friction_factor, F64(F64, F64, F64)),
    (polach_contact_terms, types.UniTuple(F64, 7)(*[F64] * 9)),
    (polach_force, types.UniTuple(F64, 2)(*[F64] * 16)),
    (polach_law, types.UniTuple(F64, 2)(*[F64] * 17)),
    (wilac_law, types.UniTuple(F64, 2)(*[F64] * 13, types.float64[::1])),
])  # fmt: skip
def test_laws_compile_as_cfunc(law, signature):
    """The native FMUs compile the scalar laws ahead of time from numba.cfunc: float64
    arguments (and the packed WILAC array), tuple returns, no exceptions, no allocation."""
    cfunc = numba.cfunc(signature, error_model="numpy")(law)
    ir = cfunc.inspect_llvm()
    parts = ir.split("\ndefine ")[1:]
    names = [re.search(r"@([^\s(]+)\(", part).group(1) for part in parts]
    assert any(law.__name__ in name for name in names)
    for part, name in zip(parts, names, strict=True):
        if name.startswith("cfunc."):
            continue  # numba's C wrapper (it reports a failed call through Python)
        body = part[: part.index("\n}\n")]
        # no allocation (reference counts of the packed array are fine: none with numba.carray)
        assert "NRT_MemInfo_alloc" not in body, name
        assert "numba_do_raise" not in body and "@Py" not in body, name  # no exception path


@numerics.jit(nogil=True)
def _square_chunks(x, out, first, last):
    for c in range(first, last):
        for k in range(c * 7, min(c * 7 + 7, x.size)):
            out[k] = x[k] * x[k]
    return last - first


def test_run_chunks_from_many_threads_with_different_thread_counts():
    """Callers in several threads, each with its own numba.get_num_threads() (numba's setting
    is per thread), share the pool: every chunk is run exactly once, results are right."""
    x = np.arange(10_000, dtype=float)
    nchunk = -(-x.size // 7)
    errors = []

    def caller(nthreads):
        try:
            numba.set_num_threads(nthreads)
            for _ in range(20):
                out = np.full_like(x, np.nan)
                done = numerics.run_chunks(_square_chunks, (x, out), nchunk, True)
                assert sum(done) == nchunk
                np.testing.assert_array_equal(out, x * x)
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=caller, args=(1 + k % numba.config.NUMBA_NUM_THREADS,))
               for k in range(6)]  # fmt: skip
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors


def _marked_modules() -> set[Path]:
    """The package's modules that define or call compiled code through numerics."""
    found = set()
    for path in PACKAGE.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module == "railadhesion.numerics":
                found.add(path.resolve())
    return found


def test_cache_key_covers_every_kernel_source():
    """Every module that builds or calls compiled code through numerics is hashed into the
    cache directory's key (editing it gives every kernel a fresh cache)."""
    sources = set(numerics.kernel_sources())
    assert _marked_modules() <= sources
    assert Path(numerics.__file__).resolve() in sources
    for name in ("contact/kalker.py", "contact/friction.py", "models/polach.py",
                 "models/wilac.py", "models/wilac_parameters.py", "contact/fastsim.py"):
        assert (PACKAGE / name).resolve() in sources, name


def test_kernel_cache_lands_in_the_keyed_directory_and_follows_the_sources(tmp_path):
    """numba is given the cache directory through its public setting numba.config.CACHE_DIR
    while a dispatcher is created. This fails loudly if numba stops honouring it: the cache
    files must appear under <NUMBA_CACHE_DIR>/railadhesion/<key of the sources>."""
    module = tmp_path / "probe_kernel.py"
    module.write_text("from railadhesion.numerics import jit\n\n\n@jit\n"
                      "def twice(x):\n    return 2.0 * x\n")  # fmt: skip
    code = ("import probe_kernel; from railadhesion import numerics;"
            "print(probe_kernel.twice(3.0)); print(numerics.cache_directory())")
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               PYTHONPATH=os.pathsep.join([str(tmp_path), str(ROOT / "src"), *sys.path]))
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=600, check=True).stdout.split()  # fmt: skip
    assert out[0] == "6.0"
    keyed = Path(out[1])
    assert keyed.parent == tmp_path / "cache" / "railadhesion"
    assert len(keyed.name) == 16 and keyed.name == numerics.cache_directory().name
    assert list(keyed.rglob("probe_kernel.twice-*.nbi")), list(tmp_path.rglob("*"))
    # the user's own numba functions keep numba's setting (not redirected)
    user = tmp_path / "user_kernel.py"
    user.write_text("import numba\n\n\n@numba.njit(cache=True)\ndef f(x):\n    return x\n")
    subprocess.run([sys.executable, "-c", "import probe_kernel, user_kernel; user_kernel.f(1)"],
                   env=env, check=True, timeout=600)  # fmt: skip
    assert list((tmp_path / "cache").glob("*/user_kernel.f-*.nbi"))
    assert not list((tmp_path / "cache" / "railadhesion").rglob("user_kernel*"))


def test_sources_key_changes_with_a_kernel_source(monkeypatch, tmp_path):
    source = tmp_path / "law.py"
    source.write_text("x = 1\n")
    monkeypatch.setattr(numerics, "_PACKAGE", tmp_path)
    monkeypatch.setattr(numerics, "kernel_sources", lambda: [source])
    before = numerics._sources_key()
    source.write_text("x = 2\n")
    assert numerics._sources_key() != before


def _declared_bound(name: str) -> tuple[str, str]:
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    match = re.search(rf'"{name}>=([0-9.]+),<([0-9.]+)"', text)
    assert match, f"pyproject.toml must declare {name}>=low,<high"
    return match.group(1), match.group(2)


def _version(text: str) -> tuple[int, ...]:
    return tuple(int(part) for part in re.findall(r"\d+", text)[:3])


@pytest.mark.parametrize("name", ["numba", "llvmlite"])
def test_installed_numba_and_llvmlite_are_within_the_declared_bounds(name):
    """The kernels use numba's public API (its internals in _jit.py only, tests/test_jit.py),
    tested with the versions in the declared range; a newer numba or llvmlite must be tested
    before the bound is raised."""
    low, high = _declared_bound(name)
    installed = _version(metadata.version(name))
    assert _version(low) <= installed < _version(high), (name, installed, low, high)
