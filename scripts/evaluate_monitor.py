"""Closed-loop evaluation of the on-board adhesion monitor (issue 21; docs/monitor.md).

A coach (``coach_default``) coasts 3 s, brakes lightly with a varying demand on a dry rail, and
runs onto a low-adhesion section (WILAC at 25 ul/s, Polach wet-type sets), with issue 21's
sensor noise and the WSP in the loop; the monitor is fed every 2.4 ms by its per-sample call
(:mod:`railadhesion.monitor.evaluation`). Then 100 km of dry rail for false alarms.

Cases:

* main: every condition x speeds 30-55 m/s x ``--seeds`` seeds, 0.5 % creep, demand
  modulated +-25 %;
* creep: 0.1 %, 0.2 % and 1 % creep at 30, 40 and 55 m/s, 2 seeds;
* steady: no modulation, 0.5 % creep, at 30, 40 and 55 m/s, 2 seeds;
* dry: 100 km of dry rail (runs from 30-55 m/s, random light braking and modulation);
* traction: only if the simulator has ``inputs.torque`` (it has not yet).

Writes ``results.json`` into ``--out`` (not under version control) and the figures
``docs/figures/monitor_track_low.png``, ``monitor_track_damp.png``, ``monitor_delays.png``;
prints the tables of docs/monitor.md.

Run: ``PYTHONPATH=src python3 scripts/evaluate_monitor.py [--seeds 5] [--out out/monitor-eval]``
(about 40 min on a loaded 2-core machine; ``--quick`` for a 2-minute check).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import time
from pathlib import Path

import numpy as np

from railadhesion.monitor.evaluation import (
    CONDITIONS,
    MonitorCase,
    run_case,
    run_dry_distance,
    run_traction_case,
)
from railadhesion.monitor.layout import LEVELS, LOW

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
SPEEDS = (30.0, 35.0, 40.0, 45.0, 50.0, 55.0)


def _pct(x, q):
    x = np.asarray([v for v in x if v is not None and math.isfinite(v)], float)
    return float(np.percentile(x, q)) if x.size else None


def _summarise(results):
    """Aggregate the cases of one (condition, creep, modulation) group."""
    delays = []
    firsts = []
    errors = []
    inside = []
    end_levels = np.zeros(len(LEVELS))
    false_before = 0
    false_section = 0
    false_after = 0
    lingers = []
    found_all = 0
    truth = []
    creeps = []
    for res in results:
        s = res.summary
        h = res.history
        truth.append(s["truth"])
        creeps.append(s["section_creep_median"])
        d = np.array([np.nan if x is None else x for x in s["delays_s"]], float)
        delays += d.tolist()
        firsts.append(np.nan if s["delay_first_axle_s"] is None else s["delay_first_axle_s"])
        found_all += int(np.all(np.isfinite(d) & (d <= 2.0)))
        false_before += int(s["false_low_before_section"])
        if res.expected != "low" and s["detected_axles"] > 0:
            false_section += 1
        for i in range(res.entry_time.size):
            if not math.isfinite(res.exit_time[i]):
                continue
            # on the section, from the first low level to the exit: the estimation error and
            # whether the band holds the truth
            on = (h["time"] >= res.entry_time[i]) & (h["time"] <= res.exit_time[i])
            low = on & (h["level"][:, i] == LOW)
            if low.any():
                e = (h["estimate"][:, i] - h["truth"][:, i])[low]
                errors += np.abs(e[np.isfinite(e)]).tolist()
                t = h["truth"][low, i]
                inside += ((h["lower"][low, i] <= t + 1e-3) & (t <= h["upper"][low, i])).tolist()
            # after the exit: how long 'low' lingers on the dry rail
            after = h["time"] > res.exit_time[i]
            lv = h["level"][after, i]
            if lv.size and lv[0] == LOW:
                stop = int(np.argmax(lv != LOW)) if (lv != LOW).any() else lv.size
                lingers.append(float(h["time"][after][min(stop, lv.size - 1)]
                                     - res.exit_time[i]))
            elif lv.size:
                lingers.append(0.0)
            false_after += int((lv[int(round(1.0 / 2.4e-3)):] == LOW).any())
            sel = (h["time"] > res.exit_time[i] - 1.0) & (h["time"] <= res.exit_time[i])
            for code in range(len(LEVELS)):
                end_levels[code] += np.sum(h["level"][sel, i] == code)
    delays = np.array(delays)
    n_axles = delays.size
    within = np.isfinite(delays) & (delays <= 2.0)
    truth = float(np.mean(truth))
    return {
        "cases": len(results),
        "truth_mean": truth,
        "truth_range": [float(np.min([r.truth for r in results])),
                        float(np.max([r.truth for r in results]))],
        "expected": "low" if truth < 0.14 else "not low",
        "section_creep_median": _pct(creeps, 50),
        "axles_low_within_2s": float(within.mean()) if n_axles else None,
        "cases_all_axles_within_2s": found_all / len(results),
        "axles_found_low": float(np.isfinite(delays).mean()) if n_axles else None,
        "delay_median_s": _pct(delays, 50),
        "delay_p95_s": _pct(delays, 95),
        "delay_max_s": _pct(delays, 100),
        "first_axle_delay_median_s": _pct(firsts, 50),
        "error_abs_median": _pct(errors, 50),
        "error_abs_p95": _pct(errors, 95),
        "error_abs_max": _pct(errors, 100),
        "band_holds_truth": float(np.mean(inside)) if inside else None,
        "end_level_share": {LEVELS[k]: float(end_levels[k] / max(end_levels.sum(), 1))
                            for k in range(len(LEVELS))},
        "false_low_before_section": false_before,
        "low_lingers_after_exit_median_s": _pct(lingers, 50),
        "low_lingers_after_exit_max_s": _pct(lingers, 100),
        "axles_low_more_than_1s_after_exit": false_after,
        "cases_low_where_truth_not_low": false_section,
        "delays": [None if not math.isfinite(x) else float(x) for x in delays],
    }


def _run_group(conditions, speeds, creep, modulation, seeds, progress, runner=run_case):
    out = {}
    for cond in conditions:
        results = []
        for v in speeds:
            for seed in seeds:
                results.append(runner(MonitorCase(condition=cond, speed=v, creep=creep,
                                                  modulation=modulation, seed=seed)))
                progress()
        out[cond] = (_summarise(results), results)
    return out


def _track_figure(res, path, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from railadhesion.braking import load_vehicle
    from railadhesion.monitor.figures import plot_estimate

    offsets = load_vehicle("coach_default").axle_offsets()
    h = res.history
    fig, axes = plt.subplots(2, 1, figsize=(10, 6.4), sharex=True)
    for ax, i in zip(axes, (0, 3), strict=True):
        x = h["distance"] - offsets[i]
        plot_estimate(x, h["estimate"][:, i], h["lower"][:, i], h["upper"][:, i],
                      h["level"][:, i], adhesion_used=h["used"][:, i], truth=h["truth"][:, i],
                      axis=ax, title=f"{title}, axle {i + 1}", section=res.section,
                      xlabel="position of the axle along the track [m]" if i == 3 else "")
        ax.set_xlim(max(x[0], res.section[0] - 250.0), x[-1])
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _delay_figure(groups, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from railadhesion.monitor.figures import plot_delays

    series = {f"{c} (truth {g['truth_mean']:.3f})": np.array(
        [np.nan if d is None else d for d in g["delays"]]) for c, g in groups.items()
        if g["expected"] == "low"}
    fig = plot_delays(series, title="low after entry, 0.5 % creep, 30-55 m/s (per axle)")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _table(groups, title):
    lines = [f"\n{title}", "| section | truth | creep | low within 2 s (axles) | all 4 axles "
             "within 2 s (cases) | delay median / p95 [s] | abs. error on the section, median "
             "/ p95 / max | "
             "band holds truth | level at the section's end | low where truth is not low | "
             "low lingers after the exit, median / max [s] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for cond, g in groups.items():
        def f(x, fmt="{:.3f}"):
            return "–" if x is None else fmt.format(x)
        end = ", ".join(f"{k} {v * 100:.0f} %" for k, v in g["end_level_share"].items() if v)
        lines.append(
            f"| {cond} | {g['truth_range'][0]:.3f}-{g['truth_range'][1]:.3f} | "
            f"{f(g['section_creep_median'], '{:.2%}')} | "
            f"{f(g['axles_low_within_2s'], '{:.0%}')} | "
            f"{g['cases_all_axles_within_2s']:.0%} | "
            f"{f(g['delay_median_s'], '{:.2f}')} / {f(g['delay_p95_s'], '{:.2f}')} | "
            f"{f(g['error_abs_median'])} / {f(g['error_abs_p95'])} / {f(g['error_abs_max'])} | "
            f"{f(g['band_holds_truth'], '{:.0%}')} | {end} | "
            f"{g['cases_low_where_truth_not_low']} of {g['cases']} | "
            f"{f(g['low_lingers_after_exit_median_s'], '{:.2f}')} / "
            f"{f(g['low_lingers_after_exit_max_s'], '{:.2f}')} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--out", type=Path, default=ROOT / "out" / "monitor-eval")
    ap.add_argument("--quick", action="store_true", help="a few cases only (a check)")
    ap.add_argument("--dry-km", type=float, default=100.0)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    FIGURES.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    conditions = list(CONDITIONS)
    speeds = SPEEDS
    seeds = range(args.seeds)
    few = (30.0, 40.0, 55.0)
    if args.quick:
        conditions, speeds, seeds, few = conditions[:3], (40.0,), range(1), (40.0,)
    done = [0]

    def progress():
        done[0] += 1
        if done[0] % 20 == 0:
            print(f"  {done[0]} cases, {time.time() - t0:.0f} s", flush=True)

    print(f"load average {os.getloadavg()[0]:.2f}; main cases", flush=True)
    main_groups = _run_group(conditions, speeds, 0.005, 0.25, seeds, progress)
    creep_groups = {}
    for creep in (0.001, 0.002, 0.01):
        print(f"creep {creep:.1%}", flush=True)
        creep_groups[creep] = _run_group(conditions, few, creep, 0.25, range(2), progress)
    print("steady demand", flush=True)
    steady = _run_group(conditions, few, 0.005, 0.0, range(2), progress)
    print(f"dry rail, {args.dry_km:g} km", flush=True)
    dry = run_dry_distance(args.dry_km * 1e3, seed=11)
    traction_groups = {}
    for creep in (0.002, 0.005, 0.01):
        print(f"traction only, {creep:.1%} creep", flush=True)
        traction_groups[creep] = _run_group(conditions, few, creep, 0.25, range(1), progress,
                                            runner=run_traction_case)
    # figures
    low_res = next(r for r in main_groups["polach_wet_0.08"][1] if r.case.speed == 40.0)
    _track_figure(low_res, FIGURES / "monitor_track_low.png",
                  "Polach wet-type, friction 0.08, 40 m/s, 0.5 % creep")
    if "wilac_25" in main_groups:
        damp = next(r for r in main_groups["wilac_25"][1] if r.case.speed == 40.0)
        _track_figure(damp, FIGURES / "monitor_track_damp.png",
                      "WILAC, 25 ul/s (damp), 40 m/s, 0.5 % creep")
    summaries = {c: g for c, (g, _) in main_groups.items()}
    _delay_figure(summaries, FIGURES / "monitor_delays.png")
    results = {
        "main_0.5pct_modulated": summaries,
        "creep": {f"{k:.3f}": {c: g for c, (g, _) in v.items()} for k, v in creep_groups.items()},
        "steady_0.5pct": {c: g for c, (g, _) in steady.items()},
        "dry": dry,
        "traction": {f"{k:.3f}": {c: g for c, (g, _) in v.items()}
                     for k, v in traction_groups.items()},
        "wall_s": time.time() - t0,
        "load_average_end": os.getloadavg()[0],
    }
    (args.out / "results.json").write_text(json.dumps(results, indent=1), encoding="utf-8")
    print(_table(summaries, "0.5 % creep, demand modulated +-25 %, 30-55 m/s"))
    for k, v in creep_groups.items():
        print(_table({c: g for c, (g, _) in v.items()}, f"{k:.1%} creep, 30/40/55 m/s"))
    print(_table({c: g for c, (g, _) in steady.items()}, "steady demand, 0.5 % creep"))
    dry = {k: v for k, v in dry.items() if k != "low_examples"}
    print("\ndry rail:", json.dumps(dry))
    for k, v in traction_groups.items():
        print(_table({c: g for c, (g, _) in v.items()},
                     f"traction only, {k:.1%} creep, {'/'.join(f'{x:g}' for x in few)} m/s"))
    print(f"\n{time.time() - t0:.0f} s; results in {args.out / 'results.json'}")


if __name__ == "__main__":
    main()
