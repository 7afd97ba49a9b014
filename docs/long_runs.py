"""Long runs with and without the projection onto the integrals (issue 26): the relative drift of
every claimed integral against time, and gamma3's period against the reduction's quadrature.

The paper's body on the level of its Fig. 5 (examples/fig5.toml) under the meridian model to
t = 1e7; the example scenarios of the smooth, rough, rubber and parallel models to t = 1e6; the
default tolerances (rtol = 1e-10, atol = 1e-12). Writes docs/long_runs.png, docs/long_runs.json
and the block between the markers of docs/guide/accuracy.md and of README.md.
Run: python docs/long_runs.py [--quick]   (--quick: t / 100, for a look; writes nothing)
Apart, in parallel: --models=meridian --save=A.json, --models=smooth,rough --save=B.json, then
python docs/long_runs.py --part=A.json --part=B.json writes the figure and the blocks.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from rollingtop.dynamics.integrals import evaluate
from rollingtop.integrate import integrate
from rollingtop.io import write_bytes_atomic
from rollingtop.plot import save_figure
from rollingtop.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
RUNS = [("meridian", "fig5", 1e7), ("smooth", "smooth", 1e6), ("rough", "rough", 1e6),
        ("rubber", "rubber", 1e6), ("parallel", "parallel", 1e6)]  # fmt: skip
START = "<!-- long-runs:start (written by docs/long_runs.py) -->"
END = "<!-- long-runs:end -->"


def _turning_time(t, g3):
    """The time of the largest gamma3 in a dense window: a parabola through the sample at the
    maximum and its neighbours."""
    k = int(np.argmax(g3[1:-1])) + 1
    a, b, c = g3[k - 1], g3[k], g3[k + 1]
    dt = t[k + 1] - t[k]
    return t[k] + 0.5 * dt * (a - c) / (a - 2 * b + c)


def run(model: str, example: str, t_end: float) -> dict:
    sc = load_scenario(ROOT / "examples" / f"{example}.toml")
    body, y0 = sc.body, sc.require_state()
    names = sc.model.integrals_for(body)
    code = sc.model.kernel_code(body, y0)
    period = None
    if sc.model.reduction:
        from rollingtop.reduction import orbits, reduction_of

        red = reduction_of(model)
        level, h = red.level_of_state(body, y0), red.reduced_energy(body, y0)
        found = [o for o in orbits(level, h)
                 if o.gamma3_min - 1e-9 <= y0[14] <= o.gamma3_max + 1e-9]  # fmt: skip
        period = found[0].period
    grid = np.geomspace(1.0, t_end, 241)
    win = 1.5 * (period or 1.0)
    head = np.linspace(1.0, 1.0 + win, 600)
    tail = np.linspace(t_end - win, t_end, 600)
    t_eval = np.unique(np.concatenate([[0.0], grid, head, tail]))
    out = {"model": model, "example": example, "t_end": t_end, "period_quadrature": period}
    for proj in (False, True):
        start = time.perf_counter()
        try:
            r = integrate(code, body.params, y0, t_eval, rtol=1e-10, atol=1e-12,
                          max_steps=10**10, project_integrals=names if proj else ())  # fmt: skip
            reached, note = t_end, ""
            Y = r.y
        except Exception as err:  # noqa: BLE001 -- a run that stops (parallel's passages): noted
            reached, note, Y = math.nan, str(err), None
        key = "projected" if proj else "free"
        entry: dict = {"wall_s": time.perf_counter() - start, "note": note}
        if Y is not None:
            vals = evaluate(body, Y, names)
            scale = max(float(np.max(np.abs(y0[:6]))), 1e-300)
            on_grid = np.isin(t_eval, grid)
            drift = {}
            for name, v in vals.items():
                size = max(abs(float(v[0])), 1e-3 * scale)
                running = np.maximum.accumulate(np.abs(v - v[0]) / size)
                drift[name] = running[on_grid].tolist()
            entry["drift"] = drift
            entry["final_drift"] = {k: d[-1] for k, d in drift.items()}
            entry["steps"] = r.steps
            entry["projection_passes"] = r.projection_passes
            if period is not None:
                t1 = _turning_time(head, Y[np.isin(t_eval, head), 14])
                t2 = _turning_time(tail, Y[np.isin(t_eval, tail), 14])
                n = round((t2 - t1) / period)
                entry["period_error"] = abs((t2 - t1) / n - period) / period
        entry["reached"] = reached
        out[key] = entry
    out["grid"] = grid.tolist()
    return out


def figure(results: list[dict]):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 6.4), layout="constrained")
    axes = fig.subplots(2, 3).ravel()
    for ax, res in zip(axes, results, strict=False):
        t = np.array(res["grid"])
        for key, style in (("free", "-"), ("projected", "--")):
            entry = res[key]
            for k, (name, d) in enumerate(entry.get("drift", {}).items()):
                d = np.maximum(np.array(d), 1e-17)
                ax.loglog(t, d, style, color=f"C{k}", lw=1.2,
                          label=name if key == "free" else None)  # fmt: skip
        ax.axhline(1e-12, color="0.5", lw=0.7, ls=":")
        ax.set_title(f"{res['model']} ({res['example']}.toml)", fontsize=9)
        ax.set_xlabel("t")
        ax.set_ylabel("max relative drift so far")
        ax.set_ylim(1e-17, 1e-4)
        ax.legend(fontsize=7, loc="upper left")
    axes[-1].axis("off")
    axes[-1].text(0.02, 0.6, "solid: without projection\ndashed: --project-integrals\n"
                  "dotted: 1e-12", fontsize=10)  # fmt: skip
    return fig


def block(results: list[dict]) -> str:
    lines = [START, "", "| model | t | worst drift without projection | with projection | "
             "period error without | with |", "|---|---|---|---|---|---|"]  # fmt: skip

    def worst(entry: dict) -> str:
        if "final_drift" not in entry:
            return f"stopped ({entry['note'][:60]})"
        name, value = max(entry["final_drift"].items(), key=lambda kv: kv[1])
        return f"{value:.1e} ({name})"

    def period(entry: dict) -> str:
        return f"{entry['period_error']:.1e}" if "period_error" in entry else "-"

    for r in results:
        lines.append(f"| {r['model']} | {r['t_end']:.0e} | {worst(r['free'])} | "
                     f"{worst(r['projected'])} | {period(r['free'])} | "
                     f"{period(r['projected'])} |")  # fmt: skip
    lines += ["", END]
    return "\n".join(lines)


def replace_block(path: Path, text: str) -> None:
    head, sep, rest = path.read_text().partition(START)
    if not sep:
        raise SystemExit(f"{path}: no block {START!r}")
    _, sep2, tail = rest.partition(END)
    write_bytes_atomic(path, (head + text + tail).encode())


def main(argv: list[str]) -> None:
    quick = "--quick" in argv
    models = None
    for arg in argv:
        if arg.startswith("--models="):
            models = arg.split("=", 1)[1].split(",")
    parts = [a.split("=", 1)[1] for a in argv if a.startswith("--part=")]
    if parts:  # combine the results of runs made apart (--models=... --save=FILE)
        results = [r for f in parts for r in json.loads(Path(f).read_text())]
        order = [m for m, _, _ in RUNS]
        results.sort(key=lambda r: order.index(r["model"]))
    else:
        results = []
        for model, example, t_end in RUNS:
            if models is not None and model not in models:
                continue
            res = run(model, example, t_end / 100 if quick else t_end)
            print(model, {k: res[k].get("final_drift") for k in ("free", "projected")},
                  {k: res[k].get("period_error") for k in ("free", "projected")},
                  flush=True)  # fmt: skip
            results.append(res)
    save = [a.split("=", 1)[1] for a in argv if a.startswith("--save=")]
    if save:
        Path(save[0]).write_text(json.dumps(results))
        return
    if quick:
        save_figure(figure(results), "/tmp/long_runs_quick.png")
        print(block(results))
        return
    save_figure(figure(results), ROOT / "docs" / "long_runs.png", dpi=110)
    write_bytes_atomic(ROOT / "docs" / "long_runs.json", json.dumps(results).encode())
    text = block(results)
    for path in (ROOT / "docs" / "guide" / "accuracy.md", ROOT / "README.md"):
        replace_block(path, text)
    print(text)


if __name__ == "__main__":
    main(sys.argv[1:])
