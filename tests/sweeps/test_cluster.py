"""Sweeps on a distributed LocalCluster: a worker killed mid-sweep loses and duplicates
nothing; the same sweep runs by address. One module-scoped cluster (start-up is slow)."""

import os
import signal
import threading
import time
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import railadhesion
from railadhesion.sweeps import WilacSweep, plan_sweep, run_sweep

distributed = pytest.importorskip("distributed")

GRID = {
    "creep_long": np.geomspace(0.001, 0.9, 40),
    "speed": np.linspace(2.5, 20.0, 16),
    "normal_force": np.linspace(4200.0, 9700.0, 12),  # the default set's range starts at 4.2 kN
    "water_flow": np.linspace(0.0, 100.0, 15),
}  # 115 200 points


@pytest.fixture(scope="module")
def cluster():
    src = str(Path(railadhesion.__file__).resolve().parents[1])
    env = {"PYTHONPATH": os.pathsep.join(filter(None, [src, os.environ.get("PYTHONPATH")]))}
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, memory_limit="600MiB",
        dashboard_address=":0", env=env,  # any free port (bokeh, the full dashboard, is absent)
    ) as cluster, distributed.Client(cluster) as client:  # fmt: skip
        yield cluster, client


def test_killed_worker_loses_and_duplicates_no_point(cluster, tmp_path):
    _, client = cluster
    plan = plan_sweep(WilacSweep(), GRID, chunks={"creep_long": 40, "speed": 4,
                                                  "normal_force": 2, "water_flow": 5})
    assert plan.n_chunks == 72
    out = tmp_path / "map.zarr"
    markers = out / ".sweep" / "chunks"
    box = {}
    runner = threading.Thread(target=lambda: box.update(res=run_sweep(plan, out=out,
                                                                      client=client)))
    runner.start()
    pids = client.run(os.getpid)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (markers.is_dir() and
                                               len(list(markers.glob("*.json"))) >= 4):
        time.sleep(0.005)
    done_at_kill = len(list(markers.glob("*.json")))
    victim = sorted(pids.values())[0]
    os.kill(victim, signal.SIGKILL)
    runner.join(timeout=120)
    assert not runner.is_alive()
    res = box["res"]
    print(f"killed worker {victim} after {done_at_kill} of {plan.n_chunks} chunks")
    assert 4 <= done_at_kill < plan.n_chunks, "the worker was not killed mid-sweep"
    assert victim not in client.run(os.getpid).values()  # the nanny replaced the worker
    # Every chunk done exactly once (one marker each), every point present, values right.
    names = sorted(p.stem for p in markers.glob("*.json"))
    assert len(names) == len(set(names)) == plan.n_chunks
    ds = res.dataset.load()
    for dim, values in GRID.items():
        np.testing.assert_array_equal(ds[dim].values, values)
    assert int(ds.error.sum()) == 0 and bool(ds.adhesion.notnull().all())
    want = run_sweep(plan, scheduler="threads").dataset
    for name in ("fx", "fy", "adhesion"):
        np.testing.assert_allclose(ds[name].values, want[name].values, rtol=1e-12, atol=0)
    assert ds.attrs["complete"] == 1


def test_same_sweep_by_scheduler_address(cluster, tmp_path):
    local_cluster, _ = cluster
    grid = {"creep_long": [0.01, 0.1, 0.5], "water_flow": [0.0, 25.0, 60.0]}
    fixed = {"normal_force": 4200.0, "speed": 5.0}
    remote = run_sweep(WilacSweep(), grid, tmp_path / "m.zarr", fixed=fixed,
                       chunks={"water_flow": 1}, scheduler=local_cluster.scheduler_address)
    local = run_sweep(WilacSweep(), grid, fixed=fixed, scheduler="synchronous")
    assert remote.chunks_computed == 3 and remote.dashboard_link.startswith("http")
    xr.testing.assert_allclose(remote.dataset.adhesion.load(), local.dataset.adhesion,
                               rtol=1e-12, atol=0)  # fmt: skip


def test_cli_sweep_on_a_cluster_prints_the_dashboard(cluster, tmp_path):
    from typer.testing import CliRunner

    from railadhesion.cli import app

    local_cluster, _ = cluster
    spec = tmp_path / "s.toml"
    spec.write_text(
        'format = "railadhesion-sweep"\nformat_version = 1\n[model]\nname = "fletcher"\n'
        'condition = "W1"\n[grid]\ncondition = ["W1", "D3"]\n'
        "creep_long = { start = 0.0, stop = 0.01, num = 11 }\n"
    )
    result = CliRunner().invoke(app, ["sweep", str(spec), "--out", str(tmp_path / "m.zarr"),
                                      "--scheduler", local_cluster.scheduler_address])
    assert result.exit_code == 0, result.output
    assert "Dask cluster dashboard: http" in result.output
    assert "failed points: 0" in result.output
