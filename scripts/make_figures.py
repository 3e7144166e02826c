#!/usr/bin/env python3
"""Write the README figures of the WILAC model to ``docs/figures/wilac_*.png``.

Uses the default WILAC parameter set (a reconstruction: ``docs/wilac-default.md``)::

    python3 scripts/make_figures.py [--out docs/figures] [--dpi 100]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from railadhesion.plotting import (
    plot_wilac_curves,
    plot_wilac_speeds,
    plot_wilac_water,
    plot_wilac_weights,
)

REPO = Path(__file__).resolve().parents[1]

FIGURES = {
    "wilac_weights.png": lambda: plot_wilac_weights(),
    "wilac_curves.png": lambda: plot_wilac_curves(),
    "wilac_water.png": lambda: plot_wilac_water(),
    "wilac_speeds.png": lambda: plot_wilac_speeds(),
    "wilac_speeds_wet.png": lambda: plot_wilac_speeds(speeds=(10,), water_flow=350.0),
}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "figures")
    parser.add_argument("--dpi", type=int, default=100)
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, make in FIGURES.items():
        path = args.out / name
        make().savefig(path, dpi=args.dpi)
        print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
