"""Regenerate docs/passage_rule.json: how the periodic orbits of examples/parallel.toml's level
depend on the parallel model's rule at the vertical (``[contact] pole_disk``, ``relax``,
``pass_relax``; rollingtop.contact.parallel), and print the table the models guide quotes.
Run: python docs/passage_rule.py   (about 6 minutes on 2 cores; ``--docs-only``: rewrite the
guide's table from the JSON)"""

import json
import sys
import time
from pathlib import Path

from rollingtop.chaos import periodic_orbits
from rollingtop.scenario import load_scenario

ROOT = Path(__file__).resolve().parent.parent
JSON = ROOT / "docs" / "passage_rule.json"
GUIDE = ROOT / "docs" / "guide" / "models.md"
START = "<!-- passage-rule:start (written by docs/passage_rule.py) -->"
END = "<!-- passage-rule:end -->"
#: The rules tried: the registered one first.
RULES = [
    {},
    {"pole_disk": 1e-5},
    {"pole_disk": 1e-7},
    {"pole_disk": 1e-8},
    {"relax": 0.5, "pass_relax": 0.5},
    {"relax": 2.0, "pass_relax": 2.0},
]


def main():
    sc = load_scenario(ROOT / "examples" / "parallel.toml")
    rows = []
    for rule in RULES:
        model = sc.model.with_parameters(**rule)
        t0 = time.perf_counter()
        found = periodic_orbits(sc.body, model, sc.require_state())
        orbits = [
            {
                "returns": o.returns,
                "period": round(o.period, 6),
                "type": o.type,
                "through_vertical": o.through_vertical,
                "moduli": [round(float(abs(m)), 4) for m in o.multipliers],
            }
            for o in found
        ]
        rows.append({"rule": model.parameter_values, "orbits": orbits})
        print(f"{model.parameter_values} ({time.perf_counter() - t0:.0f} s)")
        for o in orbits:
            flag = " through the vertical" if o["through_vertical"] else ""
            print(
                f"  {o['returns']} returns, period {o['period']}, {o['type']} {o['moduli']}{flag}"
            )
    JSON.write_text(json.dumps(rows, indent=1) + "\n")
    print(f"wrote {JSON}")
    write_guide(rows)


def _orbit(o):
    mods = ", ".join(f"{m:.3g}" for m in o["moduli"])
    mark = "*" if o["through_vertical"] else ""
    return f"{o['returns']}: {o['period']:.6f}{mark} {o['type']} ({mods})"


def write_guide(rows):
    """The table between START and END in the models guide."""
    lines = [
        START,
        "| rule (`[contact]`) | orbits: returns: period, type (multipliers' moduli); "
        "`*` through the vertical |",
        "|---|---|",
    ]
    for row in rows:
        rule = ", ".join(f"{k} = {v:g}" for k, v in row["rule"].items())
        lines.append(f"| {rule} | " + "<br>".join(_orbit(o) for o in row["orbits"]) + " |")
    lines.append(END)
    text = GUIDE.read_text()
    head, rest = text.split(START, 1)
    tail = rest.split(END, 1)[1]
    GUIDE.write_text(head + "\n".join(lines) + tail)
    print(f"wrote the table in {GUIDE}")


if __name__ == "__main__":
    if "--docs-only" in sys.argv:
        write_guide(json.loads(JSON.read_text()))
    else:
        main()
