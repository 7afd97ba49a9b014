"""The C limit (issue 13): rollingtop's integration written in plain C, side by side with rollingtop.

``benchmarks/c_limit/dop853.c`` is the same DOP853 integration of the meridian model (kernel code
0) as rollingtop's compiled stepper -- same tableau, step-size controller, initial step, dense
output, closed-form right-hand side, projection and reaction monitoring after every accepted step
-- written as one would write it by hand in C. It is shipped as source and compiled here, at
benchmark time, with the system C compiler into ``benchmarks/.build/`` (which holds its own
``.gitignore``); without a compiler :func:`build` says so in one line and returns ``None``.

Floating-point flags: numba compiles rollingtop's kernels for the host CPU with fused
multiply-add allowed (``fastmath={"contract"}``, :mod:`rollingtop._jit`), and LLVM fuses products
into sums by its own rules. The C source spells the same fusions out (its ``FMA`` macro) and is
compiled with ``-O3 -march=native -ffp-contract=off`` (:data:`FLAGS`) so that the C compiler adds
none of its own: on an x86-64 CPU with FMA the C run then equals rollingtop's to the last bit
(``--check`` compares the pieces -- right-hand side, projection, stages, error estimates, dense
output, initial step -- on states along W1). ``-ffp-contract=fast`` (GCC's own fusions) or no FMA
give the same step counts on W1 and final states within a few 1e-10 (``--flags``). Where
``-march=native`` is not accepted, ``-O3 -ffp-contract=off`` (no FMA) is used.

Run from the repository root:

    python benchmarks/c_limit.py [--rounds 7] [--check] [--flags] [--processes P]

W1 once with C and once with rollingtop: step counts (asserted identical), the largest difference
of the final states, ns per right-hand-side evaluation; then paired, interleaved rounds (the
order alternating within each round) and the median of the per-round ratios rollingtop / C. The
process pins itself to one CPU (:func:`pin_to_one_cpu`). ``--processes P`` instead pools the
rounds of P fresh processes, as ``run_benchmarks.py`` does (:func:`c_limit_w1`): the speed of
rollingtop's compiled code differs by a few per cent from one process to the next.
Times are of the whole call (rollingtop: :func:`rollingtop.integrate.driver.integrate`, compiled
kernels already loaded; C: the ``ctypes`` call).
"""

from __future__ import annotations

import argparse
import ctypes
import hashlib
import json
import os
import shlex
import shutil
import statistics
import subprocess
import sys
import sysconfig
import time
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
SOURCE = HERE / "c_limit" / "dop853.c"
BUILD = HERE / ".build"
#: Compiler flags, tried in order (the first that compiles is used).
FLAGS = (
    ("-O3", "-march=native", "-ffp-contract=off"),
    ("-O3", "-ffp-contract=off"),
)
COMMON = ("-std=c99", "-fPIC", "-shared")
#: W1 (benchmarks/run_benchmarks.py): the paper's body, t = 1e4, rtol 1e-10, atol 1e-12.
W1 = {"t_end": 1e4, "rtol": 1e-10, "atol": 1e-12, "samples": 2}
N_STATE = 18

_lib: ctypes.CDLL | None = None
_built: dict[str, str] = {}
_dp = ctypes.POINTER(ctypes.c_double)
_D = ctypes.c_double
#: ctypes signatures of the library's functions: rt_integrate, then the pieces for --check.
_SIGNATURES: dict[str, tuple[list[Any], Any]] = {
    "rt_integrate": (
        [_dp, _dp, _dp, ctypes.c_long, _dp, _D, _D, ctypes.POINTER(ctypes.c_long), _dp],
        ctypes.c_int,
    ),
    "rt_rhs": ([_dp, _dp, _dp], _D),
    "rt_project": ([_dp, _dp], None),
    "rt_stage": ([_dp, ctypes.c_int, _dp, _D, _dp], None),
    "rt_scaled_errors": ([_dp, _dp, _dp, _D, _D, _dp, _dp], None),
    "rt_prepare_dense": ([_dp, _dp, _dp, _dp, _D, _dp], None),
    "rt_dense_eval": ([_dp, _dp, _D, _dp], None),
    "rt_initial_step": ([_dp, _dp, _dp, _D, _D, _D, _D], _D),
}


def find_compiler() -> list[str] | None:
    """The system C compiler as a command (``$CC``, Python's own ``CC``, ``cc``, ``gcc``,
    ``clang``), or ``None``."""
    for cand in (os.environ.get("CC"), sysconfig.get_config_var("CC"), "cc", "gcc", "clang"):
        cmd = shlex.split(cand) if cand else []
        path = shutil.which(cmd[0]) if cmd else None
        if path:
            return [path, *cmd[1:]]
    return None


def build(flags: tuple[str, ...] | None = None, quiet: bool = False) -> ctypes.CDLL | None:
    """Compile ``dop853.c`` (once per source, compiler and flags: cached in
    ``benchmarks/.build/``) and load it; ``None``, with a one-line message, when there is no
    working C compiler. ``flags`` replaces :data:`FLAGS` (one set, no fallback)."""
    global _lib
    if flags is None and _lib is not None:
        return _lib
    cc = find_compiler()
    if cc is None:
        print("C limit skipped: no C compiler found (set CC, or install cc, gcc or clang)")
        return None
    BUILD.mkdir(exist_ok=True)
    ignore = BUILD / ".gitignore"
    if not ignore.exists():
        ignore.write_text("# build products of benchmarks/c_limit.py\n*\n")
    source = SOURCE.read_bytes()
    suffix = sysconfig.get_config_var("SHLIB_SUFFIX") or ".so"
    errors = []
    for fl in (flags,) if flags is not None else FLAGS:
        cmd = [*cc, *fl, *COMMON]
        key = hashlib.sha256(source + "\0".join(cmd).encode()).hexdigest()[:16]
        target = BUILD / f"dop853-{key}{suffix}"
        if not target.exists():
            tmp = BUILD / f"dop853-{key}.tmp{os.getpid()}{suffix}"
            proc = subprocess.run([*cmd, "-o", str(tmp), str(SOURCE), "-lm"],
                                  capture_output=True, text=True)  # fmt: skip
            if proc.returncode != 0:
                last = (proc.stderr.strip().splitlines() or ["failed"])[-1]
                errors.append(f"{' '.join(cmd)}: {last}")
                continue
            tmp.replace(target)
        lib = ctypes.CDLL(str(target))
        for name, (argtypes, restype) in _SIGNATURES.items():
            fn = getattr(lib, name)
            fn.argtypes, fn.restype = argtypes, restype
        if not quiet:
            print(f"C limit built: {' '.join(cmd)} -> {target.relative_to(ROOT)}")
        if flags is None:
            _built.update(compiler=" ".join(cc), flags=" ".join(fl))
            _lib = lib
        return lib
    print("C limit skipped: the C compiler failed (" + "; ".join(errors) + ")")
    return None


def _ptr(a: np.ndarray) -> Any:
    assert a.dtype == np.float64 and a.flags.c_contiguous
    return a.ctypes.data_as(_dp)


def integrate_c(
    params: Any,
    y0: Any,
    t_end: float,
    rtol: float,
    atol: float,
    t0: float = 0.0,
    lib: ctypes.CDLL | None = None,
) -> dict[str, Any] | None:
    """Integrate the meridian model (geometric ``nu``, kernel code 0) in C from ``y0`` at ``t0``
    to ``t_end``; ``None`` when there is no C compiler.

    Returns ``y`` (the state at ``t_end`` from the dense output, projected: what rollingtop
    returns as its last sample), ``y_step`` (the projected state of the last accepted step),
    ``steps``, ``rejected``, ``rhs_evals`` (counted as rollingtop counts them), ``wall_s`` (the
    call), ``status`` (rollingtop's status codes, 0: finished) and ``reactions`` (as
    rollingtop's ``step_reactions``).
    """
    lib = lib if lib is not None else build()
    if lib is None:
        return None
    p = np.ascontiguousarray(params, dtype=float)
    y = np.array(y0, dtype=float)
    # (13,): a body's, shell and the contact model's slots included
    if p.shape not in ((7,), (9,), (13,)) or y.shape != (N_STATE,):
        raise ValueError("params must have shape (7,), (9,) or (13,) and y0 shape (18,)")
    p = np.ascontiguousarray(p[:7])  # the C code knows the single body (meridian model)
    t_eval = np.array([t0, t_end], dtype=float)
    out = np.full((2, N_STATE), np.nan)
    stats = (ctypes.c_long * 3)()
    track = np.zeros(6)
    start = time.perf_counter()
    status = lib.rt_integrate(_ptr(p), _ptr(y), _ptr(t_eval), 2, _ptr(out), rtol, atol, stats,
                              _ptr(track))  # fmt: skip
    wall = time.perf_counter() - start
    return {
        "y": out[-1].copy(),
        "y_step": y,
        "steps": int(stats[0]),
        "rejected": int(stats[1]),
        "rhs_evals": int(stats[2]),
        "wall_s": wall,
        "status": int(status),
        "reactions": {
            "min_normal_force": float(track[0]),
            "t_min_normal_force": float(track[1]),
            "contact_lost_at": None if np.isnan(track[2]) else float(track[2]),
            "max_friction_ratio": float(track[3]),
            "t_max_friction_ratio": float(track[4]),
        },
    }


def w1_problem() -> tuple[Any, int]:
    """W1's scenario and its kernel code (0: the meridian model's geometric variant)."""
    import rollingtop

    sc = rollingtop.load_scenario(ROOT / "examples" / "paper.toml").with_overrides(**W1)
    return sc, int(sc.model.kernel_code(sc.body, sc.require_state()))


def integrate_rollingtop(sc: Any, code: int) -> dict[str, Any]:
    """W1 with rollingtop's driver (:func:`rollingtop.integrate.driver.integrate`), timed as a
    call (``wall_s``) and in its compiled loop (``loop_s``). The reactions monitored at step
    ends, as the C code does (``locate_dips=False``: no search for the normal force's minima
    inside steps, which costs about a quarter of W1's time where it is on)."""
    from rollingtop.integrate.driver import integrate

    opts = sc.integration
    start = time.perf_counter()
    res = integrate(
        code,
        sc.body.params,
        sc.require_state(),
        opts.t_eval,
        rtol=opts.rtol,
        atol=opts.resolved_atol,
        locate_dips=False,
    )
    wall = time.perf_counter() - start
    return {
        "y": res.y[-1].copy(),
        "steps": res.steps,
        "rejected": res.rejected_steps,
        "rhs_evals": res.rhs_evals,
        "wall_s": wall,
        "loop_s": res.wall_time_s,
        "reactions": res.reactions,
    }


def run_c(sc: Any, lib: ctypes.CDLL | None = None) -> dict[str, Any] | None:
    """W1 (or any scenario of kernel code 0) in C."""
    opts = sc.integration
    return integrate_c(sc.body.params, sc.require_state(), opts.t_end, opts.rtol, opts.resolved_atol,
                       lib=lib)  # fmt: skip


def ns_per_eval(r: dict[str, Any], key: str = "wall_s") -> float:
    return 1e9 * float(r[key]) / int(r["rhs_evals"])


def check_pieces(lib: ctypes.CDLL, sc: Any, code: int, n_states: int = 200) -> dict[str, int]:
    """Components that differ between the C pieces and rollingtop's compiled functions, on
    ``n_states`` states along W1's first 50 time units (perturbed by 1e-3) with random stages:
    all 0 when the two round alike."""
    import rollingtop
    from rollingtop._compiled import _dop853_dense, _dop853_stages, for_code
    from rollingtop._compiled._kernel import new_workspace, reaction
    from rollingtop._jit import call

    kernels = for_code(code)  # the meridian model's compiled package
    p = np.ascontiguousarray(sc.body.params, dtype=float)
    ws = call(new_workspace)
    ys = rollingtop.simulate(sc.with_overrides(t_end=50.0, samples=n_states)).y
    rng = np.random.default_rng(1)
    rtol, atol = sc.integration.rtol, sc.integration.resolved_atol
    differ = dict.fromkeys(
        ("rhs", "normal force", "project", "stage", "scaled_errors", "prepare_dense",
         "dense_eval", "initial_step"), 0)  # fmt: skip
    for y in ys:
        y = np.ascontiguousarray(y + rng.normal(scale=1e-3, size=N_STATE))
        dy_rt, dy_c = np.zeros(N_STATE), np.zeros(N_STATE)
        nc = call(kernels.dynamics.rhs, code, p, y, dy_rt, ws)
        N_rt, _ = call(reaction, nc, y, ws)
        N_c = lib.rt_rhs(_ptr(p), _ptr(y), _ptr(dy_c))
        differ["rhs"] += int(np.sum(dy_rt != dy_c))
        differ["normal force"] += int(N_rt != N_c)
        a, b = y.copy(), y.copy()
        call(kernels.dynamics.project, code, p, a, ws)
        lib.rt_project(_ptr(p), _ptr(b))
        differ["project"] += int(np.sum(a != b))
        K = rng.normal(size=(16, N_STATE))
        h = float(rng.uniform(0.0, 0.1))
        for s in range(1, 16):
            o_rt, o_c = np.zeros(N_STATE), np.zeros(N_STATE)
            call(_dop853_stages.stage, K, s, y, h, o_rt)
            lib.rt_stage(_ptr(K), s, _ptr(y), h, _ptr(o_c))
            differ["stage"] += int(np.sum(o_rt != o_c))
        ynew = np.ascontiguousarray(y + rng.normal(scale=1e-3, size=N_STATE))
        e_rt = [np.zeros(N_STATE) for _ in range(2)]
        e_c = [np.zeros(N_STATE) for _ in range(2)]
        call(_dop853_stages.scaled_errors, K, y, ynew, rtol, atol, *e_rt)
        lib.rt_scaled_errors(_ptr(K), _ptr(y), _ptr(ynew), rtol, atol, *map(_ptr, e_c))
        differ["scaled_errors"] += sum(int(np.sum(u != v)) for u, v in zip(e_rt, e_c, strict=True))
        K_rt, K_c = K.copy(), K.copy()
        F_rt, F_c = np.zeros((7, N_STATE)), np.zeros((7, N_STATE))
        call(kernels.dense.prepare_dense, code, p, K_rt, y, ynew, h, np.zeros(N_STATE), F_rt, ws)
        lib.rt_prepare_dense(_ptr(p), _ptr(K_c), _ptr(y), _ptr(ynew), h, _ptr(F_c))
        differ["prepare_dense"] += int(np.sum(F_rt != F_c))
        x = float(rng.uniform())
        o_rt, o_c = np.zeros(N_STATE), np.zeros(N_STATE)
        call(_dop853_dense.dense_eval, F_rt, y, x, o_rt)
        lib.rt_dense_eval(_ptr(F_rt), _ptr(y), x, _ptr(o_c))
        differ["dense_eval"] += int(np.sum(o_rt != o_c))
        h_rt = call(kernels.stepper.initial_step, code, p, y, dy_rt, 1e4, 0.0, rtol, atol,
                    np.zeros(N_STATE), np.zeros(N_STATE), ws)  # fmt: skip
        h_c = lib.rt_initial_step(_ptr(p), _ptr(y), _ptr(dy_rt), 1e4, 0.0, rtol, atol)
        differ["initial_step"] += int(h_rt != h_c)
    return differ


def compare_flags(sc: Any, rt: dict[str, Any]) -> None:
    """Step counts and final-state difference under other floating-point flags (--flags)."""
    variants = [
        ("-O3", "-march=native", "-ffp-contract=off"),
        ("-O3", "-march=native", "-ffp-contract=fast"),
        ("-O3", "-ffp-contract=off"),
    ]
    for fl in variants:
        lib = build(fl, quiet=True)
        if lib is None:
            continue
        c = run_c(sc, lib)
        assert c is not None
        same = (c["steps"], c["rejected"]) == (rt["steps"], rt["rejected"])
        print(f"  {' '.join(fl):38s} steps {c['steps']:7d}  rejected {c['rejected']:6d}  "
              f"{'identical' if same else 'DIFFERENT'}  max |y_C - y_rt| "
              f"{np.max(np.abs(c['y'] - rt['y'])):.2e}  {ns_per_eval(c):6.1f} ns/eval")  # fmt: skip


def paired_rounds(
    sc: Any, code: int, lib: ctypes.CDLL, rounds: int = 7, verbose: bool = False
) -> dict[str, Any]:
    """W1 with C and with rollingtop, alternately first, ``rounds`` times: the per-round ns per
    rhs evaluation of each, the ratios rollingtop / C and their median, and the ratio of the
    fastest rounds."""
    ratios, loop_ratios, c_ns, rt_ns = [], [], [], []
    if verbose:
        print(f"paired, interleaved rounds ({rounds}):")
    for k in range(rounds):
        # alternate which goes first, so that neither always runs second
        order = ("c", "rt") if k % 2 == 0 else ("rt", "c")
        res: dict[str, dict[str, Any]] = {}
        for who in order:
            result = run_c(sc, lib) if who == "c" else integrate_rollingtop(sc, code)
            assert result is not None
            res[who] = result
        ratios.append(res["rt"]["wall_s"] / res["c"]["wall_s"])
        loop_ratios.append(res["rt"]["loop_s"] / res["c"]["wall_s"])
        c_ns.append(ns_per_eval(res["c"]))
        rt_ns.append(ns_per_eval(res["rt"]))
        if verbose:
            print(f"  round {k + 1}: C {c_ns[-1]:6.1f} ns/eval, rollingtop {rt_ns[-1]:6.1f} "
                  f"ns/eval ({ns_per_eval(res['rt'], 'loop_s'):6.1f} in its compiled loop), "
                  f"ratio {ratios[-1]:.3f}")  # fmt: skip
    return {
        "c_ns_per_eval": c_ns, "rollingtop_ns_per_eval": rt_ns, "ratios": ratios,
        "ratio_median": statistics.median(ratios),
        "loop_ratio_median": statistics.median(loop_ratios),
        "ratio_fastest": min(rt_ns) / min(c_ns),
    }  # fmt: skip


def pin_to_one_cpu() -> int | None:
    """Pin this process to the last CPU it may run on (Linux), so that the scheduler does not
    migrate it between rounds; returns that CPU (``None`` where affinity is not supported).

    Measured on the 2-core development VM: unpinned, the per-process median ratio of W1 ranged
    over 1.02-1.16 for the same compiled code; pinned, over 1.00-1.05 in the same machine state.
    """
    if not hasattr(os, "sched_setaffinity"):
        return None
    cpu = max(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cpu})
    return cpu


def measure(rounds: int) -> dict[str, Any] | None:
    """One process's part of :func:`c_limit_w1`: pinned, the step counts of both (they must
    agree), the final-state difference and ``rounds`` paired rounds; ``None`` without a
    compiler."""
    lib = build(quiet=True)
    if lib is None:
        return None
    cpu = pin_to_one_cpu()
    sc, code = w1_problem()
    from rollingtop.integrate.driver import compile_kernels

    compile_kernels("meridian")
    c, rt = run_c(sc, lib), integrate_rollingtop(sc, code)
    assert c is not None
    counts = {
        who: [r["steps"], r["rejected"], r["rhs_evals"]]
        for who, r in (("c", c), ("rollingtop", rt))
    }
    return {
        "flags": _built["flags"], "cpu": cpu, "counts": counts,
        "identical_steps": counts["c"] == counts["rollingtop"],
        "final_state_difference": float(np.max(np.abs(c["y"] - rt["y"]))),
        **paired_rounds(sc, code, lib, rounds),
    }  # fmt: skip


def c_limit_w1(rounds: int = 9, processes: int = 3) -> dict[str, Any] | None:
    """The C limit on W1 for ``run_benchmarks.py``: :func:`measure` in ``processes`` fresh
    processes of ``rounds`` paired rounds each (the compiled code's speed differs from one
    process to the next by a few per cent, so one process is not enough), pooled: the median of
    all per-round ratios, and each process's median. ``None`` without a compiler."""
    if build() is None:
        return None
    parts = []
    for _ in range(processes):
        proc = subprocess.run(
            [sys.executable, str(Path(__file__).resolve()), "--measure", str(rounds)],
            capture_output=True, text=True, check=True,
        )  # fmt: skip
        parts.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    first = parts[0]
    pooled = {key: [v for part in parts for v in part[key]]
              for key in ("c_ns_per_eval", "rollingtop_ns_per_eval", "ratios")}  # fmt: skip
    return {
        "flags": first["flags"], "counts": first["counts"],
        "identical_steps": all(part["identical_steps"] for part in parts),
        "final_state_difference": max(part["final_state_difference"] for part in parts),
        "processes": processes, "rounds_per_process": rounds, "pinned": first["cpu"] is not None,
        **pooled,
        "ratio_median": statistics.median(pooled["ratios"]),
        "ratio_median_per_process": [part["ratio_median"] for part in parts],
        "loop_ratio_median": statistics.median(part["loop_ratio_median"] for part in parts),
        "ratio_fastest": min(pooled["rollingtop_ns_per_eval"]) / min(pooled["c_ns_per_eval"]),
    }  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7, help="paired rounds (default 7)")
    ap.add_argument("--check", action="store_true",
                    help="compare the C pieces with rollingtop's, bit for bit")  # fmt: skip
    ap.add_argument("--flags", action="store_true", help="also try other floating-point flags")
    ap.add_argument("--processes", type=int, default=0, metavar="P",
                    help="instead: P fresh, pinned processes of ROUNDS rounds each, pooled")  # fmt: skip
    ap.add_argument("--measure", type=int, metavar="ROUNDS", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.measure is not None:  # one process of c_limit_w1: JSON on the last line
        print(json.dumps(measure(args.measure)))
        return 0
    if args.processes > 0:
        pooled = c_limit_w1(args.rounds, args.processes)
        if pooled is not None:
            print(f"{args.processes} pinned processes x {args.rounds} rounds: rollingtop / C = "
                  f"{pooled['ratio_median']:.3f} (median of all rounds); per process "
                  + ", ".join(f"{r:.3f}" for r in pooled["ratio_median_per_process"]))  # fmt: skip
        return 0

    lib = build()
    if lib is None:
        return 0
    cpu = pin_to_one_cpu()
    print(f"pinned to CPU {cpu}" if cpu is not None else "not pinned (no CPU affinity here)")
    sc, code = w1_problem()
    if code != 0:
        print(f"W1 starts in kernel code {code}, but the C limit implements code 0 only")
        return 1
    from rollingtop.integrate.driver import compile_kernels

    print(f"rollingtop kernels compiled or loaded in {compile_kernels('meridian'):.1f} s")
    if args.check:
        differ = check_pieces(lib, sc, code)
        verdict = "all equal to the last bit" if not any(differ.values()) else "DIFFERENT"
        print(f"pieces, components that differ from rollingtop's: {differ} ({verdict})")
    print(f"W1: t_end = {W1['t_end']:g}, rtol = {W1['rtol']:g}, atol = {W1['atol']:g}; "
          f"C flags: {_built['flags']}")  # fmt: skip
    c = run_c(sc, lib)
    rt = integrate_rollingtop(sc, code)
    assert c is not None
    for name, r in (("C", c), ("rollingtop", rt)):
        print(f"  {name:10s} steps {r['steps']:7d}  rejected {r['rejected']:6d}  rhs evals "
              f"{r['rhs_evals']:8d}  {r['wall_s']:.3f} s  {ns_per_eval(r):6.1f} ns/eval")  # fmt: skip
    diff = float(np.max(np.abs(c["y"] - rt["y"])))
    same_bits = bool(np.array_equal(c["y"], rt["y"]))
    print(f"  final states: max |y_C - y_rollingtop| = {diff:.3e}"
          + (" (identical to the last bit)" if same_bits else ""))  # fmt: skip
    print(f"  min normal force: C {c['reactions']['min_normal_force']!r}, "
          f"rollingtop {rt['reactions']['min_normal_force']!r}")  # fmt: skip
    counts_c = (c["steps"], c["rejected"], c["rhs_evals"])
    counts_rt = (rt["steps"], rt["rejected"], rt["rhs_evals"])
    if counts_c == counts_rt:
        print("  step counts IDENTICAL (accepted, rejected, rhs evaluations)")
    else:
        print(f"  STEP COUNTS DIFFER: C {counts_c}, rollingtop {counts_rt}")
    if args.flags:
        print("other floating-point flags:")
        compare_flags(sc, rt)

    paired = paired_rounds(sc, code, lib, args.rounds, verbose=True)
    c_ns, rt_ns, ratios = (
        paired["c_ns_per_eval"],
        paired["rollingtop_ns_per_eval"],
        paired["ratios"],
    )
    print(f"median: C {statistics.median(c_ns):.1f} ns/eval, rollingtop "
          f"{statistics.median(rt_ns):.1f} ns/eval; rollingtop / C = "
          f"{paired['ratio_median']:.3f} (call), {paired['loop_ratio_median']:.3f} "
          f"(rollingtop's compiled loop only)")  # fmt: skip
    # On a shared (virtual) machine the speed of both drifts between regimes within seconds;
    # the fastest round of each is the least disturbed figure.
    print(f"fastest rounds: C {min(c_ns):.1f} ns/eval, rollingtop {min(rt_ns):.1f} ns/eval "
          f"(ratio {paired['ratio_fastest']:.3f}); per-round ratios {min(ratios):.3f} to "
          f"{max(ratios):.3f}")  # fmt: skip
    assert counts_c == counts_rt, f"different steps on W1: C {counts_c}, rollingtop {counts_rt}"
    return 0


if __name__ == "__main__":
    sys.exit(main())
