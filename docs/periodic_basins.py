"""Regenerate docs/periodic.png and docs/basins.png: the relative periodic orbits of
examples/parallel.toml's level (``rollingtop periodic``) and the basins of its attracting ones
on a 40 x 40 grid of the section plane, sheet 0, after 200 crossings (``rollingtop basins``),
and print the numbers the guide quotes.
Run: python docs/periodic_basins.py [--scheduler ADDRESS]"""

import json
import sys
import time
from pathlib import Path

import numpy as np

from rollingtop.basins import LABELS, basin_map
from rollingtop.chaos import periodic_orbits
from rollingtop.plot import save_figure
from rollingtop.plot.basins import basins_figure
from rollingtop.plot.periodic import periodic_figure
from rollingtop.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent
GRID = 40
CROSSINGS = 200


def main(scheduler=None):
    sc = load_scenario(ROOT / "examples" / "parallel.toml")
    t0 = time.perf_counter()
    found = periodic_orbits(sc.body, sc.model, sc.require_state())
    print(f"periodic: {time.perf_counter() - t0:.1f} s")
    for o in found:
        print(f"  {o.returns} returns, period {o.period:.10g}, {o.type}, "
              f"|mu| {[round(float(abs(m)), 4) for m in o.multipliers]}, "
              f"through the vertical: {o.through_vertical}")  # fmt: skip
    save_figure(periodic_figure(found), ROOT / "docs" / "periodic.png", dpi=150)
    t0 = time.perf_counter()
    ds = basin_map(sc.body, sc.model, sc.require_state(), found=found, grid=GRID,
                   crossings=CROSSINGS, scheduler=scheduler)  # fmt: skip
    print(f"basins: {time.perf_counter() - t0:.1f} s")
    label = ds["label"].values
    on = label != -3
    for k, a in enumerate(json.loads(ds.attrs["attractors"])):
        print(f"  attractor {k + 1} ({a['returns']} returns): {np.mean(label[on] == k):.0%}")
    for code, name in LABELS.items():
        print(f"  {name}: {np.sum(label == code)} of {label.size}")
    save_figure(basins_figure(ds), ROOT / "docs" / "basins.png", dpi=150)


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--scheduler") + 1] if "--scheduler" in sys.argv else None)
