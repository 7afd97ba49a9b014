"""Measure the accuracy claims the README makes about long runs, and write them into its block.

For the paper's state (examples/paper.toml) under each contact model, t = 1000, rtol = 1e-12,
atol = 1e-14: the largest relative drift of every reported integral, the largest constraint
residual, the steps and the wall time. Run: python docs/accuracy.py [--readme]
"""

from __future__ import annotations

import sys
from pathlib import Path

import rollingtop as rt

ROOT = Path(__file__).resolve().parents[1]
START = "<!-- accuracy:start (written by docs/accuracy.py --readme) -->"
END = "<!-- accuracy:end -->"


def measure() -> list[dict]:
    rows = []
    for model in ("meridian", "smooth", "rough"):
        traj = rt.simulate(ROOT / "examples" / "paper.toml", t_end=1000.0, rtol=1e-12, atol=1e-14,
                           model=model, samples=20001)  # fmt: skip
        s = traj.summary()
        drifts = {k: v["max_rel_drift"] for k, v in s["integrals"].items() if v["max_rel_drift"]}
        rows.append(dict(model=model, worst=max(drifts, key=drifts.get),
                         drift=max(drifts.values()),
                         residual=s["constraints"]["max_abs_residual"],
                         steps=s["stats"]["steps"], wall=s["stats"]["wall_time_s"]))  # fmt: skip
    return rows


def block(rows) -> str:
    lines = [START, "", "| model | largest relative integral drift | (integral) | max constraint "
             "residual | steps | time (s) |", "|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        lines.append(f"| `{r['model']}` | {r['drift']:.2e} | {r['worst']} | {r['residual']:.1e} "
                     f"| {r['steps']:,} | {r['wall']:.2f} |")  # fmt: skip
    return "\n".join([*lines, "", END])


if __name__ == "__main__":
    rows = measure()
    text = block(rows)
    print(text)
    if "--readme" in sys.argv:
        readme = ROOT / "README.md"
        s = readme.read_text()
        i, j = s.index(START), s.index(END) + len(END)
        readme.write_text(s[:i] + text + s[j:])
