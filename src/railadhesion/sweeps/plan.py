"""A sweep plan: model, labelled grid, fixed inputs and chunking; and the evaluation of a chunk.

Everything a chunk task needs is in the :class:`SweepPlan` (picklable, no open files), so a
chunk is a pure function of the plan and its index: recomputing it gives identical values.
"""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from railadhesion.sweeps.models import DIMENSIONS, LABEL_DIMENSIONS, SweepModel

__all__ = ["SweepPlan", "plan_sweep", "full_factorial", "monte_carlo", "DEFAULT_CHUNK_POINTS"]

#: Default number of grid points per chunk (about 2 MB per float64 variable).
DEFAULT_CHUNK_POINTS = 2**18

#: The per-point failure flag every map carries besides the model's outputs.
ERROR_VARIABLE = ("uint8", "", "1 where the model raised for this point (message in attrs), "
                  "else 0")  # fmt: skip


def _as_coordinate(dim: str, values, where: str) -> np.ndarray:
    if dim in LABEL_DIMENSIONS:
        if isinstance(values, str):
            values = [values]
        arr = np.asarray([str(v) for v in values])
    else:
        try:
            arr = np.atleast_1d(np.asarray(values, dtype=float))
        except (TypeError, ValueError):
            raise ValueError(f"{where}: expected numbers, got {values!r}") from None
        if arr.ndim != 1:
            raise ValueError(f"{where}: expected a 1-D sequence of values, got shape {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{where}: values must be finite, got {arr[~np.isfinite(arr)][:3]}")
    if arr.size == 0:
        raise ValueError(f"{where}: expected at least one value")
    if len(np.unique(arr)) != arr.size:
        raise ValueError(f"{where}: values must be unique (each grid point once)")
    return arr


def _default_chunks(shape: tuple[int, ...], target: int) -> tuple[int, ...]:
    """Chunk sizes: leading dimensions whole while the chunk stays within ``target`` points."""
    out, room = [], max(1, int(target))
    for n in shape:
        c = max(1, min(n, room))
        out.append(c)
        room = max(1, room // c)
    return tuple(out)


@dataclass(frozen=True, eq=False)
class SweepPlan:
    """What to compute: a model over a labelled grid, cut into chunks.

    Build it with :func:`plan_sweep`. ``dims`` and ``coords`` give the grid in order,
    ``chunk_shape`` the size of a chunk along each dimension (the last chunk along a dimension
    may be smaller), ``fixed`` the values of the model inputs that are not swept.
    """

    model: SweepModel
    dims: tuple[str, ...]
    coords: tuple[np.ndarray, ...]
    fixed: dict
    chunk_shape: tuple[int, ...]
    along: dict = field(default_factory=dict)
    #: Threads for the model's compiled kernels within one chunk (numba), or None for
    #: numba's default. Dask parallelises over chunks, so run_sweep sets 1 under its
    #: parallel schedulers (no oversubscription). Does not change the values.
    kernel_threads: int | None = None

    @property
    def variables(self) -> dict[str, tuple[str, str, str]]:
        """Stored variables: name -> (dtype, units, description); the model's outputs, error."""
        out = {k: ("float64", u, t) for k, (u, t) in self.model.outputs.items()}
        out["error"] = ERROR_VARIABLE
        return out

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(c) for c in self.coords)

    @property
    def size(self) -> int:
        return math.prod(self.shape)

    @property
    def chunks(self) -> tuple[tuple[int, ...], ...]:
        """Dask-style chunk sizes along each dimension."""
        out = []
        for n, c in zip(self.shape, self.chunk_shape, strict=True):
            out.append((c,) * (n // c) + ((n % c,) if n % c else ()))
        return tuple(out)

    @property
    def chunk_grid(self) -> tuple[int, ...]:
        """Number of chunks along each dimension."""
        return tuple(len(c) for c in self.chunks)

    @property
    def n_chunks(self) -> int:
        return math.prod(self.chunk_grid)

    def chunk_indices(self):
        """All chunk indices, in C order."""
        return itertools.product(*(range(n) for n in self.chunk_grid))

    def chunk_slices(self, index) -> tuple[slice, ...]:
        return tuple(
            slice(i * c, min((i + 1) * c, n))
            for i, c, n in zip(index, self.chunk_shape, self.shape, strict=True)
        )

    @cached_property
    def fingerprint(self) -> str:
        """SHA-256 of everything that determines the values (model, grid, fixed, chunks)."""
        doc = {
            "model": self.model.describe(),
            "model_class": type(self.model).__name__,
            "dims": list(self.dims),
            "coords": [c.tolist() for c in self.coords],
            "fixed": {k: (v if isinstance(v, str) else float(v)) for k, v in self.fixed.items()},
            "chunk_shape": list(self.chunk_shape),
            "along": {k: [d, v.tolist()] for k, (d, v) in sorted(self.along.items())},
        }
        text = json.dumps(doc, sort_keys=True, default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    def __dask_tokenize__(self):
        return ("railadhesion.SweepPlan", self.fingerprint)

    def point(self, index, flat: int) -> dict:
        """Coordinates of point ``flat`` (C order) of chunk ``index``."""
        sl = self.chunk_slices(index)
        sub = np.unravel_index(flat, tuple(s.stop - s.start for s in sl))
        return {
            d: _plain(c[s.start + k]) for d, c, s, k in zip(self.dims, self.coords, sl, sub,
                                                             strict=True)
        }

    def evaluate_chunk(self, index) -> tuple[dict[str, np.ndarray], list]:
        """Evaluate chunk ``index``: the arrays of :attr:`variables` and the failed points.

        A block is evaluated by one broadcasting call of the model; if that raises, the block
        is bisected until the failing points are isolated, each recorded with its message
        (``[flat index within the chunk, "ExceptionType: message"]``).
        """
        with _kernel_threads(self.kernel_threads):
            return self._evaluate_chunk(index)

    def _evaluate_chunk(self, index):
        sl = self.chunk_slices(index)
        block = {d: c[s] for d, c, s in zip(self.dims, self.coords, sl, strict=True)}
        shape = tuple(len(v) for v in block.values())
        out = {name: np.full(shape, np.nan) for name in self.model.outputs}
        out["error"] = np.zeros(shape, dtype=np.uint8)
        errors: list = []
        label_dims = [d for d in self.dims if d in LABEL_DIMENSIONS]
        numeric_axes = [i for i, d in enumerate(self.dims) if d not in LABEL_DIMENSIONS]
        for combo in itertools.product(*(range(len(block[d])) for d in label_dims)):
            labels = dict(self.model.labels)
            labels.update({k: v for k, v in self.fixed.items() if k in LABEL_DIMENSIONS})
            where = [slice(None)] * len(self.dims)
            for d, i in zip(label_dims, combo, strict=True):
                labels[d] = str(block[d][i])
                where[self.dims.index(d)] = slice(i, i + 1)
            region = tuple((s.start or 0, s.stop) if s.stop is not None else (0, shape[k])
                           for k, s in enumerate(where))  # fmt: skip
            self._evaluate_region(block, labels, numeric_axes, region, out, errors, shape)
        return out, errors

    def _evaluate_region(self, block, labels, numeric_axes, region, out, errors, shape):
        ndim = len(self.dims)
        values = {}
        for name, default in self.model.inputs.items():
            if name in self.along:  # a scenario input: varies along its scenario dimension
                dim, column = self.along[name]
                k = self.dims.index(dim)
                lo, hi = region[k]
                v = column[block[dim][lo:hi]]  # the scenario coordinate is 0 .. n-1
                values[name] = v.reshape((1,) * k + (hi - lo,) + (1,) * (ndim - k - 1))
            elif name in block:
                k = self.dims.index(name)
                lo, hi = region[k]
                v = block[name][lo:hi].astype(float)
                values[name] = v.reshape((1,) * k + (hi - lo,) + (1,) * (ndim - k - 1))
            else:
                values[name] = float(self.fixed.get(name, default))
        target = tuple(slice(lo, hi) for lo, hi in region)
        rshape = tuple(hi - lo for lo, hi in region)
        if getattr(self.model, "pointwise", False) and math.prod(rshape) > 1:
            # one task call per point (e.g. a braking simulation): failures are isolated
            # directly, without bisecting.
            for sub in np.ndindex(*rshape):
                point = tuple((lo + k, lo + k + 1) for (lo, _), k in zip(region, sub,
                                                                          strict=True))
                self._evaluate_region(block, labels, numeric_axes, point, out, errors, shape)
            return
        try:
            results = self.model.evaluate(values, labels)
        except Exception as exc:  # noqa: BLE001 - any failure of a point is recorded, not fatal
            sizes = [(rshape[k], k) for k in numeric_axes if rshape[k] > 1]
            if not sizes:
                out["error"][target] = 1
                flat = int(np.ravel_multi_index(tuple(lo for lo, _ in region), shape))
                errors.append([flat, f"{type(exc).__name__}: {exc}"])
                return
            _, k = max(sizes)
            lo, hi = region[k]
            mid = (lo + hi) // 2
            for part in ((lo, mid), (mid, hi)):
                sub = list(region)
                sub[k] = part
                self._evaluate_region(block, labels, numeric_axes, tuple(sub), out, errors,
                                      shape)  # fmt: skip
            return
        for name, value in zip(self.model.outputs, results, strict=True):
            out[name][target] = np.broadcast_to(value, rshape)


@contextlib.contextmanager
def _kernel_threads(n: int | None):
    """Limit numba's threads for this thread (numba's setting is thread-local)."""
    if n is None:
        yield
        return
    try:
        import numba
    except ImportError:  # pragma: no cover - numba is a dependency
        yield
        return
    before = numba.get_num_threads()
    numba.set_num_threads(min(n, numba.config.NUMBA_NUM_THREADS))
    try:
        yield
    finally:
        numba.set_num_threads(before)


def _plain(x):
    return x.item() if hasattr(x, "item") else x


def plan_sweep(model: SweepModel, grid, *, fixed=None, chunks=None,
               chunk_points: int = DEFAULT_CHUNK_POINTS) -> SweepPlan:  # fmt: skip
    """Validate a sweep and cut it into chunks.

    Parameters
    ----------
    model : SweepModel
        E.g. :class:`~railadhesion.sweeps.models.WilacSweep`.
    grid : mapping of str to array_like
        The swept inputs in dimension order, e.g. ``{"creep_long": ..., "speed": ...}``;
        numeric values in SI units (water flow in µl/s), labels as strings. Values must be
        unique.
    fixed : mapping, optional
        Values of model inputs that are not swept (e.g. ``{"speed": 5.0}``).
    chunks : mapping of str to int, optional
        Chunk size along some dimensions; the others are chosen to give about
        ``chunk_points`` points per chunk (leading dimensions whole first).
    chunk_points : int, optional
        Target number of points per chunk.

    Raises
    ------
    ValueError
        Naming the grid dimension or fixed input that is wrong, or the input that is missing.
    """
    if not isinstance(model, SweepModel):
        raise ValueError(f"model: expected a SweepModel, got {type(model).__name__}")
    if not grid:
        raise ValueError("grid: expected at least one dimension")
    fixed = dict(fixed or {})
    allowed = set(model.inputs) | set(model.labels)
    dims, coords, along = [], [], {}
    for dim, values in grid.items():
        if isinstance(values, Mapping):
            n = _scenario_dimension(model, dim, values, along, allowed)
            dims.append(dim)
            coords.append(np.arange(n))
            continue
        if dim not in allowed:
            raise ValueError(
                f"grid.{dim}: not an input of the {model.name!r} model; allowed: "
                f"{sorted(allowed)}"
            )
        coord = _as_coordinate(dim, values, f"grid.{dim}")
        if dim in model.labels:
            for label in coord:
                try:
                    model.check_label(dim, str(label))
                except ValueError as exc:
                    raise ValueError(f"grid.{dim}: {exc}") from None
        dims.append(dim)
        coords.append(coord)
    for name, value in fixed.items():
        if name not in allowed:
            raise ValueError(
                f"fixed.{name}: not an input of the {model.name!r} model; allowed: "
                f"{sorted(allowed)}"
            )
        if name in dims or name in along:
            raise ValueError(f"fixed.{name}: also swept in the grid; give it in one place only")
        if name in model.labels:
            model.check_label(name, str(value))
        else:
            try:
                x = float(value)
            except (TypeError, ValueError):
                raise ValueError(f"fixed.{name}: expected a number, got {value!r}") from None
            if not math.isfinite(x):
                raise ValueError(f"fixed.{name}: expected a finite number, got {value!r}")
    missing = [k for k, v in model.inputs.items()
               if v is None and k not in dims and k not in fixed and k not in along]  # fmt: skip
    if missing:
        raise ValueError(
            f"grid: the {model.name!r} model needs {missing}: sweep them (grid) or fix them "
            "(fixed)"
        )
    shape = tuple(len(c) for c in coords)
    chunks = dict(chunks or {})
    for dim, size in chunks.items():
        if dim not in dims:
            raise ValueError(f"chunks.{dim}: not a grid dimension; dimensions: {dims}")
        if isinstance(size, bool) or not isinstance(size, int | np.integer) or size < 1:
            raise ValueError(f"chunks.{dim}: expected an integer >= 1, got {size!r}")
    if isinstance(chunk_points, bool) or not isinstance(chunk_points, int) or chunk_points < 1:
        raise ValueError(f"chunk_points: expected an integer >= 1, got {chunk_points!r}")
    free = [n for d, n in zip(dims, shape, strict=True) if d not in chunks]
    given = math.prod(min(int(chunks[d]), n) for d, n in zip(dims, shape, strict=True)
                      if d in chunks)  # fmt: skip
    auto = iter(_default_chunks(tuple(free), max(1, chunk_points // given)))
    chunk_shape = tuple(
        min(int(chunks[d]), n) if d in chunks else next(auto)
        for d, n in zip(dims, shape, strict=True)
    )
    return SweepPlan(model, tuple(dims), tuple(coords), fixed, chunk_shape, along)


def _scenario_dimension(model, dim, columns, along, allowed) -> int:
    """Check a scenario dimension (inputs varying together along ``dim``); its length."""
    if dim in allowed:
        raise ValueError(f"grid.{dim}: a scenario dimension needs a name that is not an input "
                         "(e.g. 'scenario' or 'sample')")  # fmt: skip
    if not columns:
        raise ValueError(f"grid.{dim}: expected at least one input varying along it")
    n = None
    for name, values in columns.items():
        where = f"grid.{dim}.{name}"
        if name not in model.inputs:
            raise ValueError(f"{where}: not a numeric input of the {model.name!r} model; "
                             f"inputs: {sorted(model.inputs)}")  # fmt: skip
        if name in along:
            raise ValueError(f"{where}: already varies along {along[name][0]!r}")
        try:
            arr = np.asarray(values, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"{where}: expected numbers") from None
        if arr.ndim != 1 or arr.size == 0 or not np.all(np.isfinite(arr)):
            raise ValueError(f"{where}: expected a non-empty 1-D sequence of finite numbers")
        if n is not None and arr.size != n:
            raise ValueError(f"{where}: {arr.size} values, but the other inputs along {dim!r} "
                             f"have {n}")  # fmt: skip
        n = arr.size
        along[name] = (dim, arr)
    return n


def full_factorial(**axes) -> dict:
    """A full-factorial design: every combination of the given values (the plain grid).

    >>> list(full_factorial(speed=[5.0, 10.0], water_flow=[0.0, 25.0]))
    ['speed', 'water_flow']
    """
    return {name: np.atleast_1d(np.asarray(v)) for name, v in axes.items()}


def monte_carlo(n: int, seed: int, dim: str = "sample", **distributions) -> dict:
    """A Monte Carlo design: ``n`` scenarios along dimension ``dim``, inputs drawn at random.

    Parameters
    ----------
    n : int
        Number of scenarios.
    seed : int
        Seed of :func:`numpy.random.default_rng`: the same seed gives the same design.
    dim : str, optional
        Name of the scenario dimension.
    **distributions
        Per input: ``("uniform", low, high)``, ``("normal", mean, sd)``,
        ``("lognormal", mean_of_log, sd_of_log)`` or ``("choice", [values])``. Inputs are
        drawn in the order given.

    Returns
    -------
    dict
        ``{dim: {input: values}}``, to be merged into a grid for :func:`plan_sweep`.

    Examples
    --------
    >>> d = monte_carlo(3, seed=1, speed=("uniform", 5.0, 40.0))
    >>> d["sample"]["speed"].round(2)
    array([22.91, 38.27, 10.05])
    """
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"n: expected an integer >= 1, got {n!r}")
    rng = np.random.default_rng(seed)
    columns = {}
    for name, spec in distributions.items():
        kind, *args = spec
        if kind == "uniform":
            columns[name] = rng.uniform(args[0], args[1], n)
        elif kind == "normal":
            columns[name] = rng.normal(args[0], args[1], n)
        elif kind == "lognormal":
            columns[name] = rng.lognormal(args[0], args[1], n)
        elif kind == "choice":
            columns[name] = rng.choice(np.asarray(args[0], dtype=float), n)
        else:
            raise ValueError(f"{name}: unknown distribution {kind!r}; expected uniform, normal, "
                             "lognormal or choice")  # fmt: skip
    return {dim: columns}


def dimension_attrs(dim: str, model: SweepModel | None = None) -> dict:
    """Units and description of a sweep dimension or input, for the coordinate's attrs."""
    if dim in DIMENSIONS:
        units, text = DIMENSIONS[dim]
        return {"units": units, "long_name": text}
    if dim in LABEL_DIMENSIONS:
        return {"long_name": LABEL_DIMENSIONS[dim]}
    extra = getattr(model, "input_attrs", {}) or {}
    if dim in extra:
        return dict(extra[dim])
    return {"long_name": f"{dim} (scenario index)"}
