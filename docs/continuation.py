"""Regenerate docs/continuation.png: the attracting 3-cycle of examples/parallel.toml's level
followed in a3 over [0.05, 0.15] (``rollingtop continue examples/parallel.toml --orbit 3 --param
a3 --range 0.05,0.15``, 40 points each way), and print the numbers the guide quotes.
Run: python docs/continuation.py"""

import time
from collections import Counter
from pathlib import Path

from rollingtop.chaos import continue_orbit, periodic_orbits
from rollingtop.plot import save_figure
from rollingtop.plot.continuation import branch_figure
from rollingtop.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent


def main():
    sc = load_scenario(ROOT / "examples" / "parallel.toml")
    found = periodic_orbits(sc.body, sc.model, sc.require_state())
    (orbit,) = [o for o in found if o.returns == 3]
    t0 = time.perf_counter()
    branch = continue_orbit(
        sc.body, sc.model, orbit, param="a3", bounds=(0.05, 0.15), max_points=40
    )
    print(
        f"continue: {time.perf_counter() - t0:.1f} s, {len(branch.points)} points, "
        f"a3 from {min(p.param for p in branch.points):.6g} to "
        f"{max(p.param for p in branch.points):.6g}, largest unfolding parameter "
        f"{branch.max_unfolding:.1g}, stopped: {branch.stopped}"
    )
    for b in branch.bifurcations:
        mu = ", ".join(
            f"{m.real:.5g}{m.imag:+.5g}i (|mu| {abs(m):.5g})" for m in b.point.multipliers
        )
        print(
            f"  {b.kind} at a3 = {b.point.param:.8g} (between {b.bracket[0]:.8g} and "
            f"{b.bracket[1]:.8g}; converged: {b.converged}), period {b.point.period:.6g}, "
            f"multipliers {mu}"
        )
    print("  types along the branch:", dict(Counter(p.type for p in branch.points)))
    save_figure(branch_figure(branch), ROOT / "docs" / "continuation.png", dpi=150)


if __name__ == "__main__":
    main()
