"""Regenerate docs/oblique_map.json and docs/oblique_map.png: the oblique family's chaos atlas
(rollingtop.atlas, a chaos atlas over the constraint angle phi) for two bodies, and write the
table of docs/guide/oblique.md. Each cell: the median MEGNO and largest Lyapunov exponent of
three seeds of the level of one state (t = 100), the seeds that reach the vertical, the
phase-volume rate, the periodic orbits the section settles onto and the attracting ones.
Run: python docs/oblique_map.py   (about 5 minutes on 2 cores; ``--docs-only``: rewrite the
page's table and the figure from the JSON)"""

import json
import math
import sys
from pathlib import Path

import numpy as np

from rollingtop.atlas import atlas, atlas_spec_from_dict

ROOT = Path(__file__).resolve().parent.parent
JSON = ROOT / "docs" / "oblique_map.json"
FIGURE = ROOT / "docs" / "oblique_map.png"
PAGE = ROOT / "docs" / "guide" / "oblique.md"
START = "<!-- oblique-map:start (written by docs/oblique_map.py) -->"
END = "<!-- oblique-map:end -->"
ANSWER_START = "<!-- oblique-answer:start (written by docs/oblique_map.py) -->"
ANSWER_END = "<!-- oblique-answer:end -->"
#: phi in [0, pi): phi and phi + pi are one constraint.
ANGLES = [k * math.pi / 12 for k in range(12)]
STATE = {"gamma": [0.0, 0.6, 0.8], "omega": [0.7, -0.3, 2.0], "v_slip": 0.25}
BODIES = {
    "the paper's body": {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5},
    "a heavy flat top": {"R": 0.8, "m": 2.0, "g": 1.5, "a3": -0.25, "I1": 0.4, "I3": 0.2},
}
VARIABLES = ("megno", "lyapunov", "n_finished", "n_vertical", "n_failed", "volume_rate",
             "n_periodic", "n_attracting")  # fmt: skip


def main():
    rows = []
    for name, body in BODIES.items():
        spec = atlas_spec_from_dict({
            "body": body, "contact": {"model": "oblique"}, "initial": dict(STATE),
            "chaos": {"t_end": 100.0, "seeds": 3}, "axes": {"angle": ANGLES},
        })  # fmt: skip
        ds = atlas(spec, chunk=1, progress=lambda d, n, name=name: print(f"{name}: {d}/{n}"))
        cells = []
        for k, phi in enumerate(ANGLES):
            cell = {"angle": phi, "status": int(ds["status"].values[k])}
            for v in VARIABLES:
                x = ds[v].values[k]
                cell[v] = None if (isinstance(x, float) and math.isnan(x)) else x.item()
            cells.append(cell)
        rows.append({"name": name, "body": body, "cells": cells})
    JSON.write_text(json.dumps({"state": STATE, "t_end": 100.0, "seeds": 3, "bodies": rows},
                               indent=1) + "\n")  # fmt: skip
    print(f"wrote {JSON}")
    write(json.loads(JSON.read_text()))


def _fmt(x, spec):
    return "-" if x is None else format(x, spec)


def write(data):
    """The figure and the page's table from the JSON."""
    from matplotlib.figure import Figure

    from rollingtop.plot import save_figure

    fig = Figure(figsize=(9.0, 7.0))
    axes = fig.subplots(3, 1, sharex=True)
    for row, marker, colour in zip(data["bodies"], "os", ("C0", "C1"), strict=False):
        phi = np.array([c["angle"] for c in row["cells"]])
        get = lambda v, row=row: np.array(  # noqa: E731
            [np.nan if c[v] is None else c[v] for c in row["cells"]], dtype=float
        )
        name = row["name"]
        axes[0].plot(phi, get("megno"), marker=marker, color=colour, label=name)
        axes[1].plot(phi, get("volume_rate"), marker=marker, color=colour, label=name)
        axes[2].plot(phi, get("n_vertical"), marker=marker, color=colour, ls="--",
                     label=f"{name}: seeds reaching the vertical")  # fmt: skip
        axes[2].plot(phi, get("n_attracting"), marker=marker, color=colour, ls=":", mfc="none",
                     label=f"{name}: attracting periodic orbits")  # fmt: skip
    axes[0].axhline(2.0, color="0.6", lw=0.8)
    axes[0].set_ylabel("median MEGNO\n(seeds that finished)")
    axes[1].axhline(0.0, color="0.6", lw=0.8)
    axes[1].set_yscale("symlog", linthresh=1e-2)
    axes[1].set_ylabel("phase-volume rate\n(symlog)")
    axes[2].set_ylabel("count")
    axes[2].set_xlabel("constraint angle phi (rad): 0 the paper's, pi/2 the companion's")
    axes[2].set_xticks([0, math.pi / 4, math.pi / 2, 3 * math.pi / 4],
                       ["0", "pi/4", "pi/2", "3pi/4"])  # fmt: skip
    axes[1].margins(y=0.15)
    axes[2].set_ylim(-0.3, 4.6)  # room above the counts for the legend
    for ax in axes[:2]:
        ax.legend(fontsize=7, loc="best")
    axes[2].legend(fontsize=7, loc="upper center", ncol=2)
    fig.suptitle("the oblique family: no slip along cos(phi) nu + sin(phi) tau")
    save_figure(fig, FIGURE)
    print(f"wrote {FIGURE}")
    text = PAGE.read_text()
    blocks = ((START, END, block(data)), (ANSWER_START, ANSWER_END, answer_block(data)))
    for start, end, new in blocks:
        head, rest = text.split(start, 1)
        text = head + new + rest.split(end, 1)[1]
    PAGE.write_text(text)
    print(f"wrote the table and the answer in {PAGE}")


def answer_block(data):
    """The page's answer, markers included."""
    return "\n".join([ANSWER_START, *answer(data), ANSWER_END])


def block(data):
    """The page's table, markers included."""
    lines = [
        START,
        "| body | phi | MEGNO | Lyapunov | seeds finished / to the vertical / failed "
        "| phase-volume "
        "rate | periodic orbits (attracting) |",
        "|---|---|---|---|---|---|---|",
    ]
    for row in data["bodies"]:
        for c in row["cells"]:
            lines.append(
                f"| {row['name']} | {c['angle']:.4f} | {_fmt(c['megno'], '.3f')} | "
                f"{_fmt(c['lyapunov'], '.4f')} | {c['n_finished']} / {c['n_vertical']} / "
                f"{c['n_failed']} | "
                f"{_fmt(c['volume_rate'], '.3e')} | {c['n_periodic']} ({c['n_attracting']}) |"
            )
    lines.append(END)
    return "\n".join(lines)


def answer(data):
    """The page's measured answer, each number from the JSON."""
    cells = [(row["name"], c) for row in data["bodies"] for c in row["cells"]]
    ends = [c for _, c in cells if c["angle"] == 0.0]
    others = [c for _, c in cells if c["angle"] != 0.0]
    megno = [c["megno"] for _, c in cells if c["megno"] is not None]
    rate0 = max(abs(c["volume_rate"]) for c in ends)
    rates = [c["volume_rate"] for c in others if c["volume_rate"] is not None]
    seeds = data["seeds"]
    vertical = sum(c["n_vertical"] for c in others)
    end_megno = ", ".join(format(c["megno"], ".3f") for c in ends)
    return [
        f"- **At `phi = 0`** every seed ran to `t = {data['t_end']:g}`, with median MEGNO "
        f"{end_megno} and a phase-volume rate of at most "
        f"{rate0:.1e} in modulus (a total derivative over `t`: the paper's measure); the "
        f"section settles onto {', '.join(str(c['n_periodic']) for c in ends)} periodic "
        f"orbits, {sum(c['n_attracting'] for c in ends)} of them attracting.",
        f"- **At the other {len(others) // len(data['bodies'])} angles** "
        f"{vertical} of {seeds * len(others)} seeds reach the vertical before "
        f"`t = {data['t_end']:g}`; along the {len(rates)} initial motions that stay away "
        f"from it, the phase-volume rate lies between {min(rates):.3g} and {max(rates):.3g} "
        f"({sum(r < 0 for r in rates)} of {len(rates)} negative: phase volume contracts "
        "there).",
        f"- **MEGNO** (median per cell) over the seeds that finished, at every angle: "
        f"{min(megno):.3f} to {max(megno):.3f} (2 for quasi-periodic motion): no chaos among "
        f"the motions that stay away from the vertical; attracting periodic orbits found: "
        f"{sum(c['n_attracting'] for _, c in cells)}.",
    ]


if __name__ == "__main__":
    if "--docs-only" in sys.argv:
        write(json.loads(JSON.read_text()))
    else:
        main()
