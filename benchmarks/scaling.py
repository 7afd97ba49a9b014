"""How rollingtop's cost grows with the work (issue 13, "The benchmark suite, side by side in one run").

Run:  python benchmarks/scaling.py [--only t_end,rtol,ensemble] [--fig-dir DIR] [--json FILE]
      (a quick version, smaller sizes; prints the results and writes the figures)

- :func:`scaling_t_end`: time and steps of one trajectory (the paper's state, rtol 1e-10) against
  ``t_end``; a fitted exponent near 1 means the cost is linear in the simulated time.
- :func:`scaling_rtol`: steps and time against ``rtol`` (atol = rtol / 100, as in W3) at a fixed
  ``t_end``; for an order-8 method the steps grow as ``rtol^(-1/8)`` once the step size is set by
  accuracy alone.
- :func:`scaling_ensemble`: ensemble time against the number of trajectories, on 1 and 2 threads,
  and the parallel efficiency ``t1 / (2 t2)`` per size.

Each returns a dict of numbers (for results.json: every point, the fitted exponents and
prefactors of ``y = c x^k`` by least squares in log-log) and writes one log-log figure with the
fits, ``benchmarks/scaling_{t_end,rtol,ensemble}.png``.  The sizes are measured interleaved, round
by round (each round visits every size once), and the time of a point is the median over rounds,
so a drift of the machine's speed does not bend a curve.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import ROOT, machine, median_time  # noqa: E402

BENCH = ROOT / "benchmarks"
PAPER = ROOT / "examples" / "paper.toml"


def fit_power(x, y) -> dict:
    """``y = c x^k`` by least squares on ``log y = log c + k log x``."""
    lx, ly = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    k, logc = np.polyfit(lx, ly, 1)
    resid = ly - (logc + k * lx)
    return {"exponent": float(k), "prefactor": float(np.exp(logc)),
            "max_rel_residual": float(np.max(np.abs(np.expm1(resid))))}  # fmt: skip


def local_exponents(x, y) -> list[float]:
    """Slopes between neighbouring points in log-log."""
    lx, ly = np.log(np.asarray(x, float)), np.log(np.asarray(y, float))
    return [float(v) for v in np.diff(ly) / np.diff(lx)]


# ----------------------------------------------------------------------------------------------
# figures
# ----------------------------------------------------------------------------------------------


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.rcParams.update({"font.size": 10, "axes.grid": True, "grid.alpha": 0.3,
                         "legend.fontsize": 9, "figure.dpi": 110})  # fmt: skip
    return plt


def _log_ticks(ax, x: bool = True, y: bool = True) -> None:
    """Plain-number tick labels at 1, 2, 5 x 10^k on the log axes (no minor labels)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axes = ([ax.xaxis] if x else []) + ([ax.yaxis] if y else [])
    for axis in axes:
        axis.set_major_locator(LogLocator(base=10, subs=(1.0, 2.0, 5.0)))
        axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        axis.set_minor_formatter(NullFormatter())


def _fit_line(ax, x, fit, style, label, colour):
    xs = np.geomspace(min(x), max(x), 50)
    ax.plot(xs, fit["prefactor"] * xs ** fit["exponent"], style, color=colour, lw=1.2,
            label=f"{label}: fit $\\propto x^{{{fit['exponent']:.3f}}}$")  # fmt: skip


def _time_panel(ax, x, points, out) -> None:
    """Wall time of the whole ``simulate`` call and of the compiled kernel, with their fits."""
    ax.loglog(x, [p["wall_s"] for p in points], "o", color="C0", label="simulate() call")
    _fit_line(ax, x, out["fit_wall"], "-", "call", "C0")
    ax.loglog(x, [p["kernel_wall_s"] for p in points], "s", color="C1", mfc="none",
              label="compiled kernel")  # fmt: skip
    _fit_line(ax, x, out["fit_kernel"], "--", "kernel", "C1")


def _save(fig, path: Path | None) -> str | None:
    if path is None:
        return None
    path = Path(path)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, bbox_inches="tight")
    try:
        shown = str(path.relative_to(ROOT))
    except ValueError:
        shown = str(path)
    return shown


def _machine_line() -> str:
    m = machine()
    return f"{m['cpu']}, {m['cores']} cores"


# ----------------------------------------------------------------------------------------------
# time against t_end
# ----------------------------------------------------------------------------------------------


def scaling_t_end(t_ends=(1e2, 3e2, 1e3, 3e3, 1e4), rounds: int = 5, rtol: float = 1e-10,
                  figure: Path | None = BENCH / "scaling_t_end.png", verbose: bool = True) -> dict:  # fmt: skip
    """rollingtop's wall time (the whole ``simulate`` call, and the compiled kernel's own time)
    and accepted steps against ``t_end``, W1's state and tolerances; fitted exponents."""
    import rollingtop as rt

    say = print if verbose else (lambda *a, **k: None)
    base = rt.load_scenario(PAPER).with_overrides(rtol=rtol, atol=rtol / 100, samples=2)
    rt.simulate(base, t_end=1.0)  # compile / load the cache outside the timing
    t_ends = sorted(float(t) for t in t_ends)
    # short runs are repeated within a round so that every point costs about the same
    inner = {t: max(1, min(25, round(t_ends[-1] / t))) for t in t_ends}
    walls = {t: [] for t in t_ends}
    kernels = {t: [] for t in t_ends}
    steps: dict[float, dict] = {}
    for k in range(rounds):
        for t in t_ends:
            sc = base.with_overrides(t_end=t)
            wall, _, traj = median_time(lambda sc=sc: rt.simulate(sc), inner[t])
            walls[t].append(wall)
            kernels[t].append(traj.stats["wall_time_s"])
            st = traj.stats
            steps[t] = {"steps": st["steps"], "rejected_steps": st.get("rejected_steps"),
                        "rhs_evals": st["rhs_evals"]}  # fmt: skip
        say(f"  t_end round {k + 1}/{rounds}: " + ", ".join(
            f"{t:g}: {1e3 * walls[t][-1]:.1f} ms" for t in t_ends), flush=True)  # fmt: skip
    points = []
    for t in t_ends:
        wall, kern = statistics.median(walls[t]), statistics.median(kernels[t])
        points.append({"t_end": t, "wall_s": wall, "kernel_wall_s": kern, **steps[t],
                       "us_per_step": 1e6 * wall / steps[t]["steps"], "inner_repeat": inner[t],
                       "times": walls[t]})  # fmt: skip
    x = [p["t_end"] for p in points]
    out = {
        "rtol": rtol, "atol": rtol / 100, "rounds": rounds, "points": points,
        "fit_wall": fit_power(x, [p["wall_s"] for p in points]),
        "fit_kernel": fit_power(x, [p["kernel_wall_s"] for p in points]),
        "fit_steps": fit_power(x, [p["steps"] for p in points]),
        "local_exponents_wall": local_exponents(x, [p["wall_s"] for p in points]),
    }  # fmt: skip

    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    _time_panel(a1, x, points, out)
    a1.set_xlabel("t_end")
    a1.set_ylabel("wall time (s)")
    a1.set_title("time against t_end")
    _log_ticks(a1)
    a1.legend()
    a2.loglog(x, [p["steps"] for p in points], "o", color="C2", label="accepted steps")
    _fit_line(a2, x, out["fit_steps"], "-", "steps", "C2")
    a2.set_xlabel("t_end")
    a2.set_ylabel("accepted steps")
    a2.set_title("steps against t_end")
    _log_ticks(a2)
    a2.legend()
    fig.suptitle(f"rollingtop, paper's state, rtol {rtol:g}, atol {rtol / 100:g} (median of "
                 f"{rounds} interleaved rounds; {_machine_line()})", fontsize=9)  # fmt: skip
    out["figure"] = _save(fig, figure)
    plt.close(fig)
    return out


# ----------------------------------------------------------------------------------------------
# steps and time against rtol
# ----------------------------------------------------------------------------------------------


def scaling_rtol(rtols=(1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13), t_end: float = 1e3,
                 rounds: int = 5, figure: Path | None = BENCH / "scaling_rtol.png",
                 verbose: bool = True) -> dict:  # fmt: skip
    """Accepted steps and wall time against ``rtol`` (atol = rtol / 100) at ``t_end``; fitted
    exponents (``-1/8`` expected for the steps of an order-8 method), over all points and over the
    tighter half, and the slopes between neighbours."""
    import rollingtop as rt

    say = print if verbose else (lambda *a, **k: None)
    base = rt.load_scenario(PAPER).with_overrides(t_end=t_end, samples=2)
    rt.simulate(base, t_end=1.0)
    rtols = sorted((float(r) for r in rtols), reverse=True)
    walls = {r: [] for r in rtols}
    kernels = {r: [] for r in rtols}
    stats: dict[float, dict] = {}
    for k in range(rounds):
        for r in rtols:
            wall, _, traj = median_time(lambda r=r: rt.simulate(base, rtol=r, atol=r / 100), 3)
            walls[r].append(wall)
            kernels[r].append(traj.stats["wall_time_s"])
            st = traj.stats
            stats[r] = {"steps": st["steps"], "rejected_steps": st.get("rejected_steps"),
                        "rhs_evals": st["rhs_evals"]}  # fmt: skip
        say(f"  rtol round {k + 1}/{rounds}: " + ", ".join(
            f"{r:.0e}: {1e3 * walls[r][-1]:.1f} ms" for r in rtols), flush=True)  # fmt: skip
    points = [{"rtol": r, "atol": r / 100, "wall_s": statistics.median(walls[r]),
               "kernel_wall_s": statistics.median(kernels[r]), **stats[r], "times": walls[r]}
              for r in rtols]  # fmt: skip
    x = [p["rtol"] for p in points]
    steps = [p["steps"] for p in points]
    half = max(3, len(points) // 2)
    out = {
        "t_end": t_end, "rounds": rounds, "expected_steps_exponent": -1 / 8, "points": points,
        "fit_steps": fit_power(x, steps),
        "fit_steps_tight_half": fit_power(x[-half:], steps[-half:]),
        "tight_half_rtols": x[-half:],
        "fit_wall": fit_power(x, [p["wall_s"] for p in points]),
        "fit_kernel": fit_power(x, [p["kernel_wall_s"] for p in points]),
        "local_exponents_steps": local_exponents(x, steps),
    }  # fmt: skip

    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.loglog(x, steps, "o", color="C2", label="accepted steps")
    _fit_line(a1, x, out["fit_steps"], "-", "all points", "C2")
    # the expected slope -1/8, through the tightest point
    xs = np.geomspace(min(x), max(x), 50)
    a1.loglog(xs, steps[-1] * (xs / x[-1]) ** (-1 / 8), ":", color="k", lw=1.2,
              label="$\\propto$ rtol$^{-1/8}$ (through the tightest point)")  # fmt: skip
    a1.set_xlabel("rtol (atol = rtol / 100)")
    a1.set_ylabel("accepted steps")
    a1.set_title("steps against rtol")
    _log_ticks(a1, x=False)
    a1.invert_xaxis()
    a1.legend()
    _time_panel(a2, x, points, out)
    a2.set_xlabel("rtol (atol = rtol / 100)")
    a2.set_ylabel("wall time (s)")
    a2.set_title("time against rtol")
    _log_ticks(a2, x=False)
    a2.invert_xaxis()
    a2.legend()
    fig.suptitle(f"rollingtop, paper's state, t_end = {t_end:g} (median of {rounds} interleaved "
                 f"rounds; {_machine_line()})", fontsize=9)  # fmt: skip
    out["figure"] = _save(fig, figure)
    plt.close(fig)
    return out


# ----------------------------------------------------------------------------------------------
# ensemble time against trajectories and threads
# ----------------------------------------------------------------------------------------------


def ensemble_states(n_max: int, seed: int = 13):
    """``n_max`` initial states from W2's grid (omega3 in [1.5, 2.5] x v_tau in [-0.4, 0.4]), in
    a fixed random order: the first ``n`` of them are a representative sample for every ``n``."""
    import rollingtop as rt
    from rollingtop.ensemble import grid_table, states_from_table

    sc = rt.load_scenario(PAPER)
    side = math.ceil(math.sqrt(n_max))
    states = states_from_table(sc, grid_table(f"omega3=1.5:2.5:{side},v_tau=-0.4:0.4:{side}"))
    order = np.random.default_rng(seed).permutation(len(states))
    return sc, states[order[:n_max]]


def scaling_ensemble(ns=(250, 500, 1000, 2000, 4000, 8000), threads=(1, 2), t_end: float = 100.0,
                     rounds: int = 3, rtol: float = 1e-10,
                     figure: Path | None = BENCH / "scaling_ensemble.png",
                     verbose: bool = True) -> dict:  # fmt: skip
    """``simulate_ensemble`` wall time against the number of trajectories, per thread count (the
    threads numba may use; more are dropped with a note), and the parallel efficiency
    ``t1 / (k t_k)`` per size; fitted exponents of time against ``n``."""
    import numba

    import rollingtop as rt

    say = print if verbose else (lambda *a, **k: None)
    ns = sorted(int(n) for n in ns)
    available = numba.config.NUMBA_NUM_THREADS
    used = [k for k in threads if k <= available]
    sc, states = ensemble_states(ns[-1])
    rt.simulate_ensemble(sc.body, sc.model, states[:4], t_end=1.0)  # compile outside timing
    walls = {(n, k): [] for n in ns for k in used}
    busy = {(n, k): [] for n in ns for k in used}
    steps: dict[int, int] = {}
    failed: dict[int, int] = {}
    for r in range(rounds):
        for n in ns:
            for k in used:
                cpu = time.process_time()
                res = rt.simulate_ensemble(sc.body, sc.model, states[:n], t_end=t_end, rtol=rtol,
                                           atol=rtol / 100, threads=k)  # fmt: skip
                cpu = time.process_time() - cpu
                walls[n, k].append(res.wall_time_s)
                busy[n, k].append(cpu / (k * res.wall_time_s))
                steps[n] = int(res.steps.sum())
                failed[n] = int(np.sum(res.status != 0))
        say(f"  ensemble round {r + 1}/{rounds}: " + ", ".join(
            f"{n}: " + "/".join(f"{walls[n, k][-1]:.2f}" for k in used) + " s" for n in ns),
            flush=True)  # fmt: skip
    points = []
    for n in ns:
        pt: dict = {"n": n, "steps_total": steps[n], "failed": failed[n]}
        for k in used:
            wall = statistics.median(walls[n, k])
            pt[f"threads_{k}"] = {"wall_s": wall, "times": walls[n, k],
                                  "trajectories_per_s": n / wall,
                                  "ns_per_step": 1e9 * wall * k / steps[n],
                                  "busy_fraction": statistics.median(busy[n, k])}  # fmt: skip
        if 1 in used:
            for k in used:
                if k > 1:
                    pairs = [a / (k * b) for a, b in zip(walls[n, 1], walls[n, k], strict=True)]
                    pt[f"parallel_efficiency_{k}"] = statistics.median(pairs)
                    pt[f"parallel_efficiency_{k}_pairs"] = pairs
        points.append(pt)
    out: dict = {"t_end": t_end, "rtol": rtol, "atol": rtol / 100, "rounds": rounds,
                 "threads": used, "threads_available": available, "points": points}  # fmt: skip
    if len(used) < len(threads):
        out["note"] = (
            f"numba may use {available} thread(s): {sorted(set(threads) - set(used))} skipped"
        )
    for k in used:
        out[f"fit_threads_{k}"] = fit_power(ns, [p[f"threads_{k}"]["wall_s"] for p in points])

    plt = _plt()
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4), gridspec_kw={"width_ratios": [3, 2]})
    for i, k in enumerate(used):
        y = [p[f"threads_{k}"]["wall_s"] for p in points]
        a1.loglog(ns, y, "os"[i % 2], color=f"C{i}", label=f"{k} thread{'s' if k > 1 else ''}")
        _fit_line(a1, ns, out[f"fit_threads_{k}"], "-", f"{k} thr.", f"C{i}")
    a1.set_xlabel("trajectories")
    a1.set_ylabel("ensemble wall time (s)")
    a1.set_title("ensemble time against size")
    _log_ticks(a1)
    a1.legend()
    effs = [k for k in used if k > 1 and 1 in used]
    for i, k in enumerate(effs):
        a2.semilogx(ns, [100 * p[f"parallel_efficiency_{k}"] for p in points], "o-",
                    color=f"C{i + 1}", label=f"{k} threads: t1 / ({k} t{k})")  # fmt: skip
    a2.axhline(100, color="k", lw=0.8)
    a2.axhline(90, color="k", lw=0.8, ls=":", label="90 %")
    a2.set_ylim(0, 110)
    a2.set_xlabel("trajectories")
    a2.set_ylabel("parallel efficiency (%)")
    a2.set_title("parallel efficiency")
    _log_ticks(a2, y=False)
    if effs:
        a2.legend(loc="lower right")
    else:
        a2.text(0.5, 0.5, "one thread only", transform=a2.transAxes, ha="center")
    fig.suptitle(f"rollingtop simulate_ensemble, W2's states, t_end = {t_end:g}, rtol {rtol:g} "
                 f"(median of {rounds} interleaved rounds; {_machine_line()})", fontsize=9)  # fmt: skip
    out["figure"] = _save(fig, figure)
    plt.close(fig)
    return out


def table(res: dict) -> str:
    """A Markdown table of the fitted exponents, from ``{"t_end": ..., "rtol": ...,
    "ensemble": ...}`` (any subset: the results of the three functions)."""
    rows = ["| How cost grows | measured | fitted exponent | expected |", "|---|---|---|---|"]
    if "t_end" in res:
        r = res["t_end"]
        span = f"t_end {r['points'][0]['t_end']:g} to {r['points'][-1]['t_end']:g}"
        rows.append(f"| time against t_end (rtol {r['rtol']:g}) | {span} | "
                    f"{r['fit_wall']['exponent']:.3f} (call), {r['fit_kernel']['exponent']:.3f} "
                    f"(kernel); steps {r['fit_steps']['exponent']:.3f} | 1 |")  # fmt: skip
    if "rtol" in res:
        r = res["rtol"]
        span = f"rtol {r['points'][0]['rtol']:.0e} to {r['points'][-1]['rtol']:.0e}"
        rows.append(f"| steps against rtol (t_end {r['t_end']:g}) | {span} | "
                    f"{r['fit_steps']['exponent']:.3f} (all), "
                    f"{r['fit_steps_tight_half']['exponent']:.3f} (rtol <= "
                    f"{r['tight_half_rtols'][0]:.0e}); time {r['fit_wall']['exponent']:.3f} | "
                    "-1/8 = -0.125 |")  # fmt: skip
    if "ensemble" in res:
        r = res["ensemble"]
        span = f"{r['points'][0]['n']} to {r['points'][-1]['n']} trajectories"
        fits = ", ".join(
            f"{r[f'fit_threads_{k}']['exponent']:.3f} ({k} thr.)" for k in r["threads"]
        )
        rows.append(f"| ensemble time against size (t_end {r['t_end']:g}) | {span} | {fits} | 1 |")
        effs = [p["parallel_efficiency_2"] for p in r["points"] if "parallel_efficiency_2" in p]
        if effs:
            rows.append(f"| 2-thread efficiency t1 / (2 t2) over those sizes | {span} | "
                        f"{100 * min(effs):.0f}-{100 * max(effs):.0f} % | >= 90 % |")  # fmt: skip
    return "\n".join(rows)


def summary(res: dict) -> str:
    """A few lines per measurement, for printing."""
    lines = []
    if "t_end" in res:
        r = res["t_end"]
        sizes = ", ".join(format(p["t_end"], "g") for p in r["points"])
        lines.append(f"time against t_end ({sizes}): "
                     f"exponent {r['fit_wall']['exponent']:.3f} (call), "
                     f"{r['fit_kernel']['exponent']:.3f} (kernel); steps exponent "
                     f"{r['fit_steps']['exponent']:.3f}")  # fmt: skip
        for p in r["points"]:
            lines.append(f"  t_end {p['t_end']:8g}: {1e3 * p['wall_s']:9.2f} ms (kernel "
                         f"{1e3 * p['kernel_wall_s']:9.2f} ms), {p['steps']:7d} steps, "
                         f"{p['us_per_step']:.2f} us/step")  # fmt: skip
    if "rtol" in res:
        r = res["rtol"]
        lines.append(f"steps against rtol (t_end {r['t_end']:g}): exponent "
                     f"{r['fit_steps']['exponent']:.4f} over all, "
                     f"{r['fit_steps_tight_half']['exponent']:.4f} over rtol <= "
                     f"{r['tight_half_rtols'][0]:.0e} (expected -1/8 = -0.125); time exponent "
                     f"{r['fit_wall']['exponent']:.3f}")  # fmt: skip
        for p in r["points"]:
            lines.append(f"  rtol {p['rtol']:.0e}: {p['steps']:7d} steps "
                         f"({p['rejected_steps']} rejected), {1e3 * p['wall_s']:9.2f} ms")  # fmt: skip
    if "ensemble" in res:
        r = res["ensemble"]
        fits = ", ".join(
            f"{k} thread(s) {r[f'fit_threads_{k}']['exponent']:.3f}" for k in r["threads"]
        )
        lines.append(f"ensemble time against n (t_end {r['t_end']:g}): exponent {fits}")
        for p in r["points"]:
            parts = [f"{k} thr {p[f'threads_{k}']['wall_s']:.3f} s" for k in r["threads"]]
            if "parallel_efficiency_2" in p:
                parts.append(f"efficiency {100 * p['parallel_efficiency_2']:.0f} %")
            lines.append(f"  n {p['n']:6d}: " + ", ".join(parts))
    for r in res.values():
        if isinstance(r, dict) and r.get("figure"):
            lines.append(f"wrote {r['figure']}")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description="rollingtop scaling measurements (quick sizes)")
    ap.add_argument("--only", default="t_end,rtol,ensemble")
    ap.add_argument("--full", action="store_true", help="the full sizes (the functions' defaults)")
    ap.add_argument("--fig-dir", default=str(BENCH))
    ap.add_argument("--json", metavar="FILE", help="also write the results to FILE")
    args = ap.parse_args()
    parts = set(args.only.split(","))
    fig = Path(args.fig_dir)
    quick = {} if args.full else {
        "ensemble": {"ns": (100, 200, 400, 800), "t_end": 20.0, "rounds": 2},
        "t_end": {"t_ends": (1e2, 3e2, 1e3), "rounds": 3},
        "rtol": {"t_end": 100.0, "rounds": 2},
    }  # fmt: skip
    res: dict = {}
    if "ensemble" in parts:  # first: it wants otherwise idle cores
        print("ensemble ...", flush=True)
        res["ensemble"] = scaling_ensemble(
            figure=fig / "scaling_ensemble.png", **quick.get("ensemble", {})
        )
    if "t_end" in parts:
        print("t_end ...", flush=True)
        res["t_end"] = scaling_t_end(figure=fig / "scaling_t_end.png", **quick.get("t_end", {}))
    if "rtol" in parts:
        print("rtol ...", flush=True)
        res["rtol"] = scaling_rtol(figure=fig / "scaling_rtol.png", **quick.get("rtol", {}))
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2))
    print(summary(res))
    print(table(res))


if __name__ == "__main__":
    main()
