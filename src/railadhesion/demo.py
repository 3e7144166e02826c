"""The demo behind ``railadhesion demo``: every model on a realistic case, printed and plotted.

Each number printed comes from the public API; where a published reference value exists it is
printed beside ours with its source.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

# CONTACT's tractcurv example, first series (Eurosprinter, exact Coulomb friction mu = 0.33):
# Fx/(mu Fn) at xi = 0.4 ... 3.2 per mille (MODELS.md §3, contact/tractcurv.ref_out).
_CONTACT_XI = np.arange(1, 9) * 0.4e-3
_CONTACT_FX = np.array([-0.2588, -0.4742, -0.6482, -0.7831, -0.8816, -0.9467, -0.9832, -0.9976])


class _Report:
    """Prints titled tables; every cell is plain text (units in [..] are not rich markup)."""

    def __init__(self, console: Console):
        self.console = console

    def table(self, title: str, columns: list[str], rows) -> None:
        table = Table(show_edge=True)
        for col in columns:
            table.add_column(escape(col), justify="right")
        for row in rows:
            table.add_row(*[escape(str(cell)) for cell in row])
        self.console.print()
        self.console.print(escape(title), style="bold", highlight=False)
        self.console.print(table)


def run_demo(out_dir: Path | str = "demo-output", console: Console | None = None) -> list[Path]:
    """Print the demo tables and write the demo figures; return the figure paths."""
    from railadhesion import adhesion
    from railadhesion.contact.fastsim import fastsim
    from railadhesion.contact.hertz import hertz_3d
    from railadhesion.contact.kalker import kalker_coefficients
    from railadhesion.models.parameters import polach_parameters
    from railadhesion.models.polach import polach_forces
    from railadhesion.models.twod import fletcher_condition
    from railadhesion.models.wilac import Wilac
    from railadhesion.plotting import (
        contact_semi_axes,
        plot_wilac_curves,
        plot_wilac_speeds,
        plot_wilac_water,
    )

    report = _Report(console or Console())
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)

    # 1. Hertz: a locomotive wheel (radius 0.625 m) on a rail head (lateral radius 0.3 m).
    q = 110e3
    h = hertz_3d(q, 0.625, np.inf, 0.3)
    report.table(
        "1. Hertz: Q = 110 kN, wheel R = 0.625 m on a rail head of lateral radius 0.3 m",
        ["a [mm]", "b [mm]", "a/b", "p0 [MPa]", "approach [µm]"],
        [[f"{v:.4g}" for v in (h.a * 1e3, h.b * 1e3, h.a_over_b, h.max_pressure / 1e6,
                               h.approach * 1e6)]],
    )

    # 2. Kalker's coefficients for that contact.
    k = kalker_coefficients(h.a_over_b, 0.28)
    report.table(
        f"2. Kalker's creepage coefficients at a/b = {h.a_over_b:.3f}, nu = 0.28",
        ["C11", "C22", "C23", "C33"],
        [[f"{float(v):.4f}" for v in k]],
    )

    # 3. Polach (k_A = k_S = 1, mu = 0.33) against CONTACT's exact Coulomb creep curve.
    a_e, b_e = 6.304e-3, 12.61e-3  # semi-axes printed in tractcurv.ref_out (a/b = 0.5)
    fx, _ = polach_forces(_CONTACT_XI, 0.0, 0.0, 106.7e3, 10.0, a_e, b_e, mu0=0.33)
    ours = fx / (0.33 * 106.7e3)
    report.table(
        "3. Polach vs CONTACT's exact theory (Eurosprinter, Coulomb mu = 0.33; tractcurv.ref_out)",
        ["xi [‰]", "CONTACT Fx/(mu Fn)", "Polach", "deviation [%]"],
        [[f"{xi * 1e3:.1f}", f"{ref:.4f}", f"{val:.4f}", f"{100 * (val - ref) / ref:+.1f}"]
         for xi, ref, val in zip(_CONTACT_XI, _CONTACT_FX, ours, strict=True)],
    )

    # 4. FASTSIM on CONTACT's check case (a = 8 mm, b = 4 mm, Fn = 82 kN, mu = 0.3). CONTACT's
    #    "40x40" is a 44x44 rectangular grid over 1.1 a x 1.1 b (fastsim.inp); our strip layout
    #    is Kalker's (converges faster).
    rows = []
    for n, bound, ref in [(40, "parabolic", -0.6118), (40, "elliptic", -0.6016),
                          (200, "parabolic", -0.6359), (200, "elliptic", -0.5956)]:
        kw = dict(shear_modulus=82e9, poisson=0.28, bound=bound)
        rect = fastsim(0.0, -0.000625, 0.625, 82e3, 8e-3, 4e-3, 0.3, nx=int(1.1 * n),
                       ny=int(1.1 * n), grid="rectangular", **kw)
        strips = fastsim(0.0, -0.000625, 0.625, 82e3, 8e-3, 4e-3, 0.3, nx=n, ny=n, **kw)
        rows.append([f"{n}x{n}", bound, f"{ref:.4f}", f"{float(rect.fy) / (0.3 * 82e3):.4f}",
                     f"{float(strips.fy) / (0.3 * 82e3):.4f}"])
    report.table(
        "4. FASTSIM on CONTACT's check case (a = 8 mm, b = 4 mm, 82 kN; fastsim.ref_out): "
        "Fy/(mu Fn)",
        ["grid", "bound", "CONTACT", "ours, CONTACT's grid", "ours, Kalker's strips"],
        rows,
    )

    # 5. Polach's published dry and wet sets on the locomotive contact.
    creep = np.array([0.002, 0.01, 0.03, 0.1, 0.3])
    rows = []
    for name in ("polach2005_dry", "polach2005_wet"):
        p = polach_parameters(name)
        fx, fy = polach_forces(creep, 0.0, 0.0, q, 10.0, h.a, h.b, **p.as_dict())
        rows.append([name, *[f"{v:.3f}" for v in adhesion(fx, fy, q)]])
    report.table(
        "5. Polach 2005 parameter sets at 110 kN, 10 m/s: adhesion |T|/Q against creep",
        ["set"] + [f"{c * 100:g} %" for c in creep],
        rows,
    )

    # 6. Fletcher's twin-disc conditions (seed 001, Tables 1-2).
    creep2d = np.array([0.001, 0.002, 0.005, 0.01])
    rows = []
    for code in ("D3", "W1", "L1", "O1", "CG1"):
        cond = fletcher_condition(code)
        rows.append([code, cond.lubricant, *[f"{v:.3f}" for v in cond.adhesion(creep2d)]])
    report.table(
        "6. Fletcher (2013) twin-disc conditions, 47 mm discs at 1000 MPa: adhesion Q/P",
        ["code", "lubricant"] + [f"{c * 100:g} %" for c in creep2d],
        rows,
    )

    # 7. WILAC on the tram rig (seed 000): adhesion over water flow and creep.
    w = np.array([0.0, 25.0, 35.0, 60.0, 350.0])
    creep_w = np.array([0.01, 0.03, 0.1, 0.3, 0.6, 0.9])
    a_t, b_t = contact_semi_axes("tram", 4200.0)
    mu_w = Wilac().adhesion(creep_w[None, :], 0.0, 0.0, 4200.0, 5.0, a_t, b_t, w[:, None])
    report.table(
        "7. WILAC, tram rig 4.2 kN, 5 m/s: adhesion |T|/Q "
        "(default set = a reconstruction, docs/wilac-default.md)",
        ["w [µl/s]"] + [f"{c * 100:g} %" for c in creep_w],
        [[f"{wi:g}", *[f"{v:.3f}" for v in row]] for wi, row in zip(w, mu_w, strict=True)],
    )

    written = []
    for name, fig in [("wilac_curves.png", plot_wilac_curves()),
                      ("wilac_water.png", plot_wilac_water()),
                      ("wilac_speeds.png", plot_wilac_speeds())]:
        path = out_dir / name
        fig.savefig(path, dpi=100)
        written.append(path)
    report.console.print()
    report.console.print(f"figures written: {', '.join(str(p) for p in written)}",
                         highlight=False)
    return written
