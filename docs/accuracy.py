"""Measure the accuracy claims the docs make about long runs, and write them into their block.

For the paper's state (examples/paper.toml) under each contact model, t = 1000, rtol = 1e-12,
atol = 1e-14: the largest relative drift of every reported integral, the largest constraint
residual, the steps and the wall time. Run: python docs/accuracy.py [--write-docs]
(--write-docs replaces the block between the markers of docs/guide/accuracy.md; --readme is its
old name).
"""

from __future__ import annotations

import sys
from pathlib import Path

import rollingtop as rt

ROOT = Path(__file__).resolve().parents[1]
TARGET = ROOT / "docs" / "guide" / "accuracy.md"
START = "<!-- accuracy:start (written by docs/accuracy.py --write-docs) -->"
END = "<!-- accuracy:end -->"
WRITE_FLAGS = ("--write-docs", "--readme")


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


def replace_block(text: str, new_block: str) -> str:
    """``text`` with the block from ``START`` to ``END`` (markers included) replaced."""
    i, j = text.find(START), text.find(END)
    if i < 0 or j < i:
        raise SystemExit(f"{TARGET}: accuracy markers not found")
    return text[:i] + new_block + text[j + len(END) :]


def write_docs(new_block: str, path: Path = TARGET) -> None:
    path.write_text(replace_block(path.read_text(), new_block))


if __name__ == "__main__":
    text = block(measure())
    print(text)
    if any(flag in sys.argv for flag in WRITE_FLAGS):
        write_docs(text)
        print(f"wrote {TARGET.relative_to(ROOT)}")
