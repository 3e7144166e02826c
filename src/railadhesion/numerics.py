"""Ground floor of the compiled kernels: how a law is compiled, the shared numeric primitives,
the chunking and the thread pool. Every kernel module imports these; none copies them.

Importing this module does not import numba (``import railadhesion`` stays fast): numba is
imported when the first kernel is built with :func:`jit`.

**Laws and primitives** are plain Python functions of floats (and float64 arrays for packed
tables) decorated with :func:`jitable`. Such a function is registered with numba's public
extension API (``numba.extending.register_jitable``) when numba is first imported, so that
every compiled function can call it; the laws a batch loop calls are inlined at the call site
(numba's ``inline="always"``), so that the loop is one loop that LLVM can vectorise.
They must stay free of exceptions, allocations and Python objects, and return floats or
tuples of floats, so that ``numba.cfunc`` can compile them too (the native FMUs do). From
Python, call the compiled entry points of the kernel modules (e.g.
:func:`railadhesion.models.kernels.polach_scalar`), not the plain functions.

**Compiled entry points** (the loops over contacts, the jitted functions of the stable numba
API) are built with :func:`jit` (at once: the module imports numba) or :func:`kernel` (on
first call: for modules that ``import railadhesion`` loads): ``numba.njit`` with
``error_model="numpy"`` and ``cache=True``, their cache files in one directory per version of
the package's kernel sources (:func:`cache_directory`; why: ``docs/kernels.md``, "The on-disk
cache").

**Numeric primitives**: :func:`exp`, :func:`atan`, :func:`atan_nonneg` and :func:`hypot`
agree with libm's within an ulp (``tests/test_numerics.py``) but compile to code without
calls or branches, which LLVM vectorises (libm's functions are calls).

**Chunks and threads**: batch kernels work in chunks of :data:`CHUNK` contacts;
:func:`run_chunks` runs a kernel's chunks on ``numba.get_num_threads()`` threads of a
process-wide pool (the kernels release the GIL).
"""

from __future__ import annotations

import functools
import hashlib
import itertools
import math
import os
import sys
import threading
from pathlib import Path

import numpy as np

__all__ = [
    "CHUNK",
    "FINITE",
    "FRACTION",
    "NONNEGATIVE",
    "POISSON",
    "POSITIVE",
    "as_scalars",
    "atan",
    "atan_nonneg",
    "cache_directory",
    "chunk_of",
    "count_outside",
    "exp",
    "fill",
    "fill_row",
    "flatten",
    "hypot",
    "jit",
    "jitable",
    "kernel",
    "load_numba",
    "load_row",
    "output_chunk",
    "read_only",
    "run_chunks",
]

#: Contacts per chunk of the batch kernels (a chunk's scratch rows stay in the level-2 cache).
CHUNK = 512

# --- laws and primitives: plain functions that compiled code calls ---------------------------

_JITABLE: list = []  # (function, inline) in the order of definition
_STATE = {"numba": None}
_LOCK = threading.RLock()


def jitable(func=None, *, inline: str = "never"):
    """Mark ``func`` (a plain Python function) as callable from compiled code.

    The function is returned unchanged. When numba is imported (by the first :func:`jit`),
    it is registered with ``numba.extending.register_jitable`` with ``error_model="numpy"``
    (a division by zero gives inf or NaN, as in NumPy, never an exception) and ``inline``:
    ``"never"`` (the default) compiles it once, and LLVM inlines it where it is small enough
    (the primitives below); ``"always"`` inlines it into numba's IR wherever it is called, so
    that a loop calling a large law is one loop that LLVM can vectorise. An ``"always"``
    function should be called once per compiled function (numba warns when it inlines the
    same function twice into one function).
    """

    def mark(f):
        with _LOCK:
            _JITABLE.append((f, inline))
            if _STATE["numba"] is not None:
                _register(f, inline)
        return f

    return mark if func is None else mark(func)


def _register(func, inline: str) -> None:
    from numba.extending import register_jitable

    register_jitable(inline=inline, error_model="numpy")(func)


def load_numba():
    """numba, imported once, with every :func:`jitable` function registered (call it before
    compiling your own numba code that calls a law, e.g. ``numba.cfunc(...)(polach_law)``;
    :func:`jit` and importing :mod:`railadhesion.models.kernels` do it)."""
    with _LOCK:
        if _STATE["numba"] is None:
            import numba

            for func, inline in _JITABLE:
                _register(func, inline)
            _STATE["numba"] = numba
        return _STATE["numba"]


def jit(func=None, **options):
    """``numba.njit`` with the package's settings: ``cache=True`` in :func:`cache_directory`,
    ``error_model="numpy"`` unless ``options`` say otherwise; ``options`` are passed on (e.g.
    ``nogil=True``). ``signature`` (a numba signature string) compiles that version only, when
    the dispatcher is built: other argument types are converted to it by numba's dispatcher,
    never compiled anew (numba's eager compilation, ``numba.njit(signature)``).

    The cache directory is given to numba through its public setting ``numba.config.CACHE_DIR``
    while the dispatcher is created (numba picks a function's cache location then), and the
    user's setting is restored at once: the user's own functions are not affected.
    """

    flags = {"error_model": "numpy", **options, "cache": True}
    signature = flags.pop("signature", None)

    def build(f):
        numba = load_numba()
        with _LOCK:
            saved = numba.config.CACHE_DIR
            numba.config.CACHE_DIR = str(cache_directory())
            try:
                if signature is not None:
                    return numba.njit(signature, **flags)(f)
                return numba.njit(**flags)(f)
            finally:
                numba.config.CACHE_DIR = saved

    return build if func is None else build(func)


class Kernel:
    """A compiled entry point built on its first use (:func:`kernel`): callable from Python
    like the numba dispatcher it wraps (:attr:`dispatcher`). Compiled code must not call it:
    call a :func:`jitable` function from compiled code."""

    def __init__(self, py_func, options):
        self.py_func = py_func
        self.options = options
        self._dispatcher = None
        functools.update_wrapper(self, py_func)

    @property
    def dispatcher(self):
        """The numba dispatcher (imports numba and builds it on first access)."""
        if self._dispatcher is None:
            self._dispatcher = jit(self.py_func, **self.options)
        return self._dispatcher

    def __call__(self, *args):
        return self.dispatcher(*args)


def kernel(func=None, **options):
    """Like :func:`jit`, but numba is imported and the dispatcher built on the first call
    (:class:`Kernel`): for the compiled loops of modules that ``import railadhesion`` loads,
    which must not import numba."""

    def wrap(f):
        return Kernel(f, options)

    return wrap if func is None else wrap(func)


# --- the on-disk cache ----------------------------------------------------------------------

_PACKAGE = Path(__file__).resolve().parent
#: A module whose source contains this text builds or calls compiled code of this module.
_KERNEL_MARK = b"railadhesion.numerics"


def kernel_sources() -> list[Path]:
    """The package's source files that define or call compiled code through this module
    (they mention ``railadhesion.numerics``), this module first."""
    found = [Path(__file__).resolve()]
    for path in sorted(_PACKAGE.rglob("*.py")):
        if path != found[0] and _KERNEL_MARK in path.read_bytes():
            found.append(path)
    return found


def _sources_key() -> str:
    digest = hashlib.sha256()
    for path in kernel_sources():
        digest.update(path.relative_to(_PACKAGE).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def _writable(path: Path) -> bool:
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return os.access(path, os.W_OK)


def _user_cache_root() -> Path:
    if sys.platform == "win32":
        return Path(os.environ.get("LOCALAPPDATA", Path.home() / "AppData" / "Local"))
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches"
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")


_CACHE: dict = {}


def cache_directory() -> Path:
    """Directory of the compiled kernels' cache files: ``<base>/<key>``, ``key`` a hash of
    :func:`kernel_sources`, so that editing any law or kernel gives every kernel a fresh
    cache (numba alone keys a cached function on its own source file only, and would load a
    kernel compiled against an older version of a law it inlines from another module).

    ``base``: ``$NUMBA_CACHE_DIR/railadhesion`` if the user set numba's cache directory, else
    the package's ``__pycache__/numba`` if writable, else the user's cache directory
    (``~/.cache/railadhesion/numba`` on Linux). Computed once per process.
    """
    with _LOCK:
        if "dir" not in _CACHE:
            user = os.environ.get("NUMBA_CACHE_DIR", "")
            if user:
                bases = [Path(user) / "railadhesion"]
            else:
                bases = [_PACKAGE / "__pycache__" / "numba",
                         _user_cache_root() / "railadhesion" / "numba"]  # fmt: skip
            base = next((b for b in bases if _writable(b)), bases[-1])
            _CACHE["dir"] = base / _sources_key()
        return _CACHE["dir"]


# --- numeric primitives ---------------------------------------------------------------------

# exp(x) = 2^n exp(r): n = round(x / ln 2) by adding 1.5 2^52 (n then sits in the low bits of
# the sum, |n| < 2^51, read as an integer), r = x - n ln 2 with ln 2 split in two (fdlibm's
# constants: n ln2_hi is exact for |n| < 2^11), exp(r) by its Taylor series to r^13
# (|r| <= 0.35: truncation below 1e-17 relative); 2^n = 2^(n1) 2^(n - n1), n1 = floor(n/2),
# two normal powers of two built from their bits, so that results down to the subnormals
# are rounded once and overflow gives inf. Integer SIMD operations do the bit work.
_LOG2E = 1.4426950408889634
_LN2_HI = 6.93147180369123816490e-01
_LN2_LO = 1.90821492927058770002e-10
_SHIFTER = 6755399441055744.0  # 1.5 * 2^52
_SHIFTER_BITS = 0x4338000000000000
(_E2, _E3, _E4, _E5, _E6, _E7, _E8, _E9, _E10, _E11, _E12,
 _E13) = (1.0 / math.factorial(k) for k in range(2, 14))  # fmt: skip


@jitable
def exp(x):
    """e^x for every float x (inf above 709.78, 0 below -745.13, subnormals rounded once,
    NaN for NaN), within an ulp of libm's ``exp``; compiles without calls or branches."""
    xc = min(max(x, -746.0), 710.0)
    t = xc * _LOG2E + _SHIFTER
    nn = t - _SHIFTER
    r = (xc - nn * _LN2_HI) - nn * _LN2_LO
    p = _E13 * r + _E12
    p = p * r + _E11
    p = p * r + _E10
    p = p * r + _E9
    p = p * r + _E8
    p = p * r + _E7
    p = p * r + _E6
    p = p * r + _E5
    p = p * r + _E4
    p = p * r + _E3
    p = p * r + _E2
    p = p * r + 1.0
    p = p * r + 1.0
    n = np.float64(t).view(np.int64) - _SHIFTER_BITS
    n1 = n >> 1
    s1 = np.int64((n1 + 1023) << 52).view(np.float64)
    s2 = np.int64((n - n1 + 1023) << 52).view(np.float64)
    res = (p * s1) * s2
    return res if x == x else x


# arctan: range reduction and the rational approximation on [0, 0.66] of S. L. Moshier's
# Cephes library (atan.c); within an ulp of libm's atan.
_AT_P0, _AT_P1, _AT_P2, _AT_P3, _AT_P4 = (
    -8.750608600031904122785e-1, -1.615753718733365076637e1, -7.500855792314704667340e1,
    -1.228866684490136173410e2, -6.485021904942025371773e1)  # fmt: skip
_AT_Q0, _AT_Q1, _AT_Q2, _AT_Q3, _AT_Q4 = (
    2.485846490142306297962e1, 1.650270098316988542046e2, 4.328810604912902668951e2,
    4.853903996359136964868e2, 1.945506571482613964425e2)  # fmt: skip
_AT_MOREBITS = 6.123233995736765886130e-17
_AT_T3P8 = 2.41421356237309504880  # tan(3 pi/8)
_HALF_PI = 0.5 * math.pi
_QUARTER_PI = 0.25 * math.pi


@jitable
def atan_nonneg(x):
    """arctan(x) for x >= 0 (and inf), within an ulp of libm's; no calls, no branches."""
    big = x > _AT_T3P8
    mid = x > 0.66
    # the reduced argument -1/x, (x - 1)/(x + 1) or x as one division (x/1 is x exactly): a
    # loop over lanes, vectorised, computes both sides of a select, and divides only once
    num = -1.0 if big else (x - 1.0 if mid else x)
    den = x if big else (x + 1.0 if mid else 1.0)
    xr = num / den
    y0 = _HALF_PI if big else (_QUARTER_PI if mid else 0.0)
    extra = _AT_MOREBITS if big else (0.5 * _AT_MOREBITS if mid else 0.0)
    z = xr * xr
    pz = (((_AT_P0 * z + _AT_P1) * z + _AT_P2) * z + _AT_P3) * z + _AT_P4
    qz = ((((z + _AT_Q0) * z + _AT_Q1) * z + _AT_Q2) * z + _AT_Q3) * z + _AT_Q4
    return y0 + ((xr * (z * pz / qz) + xr) + extra)


@jitable
def atan(x):
    """arctan(x) for every float x, within an ulp of libm's; no calls."""
    y = atan_nonneg(abs(x))
    return -y if x < 0.0 else y


_HYPOT_BIG = 2.0**500
_HYPOT_SMALL = 2.0**-500
_HYPOT_DOWN = 2.0**-600
_HYPOT_UP = 2.0**600


@jitable
def hypot(x, y):
    """sqrt(x^2 + y^2) without overflow or loss to underflow: the plain formula where the
    larger magnitude is in [2^-500, 2^500] (then it agrees with libm's hypot to an ulp), else
    the formula on x, y scaled by a power of two; no calls, no branches."""
    m = max(abs(x), abs(y))
    big = m > _HYPOT_BIG
    small = m < _HYPOT_SMALL
    s = _HYPOT_DOWN if big else (_HYPOT_UP if small else 1.0)
    back = _HYPOT_UP if big else (_HYPOT_DOWN if small else 1.0)  # 1/s, exact
    xs = x * s
    ys = y * s
    return math.sqrt(xs * xs + ys * ys) * back


# --- chunks -----------------------------------------------------------------------------------


@jitable
def fill(out, value, m):
    """out[:m] = value (a loop: a slice assignment would compile numba's shape checks)."""
    for k in range(m):
        out[k] = value


@jitable
def chunk_of(arr, repeated, lo, hi):
    """arr[lo:hi], or ``repeated[:hi - lo]`` (arr's one value repeated, filled by the caller)
    if arr holds a single value shared by every contact."""
    if arr.size == 1:
        return repeated[: hi - lo]
    return arr[lo:hi]


@jitable
def fill_row(buf, row, x, count):
    """The first ``count`` values of row ``row`` of a chunk buffer (rows of :data:`CHUNK`
    values in the 1-d ``buf``) = the value of ``x`` if it holds one value for every contact
    (once per call; else nothing)."""
    if x.size == 1:
        dst = buf[row * CHUNK : row * CHUNK + count]  # a view: indices from 0, no wraparound
        value = x[0]
        for k in range(count):
            dst[k] = value


@jitable
def load_row(buf, row, x, lo, m):
    """Row ``row`` of a chunk buffer = x[lo:lo + m] if x holds one value per contact (the
    rows of single values are filled once, by :func:`fill_row`)."""
    if x.size > 1:
        dst = buf[row * CHUNK : row * CHUNK + m]
        src = x[lo : lo + m]
        for k in range(m):
            dst[k] = src[k]


@jitable
def output_chunk(fx, fy, lo, m, ok):
    """Views of chunk lo to lo + m of the outputs fx, fy, filled with NaN if not ``ok`` (an
    input out of range: the caller raises the error naming it)."""
    ox = fx[lo : lo + m]
    oy = fy[lo : lo + m]
    if not ok:
        fill(ox, math.nan, m)
        fill(oy, math.nan, m)
    return ox, oy


# Allowed ranges, as (low, low if closed else NaN, high, high if closed else NaN): x is in range
# if (x > low or x == low_closed) and (x < high or x == high_closed); NaN is never in range.
FINITE = (-math.inf, math.nan, math.inf, math.nan)
POSITIVE = (0.0, math.nan, math.inf, math.nan)
NONNEGATIVE = (0.0, 0.0, math.inf, math.nan)
FRACTION = (0.0, math.nan, 1.0, 1.0)  # (0, 1]
POISSON = (0.0, 0.0, 0.5, 0.5)  # [0, 0.5]


@jitable
def count_outside(x, bounds, lo, m):
    """Number of values of x[lo:lo + m] (or of x[0], one value for every contact) outside
    ``bounds`` (:data:`FINITE` and the like); vectorised."""
    low, low_closed, high, high_closed = bounds
    values = x[lo : lo + m] if x.size > 1 else x[:1]  # a view: indices from 0
    nbad = 0
    for k in range(values.size):
        v = values[k]
        nbad += 0 if ((v > low) | (v == low_closed)) & ((v < high) | (v == high_closed)) else 1
    return nbad


def as_scalars(values) -> tuple | list | None:
    """``values`` for a scalar fast path (floats), or ``None`` if any of them is not a real
    scalar.

    Python and NumPy scalars and 0-d arrays qualify (no array work is then needed); ``float``
    and ``numpy.float64`` are passed through, ints, other NumPy scalars and 0-d arrays become
    floats (so that the compiled kernels see one signature).
    """
    for v in values:  # the common case first: Python floats only
        if type(v) is not float:
            break
    else:
        return values
    scalars = []
    for v in values:
        t = type(v)
        if t is float or t is np.float64:
            scalars.append(v)
        elif t is int:
            scalars.append(float(v))
        elif isinstance(v, np.generic | np.ndarray) and v.ndim == 0 and v.dtype.kind in "fiu":
            scalars.append(float(v))
        else:
            return None
    return scalars


def read_only(x: np.ndarray) -> np.ndarray:
    """A read-only view of ``x`` (the kernels are compiled for read-only inputs only: numba
    compiles anew for each combination of read-only and writeable arguments)."""
    if x.flags.writeable:
        x = x.view()
        x.flags.writeable = False
    return x


def flatten(arrays):
    """Broadcast float64 arrays to one shape; return (shape, n, 1-d read-only arrays of
    length n or 1).

    Arrays of one element stay of length 1 and arrays of the full shape are raveled (no copy
    if contiguous); only partly broadcast arrays are materialised. The caller's arrays are
    untouched (the read-only arrays are views).
    """
    shape = None
    for x in arrays:  # the common case: the arrays that are not 0-d all have one shape
        if x.ndim:
            if shape is None:
                shape = x.shape
            elif x.shape != shape:
                shape = np.broadcast_shapes(*(y.shape for y in arrays))
                break
    if shape is None:
        shape = ()
    n = math.prod(shape)
    flat = []
    for x in arrays:
        if x.size == 1:
            x = x.reshape(1)
        elif x.shape == shape:
            x = np.ascontiguousarray(x).reshape(-1)
        else:
            x = np.ascontiguousarray(np.broadcast_to(x, shape)).reshape(-1)
        flat.append(read_only(x))
    return shape, n, flat


# --- threads ----------------------------------------------------------------------------------

#: Tasks per thread of a parallel call, handed out one by one: a thread that gets ahead, or one
#: that a busy machine holds up, is balanced by the others.
TASKS_PER_THREAD = 4
_POOL: dict = {}


def _pool():
    """The process's pool of kernel threads, created on first use (under a lock) with
    ``numba.config.NUMBA_NUM_THREADS - 1`` threads at most (``numba.set_num_threads`` cannot
    ask for more), started as needed; anew in a forked child, whose copy has no threads. It
    is never replaced while in use: callers asking for fewer threads submit fewer tasks."""
    from concurrent.futures import ThreadPoolExecutor

    with _LOCK:
        if _POOL.get("pid") != os.getpid():
            workers = max(load_numba().config.NUMBA_NUM_THREADS - 1, 1)
            _POOL["pool"] = ThreadPoolExecutor(max_workers=workers,
                                               thread_name_prefix="railadhesion-kernel")
            _POOL["pid"] = os.getpid()
        return _POOL["pool"]


def run_chunks(func, args, nchunk: int, parallel: bool) -> list:
    """Run ``func(*args, first, last)`` over the chunks ``0`` to ``nchunk - 1``; return the
    results of the calls.

    ``parallel`` False, or one thread (``numba.get_num_threads()``): one call. Else the chunks
    are split into up to :data:`TASKS_PER_THREAD` tasks per thread, taken one by one by the
    calling thread and ``numba.get_num_threads() - 1`` threads of the pool (``func`` must
    release the GIL: ``jit(nogil=True)``). Safe to call from several threads at once, with
    different thread counts.
    """
    nthreads = load_numba().get_num_threads() if parallel else 1
    if nthreads <= 1 or nchunk < 2:
        return [func(*args, 0, nchunk)]
    ntask = min(nchunk, TASKS_PER_THREAD * nthreads)
    bounds = [nchunk * t // ntask for t in range(ntask + 1)]
    tasks = itertools.count()  # next() is atomic under the GIL
    results = [None] * ntask

    def work():
        for t in iter(tasks.__next__, None):
            if t >= ntask:
                return
            results[t] = func(*args, bounds[t], bounds[t + 1])

    pool = _pool()
    helpers = [pool.submit(work) for _ in range(min(nthreads, ntask) - 1)]
    work()
    for helper in helpers:
        helper.result()
    return results
