"""Regenerate docs/oblique_search.json: the oblique family's search for an invariant measure and
integrals by angle (rollingtop.symbolic.oblique_search, ``rollingtop verify --search``) for three
bodies, and write the table the models guide quotes.
Run: python docs/oblique_search.py   (about 90 s; ``--docs-only``: rewrite the guide's table
from the JSON)"""

import json
import sys
import time
from pathlib import Path

from rollingtop.symbolic.oblique_search import search

ROOT = Path(__file__).resolve().parent.parent
JSON = ROOT / "docs" / "oblique_search.json"
GUIDE = ROOT / "docs" / "guide" / "models.md"
START = "<!-- oblique-search:start (written by docs/oblique_search.py) -->"
END = "<!-- oblique-search:end -->"
BODIES = {
    "the paper's body": {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5},
    "a heavy flat top": {"R": 0.8, "m": 2.0, "g": 1.5, "a3": -0.25, "I1": 0.4, "I3": 0.2},
    "the balanced ball (a3 = 0, I3 = I1)": {
        "R": 1.0,
        "m": 1.0,
        "g": 1.0,
        "a3": 0.0,
        "I1": 0.3,
        "I3": 0.3,
    },
}


def main():
    rows = []
    for name, body in BODIES.items():
        t0 = time.perf_counter()
        result = search(body)
        rows.append({"name": name, **result.to_dict()})
        print(
            f"{name}: {time.perf_counter() - t0:.0f} s, obstruction {result.obstruction.as_expr()}"
        )
    JSON.write_text(json.dumps(rows, indent=1) + "\n")
    print(f"wrote {JSON}")
    write_guide(rows)


def _summary(angles, keep):
    """The angles' ``t`` values whose result ``keep`` selects, as a list."""
    return ", ".join(a["t"] for a in angles if keep(a)) or "none"


def write_guide(rows):
    text = GUIDE.read_text()
    head, rest = text.split(START, 1)
    tail = rest.split(END, 1)[1]
    GUIDE.write_text(head + block(rows) + tail)
    print(f"wrote the table in {GUIDE}")


def block(rows):
    """The guide's table, markers included, for the saved ``rows``."""
    lines = [
        START,
        "| body | density of `gamma3` (symbolic in `t`) | `t` with nothing beyond the classical "
        "integrals (linear, quadratic) and no density of degree <= 2 | `t` where a class holds "
        "more: bound / classical | integrals proved |",
        "|---|---|---|---|---|",
    ]
    for row in rows:
        angles = row["angles"]

        def closed(a):
            return all(a["bounds"][k] == a["known"][k] for k in a["bounds"])

        more = [
            f"{a['t']}: "
            + ", ".join(
                f"{k} {a['bounds'][k]}/{a['known'][k]}"
                for k in a["bounds"]
                if a["bounds"][k] != a["known"][k]
            )
            for a in angles
            if not closed(a)
        ]
        integrals = sorted({", ".join(a["integrals"]) for a in angles})
        lines.append(
            f"| {row['name']} | only where `{row['obstruction']} = 0` | "
            f"{_summary(angles, closed)} | {'<br>'.join(more) or 'none'} | "
            f"{'<br>'.join(integrals)} |"
        )
    lines.append(END)
    return "\n".join(lines)


if __name__ == "__main__":
    if "--docs-only" in sys.argv:
        write_guide(json.loads(JSON.read_text()))
    else:
        main()
