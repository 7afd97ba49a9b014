"""What the benchmark scripts share: the repository root, a median timer, the machine's
description, and the right-hand sides the peers integrate (imported by run_benchmarks, peers,
scaling; imports none of them)."""

from __future__ import annotations

import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

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

    from rollingtop._compiled import for_code

    model_rhs = for_code(code).dynamics.rhs

    @njit
    def f(y):
        dy = np.empty(18)
        ws = (np.empty((4, 6)), np.empty(4), np.empty((4, 3)), np.empty((4, 4)), np.empty(4))
        model_rhs(code, p, y, dy, ws)
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


def replace_between(text: str, start: str, end: str, block: str, where: object) -> str:
    """``text`` with what lies between its marker lines ``start`` and ``end`` replaced by
    ``block`` (``SystemExit`` naming ``where`` when a marker is missing)."""
    head, sep, rest = text.partition(start)
    _, sep2, tail = rest.partition(end)
    if not sep or not sep2:
        raise SystemExit(f"{where}: markers {start!r} ... {end!r} not found")
    return f"{head}{start}\n{block}\n{end}{tail}"


def write_atomically(path: Path, text: str) -> None:
    """``path``'s new text, renamed into place (a reader never sees half a file)."""
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    os.replace(tmp, path)
