"""Peers side by side with rollingtop on W1 (issue 13, "The benchmark suite, side by side in one run").

Run:  python benchmarks/peers.py [--t-end 1e3] [--rounds 3]     (a quick version; prints the results)

W1 is the paper's body (examples/paper.toml) from its initial state to ``t_end`` at rtol 1e-10,
atol 1e-12.  Every peer integrates the same 18 equations with the same tolerances, calling
rollingtop's compiled right-hand side (the model's ``dynamics.rhs``, :mod:`rollingtop._compiled`) through the interface
the peer wants -- except "solve_ivp, NumPy rhs", which is what a user would write without
rollingtop (``run_benchmarks.numpy_rhs_factory``), and diffrax, which needs a JAX rhs:

- CyRK ``nbsolve_ivp`` (DOP853; an njit ``diffeq(t, y, *args) -> dy``);
- CyRK ``nbsolve2_ivp`` (CyRK's C++ solver, DOP853; a ``numba.cfunc`` ``(dy*, t, y*, args*)``);
- CyRK ``pysolve_ivp`` (the same C++ solver calling a Python-level callable per evaluation);
- numbalsoda ``dop853`` (Hairer's DOP853 in Fortran; a ``numba.cfunc`` ``(t, u*, du*, data*)``);
- SciPy ``solve_ivp`` DOP853 with the NumPy rhs and with rollingtop's compiled rhs;
- diffrax ``Dopri8`` (jit), only when jax and diffrax are importable (never installed here).

rollingtop projects the state onto the constraints and monitors the contact reaction after every
accepted step; none of the peers does either (:data:`NO_PROJECTION`).

Timing: each peer run is paired with rollingtop runs right beside it (the median of three just
before it; for a peer measured once, also three just after) and the ratio peer / rollingtop is
taken per pair; the result is the median of the ratios and their range.  The fast peers are
interleaved round by round (round 1: each peer once, round 2: each peer again, ...), so a drift of
the machine's speed falls on all of them alike.  Steps and right-hand-side evaluations come from a
separate, untimed run with a counting right-hand side (same arithmetic, so the same steps); where a
peer does not report its rejected steps they are derived from its evaluation count (documented per
peer under ``"counts"``).  Errors: max over the 17 state components (the 18th, the direction angle
rate, is not in the NumPy rhs) at ``t_end`` against a reference by rollingtop at rtol 1e-13,
cross-checked by solve_ivp at rtol 1e-13 on the compiled rhs.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parent))

from _common import ROOT, compiled_rhs_factory, median_time, numpy_rhs_factory  # noqa: E402

#: Said in every result: what the comparison does not include.
NO_PROJECTION = (
    "rollingtop projects the state onto the constraints and monitors the contact reaction after "
    "every accepted step (its time includes both); none of the peers projects or monitors: they "
    "integrate the same 18 equations and drift off the constraints at the tolerance's rate"
)

RTOL, ATOL = 1e-10, 1e-12
REF_RTOL, REF_ATOL = 1e-13, 1e-15

# ----------------------------------------------------------------------------------------------
# rollingtop's compiled right-hand side in each peer's calling convention
#
# The kernel wants ``rhs(code, p, y, dy, ws)`` with a work tuple ``ws = (J, bias, dirs, A, lam)``.
# Allocating ``ws`` per call would cost more than the right-hand side itself, so every wrapper gets
# one flat float64 buffer (through the peer's "args"/"data" channel) holding ``p``, the work arrays
# and three counters, and cuts views out of it: no allocation per call (except where the peer's
# interface returns a new ``dy``: nbsolve_ivp).
# ----------------------------------------------------------------------------------------------

N_P = 7
_WS_SHAPES = ((4, 6), (4,), (4, 3), (4, 4), (4,))  # rollingtop._compiled._kernel.new_workspace()
_WS_SIZE = sum(int(np.prod(s)) for s in _WS_SHAPES)
I_COUNT = N_P + _WS_SIZE  # rhs evaluations (counting variants only)
I_LAST_T = I_COUNT + 1  # t of the previous evaluation (numbalsoda: accepted-step detection)
I_SAME_T = I_COUNT + 2  # evaluations at the same t as the previous one
BUF_SIZE = I_COUNT + 3


def packed(p) -> np.ndarray:
    """The flat buffer: ``p``, the work arrays, the counters (zero)."""
    buf = np.zeros(BUF_SIZE)
    buf[:N_P] = p[:N_P]  # the single body's (meridian model)
    buf[I_LAST_T] = np.nan
    return buf


def _check_workspace_layout() -> None:
    from rollingtop._compiled._kernel import new_workspace

    shapes = tuple(a.shape for a in new_workspace())
    if shapes != _WS_SHAPES:
        raise RuntimeError(f"rollingtop's workspace is {shapes}, peers.py expects {_WS_SHAPES}")


def rhs_kernels(code: int) -> dict[str, object]:
    """Compiled wrappers of rollingtop's right-hand side for the model ``code``: for each peer a
    plain one (timed) and a counting one (``buf[I_COUNT] += 1`` per call, and the same-t count)."""
    from numba import carray, cfunc, njit, types

    from rollingtop._compiled import for_code

    model_rhs = for_code(code).dynamics.rhs

    _check_workspace_layout()
    o1, o2, o3, o4, o5, o6 = (N_P + int(v) for v in np.cumsum([0, *map(np.prod, _WS_SHAPES)]))

    @njit(inline="always")
    def views(buf):
        ws = (
            buf[o1:o2].reshape((4, 6)),
            buf[o2:o3],
            buf[o3:o4].reshape((4, 3)),
            buf[o4:o5].reshape((4, 4)),
            buf[o5:o6],
        )
        return buf[0:N_P], ws

    @njit(inline="always")
    def count(t, buf):
        buf[I_COUNT] += 1.0
        if t == buf[I_LAST_T]:
            buf[I_SAME_T] += 1.0
        buf[I_LAST_T] = t

    def make(counting: bool):
        # CyRK nbsolve_ivp: njit diffeq(t, y, *args) -> new dy
        @njit
        def nb_diffeq(t, y, buf):
            if counting:
                count(t, buf)
            p, ws = views(buf)
            dy = np.empty(18)
            model_rhs(code, p, y, dy, ws)
            return dy

        # CyRK nbsolve2_ivp: void(double* dy, double t, double* y, double* args)
        # (CyRK passes a fifth argument, its pre-evaluation function, which is not used)
        @cfunc(types.void(types.CPointer(types.float64), types.float64,
                          types.CPointer(types.float64), types.CPointer(types.float64)))  # fmt: skip
        def cy_diffeq(dy_, t, y_, args_):
            buf = carray(args_, (BUF_SIZE,))
            if counting:
                count(t, buf)
            p, ws = views(buf)
            model_rhs(code, p, carray(y_, (18,)), carray(dy_, (18,)), ws)

        # CyRK pysolve_ivp with pass_dy_as_arg=True: diffeq(dy, t, y, *args), called from Python
        @njit
        def py_diffeq(dy, t, y, buf):
            if counting:
                count(t, buf)
            p, ws = views(buf)
            model_rhs(code, p, y, dy, ws)

        # numbalsoda: void(double t, double* u, double* du, double* data)
        @cfunc(types.void(types.float64, types.CPointer(types.float64),
                          types.CPointer(types.float64), types.CPointer(types.float64)))  # fmt: skip
        def lsoda_rhs(t, u_, du_, data_):
            buf = carray(data_, (BUF_SIZE,))
            if counting:
                count(t, buf)
            p, ws = views(buf)
            model_rhs(code, p, carray(u_, (18,)), carray(du_, (18,)), ws)

        return {"nb": nb_diffeq, "cy": cy_diffeq, "py": py_diffeq, "nbl": lsoda_rhs}

    return {"plain": make(False), "counting": make(True)}


# ----------------------------------------------------------------------------------------------
# The peers: each a factory returning ``run() -> (y_end, info)`` (timed) and ``count() ->
# counts dict`` (untimed), or raising _Skip with the reason.
# ----------------------------------------------------------------------------------------------


class _Skip(Exception):
    pass


def _derived_rejected(nfev: int, accepted: int, per_attempt: int, start: tuple[int, ...],
                      per_accepted: int = 0, extra: tuple[int, ...] = (0,)) -> dict:  # fmt: skip
    """Attempted steps from ``nfev = s + per_attempt * attempts + per_accepted * accepted + e``
    with ``s`` in ``start`` and ``e`` in ``extra``: the one decomposition that divides evenly."""
    found = []
    for s in start:
        for e in extra:
            rest = nfev - s - e - per_accepted * accepted
            if rest >= 0 and rest % per_attempt == 0:
                found.append(rest // per_attempt)
    if len(set(found)) == 1 and found[0] >= accepted:
        return {"rejected_steps": found[0] - accepted, "rejected_derived": True}
    return {"rejected_steps": None}


def _version(dist: str) -> str | None:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(dist)
    except PackageNotFoundError:
        return None


def _final(y) -> np.ndarray:
    return np.array(y, dtype=float)[:17]


def peer_cyrk_nbsolve_ivp(ctx):
    try:
        from CyRK import nbsolve_ivp
    except ImportError as exc:
        raise _Skip(f"CyRK not importable ({exc})") from None
    y0, t_end, buf = ctx["y0"], ctx["t_end"], packed(ctx["p"])
    plain, counting = ctx["kernels"]["plain"]["nb"], ctx["kernels"]["counting"]["nb"]

    def solve(f, b):
        res = nbsolve_ivp(f, (0.0, t_end), y0, args=(b,), rtol=RTOL, atol=ATOL, rk_method=2,
                          warnings=False)  # fmt: skip
        if not res.success:
            raise RuntimeError(f"nbsolve_ivp failed: {res.message}")
        return res.t, res.y

    def run():
        t, y = solve(plain, buf)
        return y[:, -1], {}

    def count():
        b = packed(ctx["p"])
        t, y = solve(counting, b)
        nfev, accepted = int(b[I_COUNT]), len(t) - 1
        # SciPy's DOP853 ported: f(y0), one for the initial step, 12 per attempted step
        return {"steps": accepted, "rhs_evals": nfev, "y_end": y[:, -1],
                **_derived_rejected(nfev, accepted, 12, (1, 2)),
                "how": "steps = stored points - 1 (every accepted step is stored); rhs evals "
                       "counted; rejected = (evals - 2) / 12 - accepted (SciPy's DOP853 scheme)"}  # fmt: skip

    return run, count, f"CyRK {_version('CyRK')} nbsolve_ivp (DOP853, njit rhs)"


def peer_cyrk_nbsolve2_ivp(ctx):
    try:
        import CyRK
        from CyRK import nbsolve2_ivp
        from CyRK.nb.numba_solver import c_get_args_ptr
    except ImportError as exc:
        raise _Skip(f"CyRK nbsolve2_ivp not importable ({exc})") from None
    import ctypes

    y0, t_end = ctx["y0"], ctx["t_end"]
    plain = ctx["kernels"]["plain"]["cy"].address
    counting = ctx["kernels"]["counting"]["cy"].address
    buf = packed(ctx["p"])
    t_eval = np.array([t_end])

    def solve(addr, b):
        res = nbsolve2_ivp(addr, (0.0, t_end), y0, method="DOP853", t_eval=t_eval, args=b,
                           rtol=RTOL, atol=ATOL)  # fmt: skip
        try:
            if not res.success:
                raise RuntimeError(f"nbsolve2_ivp failed: {res.message}")
            y_end = np.array(res.y[:, -1])
            steps = int(res.steps_taken)
            # CyRK copies ``args`` into the result: read the counters back from that copy
            ptr = ctypes.cast(c_get_args_ptr(res._ptr), ctypes.POINTER(ctypes.c_double))
            counters = np.ctypeslib.as_array(ptr, (BUF_SIZE,)).copy()
        finally:
            res.free()
        return y_end, steps, counters

    def run():
        return solve(plain, buf)[0], {}

    def count():
        y_end, accepted, counters = solve(counting, packed(ctx["p"]))
        nfev = int(counters[I_COUNT])
        return {"steps": accepted, "rhs_evals": nfev, "y_end": y_end,
                **_derived_rejected(nfev, accepted, 12, (1, 2), extra=(0, 3)),
                "how": "steps = CyRK's steps_taken (accepted); rhs evals counted in the rhs; "
                       "rejected = (evals - start) / 12 - accepted"}  # fmt: skip

    return run, count, f"CyRK {CyRK.__version__} nbsolve2_ivp (C++ DOP853, cfunc rhs)"


def peer_cyrk_pysolve_ivp(ctx):
    try:
        import CyRK
        from CyRK import pysolve_ivp
    except ImportError as exc:
        raise _Skip(f"CyRK not importable ({exc})") from None
    y0, t_end = ctx["y0"], ctx["t_end"]
    plain, counting = ctx["kernels"]["plain"]["py"], ctx["kernels"]["counting"]["py"]
    buf = packed(ctx["p"])
    t_eval = np.array([t_end])

    def solve(f, b):
        res = pysolve_ivp(f, (0.0, t_end), y0, method="DOP853", t_eval=t_eval, args=(b,),
                          rtol=RTOL, atol=ATOL, pass_dy_as_arg=True)  # fmt: skip
        if not res.success:
            raise RuntimeError(f"pysolve_ivp failed: {res.message}")
        return np.array(res.y[:, -1]), int(res.steps_taken)

    def run():
        return solve(plain, buf)[0], {}

    def count():
        b = packed(ctx["p"])
        y_end, accepted = solve(counting, b)
        nfev = int(b[I_COUNT])
        return {
            "steps": accepted,
            "rhs_evals": nfev,
            "y_end": y_end,
            **_derived_rejected(nfev, accepted, 12, (1, 2), extra=(0, 3)),
            "how": "as nbsolve2_ivp (the same C++ solver)",
        }

    return run, count, f"CyRK {CyRK.__version__} pysolve_ivp (C++ DOP853, Python-level rhs call)"


def peer_numbalsoda_dop853(ctx):
    try:
        import numbalsoda
        from numbalsoda import dop853
    except (ImportError, OSError) as exc:
        raise _Skip(f"numbalsoda not importable ({exc})") from None
    y0, t_end = ctx["y0"], ctx["t_end"]
    plain = ctx["kernels"]["plain"]["nbl"].address
    counting = ctx["kernels"]["counting"]["nbl"].address
    buf = packed(ctx["p"])
    t_eval = np.array([0.0, t_end])
    mxstep = 2**31 - 1

    def solve(addr, b):
        usol, ok = dop853(addr, y0, t_eval, data=b, rtol=RTOL, atol=ATOL, mxstep=mxstep)
        if not ok:
            raise RuntimeError("numbalsoda dop853 failed")
        return usol[-1]

    def run():
        return solve(plain, buf), {}

    def count():
        b = packed(ctx["p"])
        y_end = solve(counting, b)
        nfev = int(b[I_COUNT])
        # Hairer's DOP853: f(y0) and one for the initial step; 11 per attempted step; 1 more per
        # accepted step (the new state's derivative, at the same t as the last stage: counted by
        # the same-t detection); 3 per dense-output evaluation (two here: t = 0 and t = t_end)
        accepted = int(b[I_SAME_T])
        return {"steps": accepted, "rhs_evals": nfev, "y_end": y_end,
                **_derived_rejected(nfev, accepted, 11, (2,), per_accepted=1,
                                    extra=(0, 3, 6)),
                "how": "Hairer's counters are not returned: rhs evals counted in the rhs; "
                       "accepted = evaluations at the same t as the one before (the new state's "
                       "derivative after the last stage); rejected = (evals - 2 - accepted - "
                       "3 * dense) / 11 - accepted"}  # fmt: skip

    del numbalsoda
    return run, count, f"numbalsoda {_version('numbalsoda')} dop853 (Hairer's DOP853, cfunc rhs)"


def _solve_ivp_peer(make_rhs, label):
    def factory(ctx):
        y0, t_end = ctx["y0"], ctx["t_end"]
        f = make_rhs(ctx)  # once: compiled_rhs_factory compiles
        last = {}

        def run():
            sol = solve_ivp(f, (0.0, t_end), y0, method="DOP853", rtol=RTOL, atol=ATOL)
            if not sol.success:
                raise RuntimeError(f"solve_ivp failed: {sol.message}")
            last["sol"] = sol
            return sol.y[:, -1], {}

        def count():  # from the last timed run (a slow peer is not run again to count)
            if "sol" not in last:
                run()
            sol = last["sol"]
            accepted, nfev = len(sol.t) - 1, int(sol.nfev)
            return {"steps": accepted, "rhs_evals": nfev, "y_end": sol.y[:, -1],
                    **_derived_rejected(nfev, accepted, 12, (2,)),
                    "how": "steps = len(sol.t) - 1; rhs evals = sol.nfev; rejected = (nfev - 2) "
                           "/ 12 - accepted"}  # fmt: skip

        return run, count, label

    return factory


def _jax_rhs(p):
    """The NumPy rhs (run_benchmarks.numpy_rhs_factory) in jax.numpy, for diffrax."""
    import jax.numpy as jnp

    R, m, g, a3, I1, I2, I3 = (float(x) for x in p)
    Iv = jnp.array([I1, I2, I3])
    e3 = jnp.array([0.0, 0.0, 1.0])
    avec = jnp.array([0.0, 0.0, a3])

    def rhs(t, y, args):
        v, w = y[0:3], y[3:6]
        alpha, beta, gamma = y[6:9], y[9:12], y[12:15]
        r = -R * gamma - avec
        gdot = jnp.cross(gamma, w)
        rdot = -R * gdot
        vp = v + jnp.cross(w, r)
        g3, g3dot = gamma[2], gdot[2]
        s = jnp.sqrt(1.0 - g3 * g3)
        pvec = e3 - g3 * gamma
        nu = pvec / s
        nudot = (-g3dot * gamma - g3 * gdot) / s + pvec * g3 * g3dot / s**3
        D = jnp.stack([gamma, nu])
        Dd = jnp.stack([gdot, nudot])
        RxD = jnp.cross(r[None, :], D)
        M = jnp.zeros((8, 8))
        M = M.at[0:3, 0:3].set(m * jnp.eye(3)).at[3:6, 3:6].set(jnp.diag(Iv))
        M = M.at[0:3, 6:8].set(-D.T).at[3:6, 6:8].set(-RxD.T)
        M = M.at[6:8, 0:3].set(D).at[6:8, 3:6].set(RxD)
        b = jnp.concatenate([m * jnp.cross(v, w) - m * g * gamma, jnp.cross(Iv * w, w),
                             -(D @ jnp.cross(w, rdot)) - Dd @ vp])  # fmt: skip
        sol = jnp.linalg.solve(M, b)
        return jnp.concatenate([sol[0:6], jnp.cross(alpha, w), jnp.cross(beta, w), gdot,
                                jnp.stack([v @ alpha, v @ beta, 0.0 * g3])])  # fmt: skip

    return rhs


def peer_diffrax(ctx):
    try:
        import diffrax
        import jax
    except ImportError as exc:
        raise _Skip(f"jax/diffrax not installed ({exc.name}); optional, not in the bench "
                    "extra") from None  # fmt: skip
    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    y0, t_end = jnp.asarray(ctx["y0"]), ctx["t_end"]
    term = diffrax.ODETerm(_jax_rhs(ctx["p"]))
    solver = diffrax.Dopri8()
    controller = diffrax.PIDController(rtol=RTOL, atol=ATOL)

    @jax.jit
    def solve(y):
        return diffrax.diffeqsolve(term, solver, 0.0, t_end, None, y,
                                   stepsize_controller=controller,
                                   saveat=diffrax.SaveAt(t1=True), max_steps=10**8)  # fmt: skip

    t0 = time.perf_counter()
    jax.block_until_ready(solve(y0).ys)
    ctx["diffrax_compile_s"] = time.perf_counter() - t0

    def run():
        sol = solve(y0)
        ys = jax.block_until_ready(sol.ys)
        ctx["_diffrax_sol"] = sol
        return np.asarray(ys[-1]), {}

    def count():
        sol = ctx.get("_diffrax_sol")
        if sol is None:
            run()
            sol = ctx["_diffrax_sol"]
        st = {k: int(np.asarray(v)) for k, v in sol.stats.items() if np.ndim(v) == 0}
        return {"steps": st.get("num_accepted_steps"), "rejected_steps": st.get("num_rejected_steps"),
                "rhs_evals": None, "y_end": np.asarray(sol.ys[-1]),
                "how": "diffrax's stats (num_accepted_steps, num_rejected_steps)",
                "compile_s": ctx["diffrax_compile_s"]}  # fmt: skip

    return run, count, f"diffrax {diffrax.__version__} Dopri8 (jax {jax.__version__}, jit)"


#: name -> (factory, fast): fast peers run in the interleaved rounds, slow ones after them.
PEERS: dict[str, tuple[Callable, bool]] = {
    "cyrk_nbsolve_ivp": (peer_cyrk_nbsolve_ivp, True),
    "cyrk_nbsolve2_ivp": (peer_cyrk_nbsolve2_ivp, True),
    "cyrk_pysolve_ivp": (peer_cyrk_pysolve_ivp, True),
    "numbalsoda_dop853": (peer_numbalsoda_dop853, True),
    "solve_ivp_compiled_rhs": (_solve_ivp_peer(
        lambda ctx: compiled_rhs_factory(ctx["code"], ctx["p"]),
        "SciPy solve_ivp DOP853, rollingtop's compiled rhs"), False),
    "solve_ivp_numpy_rhs": (_solve_ivp_peer(
        lambda ctx: numpy_rhs_factory(ctx["p"]), "SciPy solve_ivp DOP853, NumPy rhs"), False),
    "diffrax_dopri8": (peer_diffrax, False),
}  # fmt: skip


def peers_w1(t_end: float = 1e4, rounds: int = 5, slow_rounds: int = 1,
             peers: tuple[str, ...] | None = None, verbose: bool = True) -> dict:  # fmt: skip
    """Each peer on W1 beside rollingtop (module docstring); a dict for results.json."""
    import rollingtop as rt

    say = print if verbose else (lambda *a, **k: None)
    sc = rt.load_scenario(ROOT / "examples" / "paper.toml").with_overrides(
        t_end=t_end, rtol=RTOL, atol=ATOL, samples=2
    )
    y0 = np.ascontiguousarray(sc.y0, dtype=float)
    p = np.ascontiguousarray(sc.body.params, dtype=float)
    code = int(sc.model.code)
    rt.simulate(sc, t_end=1.0)  # compile / load the cache outside the timing

    ours_times: list[float] = []

    def ours_now() -> tuple[float, object]:
        wall, times, traj = median_time(lambda: rt.simulate(sc), 3)
        ours_times.extend(times)
        return wall, traj

    _, traj = ours_now()
    y_ours = np.asarray(traj.y[-1])
    say(f"  reference (rollingtop and solve_ivp at rtol {REF_RTOL:g}) ...", flush=True)
    ref = np.asarray(rt.simulate(sc, rtol=REF_RTOL, atol=REF_ATOL).y[-1])[:17]
    ref_b = solve_ivp(compiled_rhs_factory(code, p), (0.0, t_end), y0, method="DOP853",
                      rtol=REF_RTOL, atol=REF_ATOL).y[:17, -1]  # fmt: skip
    out: dict = {
        "t_end": t_end, "rtol": RTOL, "atol": ATOL, "rounds": rounds, "slow_rounds": slow_rounds,
        "note": NO_PROJECTION,
        "reference": f"rollingtop at rtol {REF_RTOL:g}, atol {REF_ATOL:g}",
        "reference_cross_check": float(np.max(np.abs(ref - ref_b))),
        "error_norm": "max |y - y_ref| over the 17 state components at t_end",
        "skipped": {},
    }  # fmt: skip

    ctx = {"y0": y0, "p": p, "code": code, "t_end": t_end}
    names = list(PEERS) if peers is None else list(peers)
    need_kernels = any(n.startswith(("cyrk", "numbalsoda")) for n in names)
    if need_kernels:
        say("  compiling the rhs wrappers ...", flush=True)
        ctx["kernels"] = rhs_kernels(code)

    def fail(name: str, exc: Exception) -> None:
        why = str(exc) if isinstance(exc, _Skip) else f"failed: {type(exc).__name__}: {exc}"
        out["skipped"][name] = why
        ready.pop(name, None)
        say(f"  {name}: {'skipped' if isinstance(exc, _Skip) else 'not measured'} -- {why}",
            flush=True)  # fmt: skip

    ready: dict[str, dict] = {}
    for name in names:
        factory, fast = PEERS[name]
        try:
            run, count, label = factory(ctx)
            if fast:
                run()  # warm-up: what the peer compiles or loads on first use
        except Exception as exc:  # a peer that is missing or fails is reported, not fatal
            fail(name, exc)
            continue
        ready[name] = {"run": run, "count": count, "fast": fast, "label": label,
                       "times": [], "ratios": []}  # fmt: skip

    def one(name: str, single: bool) -> None:
        entry = ready[name]
        before, _ = ours_now()
        start = time.perf_counter()
        y_end, _ = entry["run"]()
        wall = time.perf_counter() - start
        beside = (before + ours_now()[0]) / 2 if single else before
        entry["times"].append(wall)
        entry["ratios"].append(wall / beside)
        entry["y_end"] = _final(y_end)

    fast = [n for n in ready if ready[n]["fast"]]
    slow = [n for n in ready if not ready[n]["fast"]]
    for k in range(rounds):
        for name in [n for n in fast if n in ready]:
            try:
                one(name, single=rounds == 1)
            except Exception as exc:
                fail(name, exc)
        say(f"  round {k + 1}/{rounds}: " + ", ".join(
            f"{n} x{ready[n]['ratios'][-1]:.2f}" for n in fast if n in ready), flush=True)  # fmt: skip
    for name in slow:
        try:
            for _ in range(slow_rounds):
                one(name, single=slow_rounds == 1)
        except Exception as exc:
            fail(name, exc)
            continue
        say(f"  {name}: x{statistics.median(ready[name]['ratios']):.1f}", flush=True)
    # steps and evaluations: an untimed counting run (fast peers) or the last timed run (slow)
    for name in list(ready):
        try:
            counts = ready[name]["count"]()
        except Exception as exc:
            fail(name, exc)
            continue
        ready[name]["y_count"] = _final(counts.pop("y_end"))
        ready[name]["counts"] = counts

    wall_ours = statistics.median(ours_times)
    st = traj.stats
    out["rollingtop"] = {
        "label": "rollingtop (DOP853 with projection and reaction monitoring)",
        "wall_s": wall_ours,
        "kernel_wall_s": st["wall_time_s"],
        "steps": st["steps"],
        "rejected_steps": st.get("rejected_steps"),
        "rhs_evals": st["rhs_evals"],
        "us_per_rhs_eval": 1e6 * wall_ours / st["rhs_evals"],
        "times": ours_times,
        "final_state_error": float(np.max(np.abs(y_ours[:17] - ref))),
    }
    for name, entry in ready.items():
        wall = statistics.median(entry["times"])
        c = entry["counts"]
        ratios = entry["ratios"]
        out[name] = {
            "label": entry["label"],
            "wall_s": wall,
            "steps": c.get("steps"),
            "rejected_steps": c.get("rejected_steps"),
            "rejected_derived_from_rhs_evals": bool(c.get("rejected_derived", False)),
            "rhs_evals": c.get("rhs_evals"),
            "us_per_rhs_eval": 1e6 * wall / c["rhs_evals"] if c.get("rhs_evals") else None,
            "counts_how": c.get("how"),
            "times": entry["times"],
            "paired_ratios": ratios,
            "ratio_to_rollingtop": statistics.median(ratios),
            "ratio_range": [min(ratios), max(ratios)],
            "final_state_error": float(np.max(np.abs(entry["y_end"] - ref))),
            "final_state_diff_vs_rollingtop": float(np.max(np.abs(entry["y_end"] - y_ours[:17]))),
            "counting_run_same_result": bool(np.array_equal(entry["y_count"], entry["y_end"])),
        }
        if "compile_s" in c:
            out[name]["compile_s"] = c["compile_s"]
    out["versions"] = _versions()
    return out


def _versions() -> dict:
    dists = ("rollingtop", "numba", "numpy", "scipy", "CyRK", "numbalsoda", "jax", "diffrax")
    return {dist: _version(dist) for dist in dists}


def table(res: dict) -> str:
    """A Markdown table of :func:`peers_w1`'s result."""
    rows = [
        f"| W1 peers: t = {res['t_end']:g}, rtol {res['rtol']:g}, atol {res['atol']:g} | wall (s) "
        "| accepted steps | rejected | rhs evals | us/eval | error at t_end | time / rollingtop's "
        "(median of paired runs; range) |",
        "|---|---|---|---|---|---|---|---|",
    ]

    def fmt(x, spec):
        return "-" if x is None else format(x, spec)

    o = res["rollingtop"]
    rows.append(f"| rollingtop (projects, monitors) | {o['wall_s']:.4g} | {o['steps']} | "
                f"{fmt(o['rejected_steps'], 'd')} | {o['rhs_evals']} | {o['us_per_rhs_eval']:.3f} | "
                f"{o['final_state_error']:.1e} | 1 |")  # fmt: skip
    for name in PEERS:
        if name not in res:
            continue
        e = res[name]
        rej = fmt(e["rejected_steps"], "d") + ("*" if e["rejected_derived_from_rhs_evals"] else "")
        lo, hi = e["ratio_range"]
        rng = f" ({lo:.2f}-{hi:.2f})" if len(e["paired_ratios"]) > 1 else ""
        rows.append(f"| {e['label']} | {e['wall_s']:.4g} | {fmt(e['steps'], 'd')} | {rej} | "
                    f"{fmt(e['rhs_evals'], 'd')} | {fmt(e['us_per_rhs_eval'], '.3f')} | "
                    f"{e['final_state_error']:.1e} | {e['ratio_to_rollingtop']:.2f}{rng} |")  # fmt: skip
    rows += ["", f"Note: {res['note']}.", "* derived from the counted rhs evaluations "
             "(the peer does not report rejected steps).",
             f"Errors: {res['error_norm']}, against {res['reference']} (solve_ivp at the same "
             f"tolerance agrees to {res['reference_cross_check']:.1e})."]  # fmt: skip
    for name, why in res["skipped"].items():
        rows.append(f"Skipped {name}: {why}.")
    return "\n".join(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description="peers beside rollingtop on W1 (quick by default)")
    ap.add_argument("--t-end", type=float, default=1e3)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--slow-rounds", type=int, default=1)
    ap.add_argument("--peers", help="comma-separated subset of: " + ", ".join(PEERS))
    ap.add_argument("--json", metavar="FILE", help="also write the result to FILE")
    args = ap.parse_args()
    res = peers_w1(args.t_end, args.rounds, args.slow_rounds,
                   tuple(args.peers.split(",")) if args.peers else None)  # fmt: skip
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2))
    print(table(res))


if __name__ == "__main__":
    main()
