"""Run a sweep with Dask: in memory, to NetCDF, or to a resumable Zarr store.

Where it runs is the caller's choice, as in Dask: by default Dask's local threaded scheduler
(nothing to set up); ``scheduler="synchronous"`` or ``"processes"`` for the other local
schedulers; ``client=`` a :class:`distributed.Client` or ``scheduler="tcp://HOST:PORT"`` for a
cluster. The code of the sweep does not change.

Zarr stores are written chunk by chunk as they are computed. Each chunk is one task, a pure
function of the plan and the chunk index: it evaluates the chunk, writes its region of every
variable (Zarr writes each chunk file atomically) and *then* writes a marker
``<store>/.sweep/chunks/<i>_<j>_....json`` (atomically, via a temporary file and a rename)
holding the chunk's failed points. A chunk without a marker is not done; a chunk is never
half-done with a marker. So a task retried after a killed worker rewrites identical values,
and a re-run after an interruption computes only the chunks without a marker.
"""

from __future__ import annotations

import dataclasses
import datetime
import json
import os
import shutil
import time
import uuid
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from railadhesion.sweeps.plan import SweepPlan, dimension_attrs, plan_sweep

__all__ = ["SweepResult", "run_sweep", "sweep_dataset", "sweep_errors", "open_sweep"]

_META = ".sweep"
#: How many failed points a chunk marker records with their messages (all are flagged).
MAX_ERRORS_PER_CHUNK = 100
#: How many failure messages the dataset's attrs quote.
MAX_ERRORS_IN_ATTRS = 20


@dataclass
class SweepResult:
    """Outcome of :func:`run_sweep`.

    Attributes
    ----------
    dataset : xarray.Dataset
        The map (lazy, Dask-backed, when read from a store).
    path : Path or None
        Where it was written.
    chunks_total, chunks_computed, chunks_skipped : int
        Chunks of the plan; computed by this call; found already done (resume).
    failed_points : int
        Points where the model raised (``dataset.error == 1``).
    elapsed : float
        Wall time of the computation [s].
    dashboard_link : str or None
        Dask dashboard of the cluster used, if any.
    """

    dataset: object
    path: Path | None
    chunks_total: int
    chunks_computed: int
    chunks_skipped: int
    failed_points: int
    elapsed: float
    dashboard_link: str | None = None
    plan: SweepPlan | None = field(default=None, repr=False)

    @property
    def points_per_second(self) -> float:
        """Throughput of this call (points of the computed chunks per second)."""
        if self.plan is None or self.chunks_total == 0 or self.elapsed <= 0:
            return float("nan")
        return self.plan.size * self.chunks_computed / self.chunks_total / self.elapsed


def _attrs(plan: SweepPlan, extra=None) -> dict:
    import dask
    import xarray

    import railadhesion

    desc = plan.model.describe()
    attrs = {
        "title": f"{plan.model.name} adhesion map",
        "model": plan.model.name,
        "model_description": desc.pop("model"),
        "parameters": json.dumps(desc, sort_keys=True, default=str),
        "fixed_inputs": json.dumps(plan.fixed, sort_keys=True, default=str),
        "sign_convention": "Kalker/CONTACT: creep_long = (V - omega R)/V, braking > 0; forces "
        "of the rail on the wheel, opposing the creepage",
        "sweep_fingerprint": plan.fingerprint,
        "chunk_shape": json.dumps(dict(zip(plan.dims, plan.chunk_shape, strict=True))),
        "software": f"railadhesion {getattr(railadhesion, '__version__', '?')}, "
        f"dask {dask.__version__}, xarray {xarray.__version__}, numpy {np.__version__}",
        "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
    }
    attrs.update(extra or {})
    return attrs


def _template(plan: SweepPlan, attrs=None):
    """Lazy Dataset of the plan's shape (zeros), carrying coords, units and attrs."""
    import dask.array as da
    import xarray as xr

    coords = {d: (d, c, dimension_attrs(d, plan.model))
              for d, c in zip(plan.dims, plan.coords, strict=True)}  # fmt: skip
    for name, (dim, column) in plan.along.items():  # scenario inputs, e.g. speed(sample)
        coords[name] = (dim, column, dimension_attrs(name, plan.model))
    data = {}
    for name, (dtype, units, text) in plan.variables.items():
        arr = da.zeros(plan.shape, chunks=plan.chunks, dtype=dtype)
        var_attrs = {"long_name": text}
        if units:
            var_attrs["units"] = units
        data[name] = (plan.dims, arr, var_attrs)
    return xr.Dataset(data, coords=coords, attrs=_attrs(plan, attrs))


def _chunk_block(plan: SweepPlan, index) -> np.ndarray:
    out, _ = plan.evaluate_chunk(index)
    return np.stack([out[name].astype(float) for name in plan.variables])


def sweep_dataset(plan: SweepPlan, attrs=None):
    """The map as a lazy xarray Dataset (one Dask task per chunk); nothing is computed yet.

    Use it like any Dask-backed Dataset: ``.compute()``, ``.to_netcdf(path)`` (streams chunk
    by chunk), ``.sel(...)``, or the derived quantities of :mod:`railadhesion.sweeps.derived`.
    Failure messages are not collected on this path (points are flagged in ``error``); use
    :func:`run_sweep` with a Zarr store for them.
    """
    import dask
    import dask.array as da

    ds = _template(plan, attrs)
    blocks = np.empty(plan.chunk_grid, dtype=object)
    task = dask.delayed(_chunk_block, pure=True)
    for index in plan.chunk_indices():
        shape = tuple(s.stop - s.start for s in plan.chunk_slices(index))
        blocks[index] = da.from_delayed(task(plan, index), (len(plan.variables), *shape),
                                        dtype=float)  # fmt: skip
    stacked = da.block(_nested(blocks, 0, ()), allow_unknown_chunksizes=False)
    # da.block joins along the last axes; the stacked leading axis (variables) is not split.
    for k, (name, (dtype, _, _)) in enumerate(plan.variables.items()):
        ds[name] = (plan.dims, stacked[k].astype(dtype), ds[name].attrs)
    return ds


def _nested(blocks: np.ndarray, axis: int, prefix: tuple):
    if axis == blocks.ndim:
        return blocks[prefix]
    return [_nested(blocks, axis + 1, prefix + (i,)) for i in range(blocks.shape[axis])]


# ----------------------------------------------------------------------------- Zarr stores


def _marker(path: Path, index) -> Path:
    return path / _META / "chunks" / ("_".join(str(i) for i in index) + ".json")


def _atomic_write_text(target: Path, text: str) -> None:
    tmp = target.with_name(f".{target.name}.{uuid.uuid4().hex}.tmp")
    tmp.write_text(text)
    os.replace(tmp, target)


def _chunk_task(plan: SweepPlan, path: str, index) -> tuple[tuple, int]:
    """Compute chunk ``index`` and write it to the store at ``path``; then its marker.

    Pure and idempotent: a retry writes identical values and an identical marker.
    """
    import zarr

    out, errors = plan.evaluate_chunk(index)
    group = zarr.open_group(path, mode="r+")
    region = plan.chunk_slices(index)
    for name in plan.variables:
        group[name][region] = out[name]
    marker = {
        "failed": len(errors),
        "errors": errors[:MAX_ERRORS_PER_CHUNK],
    }
    _atomic_write_text(_marker(Path(path), index), json.dumps(marker))
    return tuple(index), len(errors)


def _read_markers(path: Path) -> dict[tuple, dict]:
    folder = path / _META / "chunks"
    done = {}
    if folder.is_dir():
        for f in folder.glob("*.json"):
            try:
                done[tuple(int(x) for x in f.stem.split("_"))] = json.loads(f.read_text())
            except (ValueError, OSError):  # a stray or unreadable file: the chunk is redone
                continue
    return done


def _init_store(plan: SweepPlan, path: Path, overwrite: bool, attrs) -> bool:
    """Create the store, or check that an existing one holds this plan. True if resuming."""
    plan_file = path / _META / "plan.json"
    if path.exists():
        if overwrite:
            shutil.rmtree(path) if path.is_dir() else path.unlink()
        elif not plan_file.is_file():
            raise ValueError(
                f"out: {path} exists and is not a sweep store; choose another path or "
                "overwrite it (overwrite=True, --overwrite)"
            )
        else:
            stored = json.loads(plan_file.read_text()).get("fingerprint")
            if stored != plan.fingerprint:
                raise ValueError(
                    f"out: {path} holds a different sweep (model, grid, fixed inputs or "
                    "chunks differ); resume needs the same spec. Choose another path or "
                    "overwrite it (overwrite=True, --overwrite)"
                )
            return True
    encoding = {name: {"chunks": plan.chunk_shape} for name in plan.variables}
    ds = _template(plan, attrs)
    ds.attrs["complete"] = 0
    ds.to_zarr(path, mode="w", compute=False, zarr_format=2, consolidated=True,
               encoding=encoding)  # fmt: skip
    (path / _META / "chunks").mkdir(parents=True, exist_ok=True)
    _atomic_write_text(plan_file, json.dumps({"fingerprint": plan.fingerprint}))
    return False


def _finalise_store(plan: SweepPlan, path: Path) -> int:
    import zarr

    markers = _read_markers(path)
    failed = sum(m["failed"] for m in markers.values())
    quoted = []
    for index in sorted(markers):
        for flat, message in markers[index]["errors"]:
            if len(quoted) < MAX_ERRORS_IN_ATTRS:
                quoted.append({"point": plan.point(index, flat), "message": message})
    group = zarr.open_group(str(path), mode="r+")
    group.attrs.update({
        "complete": int(len(markers) == plan.n_chunks),
        "failed_points": int(failed),
        "failures": json.dumps(quoted, default=str),
    })  # fmt: skip
    with warnings.catch_warnings():  # our .sweep folder is not part of the Zarr hierarchy
        warnings.simplefilter("ignore")
        zarr.consolidate_metadata(str(path))
    return failed


def open_sweep(path):
    """Open a sweep store written by :func:`run_sweep` (lazy, Dask-backed)."""
    import xarray as xr

    return xr.open_zarr(path, consolidated=True)


def sweep_errors(path):
    """All failed points of a sweep store with their messages, as a pandas DataFrame.

    One row per recorded failure (at most ``MAX_ERRORS_PER_CHUNK`` per chunk are recorded
    with a message; ``error == 1`` in the data flags every one).
    """
    import pandas as pd
    import xarray as xr

    path = Path(path)
    ds = xr.open_zarr(path, consolidated=True)
    dims = list(ds["error"].dims)
    rows = []
    for index, m in sorted(_read_markers(path).items()):
        sizes = [ds.chunks[d][i] for d, i in zip(dims, index, strict=True)]
        starts = [sum(ds.chunks[d][:i]) for d, i in zip(dims, index, strict=True)]
        for flat, message in m["errors"]:
            sub = np.unravel_index(flat, sizes)
            row = {d: ds[d].values[s + k].item() for d, s, k in zip(dims, starts, sub,
                                                                      strict=True)}
            row["message"] = message
            rows.append(row)
    return pd.DataFrame(rows, columns=[*dims, "message"])


# ----------------------------------------------------------------------------- execution


def _client_for(client, scheduler):
    """(client, owned): a distributed Client if one is asked for, else (None, False)."""
    if client is not None:
        return client, False
    if isinstance(scheduler, str) and "://" in scheduler:
        from distributed import Client

        return Client(scheduler), True
    return None, False


def _local_scheduler(scheduler) -> str:
    name = scheduler or "threads"
    if name not in ("threads", "processes", "synchronous", "sync", "single-threaded"):
        raise ValueError(
            "scheduler: expected 'threads', 'processes', 'synchronous' or a cluster address "
            f"such as 'tcp://127.0.0.1:8786', got {scheduler!r}"
        )
    return name


def _run_local(plan, path, missing, scheduler, on_chunk):
    import dask
    from dask.callbacks import Callback

    task = dask.delayed(_chunk_task, pure=True)
    tasks = [task(plan, str(path), index) for index in missing]
    keys = {t.key for t in tasks}
    counter = {"done": 0}

    class _Progress(Callback):
        def _posttask(self, key, result, dsk, state, worker_id):
            if key in keys:
                counter["done"] += 1
                if on_chunk is not None:
                    on_chunk(counter["done"], len(tasks))

    with _Progress():
        dask.compute(*tasks, scheduler=scheduler)


def _run_distributed(plan, path, missing, client, on_chunk):
    from distributed import as_completed

    token = uuid.uuid4().hex[:8]
    futures = [
        client.submit(
            _chunk_task, plan, str(path), index, retries=2, pure=False,
            key=f"railadhesion-sweep-{token}-{'.'.join(map(str, index))}",
        )  # fmt: skip
        for index in missing
    ]
    try:
        for done, fut in enumerate(as_completed(futures), start=1):
            fut.result()
            if on_chunk is not None:
                on_chunk(done, len(futures))
    except BaseException:
        client.cancel(futures)
        raise


def run_sweep(model, grid=None, out=None, *, fixed=None, chunks=None, chunk_points=None,
              client=None, scheduler=None, overwrite=False, on_chunk=None, on_start=None,
              attrs=None, kernel_threads="auto") -> SweepResult:  # fmt: skip
    """Evaluate a model over a labelled grid with Dask; optionally write the map as computed.

    Parameters
    ----------
    model : SweepModel or SweepPlan
        The model (then ``grid`` is required) or a plan from :func:`plan_sweep`.
    grid : mapping of str to array_like, optional
        Swept inputs in dimension order (see :func:`~railadhesion.sweeps.plan.plan_sweep`).
    out : str or Path, optional
        ``*.zarr``: a Zarr store written chunk by chunk, resumable; ``*.nc``: NetCDF streamed
        chunk by chunk (not resumable); ``None``: computed into memory.
    fixed, chunks, chunk_points
        Passed to :func:`~railadhesion.sweeps.plan.plan_sweep`.
    client : distributed.Client, optional
        Run on this cluster.
    scheduler : str, optional
        ``"threads"`` (default), ``"processes"``, ``"synchronous"``, or a cluster address
        ``"tcp://HOST:PORT"`` (a Client is connected and closed afterwards).
    overwrite : bool, optional
        Replace an existing store at ``out``. Without it, a store of the *same* sweep is
        resumed (only chunks without a completion marker are computed), a different one is an
        error.
    on_chunk : callable, optional
        ``on_chunk(done, to_do)`` after each chunk (progress bars; not called for in-memory
        or NetCDF sweeps on a cluster). An exception raised here stops the sweep; completed
        chunks of a Zarr store stay written.
    on_start : callable, optional
        ``on_start(result)`` once the store is ready, before computing: ``result`` is the
        :class:`SweepResult` so far (chunks to do, dashboard link).
    attrs : mapping, optional
        Extra global attributes (e.g. the spec file's title).
    kernel_threads : int, None or "auto", optional
        Threads of the model's compiled (numba) kernels within a chunk. ``"auto"``: 1 under
        Dask's parallel schedulers and clusters (Dask already runs one chunk per core), numba's
        default with ``"synchronous"``; ``None``: numba's default.

    Returns
    -------
    SweepResult

    Examples
    --------
    >>> import numpy as np
    >>> from railadhesion.sweeps import WilacSweep, run_sweep
    >>> res = run_sweep(WilacSweep(geometry="tram"),
    ...                 {"creep_long": [0.01, 0.1], "water_flow": [0.0, 25.0]},
    ...                 fixed={"normal_force": 4200.0, "speed": 5.0})
    >>> np.round(res.dataset.adhesion.values, 3)
    array([[0.348, 0.132],
           [0.339, 0.105]])
    """
    if isinstance(model, SweepPlan):
        plan = model
    else:
        kwargs = {} if chunk_points is None else {"chunk_points": chunk_points}
        plan = plan_sweep(model, grid, fixed=fixed, chunks=chunks, **kwargs)
    client, owned = _client_for(client, scheduler)
    local = None if client is not None else _local_scheduler(scheduler)
    if kernel_threads == "auto":  # Dask parallelises over chunks: one kernel thread each
        kernel_threads = None if local in ("synchronous", "sync", "single-threaded") else 1
    plan = dataclasses.replace(plan, kernel_threads=kernel_threads)
    link = getattr(client, "dashboard_link", None) if client is not None else None
    try:
        if str(out).endswith(".nc") and local == "processes":
            raise ValueError(
                "scheduler: a NetCDF file is written from one process; use 'threads', "
                "'synchronous' or a cluster, or write a Zarr store (*.zarr)"
            )
        if out is None or str(out).endswith(".nc"):
            return _run_whole(plan, out, client, local, link, on_start, attrs, on_chunk)
        path = Path(out).absolute()
        resuming = _init_store(plan, path, overwrite, attrs)
        done = _read_markers(path) if resuming else {}
        missing = [index for index in plan.chunk_indices() if index not in done]
        result = SweepResult(None, path, plan.n_chunks, len(missing), len(done), 0, 0.0, link,
                             plan)  # fmt: skip
        if on_start is not None:
            on_start(result)
        start = time.perf_counter()
        if missing:
            if client is not None:
                _run_distributed(plan, path, missing, client, on_chunk)
            else:
                _run_local(plan, path, missing, local, on_chunk)
        result.elapsed = time.perf_counter() - start
        result.failed_points = _finalise_store(plan, path)
        result.dataset = open_sweep(path)
        return result
    finally:
        if owned:
            client.close()


class _BlockProgress:
    """Calls ``on_chunk(done, total)`` as the chunk tasks of :func:`sweep_dataset` finish
    (local schedulers)."""

    def __init__(self, total, on_chunk):
        self.total, self.on_chunk, self.done, self.cb = total, on_chunk, 0, None

    def __enter__(self):
        if self.on_chunk is not None:
            from dask.callbacks import Callback

            def posttask(key, result, dsk, state, worker_id):
                name = key[0] if isinstance(key, tuple) else key
                if str(name).startswith("chunk_block"):
                    self.done += 1
                    self.on_chunk(self.done, self.total)

            self.cb = Callback(posttask=posttask)
            self.cb.__enter__()
        return self

    def __exit__(self, *exc):
        if self.cb is not None:
            self.cb.__exit__(*exc)


def _run_whole(plan, out, client, local, link, on_start, attrs, on_chunk) -> SweepResult:
    result = SweepResult(None, None if out is None else Path(out), plan.n_chunks, plan.n_chunks,
                         0, 0, 0.0, link, plan)  # fmt: skip
    if on_start is not None:
        on_start(result)
    ds = sweep_dataset(plan, attrs)
    start = time.perf_counter()
    with _BlockProgress(plan.n_chunks, on_chunk if client is None else None):
        if out is None:
            ds = client.compute(ds).result() if client is not None else ds.compute(
                scheduler=local)
        else:
            job = ds.to_netcdf(out, compute=False)
            client.compute(job).result() if client is not None else job.compute(
                scheduler=local)
    if out is not None:
        import xarray as xr

        ds = xr.open_dataset(out, chunks={})
    result.elapsed = time.perf_counter() - start
    result.failed_points = int(ds["error"].sum())
    result.dataset = ds
    return result
