"""Where the table model's error lives: the table against the exact solver on 60 x 60.

Usage::

    PYTHONPATH=src MPLBACKEND=Agg python3 scripts/table_accuracy.py [--jobs 2] [--write-docs]

Cases: a/b x creep direction x creep magnitude x spin (normalised by tau = mu p0/G and
c = sqrt(ab): xi' = xi/tau, eta' = eta/tau, phi' = phi c/tau), at nu = 0.25, 0.28 and 0.30.
Error: |(dFx, dFy)|/(mu Fz). It is split into

* **interpolation**: the table against the solver on the table's build grid at the creepages
  the table actually interpolates (the creepages scaled with Kalker's coefficients at nu and
  the build grid's own coefficients at the table's nu);
* **build grid**: that solver against the solver on 60 x 60 at the table's nu, creepages
  scaled with Kalker's coefficients at nu over those at the table's nu (discretisation);
* **nu scaling** (nu != the table's only): the latter against the solver at nu on 60 x 60.

The 60 x 60 reference is cached (``--cache``, default in the temporary directory), so that a
rebuilt table is measured again in seconds. ``--write-docs`` writes the map
``docs/figures/exact_table_error_map.png`` and the section of
``docs/validation/exact_models.md`` between its markers. Runtime without the cache: about
6 minutes with ``--jobs 2`` on the shared project machine (about 5 CPU minutes); with it,
about 30 s.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import math
import tempfile
import time
import warnings
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from railadhesion.contact.exact import exact_rolling
from railadhesion.contact.kalker import kalker_coefficients
from railadhesion.contact.table import TABLE_POISSON, _load, build_grid, exact_table_forces
from railadhesion.plausibility import PlausibilityWarning

ROOT = Path(__file__).resolve().parents[1]
G, MU, FZ, C = 8.2e10, 0.3, 1e5, 6e-3
AOB = (0.2, 0.3, 0.5, 1.0, 2.0, 3.3, 5.0)
DIRECTIONS = (0.0, 30.0, 60.0, 90.0)  # degrees, of (xi', eta')
MAGNITUDES = (0.1, 0.3, 1.0, 3.0)  # |(xi', eta')|
SPINS = (-3.0, -1.0, -0.3, 0.0, 0.3, 1.0, 3.0)  # phi'
POISSONS = (0.25, 0.28, 0.30)
REF_GRID = 60


def cases():
    """(a/b, direction, magnitude, spin'), a, b, xi, eta, phi: one row per case."""
    rows = []
    for aob, th, r, ph in itertools.product(AOB, DIRECTIONS, MAGNITUDES, SPINS):
        a, b = C * math.sqrt(aob), C / math.sqrt(aob)
        tau = MU * 3 * FZ / (2 * math.pi * a * b) / G
        t = math.radians(th)
        rows.append((aob, th, r, ph, a, b, r * math.cos(t) * tau, r * math.sin(t) * tau,
                     ph * tau / C))  # fmt: skip
    return np.array(rows)


def random_cases(n=300, seed=22):
    """Random cases off the map's values: a/b log-uniform in [0.2, 5], creep direction
    uniform, magnitude log-uniform in [0.03, 10] tau, spin uniform in [-3, 3] tau/c (zero on
    a fifth); same columns as :func:`cases`."""
    rng = np.random.default_rng(seed)
    aob = np.exp(rng.uniform(math.log(0.2), math.log(5.0), n))
    th = rng.uniform(-180.0, 180.0, n)
    r = np.exp(rng.uniform(math.log(0.03), math.log(10.0), n))
    ph = rng.uniform(-3.0, 3.0, n) * (rng.random(n) > 0.2)
    a, b = C * np.sqrt(aob), C / np.sqrt(aob)
    tau = MU * 3 * FZ / (2 * np.pi * a * b) / G
    t = np.radians(th)
    return np.stack([aob, th, r, ph, a, b, r * np.cos(t) * tau, r * np.sin(t) * tau,
                     ph * tau / C], axis=1)  # fmt: skip


def _solve(args):
    xi, eta, phi, a, b, nu, grid = args
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        r = exact_rolling(xi, eta, phi, FZ, a, b, MU, shear_modulus=G, poisson=nu,
                          nx=grid, ny=grid)  # fmt: skip
    return np.stack([r.fx, r.fy])


def solve(xi, eta, phi, a, b, nu, grid, jobs=1):
    """(2, n) forces of the solver, in ``jobs`` processes."""
    if jobs <= 1:
        return _solve((xi, eta, phi, a, b, nu, grid))
    parts = np.array_split(np.arange(xi.size), 4 * jobs)
    with ProcessPoolExecutor(jobs) as pool:
        out = list(pool.map(_solve, [(xi[p], eta[p], phi[p], a[p], b[p], nu, grid)
                                     for p in parts]))  # fmt: skip
    return np.concatenate(out, axis=1)


def grid_coefficients(aob, nu, nx, ny):
    """The solver's own linear coefficients (C11, C22, C23) on nx x ny at a/b."""
    a, b = C * math.sqrt(aob), C / math.sqrt(aob)
    with warnings.catch_warnings():  # mu = 1000 on purpose: no slip, Kalker's linear limit
        warnings.simplefilter("ignore", PlausibilityWarning)
        lin = exact_rolling([1e-6, 0, 0], [0, 1e-6, 0], [0, 0, 1e-4], FZ, a, b, 1e3,
                            shear_modulus=G, poisson=nu, nx=nx, ny=ny)  # fmt: skip
    return np.array([-lin.fx[0] / (G * C * C * 1e-6), -lin.fy[1] / (G * C * C * 1e-6),
                     -lin.fy[2] / (G * C**3 * 1e-4)])  # fmt: skip


def reference(cs, nu, cache: Path, jobs):
    """Solver at 60 x 60 at nu; and at the table's nu with the creepages scaled by Kalker's
    coefficients at nu over those at the table's nu (the same when nu is the table's)."""
    tag = repr((nu, REF_GRID, TABLE_POISSON, "compliance"))
    key = hashlib.sha1(cs.tobytes() + tag.encode()).hexdigest()
    path = cache / f"table_accuracy_{key[:16]}.npz"
    if path.exists():
        z = np.load(path)
        return z["ref"], z["scaled"]
    aob, _, _, _, a, b, xi, eta, phi = cs.T
    ref = solve(xi, eta, phi, a, b, nu, REF_GRID, jobs)
    if nu == TABLE_POISSON:
        scaled = ref
    else:
        kn = kalker_coefficients(aob, nu, compliance=True)
        k0 = kalker_coefficients(aob, TABLE_POISSON, compliance=True)
        sx, sy, ss = kn.c11 / k0.c11, kn.c22 / k0.c22, kn.c23 / k0.c23
        scaled = solve(xi * sx, eta * sy, phi * ss, a, b, TABLE_POISSON, REF_GRID, jobs)
    np.savez(path, ref=ref, scaled=scaled)
    return ref, scaled


def build_grid_solution(cs, nu, d):
    """The solver on the table's build grid at the table's nu, at the creepages the table
    interpolates: creepages scaled by Kalker's coefficient at nu over the build grid's own
    (the build grid of each case's a/b, :func:`railadhesion.contact.table.build_grid`)."""
    aob, _, _, _, a, b, xi, eta, phi = cs.T
    n, nu0 = int(d["grid"][0]), float(d["poisson"])
    out = np.empty((2, aob.size))
    for q in np.unique(aob):
        i = aob == q
        nx, ny = build_grid(q, n) if "grids" in d else (n, n)
        k = kalker_coefficients(q, nu, compliance=True)
        s = np.array([k.c11, k.c22, k.c23]) / grid_coefficients(q, nu0, nx, ny)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlausibilityWarning)
            r = exact_rolling(xi[i] * s[0], eta[i] * s[1], phi[i] * s[2], FZ, a[i], b[i], MU,
                              shear_modulus=G, poisson=nu0, nx=nx, ny=ny)  # fmt: skip
        out[:, i] = r.fx, r.fy
    return out


def error(f, g):
    return np.hypot(f[0] - g[0], f[1] - g[1]) / (MU * FZ)


def measure(jobs=1, cache=None, split=True, cs=None):
    """Errors per nu: dict nu -> dict(total, interp, grid, nuscale) of arrays over cases
    (default: :func:`cases`)."""
    cache = Path(cache or tempfile.gettempdir())
    cs = cases() if cs is None else cs
    aob, _, _, _, a, b, xi, eta, phi = cs.T
    d = _load()
    out = {}
    for nu in POISSONS:
        ref, scaled = reference(cs, nu, cache, jobs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlausibilityWarning)
            tab = np.stack(exact_table_forces(xi, eta, phi, FZ, a, b, MU, shear_modulus=G,
                                              poisson=nu)[:2])  # fmt: skip
        e = {"total": error(tab, ref), "ref": ref}
        if split:
            bg = build_grid_solution(cs, nu, d)
            e["interp"] = error(tab, bg)
            e["grid"] = error(bg, scaled)
            e["nuscale"] = error(scaled, ref)
        out[nu] = e
    return cs, out


def _stats(x):
    return f"{np.median(x):.4f} / {np.percentile(x, 95):.4f} / {x.max():.4f}"


#: Grids of the converged check (:func:`converged_check`): the solver's error falls about as
#: 1/n (docs/validation/exact_solver.md), so F(inf) ~ (n2 F(n2) - n1 F(n1))/(n2 - n1).
CONVERGED_GRIDS = (90, 120)


def converged_check(cs, err, ref, k, nu=TABLE_POISSON):
    """The k cases of ``cs`` with the largest total error ``err`` against ``ref`` (the solver
    on 60 x 60 at nu, :func:`reference`), against the solver extrapolated to a converged
    grid from :data:`CONVERGED_GRIDS`: rows (case index, table - 60 x 60, table - converged,
    60 x 60 - converged) in mu Fz."""
    aob, _, _, _, a, b, xi, eta, phi = cs.T
    idx = np.argsort(-err)[:k]
    n1, n2 = CONVERGED_GRIDS
    f1 = solve(xi[idx], eta[idx], phi[idx], a[idx], b[idx], nu, n1)
    f2 = solve(xi[idx], eta[idx], phi[idx], a[idx], b[idx], nu, n2)
    f60 = ref[:, idx]
    conv = (n2 * f2 - n1 * f1) / (n2 - n1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        tab = np.stack(exact_table_forces(xi[idx], eta[idx], phi[idx], FZ, a[idx], b[idx], MU,
                                          shear_modulus=G, poisson=nu)[:2])  # fmt: skip
    return [(int(i), error(tab[:, j], f60[:, j]), error(tab[:, j], conv[:, j]),
             error(f60[:, j], conv[:, j])) for j, i in enumerate(idx)]  # fmt: skip


def report(cs, errs):
    aob, th, r, ph = cs.T[:4]
    print(f"{len(cs)} cases per nu; errors in mu Fz: median / 95 % / max")
    for nu, e in errs.items():
        print(f"nu = {nu}:")
        for k, v in e.items():
            if k == "ref":
                continue
            i = int(np.argmax(v))
            print(f"  {k:8s} {_stats(v)}   worst: a/b {aob[i]}, dir {th[i]:.0f}, "
                  f"|creep'| {r[i]}, spin' {ph[i]}")
    for nu, e in errs.items():
        print(f"nu = {nu}: max total error by a/b and spin' (rows a/b, columns spin')")
        print("        " + " ".join(f"{s:7.1f}" for s in SPINS))
        for q in AOB:
            row = [e["total"][(aob == q) & (ph == s)].max() for s in SPINS]
            print(f"  {q:5.2f} " + " ".join(f"{v:7.4f}" for v in row))
        print(f"nu = {nu}: max total error by a/b and |creep'| (rows a/b, columns |creep'|)")
        for q in AOB:
            row = [e["total"][(aob == q) & (r == m)].max() for m in MAGNITUDES]
            print(f"  {q:5.2f} " + " ".join(f"{v:7.4f}" for v in row))


BEGIN = "<!-- scripts/table_accuracy.py: begin -->"
END = "<!-- scripts/table_accuracy.py: end -->"
PAGE = ROOT / "docs" / "validation" / "exact_models.md"
FIGURE = ROOT / "docs" / "figures" / "exact_table_error_map.png"


def write_docs(cs, errs, seconds, rnd=None, conv=None):
    """The error map (figure) and the section of the validation page between BEGIN and END."""
    import matplotlib.pyplot as plt

    aob, th, r, ph = cs.T[:4]
    worst = np.max([e["total"] for e in errs.values()], axis=0)  # over nu
    fig, axes = plt.subplots(1, len(DIRECTIONS), figsize=(13, 3.6), sharey=True)
    vmax = max(0.02, float(worst.max()))
    for ax, d in zip(axes, DIRECTIONS, strict=True):
        grid = np.array([[worst[(aob == q) & (th == d) & (ph == sp)].max() for sp in SPINS]
                         for q in AOB])  # fmt: skip
        im = ax.imshow(grid, origin="lower", cmap="viridis", vmin=0.0, vmax=vmax, aspect="auto")
        for i in range(len(AOB)):
            for j in range(len(SPINS)):
                ax.text(j, i, f"{1e3 * grid[i, j]:.0f}", ha="center", va="center", fontsize=7,
                        color="w" if grid[i, j] < 0.6 * vmax else "k")  # fmt: skip
        ax.set_xticks(range(len(SPINS)), [f"{v:g}" for v in SPINS])
        ax.set_yticks(range(len(AOB)), [f"{v:g}" for v in AOB])
        ax.set_xlabel("spin φ c/τ")
        ax.set_title(f"creep direction {d:.0f}°")
    axes[0].set_ylabel("a/b")
    fig.colorbar(im, ax=axes, label="max |ΔF|/(μFz)")
    fig.suptitle("Table model against the exact solver on 60 × 60: largest error over creep "
                 "magnitude and ν = 0.25, 0.28, 0.30 (numbers: 1e-3 μFz)", fontsize=10)  # fmt: skip
    fig.savefig(FIGURE, dpi=110, bbox_inches="tight")
    plt.close(fig)
    n = len(cs)
    lines = [
        BEGIN,
        "",
        "## Table model: error map against the solver on 60 × 60",
        "",
        "Generated by `scripts/table_accuracy.py` (this section only). Reference: "
        f"`exact_rolling` on {REF_GRID} × {REF_GRID} at each ν (the grid of the issue's "
        "check against CONTACT). "
        f"{n} cases per ν: a/b ∈ {{{', '.join(f'{v:g}' for v in AOB)}}}, creep direction "
        f"{', '.join(f'{v:.0f}°' for v in DIRECTIONS)}, magnitude √(ξ'² + η'²) = "
        f"{', '.join(f'{v:g}' for v in MAGNITUDES)}, spin φ' = "
        f"{', '.join(f'{v:g}' for v in SPINS)} (ξ' = ξ/τ, φ' = φc/τ, τ = μp0/G, "
        "c = √(ab)). Error |ΔF|/(μFz), ΔF the vector difference of (Fx, Fy); split into the "
        "interpolation (table against the solver on its build grid at the creepages it "
        "interpolates), the build grid (that solver against 60 × 60 at the table's ν) and "
        "the ν scaling (creepages scaled with Kalker's coefficients, against the solver at ν).",
        "",
        "| ν | part | median | 95 % | max | worst case (a/b, direction, magnitude, spin) |",
        "|---:|---|---:|---:|---:|---|",
    ]
    for nu, e in errs.items():
        for k, name in (("total", "**total**"), ("interp", "interpolation"),
                        ("grid", "build grid"), ("nuscale", "ν scaling")):  # fmt: skip
            if k == "nuscale" and nu == TABLE_POISSON:
                continue
            v = e[k]
            i = int(np.argmax(v))
            lines.append(f"| {nu:g} | {name} | {np.median(v):.4f} | {np.percentile(v, 95):.4f}"
                         f" | {v.max():.4f} | {aob[i]:g}, {th[i]:.0f}°, {r[i]:g}, {ph[i]:g} |")
    if rnd:
        n_r = len(next(iter(rnd.values())))
        lines += ["", f"And {n_r} random cases off these values (`random_cases`: a/b "
                  "log-uniform in [0.2, 5], any creep direction, magnitude log-uniform in "
                  "[0.03, 10], spin uniform in [−3, 3], zero on a fifth), total error: "
                  + "; ".join(f"ν = {nu:g}: median {np.median(v):.4f}, 95 % "
                              f"{np.percentile(v, 95):.4f}, max {v.max():.4f}"
                              for nu, v in rnd.items()) + "."]  # fmt: skip
    lines += [
        "",
        "Largest total error over ν, creep direction and magnitude, by a/b and spin φ':",
        "",
        "| a/b | " + " | ".join(f"φ' = {v:g}" for v in SPINS) + " |",
        "|---:|" + "---:|" * len(SPINS),
    ]
    for q in AOB:
        lines.append(f"| {q:g} | " + " | ".join(
            f"{worst[(aob == q) & (ph == sp)].max():.4f}" for sp in SPINS) + " |")  # fmt: skip
    order = np.argsort(-worst)[:6]
    lines += ["", "Worst cases (total error, largest over ν; exact solution on 60 × 60 at "
              "ν = 0.28):", ""]  # fmt: skip
    ref = errs[TABLE_POISSON]["ref"]
    for i in order:
        lines.append(f"* a/b = {aob[i]:g}, direction {th[i]:.0f}°, magnitude {r[i]:g}, "
                     f"spin {ph[i]:g}: {worst[i]:.4f} μFz (Fx, Fy = {ref[0, i] / (MU * FZ):.4f}, "
                     f"{ref[1, i] / (MU * FZ):.4f} μFz)")  # fmt: skip
    if conv:
        rc, rows = conv
        raob, rth, rr, rph = rc.T[:4]
        n1, n2 = CONVERGED_GRIDS
        lines += ["", f"Against the converged solution: the {len(rows)} random cases with the "
                  f"largest error at ν = {TABLE_POISSON:g}, the solver extrapolated from "
                  f"{n1} × {n1} and {n2} × {n2} elements (error about ∝ 1/n: "
                  f"F∞ ≈ ({n2} F{n2} − {n1} F{n1})/{n2 - n1}); |ΔF|/(μFz):", "",
                  "| a/b, direction, magnitude, spin | table − 60 × 60 | table − converged "
                  "| 60 × 60 − converged |", "|---|---:|---:|---:|"]  # fmt: skip
        for i, t60, tc, c60 in rows:
            lines.append(f"| {raob[i]:.2f}, {rth[i]:.0f}°, {rr[i]:.3f}, {rph[i]:.2f} | "
                         f"{t60:.4f} | {tc:.4f} | {c60:.4f} |")  # fmt: skip
    lines += [
        "",
        "![error map](../figures/exact_table_error_map.png)",
        "",
        "Reading:",
        "",
        "* **Before** (the table of issue 22: separate magnitude and spin axes, 20 × 20 build "
        "grid at every a/b; measured on the same cases with this script): total median / "
        "95 % / max 0.0030 / 0.0117 / 0.0550 μFz at ν = 0.25, 0.0018 / 0.0105 / 0.0609 at "
        "0.28, 0.0026 / 0.0121 / 0.0647 at 0.30. Two parts, both on long contacts: the "
        "interpolation (max 0.053–0.058, a/b = 5, deep sliding with large spin: magnitude "
        "and spin met in a corner of the (t, u) plane where the exact solution depends on "
        "their ratio only) and the build grid (max 0.045–0.047, a/b = 5, small creepage with "
        "spin: 20 × 20 elements of aspect 5 over the ellipse).",
        "* **The fixes**: polar axes — the magnitude of (X, Y, S) and the spin angle "
        "ψ = atan2(κS, |(X, Y)|), with κ = √(1 + (b/a)²) so that wide contacts, which turn to "
        "spin-dominated sliding at small S, get their nodes there — make deep sliding one "
        "smooth function on the last magnitude nodes (interpolation max 0.058 → 0.007); "
        "build grids with more elements along the rolling direction for long contacts (n × n "
        "up to a/b = 1, 40 × 10 at a/b = 5, about as many elements) bring the build grid's "
        "max from 0.047 to 0.008. Same node count and package size.",
        "* **Kalker's coefficients between his rows**: the creepages are scaled with the "
        "compliances 1/C interpolated linearly in b/a between Kalker's rows "
        "(`kalker_coefficients(..., compliance=True)`). C linear in b/a (CONTACT's "
        "interpolation, used before) put C23 4.5 % and C11, C22 1.3 % above the solver's own "
        "coefficients converged on 160 × 160 at a/b = 3.94; the compliances are within "
        "0.3 %. Linear → compliance (measured with this script on the n = 20 table): 95th "
        "percentile of the random cases 0.0088 → 0.0081, 0.0076 → 0.0055, 0.0108 → 0.0096 "
        "μFz at ν = 0.25, 0.28, 0.30, and the long contacts between rows (a/b ≈ 3.9) left "
        "the worst cases; the maxima rose by 0.001–0.002 (map 0.0134, 0.0149, 0.0159 → "
        "0.0150, 0.0165, 0.0175; random 0.0149, 0.0176, 0.0211 → 0.0141, 0.0188, 0.0221), in "
        "the cases of the last point, where the table was too soft already.",
        "* **Build grids of n = 24** (24 × 24 up to a/b = 1, 48 × 12 at a/b = 5; before "
        "n = 20: 20 × 20, 40 × 10). Measured with this script, n = 20 → 24: map max 0.0150, "
        "0.0165, 0.0175 → 0.0136, 0.0134, 0.0142 μFz at ν = 0.25, 0.28, 0.30; random max "
        "0.0141, 0.0188, 0.0221 → 0.0153, 0.0153, 0.0184, 95 % 0.0081, 0.0055, 0.0096 → "
        "0.0084, 0.0048, 0.0084; map median 0.0024, 0.0014, 0.0019 → 0.0023, 0.0019, 0.0029 "
        "(the finer grids' Kalker correction lands elsewhere against 60 × 60). Against the "
        "converged solution (extrapolated as above) on 40 random cases at ν = 0.28: median "
        "0.0029 → 0.0031, 90 % 0.0089 → 0.0079, max 0.0150 → 0.0121 μFz (60 × 60 itself: "
        "0.0011, 0.0060, 0.0073). Rebuild with `--jobs 2` on a two-core Intel Xeon at "
        "2.5 GHz: 231 s → 347 s. Same nodes, package size and lookup cost.",
        "* **What is left**: the worst cases (a/b 2.5–3.3, lateral creepage against spin: "
        "the net lateral force is a small difference of two large terms) are build-grid "
        "errors, larger than the map shows. Against the converged solution (the table "
        "above) the table is 0.032 μFz off at the worst random case, on the same side as "
        "60 × 60, which is itself 0.017 μFz from it (0.034 and 0.020 at the worst mapped "
        "case, a/b = 3.3, 90°, 1, −1, checked the same way). So measured against 60 × 60 "
        "the target of 0.02 cannot be read closer than the reference's own error in these "
        "cases, and the table's true error there is about twice the map's. The build grids "
        "(13–16 elements across at a/b = 2.5–3.3) with Kalker's correction of the linear "
        "range do not carry the partial-slip shape under lateral creepage and spin. Leads, "
        "checked against the converged solution on 15 random cases (the 8 worst and 7 "
        "others): build grids of n = 40 bring the build-grid solution of the worst case "
        "from 0.030 (n = 20; 0.023 at n = 24) to 0.015 μFz, their largest error over the 15 "
        "(2.8 times the elements of n = 24 and 5 times its solver time per case); "
        "Richardson extrapolation 2 F(n = 40) − F(n = 20) gives 0.0002–0.007 on 13 of them "
        "but 0.014–0.015 on 2 (the slip boundary crossing elements is not a smooth 1/n "
        "error): it would need a guard. For wide contacts (a/b ≤ 0.5) at ν ≠ 0.28 the ν "
        "scaling is the largest part (up to 0.013 μFz: Kalker's coefficients scale the "
        "linear range exactly but not the shape of the saturation).",
    ]
    lines += ["",
              f"(Runtime of the measurement: {seconds:.0f} s with the 60 × 60 reference "
              "cached.)", "", END]  # fmt: skip
    text = PAGE.read_text()
    section = "\n".join(lines)
    if BEGIN in text:
        head, rest = text.split(BEGIN, 1)
        text = head + section + rest.split(END, 1)[1]
    else:
        text = text.rstrip("\n") + "\n\n" + section + "\n"
    PAGE.write_text(text)
    print(f"wrote {FIGURE} and the section of {PAGE}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--cache", type=Path, default=None)
    ap.add_argument("--no-split", action="store_true", help="the total error only")
    ap.add_argument("--random", type=int, default=0,
                    help="also this many random cases (total error only)")  # fmt: skip
    ap.add_argument("--converged", type=int, default=0, metavar="K",
                    help="the K worst random cases against the converged solver (needs "
                         "--random)")  # fmt: skip
    ap.add_argument("--write-docs", action="store_true",
                    help="write the figure and the section of the validation page")  # fmt: skip
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    cs, errs = measure(args.jobs, args.cache, not args.no_split)
    report(cs, errs)
    seconds = time.perf_counter() - t0
    print(f"{seconds:.0f} s")
    rnd = None
    if args.random:
        rc, rerrs = measure(args.jobs, args.cache, False, random_cases(args.random))
        rnd = {nu: e["total"] for nu, e in rerrs.items()}
        print(f"{args.random} random cases (random_cases): total error median / 95 % / max")
        for nu, v in rnd.items():
            print(f"  nu = {nu}: {_stats(v)}")
    conv = None
    if args.random and args.converged:
        rows = converged_check(rc, rnd[TABLE_POISSON], rerrs[TABLE_POISSON]["ref"],
                               args.converged)
        conv = (rc, rows)
        print(f"worst {args.converged} random cases at nu = {TABLE_POISSON} against the "
              "converged solver: table - 60x60, table - converged, 60x60 - converged")
        for i, t60, tc, c60 in rows:
            print(f"  a/b {rc[i, 0]:.2f} dir {rc[i, 1]:.0f} mag {rc[i, 2]:.3f} spin "
                  f"{rc[i, 3]:.2f}: {t60:.4f} {tc:.4f} {c60:.4f}")
    if args.write_docs:
        write_docs(cs, errs, seconds, rnd, conv)


if __name__ == "__main__":
    main()
