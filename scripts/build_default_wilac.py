#!/usr/bin/env python3
"""Build the default WILAC parameter set ``src/railadhesion/data/wilac_default.toml``.

**The result is a reconstruction, not the paper's parameter set.** Trummer et al. (Tribology
International 109 (2017) 409-415; seed 000) publish neither their regression coefficients nor
their per-condition Polach parameters. This script builds a set that reproduces what the paper
*reports* (its text and figure descriptions), in four documented steps (``docs/wilac-default.md``):

1. **Anchors.** For each condition (dry, damp2, damp1, wet) one target curve at the tram rig
   (4.2 kN, 5 m/s; seed 000 §4) and one at locomotive scale (110 kN, 10 m/s; seed 000 §2 and
   §5.4), each written as Polach's saturation law with a friction coefficient that falls with
   *creep* (not slip velocity): mu(s) = mu_max [(1 - A) exp(-beta s) + A]. The anchor numbers
   (:data:`ANCHORS`) were chosen by hand so that the curves show the reported features.
2. **Targets over (Q, v).** Anchor parameters are interpolated linearly in ln Q between
   4.2 kN and 110 kN (extrapolated to 150 kN); the speed dependence is deliberately weak
   (the locomotive data of Fig. 9): mu_max falls linearly with v by ``SPEED_SLOPE`` over 5 to
   40 m/s, and because the friction decay is in creep, the slip-velocity decay rate of
   Polach's law is beta / v. Contact semi-axes along the grid come from Hertz theory with
   curvatures interpolated in ln Q from the tram rig to the locomotive wheel/rail geometry.
3. **Calibration.** Every target curve (creep 0.1 % to 100 %) is fitted with
   :func:`railadhesion.calibration.fitting.fit_polach` (all five parameters).
4. **Regressions.** Per condition and parameter, a WILAC regression on (Q', v') by the paper's
   forward selection (:func:`railadhesion.calibration.regression.build_regression`, gain
   >= 1e-4), Q' = Q / 150 kN and v' = v / 40 m/s (the maxima of the grid, as in the paper).

Run from the repository root::

    python3 scripts/build_default_wilac.py                 # writes the package data file
    python3 scripts/build_default_wilac.py --coarse --out /tmp/w.toml

The module is importable (``build(...)``) so that the tests can rerun it on a coarse grid.
"""

from __future__ import annotations

import argparse
import datetime
import math
import sys
import time
from pathlib import Path

import numpy as np

from railadhesion.calibration.fitting import fit_polach
from railadhesion.calibration.regression import build_regression
from railadhesion.contact.geometry import NAMED_GEOMETRIES as WILAC_GEOMETRIES
from railadhesion.contact.hertz import hertz_3d
from railadhesion.io.paramfiles import load_wilac_parameters, save_wilac_parameters
from railadhesion.models.polach import polach_forces
from railadhesion.models.wilac import (
    PAPER_TRANSITIONS,
    POLACH_PARAMETER_NAMES,
    WILAC_CONDITIONS,
    WilacCondition,
    WilacParameters,
)

REPO = Path(__file__).resolve().parents[1]
DEFAULT_OUT = REPO / "src" / "railadhesion" / "data" / "wilac_default.toml"

#: Tram rig operating point (seed 000 §4): Q = 4.2 kN, v = 5 m/s.
TRAM_FORCE, TRAM_SPEED = 4.2e3, 5.0
#: Locomotive tests the paper compares with (seed 000 §5.4, Figs. 9-11): Q = 110 kN; the wet
#: test and the reference curve of Fig. 11 are at 10 m/s.
LOCO_FORCE, LOCO_SPEED = 110e3, 10.0
#: Steel, both bodies (seed 000 §4 gives the materials; E and nu are our choice):
YOUNG, POISSON = 2.1e11, 0.28
SHEAR_MODULUS = YOUNG / (2 * (1 + POISSON))  # 82.0 GPa

#: Anchor curves: per condition and scale, (k_A, k_S, mu_max, A, beta). mu_max [-] holds at the
#: anchor speed (tram 5 m/s, locomotive 10 m/s); beta [-] is the decay of friction per unit
#: creep (Polach's B = beta / v). Hand-chosen to give the features the paper reports:
#: tram dry: peak ~0.39 near 3 % creep, falling to ~0.21 at 100 % ("peak at low creep, steep
#: decrease"); damp2: peak ~0.14, about the wet peaks, ~0.06 at 60-90 % creep; damp1 and wet:
#: "wet type", ~0.13-0.15 and flat; locomotive dry: maximum ~0.35 (reported 0.3-0.4 at
#: 5-20 m/s); locomotive wet: maximum ~0.25 at 10 m/s. Damp conditions at locomotive scale are
#: not reported: their anchors follow :func:`_damp_locomotive_anchor`.
ANCHORS: dict[str, dict[str, tuple[float, float, float, float, float]]] = {
    "dry": {"tram": (0.60, 0.25, 0.46, 0.45, 6.0), "locomotive": (0.70, 0.30, 0.42, 0.60, 4.0)},
    "damp2": {"tram": (0.35, 0.12, 0.175, 0.33, 9.0)},
    "damp1": {"tram": (0.12, 0.05, 0.155, 0.85, 3.0)},
    "wet": {"tram": (0.12, 0.05, 0.165, 0.85, 3.0), "locomotive": (0.25, 0.07, 0.30, 0.75, 3.0)},
}
#: Relative fall of mu_max per 35 m/s of speed (linear in v, 1 at 5 m/s): weak for dry, as
#: the locomotive data of seed 000 Fig. 9; twice that for the wet-type conditions (higher
#: speeds leave more water film; cf. the 0.10-0.16 at 100 km/h quoted in seed 000 §2).
SPEED_SLOPE = {"dry": 0.10, "damp2": 0.20, "damp1": 0.20, "wet": 0.20}

#: Calibration grid. Q [N] from the tram rig to a heavy axle; v [m/s] from 2 to 40.
FULL_GRID = (
    np.array([4.2, 6.0, 8.5, 12.0, 17.0, 25.0, 35.0, 50.0, 70.0, 90.0, 110.0, 130.0, 150.0]) * 1e3,
    np.array([2.0, 3.0, 4.0, 5.0, 7.0, 10.0, 14.0, 20.0, 28.0, 40.0]),
)
COARSE_GRID = (
    np.array([4.2, 12.0, 35.0, 110.0, 150.0]) * 1e3,
    np.array([2.0, 5.0, 10.0, 20.0, 40.0]),
)
#: Creep magnitudes of each target curve: 0.1 % to 100 %, log-spaced.
CREEP_GRID = np.geomspace(1e-3, 1.0, 25)


def _speed_factor(condition: str, speed):
    """mu_max(v) / mu_max(5 m/s): 1 - slope (v - 5)/35."""
    return 1.0 - SPEED_SLOPE[condition] * (np.asarray(speed, float) - TRAM_SPEED) / 35.0


def _damp_locomotive_anchor(condition: str) -> tuple[float, float, float, float, float]:
    """Locomotive anchor of a damp condition: its tram anchor with mu_max, k_A, k_S and A scaled
    by the wet condition's locomotive/tram ratios (beta kept): the paper gives no damp data at
    locomotive scale, and damp2 is said to peak about as high as the wet curves."""
    k_a, k_s, mu, big_a, beta = ANCHORS[condition]["tram"]
    wt, wl = ANCHORS["wet"]["tram"], ANCHORS["wet"]["locomotive"]
    mu_ratio = (wl[2] / _speed_factor("wet", LOCO_SPEED)) / wt[2]
    mu_loco = mu * mu_ratio * _speed_factor(condition, LOCO_SPEED)
    return (
        min(1.0, k_a * wl[0] / wt[0]),
        min(1.0, k_s * wl[1] / wt[1]),
        mu_loco,
        min(1.0, big_a * wl[3] / wt[3]),
        beta,
    )


def anchor(condition: str, scale: str) -> tuple[float, float, float, float, float]:
    """(k_A, k_S, mu_max at the anchor speed, A, beta) of one anchor."""
    if scale in ANCHORS[condition]:
        return ANCHORS[condition][scale]
    return _damp_locomotive_anchor(condition)


def _log_q_fraction(normal_force):
    """0 at the tram force, 1 at the locomotive force, linear in ln Q."""
    return np.log(np.asarray(normal_force, float) / TRAM_FORCE) / math.log(LOCO_FORCE / TRAM_FORCE)


def target_parameters(condition: str, normal_force, speed) -> dict[str, np.ndarray]:
    """Polach parameters of the target curve of ``condition`` at (Q [N], v [m/s]).

    Linear in ln Q between the anchors (``k_A, k_S, A, beta`` and mu_max referred to 5 m/s),
    times the speed factor for mu0; ``B = beta / v`` [s/m]."""
    t = _log_q_fraction(normal_force)
    tram, loco = np.array(anchor(condition, "tram")), np.array(anchor(condition, "locomotive"))
    tram[2] /= _speed_factor(condition, TRAM_SPEED)
    loco[2] /= _speed_factor(condition, LOCO_SPEED)
    k_a, k_s, mu5, big_a, beta = (tram[i] + t * (loco[i] - tram[i]) for i in range(5))
    v = np.asarray(speed, float)
    return {
        "k_A": np.minimum(k_a, 1.0),
        "k_S": np.minimum(k_s, 1.0),
        "mu0": mu5 * _speed_factor(condition, v),
        "A": big_a,
        "B": beta / v,
    }


def contact_semi_axes(normal_force) -> tuple[float, float]:
    """Hertz semi-axes (a, b) [m] along the calibration path: wheel, roller and lateral
    curvatures interpolated linearly in ln Q from the tram rig (4.2 kN) to the locomotive
    geometry (110 kN) and held outside."""
    t = float(np.clip(_log_q_fraction(normal_force), 0.0, 1.0))
    gt, gl = WILAC_GEOMETRIES["tram"], WILAC_GEOMETRIES["locomotive"]

    def radius(key):
        curv = (1 - t) / gt[key] + t / gl[key]
        return math.inf if curv == 0 else 1.0 / curv

    h = hertz_3d(
        float(normal_force),
        radius("wheel_radius"),
        radius("wheel_lateral_radius"),
        radius("rail_lateral_radius"),
        radius("rail_radius"),
        young=YOUNG,
        poisson=POISSON,
    )
    return float(h.a), float(h.b)


def target_curve(condition: str, normal_force: float, speed: float, a: float, b: float):
    """Adhesion |Fx|/Q of the target curve on :data:`CREEP_GRID` (braking sign; symmetric)."""
    p = target_parameters(condition, normal_force, speed)
    fx, _ = polach_forces(
        CREEP_GRID, 0.0, 0.0, normal_force, speed, a, b,
        shear_modulus=SHEAR_MODULUS, poisson=POISSON, **{k: float(v) for k, v in p.items()},
    )
    return np.abs(fx) / normal_force


def _initial(condition: str) -> dict[str, float]:
    """Starting point of every fit: the tram anchor of the condition, B for 5 m/s."""
    k_a, k_s, mu, big_a, beta = anchor(condition, "tram")
    return {"k_A": k_a, "k_S": k_s, "mu0": mu, "A": big_a, "B": beta / TRAM_SPEED}


def calibrate(grid, *, log=print):
    """Fit Polach parameters to every target curve of the grid.

    Returns ``(q, v, fitted, stats)``: flattened grid arrays [N], [m/s]; per condition a dict
    of parameter arrays; per condition the worst fit R^2 and RMSE."""
    qs, vs = grid
    q, v = (x.ravel() for x in np.meshgrid(qs, vs, indexing="ij"))
    axes = {float(x): contact_semi_axes(x) for x in qs}
    fitted, stats = {}, {}
    for cond in WILAC_CONDITIONS:
        t0 = time.perf_counter()
        rows = {name: np.empty(q.size) for name in POLACH_PARAMETER_NAMES}
        r2, rmse = [], []
        for i, (qi, vi) in enumerate(zip(q, v, strict=True)):
            a, b = axes[float(qi)]
            y = target_curve(cond, qi, vi, a, b)
            res = fit_polach(
                CREEP_GRID, y, normal_force=qi, speed=vi, a=a, b=b, initial=_initial(cond),
                shear_modulus=SHEAR_MODULUS, poisson=POISSON,
            )
            if not res.success:
                raise RuntimeError(f"{cond} fit at Q={qi:g} N, v={vi:g} m/s: {res.message}")
            for name in POLACH_PARAMETER_NAMES:
                rows[name][i] = res.params[name]
            r2.append(res.r_squared)
            rmse.append(res.rmse)
        fitted[cond] = rows
        stats[cond] = {"min_r2": float(min(r2)), "max_rmse": float(max(rmse))}
        log(f"  {cond:6s}: {q.size} fits in {time.perf_counter() - t0:.1f} s, "
            f"worst R^2 {min(r2):.6f}, worst RMSE {max(rmse):.2e}")
    return q, v, fitted, stats


def regress(q, v, fitted, q_ref, v_ref, *, log=print):
    """WILAC regressions per condition and parameter (paper's forward selection)."""
    conditions, table = {}, {}
    for cond in WILAC_CONDITIONS:
        regs = {}
        for name in POLACH_PARAMETER_NAMES:
            y = fitted[cond][name]
            fit = build_regression(q / q_ref, v / v_ref, y)
            regs[name] = fit.regression
            table[(cond, name)] = (
                fit.r_squared, len(fit.terms), float(np.max(np.abs(fit.residuals)))
            )
            log(f"  {cond:6s} {name:4s}: R^2 = {fit.r_squared:.6f}, {len(fit.terms):2d} terms, "
                f"max |residual| = {table[(cond, name)][2]:.2e}")
        conditions[cond] = WilacCondition(**regs)
    return conditions, table


def check_curves(params: WilacParameters, q, v) -> dict[str, float]:
    """Largest |adhesion(regressed parameters) - target| per condition over grid and creep."""
    worst = {}
    for cond in WILAC_CONDITIONS:
        err = 0.0
        for qi, vi in zip(q, v, strict=True):
            a, b = contact_semi_axes(qi)
            p = params.polach_parameters(cond, qi, vi)
            fx, _ = polach_forces(
                CREEP_GRID, 0.0, 0.0, qi, vi, a, b, shear_modulus=SHEAR_MODULUS,
                poisson=POISSON, **{k: float(x) for k, x in p.items()},
            )
            diff = np.abs(fx) / qi - target_curve(cond, qi, vi, a, b)
            err = max(err, float(np.max(np.abs(diff))))
        worst[cond] = err
    return worst


def _anchor_notes() -> str:
    lines = ["Anchors (k_A, k_S, mu_max at anchor speed, A, beta per unit creep; B = beta/v):"]
    for cond in WILAC_CONDITIONS:
        for scale, spd in (("tram", "4.2 kN, 5 m/s"), ("locomotive", "110 kN, 10 m/s")):
            vals = ", ".join(f"{x:.4g}" for x in anchor(cond, scale))
            lines.append(f"  {cond} {scale} ({spd}): {vals}")
    lines.append("Speed slope of mu_max per 35 m/s: "
                 + ", ".join(f"{c} {SPEED_SLOPE[c]:g}" for c in WILAC_CONDITIONS))
    return "\n".join(lines)


def build(out=DEFAULT_OUT, *, coarse: bool = False, quiet: bool = False) -> dict:
    """Run the whole build, write ``out`` and return a report (R^2 table, curve errors)."""
    log = (lambda *a, **k: None) if quiet else print
    grid = COARSE_GRID if coarse else FULL_GRID
    q_ref, v_ref = float(grid[0].max()), float(grid[1].max())
    log(f"Calibrating on {grid[0].size} x {grid[1].size} (Q, v) points per condition")
    q, v, fitted, fit_stats = calibrate(grid, log=log)
    log("Regressions (forward selection, min R^2 gain 1e-4):")
    conditions, table = regress(q, v, fitted, q_ref, v_ref, log=log)
    r2_lines = [
        f"  {c} {p}: R^2 {r2:.6f} ({n} terms)" for (c, p), (r2, n, _) in table.items()
    ]
    provenance = {
        "source": (
            "Reconstruction calibrated to the features reported by G. Trummer, "
            "L.E. Buckley-Johnstone, P. Voltr, A. Meierhofer, R. Lewis, K. Six, Wheel-rail creep "
            "force model for predicting water induced low adhesion phenomena, Tribology "
            "International 109 (2017) 409-415. NOT the authors' coefficients (unpublished)."
        ),
        "reconstruction": True,
        "description": (
            "Method: hand-chosen anchor curves per condition at the tram rig (4.2 kN, 5 m/s) "
            "and at locomotive scale (110 kN, 10 m/s), Polach saturation law with friction "
            "falling with creep; anchors interpolated linearly in ln Q, weak linear speed "
            "dependence of mu_max; each target curve (creep 0.1-100 %) fitted with fit_polach; "
            "per parameter a regression on Q' = Q/150 kN, v' = v/40 m/s by forward selection "
            "(min R^2 gain 1e-4). Grid "
            f"{'coarse' if coarse else 'full'}: Q = {', '.join(f'{x / 1e3:g}' for x in grid[0])}"
            f" kN; v = {', '.join(f'{x:g}' for x in grid[1])} m/s. See docs/wilac-default.md."
        ),
        "created": datetime.date.today().isoformat(),
        "script": "scripts/build_default_wilac.py",
        "licence": "Apache-2.0 (same as railadhesion)",
        "notes": (
            "Targets (seed 000): tram rig 4.2 kN, 5 m/s: dry peaks at low creep and falls; "
            "25 ul/s about 0.06 at 60-90 % creep, peak about as low as the wet peaks; 35, 60, "
            "350 ul/s wet type about 0.15, almost flat; minimum of adhesion over w between 20 "
            "and 40 ul/s at fixed creep; locomotive 110 kN: dry maximum 0.3-0.4 at 5-20 m/s "
            "with weak speed dependence between -10 % and -50 % creep, wet maximum about 0.25 "
            "at 10 m/s. Contact: tram wheel R 0.348 m on roller R 0.4525 m, lateral radius "
            "0.660 m; locomotive wheel R 0.625 m, straight tread on rail head radius 0.300 m; "
            "E 210 GPa, nu 0.28, G 82 GPa.\n"
            + _anchor_notes() + "\nRegression R^2:\n" + "\n".join(r2_lines)
        ),
    }
    params = WilacParameters(
        conditions,
        normal_force_ref=q_ref,
        speed_ref=v_ref,
        normal_force_range=(float(grid[0].min()), q_ref),
        speed_range=(float(grid[1].min()), v_ref),
        transitions=PAPER_TRANSITIONS,
        name="wilac_default_reconstruction",
        provenance=provenance,
    )
    curve_err = check_curves(params, q, v)
    log("Largest |adhesion error| of the regressed parameters vs the targets: "
        + ", ".join(f"{c} {e:.4f}" for c, e in curve_err.items()))
    path = save_wilac_parameters(params, out)
    if load_wilac_parameters(path) != params:
        raise RuntimeError(f"{path}: saved file does not load back to the same parameters")
    log(f"Wrote {path}")
    return {"params": params, "path": path, "fit": fit_stats, "regressions": table,
            "curve_error": curve_err}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output TOML file")
    parser.add_argument("--coarse", action="store_true", help="5 x 5 grid (quick check)")
    parser.add_argument("--quiet", action="store_true")
    args = parser.parse_args(argv)
    build(args.out, coarse=args.coarse, quiet=args.quiet)
    return 0


if __name__ == "__main__":
    sys.exit(main())
