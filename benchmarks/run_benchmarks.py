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
Cold start: what a newcomer waits for (portrait, simulate, a second model, warmup), each a whole
    process with an empty numba cache, and with a warm one (:func:`cold_start`); then the
    compile estimates of the notice, each group in a fresh process (compile_estimates.py,
    written to src/rollingtop/_compiled/estimates.json with --write-docs).

Timings are medians of repeated runs in this one process (the slow baselines run fewer times);
nothing here is asserted: this is not part of the test suite.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import (  # noqa: E402
    ROOT,
    compiled_rhs_factory,
    machine,
    median_time,
    numpy_rhs_factory,
    replace_between,
    write_atomically,
)


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


#: The commands timed for the start-up of the command line (issue 23), run from the repository
#: root in fresh processes: the README's first picture, a short run of the paper's scenario, then
#: (same cache) a short run of another model's, and the warm-up of every model.
PORTRAIT_COMMAND = ["-m", "rollingtop.cli", "portrait", "examples/fig5.toml", "-o"]
SIMULATE_COMMAND = ["-m", "rollingtop.cli", "simulate", "examples/paper.toml", "--t-end", "1",
                    "--json"]  # fmt: skip
ROUGH_COMMAND = ["-m", "rollingtop.cli", "simulate", "examples/rough.toml", "--t-end", "1",
                 "--json"]  # fmt: skip
WARMUP_COMMAND = ["-m", "rollingtop.cli", "warmup", "--json"]
#: Modules that ``import rollingtop`` must not import (they load with the commands that use them).
HEAVY_MODULES = ("matplotlib", "xarray", "dask", "distributed", "sympy", "numba")


def _wall(argv, env) -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, *argv], env=env, cwd=ROOT, capture_output=True, check=True)
    return time.perf_counter() - start


def _imported_heavy() -> tuple[list[str], float]:
    """The heavy top-level packages ``import rollingtop`` loads (``-X importtime``) and the time
    of the import itself (whole process minus a bare interpreter is not asked: the import's own
    cumulative time)."""
    proc = subprocess.run([sys.executable, "-X", "importtime", "-c", "import rollingtop"],
                          capture_output=True, text=True, check=True, cwd=ROOT)  # fmt: skip
    names, total = set(), 0.0
    for line in proc.stderr.splitlines():
        parts = [p.strip() for p in line.split("|")]
        if len(parts) == 3 and parts[1].isdigit():
            name = parts[2]
            names.add(name.split(".")[0])
            if name == "rollingtop":
                total = int(parts[1]) / 1e6
    return sorted(n for n in names if n in HEAVY_MODULES), total


#: A module with one cached numba function: the least a process that loads a compiled kernel
#: from numba's cache waits for (import numba, numba's registries, one cache load).
NUMBA_FLOOR_MODULE = """from numba import njit


@njit(cache=True)
def one(x):
    return x + 1.0
"""


def cold_start(warm_runs: int = 5):
    """What a newcomer waits for, each a whole process with ``NUMBA_CACHE_DIR`` pointing at a
    new folder: the README's portrait, a short ``simulate`` of the paper's model, then (same
    cache) of the rough model, and ``rollingtop warmup`` (every model); then, with the cache
    warm, the medians of ``warm_runs`` short ``simulate`` and ``portrait`` processes, interleaved
    with a process that only loads one cached one-line numba function (numba's floor); and what
    ``import rollingtop`` loads."""
    out = {}
    # as on a user's machine, Python keeps its bytecode (a CI or sandbox setting of
    # PYTHONDONTWRITEBYTECODE would recompile every module of every process)
    base = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    with tempfile.TemporaryDirectory() as tmp:
        png = os.path.join(tmp, "fig5.png")
        portrait_env = base | {"NUMBA_CACHE_DIR": os.path.join(tmp, "portrait")}
        out["portrait_empty_cache_s"] = _wall([*PORTRAIT_COMMAND, png], portrait_env)
        env = base | {"NUMBA_CACHE_DIR": os.path.join(tmp, "simulate")}
        out["simulate_empty_cache_s"] = _wall(SIMULATE_COMMAND, env)
        out["rough_after_paper_s"] = _wall(ROUGH_COMMAND, env)
        floor_env = base | {"NUMBA_CACHE_DIR": os.path.join(tmp, "floor"), "PYTHONPATH": tmp}
        with open(os.path.join(tmp, "numba_floor.py"), "w") as fh:
            fh.write(NUMBA_FLOOR_MODULE)
        floor = ["-c", "import numba_floor; numba_floor.one(1.0)"]
        _wall(floor, floor_env)  # compiles it once
        runs: dict[str, list[float]] = {"simulate": [], "portrait": [], "floor": []}
        for _ in range(warm_runs):  # interleaved: the machine's drift hits all three alike
            runs["simulate"].append(_wall(SIMULATE_COMMAND, env))
            runs["portrait"].append(_wall([*PORTRAIT_COMMAND, png], portrait_env))
            runs["floor"].append(_wall(floor, floor_env))
        out["simulate_warm_cache_s"] = statistics.median(runs["simulate"])
        out["portrait_warm_cache_s"] = statistics.median(runs["portrait"])
        out["numba_floor_s"] = statistics.median(runs["floor"])
        env = base | {"NUMBA_CACHE_DIR": os.path.join(tmp, "warmup")}
        out["warmup_empty_cache_s"] = _wall(WARMUP_COMMAND, env)
    out["import_heavy_modules"], out["import_s"] = _imported_heavy()
    out["warm_runs"] = warm_runs
    return out


def start_table(cs) -> str:
    """The start-up table (issue 23): each row a whole process, from the repository root."""
    heavy = ", ".join(cs["import_heavy_modules"]) or "none of " + ", ".join(HEAVY_MODULES)
    return "\n".join([
        "| start-up, whole process | numba cache | seconds |",
        "|---|---|---|",
        f"| `rollingtop portrait examples/fig5.toml -o fig5.png` | empty | "
        f"{cs['portrait_empty_cache_s']:.1f} |",
        f"| `rollingtop simulate examples/paper.toml --t-end 1` | empty | "
        f"{cs['simulate_empty_cache_s']:.1f} |",
        f"| then `rollingtop simulate examples/rough.toml --t-end 1` (compiles rough alone) | "
        f"paper's model's | {cs['rough_after_paper_s']:.1f} |",
        f"| `rollingtop warmup` (every model, one process per compiled package) | empty | "
        f"{cs['warmup_empty_cache_s']:.1f} |",
        f"| a short `simulate` (median of {cs['warm_runs']}) | warm | "
        f"{cs['simulate_warm_cache_s']:.2f} |",
        f"| `portrait` (median of {cs['warm_runs']}) | warm | {cs['portrait_warm_cache_s']:.2f} |",
        f"| numba's floor: `python -c` loading one cached one-line numba function (median of "
        f"{cs['warm_runs']}, interleaved with the two above) | warm | {cs['numba_floor_s']:.2f} |",
        f"| `import rollingtop` (loads {heavy}) | | {cs['import_s']:.2f} |",
    ])  # fmt: skip


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
    rows += ["", start_table(res["cold_start"])]
    if res.get("C"):
        c = res["C"]
        where = (f"{len(c['ratios'])} paired rounds in {c['processes']} pinned processes"
                 if "processes" in c else f"{len(c['ratios'])} paired rounds")  # fmt: skip
        rows += ["", f"C limit (benchmarks/c_limit/dop853.c, {c['flags']}): identical steps "
                 f"{c['identical_steps']} ({c['counts']['c'][0]} accepted, {c['counts']['c'][1]} "
                 f"rejected), final states differ by {c['final_state_difference']:.1e}, the "
                 f"reactions monitored at the same step ends (locate_dips=False); rollingtop "
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
        f"Measured on {_cpus(res)}, {m['cores']} cores, Python {m['python']}, numpy "
        f"{m['numpy']}, scipy {m['scipy']}, numba {m['numba']}; {when} (medians of repeated "
        "runs; the NumPy baseline runs once):\n\n" + res["table_markdown"]
    )


def _cpus(res, parts=None) -> str:
    """The CPU the results (or ``parts`` of them) were measured on; where parts ran on different
    machines (this VM's kind changes between sessions), which part on which: a ratio is
    measured side by side on one machine, but times of two machines do not compare."""
    machines = res.get("machines", {})
    chosen = {p: machines[p] for p in (parts or machines) if p in machines}
    if len(set(chosen.values())) <= 1:
        return next(iter(chosen.values()), res["machine"]["cpu"])
    by_cpu: dict[str, list[str]] = {}
    for part, cpu in sorted(chosen.items()):
        by_cpu.setdefault(cpu, []).append(part)
    return " and ".join(f"{cpu} ({', '.join(ps)})" for cpu, ps in by_cpu.items())


def replace_block(text: str, block: str, where: object = DOCS_PAGE) -> str:
    """``text`` with the lines between its benchmark markers replaced by ``block``."""
    return replace_between(text, DOCS_START, DOCS_END, block, where)


def write_docs(res, path: Path = DOCS_PAGE) -> None:
    """Replace the block between the page's markers with the new results (atomically)."""
    write_atomically(path, replace_block(path.read_text(), docs_block(res), path))


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
        f"{_cpus(res, ('W1', 'C', 'peers'))}, {m['cores']} cores, numba {m['numba']}: time of "
        "each over rollingtop's "
        "(which also projects onto the constraints and monitors the reaction at every step; "
        "medians of paired, interleaved runs):",
        "",
        "| W1 | time / rollingtop's |",
        "|---|---|",
    ]
    if c:
        rows.append(f"| the same integration hand-written in C ({c['flags']}; identical steps; "
                    "over rollingtop's with the reactions at step ends, as C) | "
                    f"{1.0 / c['ratio_median']:.2f} |")  # fmt: skip
    if peer:
        import peers

        for name in peers.PEERS:
            if name in peer:
                rows.append(f"| {peer[name]['label']} | {peer[name]['ratio_to_rollingtop']:.3g} |")
    numpy_rhs = w1r["solve_ivp_numpy_rhs"]["speedup_of_rollingtop"]  # paired with rollingtop
    rows.append(f"| SciPy solve_ivp DOP853, NumPy rhs (one run) | {numpy_rhs:.0f} |")
    w2r = res["W2"]
    rows += ["", f"Start-up on {_cpus(res, ('cold_start',))}: what a newcomer waits for, each a "
             "whole process (the first command of the quick start is the first row):", "",
             start_table(cs),
             "", f"Ensemble of {w2r['n']} trajectories on 2 threads: "
             f"{100 * w2r['parallel_efficiency_2']:.0f} % parallel efficiency."]  # fmt: skip
    if res.get("atlas"):
        a = res["atlas"]
        rows[-1] += (f" The atlas on Dask: {a['workers']['2']['cells_per_s']:.0f} cells/s on 2 "
                     f"workers, {100 * a['parallel_efficiency_2']:.0f} % parallel efficiency.")  # fmt: skip
    rows[-1] += " Details, all tables and how to rerun: [performance](docs/guide/performance.md)."
    return "\n".join(rows)


def write_readme(res, path: Path = README) -> None:
    """Replace the README's performance block with the new results (atomically)."""
    text = replace_between(path.read_text(), README_START, README_END, readme_block(res), path)
    write_atomically(path, text)


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
    # the CPU each part was measured on: a part kept from --out keeps the machine it ran on
    # (results saved before "machines" was recorded: the machine they name)
    saved_cpu = res.get("machine", {}).get("cpu")
    machines = res.setdefault("machines", {})
    if saved_cpu:
        for part in res.get("dates", {}):
            machines.setdefault(part, saved_cpu)
    res |= {"machine": machine(), "quick": quick, "date": now}
    res.setdefault("dates", {}).update({part: now for part in only})
    machines.update({part: res["machine"]["cpu"] for part in only})
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
        print("compile estimates ...", flush=True)
        from compile_estimates import estimates

        res["compile_estimates"] = estimates()
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
        if "compile_estimates" in res and "cold_start" in only:
            from compile_estimates import write as write_estimates

            write_estimates(res["compile_estimates"])
            print("wrote src/rollingtop/_compiled/estimates.json")


if __name__ == "__main__":
    main()
