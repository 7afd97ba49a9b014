"""rollingtop benchmarks: side-by-side timings against scipy.integrate.solve_ivp.

Run:  python benchmarks/run_benchmarks.py [--quick] [--write-docs]
                                          [--only W1,W2,W3,cold_start,C,peers,scaling,atlas]
                                          [--out benchmarks/results.json]

--write-docs (old name: --readme) rewrites the results block of docs/guide/performance.md and
the performance table of README.md (tests/benchmarks/test_results_docs.py holds both to
results.json).

W1  one long trajectory (paper's body, examples/paper.toml, t = 1e4, rtol 1e-10, atol 1e-12):
    rollingtop vs solve_ivp(DOP853) with a plain NumPy right-hand side and with rollingtop's
    compiled right-hand side; wall time, steps, rhs evaluations, us per step and per evaluation,
    ratios, and the final-state difference (comparable accuracy).
W2  ensemble of 1e4 initial states, t = 100: trajectories per second on 1 and 2 threads and the
    parallel efficiency.
W3  work-precision: final-state error at t = 100 against a reference solved at rtol 1e-14 by two
    methods (rollingtop and solve_ivp), for rtol 1e-6 ... 1e-13.
Cold start: import + compile in a fresh process, with an empty numba cache and with a warm one.

Timings are medians of repeated runs in this one process (the slow baselines run fewer times);
nothing here is asserted: this is not part of the test suite.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

ROOT = Path(__file__).resolve().parents[1]


def numpy_rhs_factory(p, model="meridian"):
    """A plain NumPy right-hand side of the meridian model (MODEL.md, "Dynamics"): the full
    (v', w', lambda) linear system solved with numpy.linalg.solve -- what a careful user would
    write without rollingtop."""
    R, m, g, a3, I1, I2, I3 = p[:7]
    Iv = np.array([I1, I2, I3])
    e3 = np.array([0.0, 0.0, 1.0])
    avec = np.array([0.0, 0.0, a3])

    def rhs(t, y):
        v, w = y[0:3], y[3:6]
        alpha, beta, gamma = y[6:9], y[9:12], y[12:15]
        r = -R * gamma - avec
        gdot = np.cross(gamma, w)
        rdot = -R * gdot
        vp = v + np.cross(w, r)
        g3, g3dot = gamma[2], gdot[2]
        s = np.sqrt(1.0 - g3 * g3)
        pvec = e3 - g3 * gamma
        nu = pvec / s
        nudot = (-g3dot * gamma - g3 * gdot) / s + pvec * g3 * g3dot / s**3
        dirs = ((gamma, gdot), (nu, nudot))
        M = np.zeros((8, 8))
        b = np.zeros(8)
        M[0:3, 0:3] = m * np.eye(3)
        M[3:6, 3:6] = np.diag(Iv)
        b[0:3] = m * np.cross(v, w) - m * g * gamma
        b[3:6] = np.cross(Iv * w, w)
        for i, (d, dd) in enumerate(dirs):
            rxd = np.cross(r, d)
            M[0:3, 6 + i] = -d
            M[3:6, 6 + i] = -rxd
            M[6 + i, 0:3] = d
            M[6 + i, 3:6] = rxd
            b[6 + i] = -np.cross(w, rdot) @ d - vp @ dd
        sol = np.linalg.solve(M, b)
        dy = np.zeros_like(y)
        dy[0:6] = sol[0:6]
        dy[6:9] = np.cross(alpha, w)
        dy[9:12] = np.cross(beta, w)
        dy[12:15] = gdot
        dy[15] = v @ alpha
        dy[16] = v @ beta
        return dy

    return rhs


def compiled_rhs_factory(code, p):
    """solve_ivp calling rollingtop's compiled right-hand side through one compiled function of
    a single array (``f(t, y) -> dy``), the cheapest call numba offers from Python."""
    from numba import njit

    from rollingtop.dynamics import _kernel

    @njit
    def f(y):
        dy = np.empty(18)
        ws = (np.empty((4, 6)), np.empty(4), np.empty((4, 3)), np.empty((4, 4)), np.empty(4))
        _kernel.rhs(code, p, y, dy, ws)
        return dy

    f(np.ascontiguousarray(np.r_[np.zeros(6), np.eye(3).ravel(), 0.0, 0.0, 0.0]))

    def rhs(t, y):
        return f(y)

    return rhs


def median_time(fn, repeat):
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), times, result


def machine() -> dict:
    import numba
    import scipy

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
    }


def w1(t_end, repeat, numpy_repeat):
    """Each baseline run is paired with rollingtop runs right beside it (the median of three
    just before it, and for the long NumPy run also three just after) and the speed-up is the
    median of those paired ratios: this VM's speed changes by up to a factor of two within
    minutes, and adjacent runs see the same speed."""
    import rollingtop as rt

    sc = rt.load_scenario(ROOT / "examples" / "paper.toml").with_overrides(
        t_end=t_end, rtol=1e-10, atol=1e-12, samples=2
    )
    rt.simulate(sc, t_end=1.0)  # compile / load cache outside the timing
    ours_times = []

    def ours_now():
        wall, times, traj = median_time(lambda: rt.simulate(sc), 3)
        ours_times.extend(times)
        return wall, traj

    _, traj = ours_now()
    y_ours = traj.y[-1]
    y0 = sc.y0
    # accuracy: a reference at rtol 1e-14 by rollingtop, cross-checked by solve_ivp at 1e-14 on
    # the compiled right-hand side (the two agree to the "reference_cross_check")
    ref = rt.simulate(sc, rtol=1e-14, atol=1e-16).y[-1, :17]
    ref_b = solve_ivp(compiled_rhs_factory(0, sc.body.params), (0.0, t_end), y0,
                      method="DOP853", rtol=1e-14, atol=1e-16).y[:17, -1]  # fmt: skip
    out = {"t_end": t_end, "rtol": 1e-10, "atol": 1e-12,
           "reference_cross_check": float(np.max(np.abs(ref - ref_b)))}  # fmt: skip
    for name, factory, rep in (
        ("solve_ivp_compiled_rhs", lambda: compiled_rhs_factory(0, sc.body.params), repeat),
        ("solve_ivp_numpy_rhs", lambda: numpy_rhs_factory(sc.body.params), numpy_repeat),
    ):
        f = factory()
        times, ratios = [], []
        for _ in range(rep):
            before, _ = ours_now()
            start = time.perf_counter()
            sol = solve_ivp(f, (0.0, t_end), y0, method="DOP853", rtol=1e-10, atol=1e-12)
            times.append(time.perf_counter() - start)
            beside = before if rep > 1 else (before + ours_now()[0]) / 2
            ratios.append(times[-1] / beside)
        wall = statistics.median(times)
        steps = len(sol.t) - 1
        out[name] = {
            "wall_s": wall,
            "steps": steps,
            "rhs_evals": int(sol.nfev),
            "us_per_step": 1e6 * wall / steps,
            "us_per_rhs_eval": 1e6 * wall / sol.nfev,
            "times": times,
            "paired_ratios": ratios,
            "final_state_diff_vs_rollingtop": float(np.max(np.abs(sol.y[:17, -1] - y_ours[:17]))),
            "final_state_error": float(np.max(np.abs(sol.y[:17, -1] - ref))),
            "speedup_of_rollingtop": statistics.median(ratios),
        }
        print(f"  W1 {name}: {wall:.2f} s, x{statistics.median(ratios):.0f} "
              f"(paired: {', '.join(f'x{r:.0f}' for r in ratios)})", flush=True)  # fmt: skip
    wall = statistics.median(ours_times)
    out["rollingtop"] = {
        "wall_s": wall,
        "kernel_wall_s": traj.stats["wall_time_s"],
        "steps": traj.stats["steps"],
        "rhs_evals": traj.stats["rhs_evals"],
        "times": ours_times,
        "us_per_step": 1e6 * wall / traj.stats["steps"],
        "us_per_rhs_eval": 1e6 * wall / traj.stats["rhs_evals"],
        "final_state_error": float(np.max(np.abs(y_ours[:17] - ref))),
    }
    return out


def w2(n, t_end, repeat):
    """1- and 2-thread runs alternate and the efficiency is the median over those pairs: this VM's
    speed drifts by tens of per cent over minutes, and adjacent runs see the same drift. The
    process CPU time tells idle threads (load imbalance: CPU time well below threads x wall) from
    threads that were busy but ran slower (a host that shares or down-clocks its cores)."""
    import numba

    import rollingtop as rt
    from rollingtop.ensemble import grid_table, states_from_table

    sc = rt.load_scenario(ROOT / "examples" / "paper.toml")
    side = int(round(np.sqrt(n)))
    cols = grid_table(f"omega3=1.5:2.5:{side},v_tau=-0.4:0.4:{side}")
    states = states_from_table(sc, cols)
    rt.simulate_ensemble(sc.body, "meridian", states[:4], t_end=1.0)  # compile outside timing
    out = {"n": len(states), "t_end": t_end, "rtol": 1e-10, "atol": 1e-12,
           "threads_available": numba.config.NUMBA_NUM_THREADS, "repeat": repeat}  # fmt: skip
    times = {1: [], 2: []}
    busy = {1: [], 2: []}
    for _ in range(repeat):
        for threads in (1, 2):
            cpu = time.process_time()
            res = rt.simulate_ensemble(sc.body, "meridian", states, t_end=t_end, rtol=1e-10,
                                       atol=1e-12, threads=threads)  # fmt: skip
            cpu = time.process_time() - cpu
            times[threads].append(res.wall_time_s)
            busy[threads].append(cpu / (threads * res.wall_time_s))
            print(f"  W2 {threads} thread(s): {res.wall_time_s:.1f} s", flush=True)
    for threads in (1, 2):
        wall = statistics.median(times[threads])
        out[f"threads_{threads}"] = {
            "wall_s": wall,
            "times": times[threads],
            "busy_fraction": statistics.median(busy[threads]),
            "trajectories_per_s": len(states) / wall,
            "steps_total": int(res.steps.sum()),
            "failed": int(np.sum(res.status != 0)),
        }
    pairs = [a / (2 * b) for a, b in zip(times[1], times[2], strict=True)]
    out["parallel_efficiency_pairs"] = pairs
    out["parallel_efficiency_2"] = statistics.median(pairs)
    return out


def w3(t_end):
    import rollingtop as rt

    sc = rt.load_scenario(ROOT / "examples" / "paper.toml").with_overrides(t_end=t_end, samples=2)
    ref_a = rt.simulate(sc, rtol=1e-14, atol=1e-16).y[-1, :17]
    sol = solve_ivp(compiled_rhs_factory(0, sc.body.params), (0.0, t_end), sc.y0,
                    method="DOP853", rtol=1e-14, atol=1e-16)  # fmt: skip
    ref_b = sol.y[:17, -1]
    out = {"t_end": t_end, "reference_cross_check": float(np.max(np.abs(ref_a - ref_b))),
           "points": []}  # fmt: skip
    for rtol in (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13):
        wall, _, traj = median_time(lambda r=rtol: rt.simulate(sc, rtol=r, atol=r / 100), 7)
        f = compiled_rhs_factory(0, sc.body.params)
        wall_s, _, s2 = median_time(
            lambda r=rtol, f=f: solve_ivp(f, (0.0, t_end), sc.y0, method="DOP853", rtol=r,
                                          atol=r / 100), 1)  # fmt: skip
        out["points"].append({
            "rtol": rtol,
            "rollingtop_s": wall,
            "rollingtop_error": float(np.max(np.abs(traj.y[-1, :17] - ref_a))),
            "rollingtop_steps": traj.stats["steps"],
            "solve_ivp_compiled_s": wall_s,
            "solve_ivp_error": float(np.max(np.abs(s2.y[:17, -1] - ref_a))),
        })  # fmt: skip
    return out


#: The command timed for the start-up of the command line: a short run of the paper's scenario.
SIMULATE_COMMAND = ["-m", "rollingtop.cli", "simulate", "examples/paper.toml", "--t-end", "1",
                    "--json"]  # fmt: skip


def _wall(argv, env) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, *argv], env=env, cwd=ROOT, capture_output=True, check=True)
    return time.perf_counter() - start


def cold_start(warm_runs: int = 5):
    """Import + compile in a fresh process, and the wall time of ``rollingtop simulate`` (a short
    run of examples/paper.toml), each with an empty numba cache and with a warm one (the median
    of ``warm_runs`` processes)."""
    code = ("import time; t = time.perf_counter(); import rollingtop; "
            "from rollingtop.integrate import compile_kernels; compile_kernels(); "
            "print(time.perf_counter() - t)")  # fmt: skip
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = os.environ | {"NUMBA_CACHE_DIR": cache}
        for label in ("empty_cache_s", "warm_cache_s"):
            proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                                  text=True, check=True)  # fmt: skip
            out[label] = float(proc.stdout.strip().splitlines()[-1])
    with tempfile.TemporaryDirectory() as cache:
        env = os.environ | {"NUMBA_CACHE_DIR": cache}
        out["simulate_empty_cache_s"] = _wall(SIMULATE_COMMAND, env)
        out["simulate_warm_cache_s"] = statistics.median(
            _wall(SIMULATE_COMMAND, env) for _ in range(warm_runs)
        )
    return out


def _err(entry) -> str:
    return f"{entry['final_state_error']:.1e}" if "final_state_error" in entry else "-"


def _ratio(entry) -> str:
    ratios = entry.get("paired_ratios", [])
    text = f"x{entry['speedup_of_rollingtop']:.0f}"
    if len(ratios) > 1:
        text += f" (x{min(ratios):.0f}-x{max(ratios):.0f})"
    return text


def table(res) -> str:
    w = res["W1"]
    o, c, n = w["rollingtop"], w["solve_ivp_compiled_rhs"], w["solve_ivp_numpy_rhs"]
    rows = [
        f"| W1: t = {w['t_end']:g}, rtol {w['rtol']:g} | wall (s) | steps | rhs evals | us/step | us/eval | final-state error | rollingtop faster by (median of paired runs; range) |",
        "|---|---|---|---|---|---|---|---|",
        f"| rollingtop | {o['wall_s']:.3f} | {o['steps']} | {o['rhs_evals']} | {o['us_per_step']:.2f} | {o['us_per_rhs_eval']:.3f} | {_err(o)} | - |",
        f"| solve_ivp DOP853, rollingtop's compiled rhs | {c['wall_s']:.2f} | {c['steps']} | {c['rhs_evals']} | {c['us_per_step']:.1f} | {c['us_per_rhs_eval']:.2f} | {_err(c)} | {_ratio(c)} |",
        f"| solve_ivp DOP853, NumPy rhs | {n['wall_s']:.1f} | {n['steps']} | {n['rhs_evals']} | {n['us_per_step']:.1f} | {n['us_per_rhs_eval']:.2f} | {_err(n)} | {_ratio(n)} |",
    ]  # fmt: skip
    if "reference_cross_check" in w:
        rows += ["", f"W1 final-state errors: max over the 17 state components at t = {w['t_end']:g} against "
                 f"a reference at rtol 1e-14 (rollingtop and solve_ivp references agree to "
                 f"{w['reference_cross_check']:.1e})."]  # fmt: skip
    w2 = res["W2"]
    rows += [
        "",
        f"| W2: {w2['n']} states, t = {w2['t_end']:g} | wall (s) | trajectories/s |",
        "|---|---|---|",
        f"| 1 thread | {w2['threads_1']['wall_s']:.1f} | {w2['threads_1']['trajectories_per_s']:.0f} |",
        f"| 2 threads | {w2['threads_2']['wall_s']:.1f} | {w2['threads_2']['trajectories_per_s']:.0f} |",
        f"| parallel efficiency (median of {len(w2['parallel_efficiency_pairs'])} paired runs; range) | | "
        f"{100 * w2['parallel_efficiency_2']:.0f} % ({100 * min(w2['parallel_efficiency_pairs']):.0f}-"
        f"{100 * max(w2['parallel_efficiency_pairs']):.0f} %) |",
        f"| 2 threads busy (process CPU time / (2 x wall)) | | {100 * w2['threads_2']['busy_fraction']:.0f} % |",
    ]  # fmt: skip
    w3r = res["W3"]
    rows += [
        "",
        f"| W3: rtol (t = {w3r['t_end']:g}) | rollingtop error | rollingtop (s) | solve_ivp error | solve_ivp compiled rhs (s) |",
        "|---|---|---|---|---|",
    ]  # fmt: skip
    for pt in w3r["points"]:
        rows.append(f"| {pt['rtol']:.0e} | {pt['rollingtop_error']:.1e} | {pt['rollingtop_s']:.4f} | "
                    f"{pt['solve_ivp_error']:.1e} | {pt['solve_ivp_compiled_s']:.3f} |")  # fmt: skip
    cs = res["cold_start"]
    rows += ["", f"Cold start (import + compile): {cs['empty_cache_s']:.1f} s with an empty numba "
             f"cache, {cs['warm_cache_s']:.1f} s with a warm one."]  # fmt: skip
    if "simulate_empty_cache_s" in cs:
        rows += ["", f"`rollingtop simulate examples/paper.toml --t-end 1 --json`, whole process: "
                 f"{cs['simulate_empty_cache_s']:.1f} s with an empty numba cache (everything it "
                 f"uses compiled), {cs['simulate_warm_cache_s']:.2f} s with a warm one (median of "
                 f"5 processes)."]  # fmt: skip
    if res.get("C"):
        c = res["C"]
        where = (f"{len(c['ratios'])} paired rounds in {c['processes']} pinned processes"
                 if "processes" in c else f"{len(c['ratios'])} paired rounds")  # fmt: skip
        rows += ["", f"C limit (benchmarks/c_limit/dop853.c, {c['flags']}): identical steps "
                 f"{c['identical_steps']} ({c['counts']['c'][0]} accepted, {c['counts']['c'][1]} "
                 f"rejected), final states differ by {c['final_state_difference']:.1e}; rollingtop "
                 f"/ C = {c['ratio_median']:.2f} (median of {where}; "
                 f"{min(c['ratios']):.2f}-{max(c['ratios']):.2f}), {c['ratio_fastest']:.2f} "
                 f"between the fastest rounds."]  # fmt: skip
    if res.get("peers"):
        import peers

        rows += ["", peers.table(res["peers"])]
    if res.get("scaling"):
        import scaling

        rows += ["", scaling.table(res["scaling"])]
    if res.get("atlas"):
        import atlas

        rows += ["", atlas.table(res["atlas"])]
    return "\n".join(rows)


DOCS_PAGE = ROOT / "docs" / "guide" / "performance.md"
DOCS_START = (
    "<!-- benchmark-results:start (written by benchmarks/run_benchmarks.py --write-docs) -->"
)
DOCS_END = "<!-- benchmark-results:end -->"


def docs_block(res) -> str:
    """The machine, the date and the tables, for the performance page."""
    m = res["machine"]
    dates = res.get("dates", {})
    if len(set(dates.values())) > 1:
        when = ", ".join(f"{part} measured {dates[part]}" for part in sorted(dates))
    else:
        when = res["date"]
    return (
        f"Measured on {m['cpu']}, {m['cores']} cores, Python {m['python']}, numpy {m['numpy']}, "
        f"scipy {m['scipy']}, numba {m['numba']}; {when} (medians of repeated runs; the NumPy "
        "baseline runs once):\n\n" + res["table_markdown"]
    )


def replace_block(text: str, block: str, where: object = DOCS_PAGE) -> str:
    """``text`` with the lines between its benchmark markers replaced by ``block``."""
    head, sep, rest = text.partition(DOCS_START)
    _, sep2, tail = rest.partition(DOCS_END)
    if not sep or not sep2:
        raise SystemExit(f"{where}: benchmark markers not found")
    return f"{head}{DOCS_START}\n{block}\n{DOCS_END}{tail}"


def write_docs(res, path: Path = DOCS_PAGE) -> None:
    """Replace the block between the page's markers with the new results (atomically)."""
    text = replace_block(path.read_text(), docs_block(res), path)
    tmp = path.with_suffix(".md.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


README = ROOT / "README.md"
README_START = (
    "<!-- readme-performance:start (written by benchmarks/run_benchmarks.py --write-docs) -->"
)
README_END = "<!-- readme-performance:end -->"


def readme_block(res) -> str:
    """The README's short performance table: W1 time of the C limit and of each peer over
    rollingtop's, then start-up and ensemble figures (every number from ``res``)."""
    m, w1r, c, peer, cs = (
        res["machine"],
        res["W1"],
        res.get("C"),
        res.get("peers"),
        res["cold_start"],
    )
    rows = [
        f"W1 (the paper's body and state, t = {w1r['t_end']:g}, rtol {w1r['rtol']:g}) on "
        f"{m['cpu']}, {m['cores']} cores, numba {m['numba']}: time of each over rollingtop's "
        "(which also projects onto the constraints and monitors the reaction at every step; "
        "medians of paired, interleaved runs):",
        "",
        "| W1 | time / rollingtop's |",
        "|---|---|",
    ]
    if c:
        rows.append(f"| the same integration hand-written in C ({c['flags']}; identical steps) | "
                    f"{1.0 / c['ratio_median']:.2f} |")  # fmt: skip
    if peer:
        import peers

        for name in peers.PEERS:
            if name in peer:
                rows.append(f"| {peer[name]['label']} | {peer[name]['ratio_to_rollingtop']:.3g} |")
    numpy_rhs = w1r["solve_ivp_numpy_rhs"]["speedup_of_rollingtop"]  # paired with rollingtop
    rows.append(f"| SciPy solve_ivp DOP853, NumPy rhs (one run) | {numpy_rhs:.0f} |")
    w2r = res["W2"]
    rows += ["", f"Cold start (import and compile, empty numba cache): {cs['empty_cache_s']:.0f} s; "
             f"a short `rollingtop simulate` with a warm cache: {cs['simulate_warm_cache_s']:.2f} s "
             f"(whole process). Ensemble of {w2r['n']} trajectories on 2 threads: "
             f"{100 * w2r['parallel_efficiency_2']:.0f} % parallel efficiency."]  # fmt: skip
    if res.get("atlas"):
        a = res["atlas"]
        rows[-1] += (f" The atlas on Dask: {a['workers']['2']['cells_per_s']:.0f} cells/s on 2 "
                     f"workers, {100 * a['parallel_efficiency_2']:.0f} % parallel efficiency.")  # fmt: skip
    rows[-1] += " Details, all tables and how to rerun: [performance](docs/guide/performance.md)."
    return "\n".join(rows)


def write_readme(res, path: Path = README) -> None:
    """Replace the README's performance block with the new results (atomically)."""
    head, sep, rest = path.read_text().partition(README_START)
    _, sep2, tail = rest.partition(README_END)
    if not sep or not sep2:
        raise SystemExit(f"{path}: performance markers not found")
    tmp = path.with_suffix(".md.tmp")
    tmp.write_text(f"{head}{README_START}\n{readme_block(res)}\n{README_END}{tail}")
    os.replace(tmp, path)


def run_scaling(quick: bool) -> dict:
    """How cost grows: time against t_end and rtol, ensembles against size and threads
    (benchmarks/scaling.py; figures benchmarks/scaling_*.png)."""
    import scaling

    small = quick or None
    return {
        "ensemble": scaling.scaling_ensemble(
            **({"ns": (100, 200, 400), "t_end": 20.0} if small else {})
        ),
        "t_end": scaling.scaling_t_end(
            **({"t_ends": (1e2, 3e2, 1e3), "rounds": 3} if small else {})
        ),
        "rtol": scaling.scaling_rtol(**({"t_end": 100.0, "rounds": 2} if small else {})),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller sizes, for a smoke test")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results.json"))
    ap.add_argument(
        "--write-docs",
        "--readme",
        dest="write_docs",
        action="store_true",
        help="also write the tables into docs/guide/performance.md and README.md (between their markers); "
        "--readme is the old name",
    )
    ap.add_argument(
        "--from-json",
        metavar="FILE",
        help="do not measure: (re)write the docs block from saved results",
    )
    ap.add_argument(
        "--only",
        metavar="PARTS",
        help="comma-separated subset of W1,W2,W3,cold_start,C,peers,scaling,atlas to measure; the rest "
        "is kept from --out",
    )
    args = ap.parse_args()
    if args.from_json:
        res = json.loads(Path(args.from_json).read_text())
        res["table_markdown"] = table(res)
        write_docs(res)
        write_readme(res)
        print(f"wrote {DOCS_PAGE.relative_to(ROOT)} and {README.relative_to(ROOT)}")
        return
    quick = args.quick
    parts = {"W2", "W3", "cold_start", "W1", "C", "peers", "scaling", "atlas"}
    only = set(args.only.split(",")) if args.only else parts
    if only - parts:
        raise SystemExit(f"--only: unknown part(s) {', '.join(sorted(only - parts))}")
    res = {}
    if only != parts:  # keep the other parts of the saved results
        res = json.loads(Path(args.out).read_text())
    now = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    res |= {"machine": machine(), "quick": quick, "date": now}
    res.setdefault("dates", {}).update({part: now for part in only})
    # W2 first: the parallel measurement wants otherwise idle cores
    if "W2" in only:
        print("W2 ...", flush=True)
        res["W2"] = w2(400 if quick else 10_000, 100.0, 1 if quick else 5)
    if "W3" in only:
        print("W3 ...", flush=True)
        res["W3"] = w3(20.0 if quick else 100.0)
    if "cold_start" in only:
        print("cold start ...", flush=True)
        res["cold_start"] = cold_start()
    if "scaling" in only:
        print("scaling ...", flush=True)
        res["scaling"] = run_scaling(quick)
    if "W1" in only:
        print("W1 ...", flush=True)
        res["W1"] = w1(1e3 if quick else 1e4, 3 if quick else 5, 1)
    if "C" in only:
        print("C limit ...", flush=True)
        from c_limit import c_limit_w1

        res["C"] = c_limit_w1(rounds=3 if quick else 5, processes=2 if quick else 5)
    if "peers" in only:
        print("peers ...", flush=True)
        from peers import PEERS, peers_w1

        # the NumPy solve_ivp baseline is W1's already (hundreds of seconds)
        names = tuple(n for n in PEERS if n != "solve_ivp_numpy_rhs")
        res["peers"] = peers_w1(1e3 if quick else 1e4, 2 if quick else 5, peers=names)
    if "atlas" in only:
        print("atlas ...", flush=True)
        from atlas import atlas_benchmark

        res["atlas"] = atlas_benchmark(rounds=2 if quick else 3)
    res["table_markdown"] = table(res)
    Path(args.out).write_text(json.dumps(res, indent=2))
    print(res["table_markdown"])
    print(f"wrote {args.out}")
    if args.write_docs and not quick:
        write_docs(res)
        write_readme(res)
        print(f"wrote {DOCS_PAGE.relative_to(ROOT)} and {README.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
