"""The parallel model's passages through the vertical on long runs (issue 26): 100 random bodies
and states (seed 26: I1 from 0.2 to 1, I3 from 0.05 to min(2 I1, 1.5), a3 from -0.5 to 0.5,
random axis, spin and slip) to t = 1e4 at rtol = 1e-10, atol = 1e-12, on the ensemble kernel.

Writes docs/passages.json and the block between the markers of docs/guide/models.md: how many
runs finished, the passages they went through (local minima of s = sqrt(1 - gamma3^2) below 1e-2
between samples 0.5 apart, so a lower bound) and the worst relative drift of energy and
Jellett's integral.
Run: python docs/passages.py   (about a minute on 2 cores once compiled)
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

from rollingtop import SphericalTop, initial_state
from rollingtop.dynamics.integrals import evaluate
from rollingtop.ensemble import simulate_ensemble
from rollingtop.io import write_bytes_atomic

ROOT = Path(__file__).resolve().parents[1]
START = "<!-- passages:start (written by docs/passages.py) -->"
END = "<!-- passages:end -->"
SEED, RUNS, T_END, SAMPLES, CHUNK = 26, 100, 1e4, 20001, 20


def draw(seed: int, n: int) -> tuple[list[SphericalTop], np.ndarray]:
    """The bodies and states (the same draw as tests/contact/test_parallel.py)."""
    rng = np.random.default_rng(seed)
    bodies, states = [], []
    for _ in range(n):
        I1 = rng.uniform(0.2, 1.0)
        body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=rng.uniform(-0.5, 0.5), I1=I1,
                            I3=rng.uniform(0.05, min(2 * I1, 1.5)))  # fmt: skip
        gamma = rng.normal(size=3)
        states.append(initial_state(body, "parallel", gamma=gamma / np.linalg.norm(gamma),
                                    omega=rng.normal(size=3),
                                    free={"v_nu": rng.normal() * 0.5}))  # fmt: skip
        bodies.append(body)
    return bodies, np.array(states)


def measure() -> dict:
    bodies, states = draw(SEED, RUNS)
    finished = passages = steps = 0
    drift = 0.0
    start = time.perf_counter()
    for lo in range(0, RUNS, CHUNK):  # chunks: the samples of 100 runs would take 290 MB
        res = simulate_ensemble(bodies[lo:lo + CHUNK], "parallel", states[lo:lo + CHUNK],
                                t_end=T_END, rtol=1e-10, atol=1e-12, samples=SAMPLES,
                                threads=2)  # fmt: skip
        finished += int(np.count_nonzero(res.status == 0))
        steps += int(res.steps.sum())
        for body, y in zip(bodies[lo : lo + CHUNK], res.samples, strict=True):
            s = np.hypot(y[:, 12], y[:, 13])
            passages += int(np.count_nonzero((s[1:-1] < s[:-2]) & (s[1:-1] < s[2:])
                                             & (s[1:-1] < 1e-2)))  # fmt: skip
            for v in evaluate(body, y, ["energy", "jellett"]).values():
                drift = max(drift, float(np.max(np.abs(v - v[0])) / max(1.0, abs(v[0]))))
        print(f"runs {lo + CHUNK}/{RUNS}: {finished} finished", flush=True)
    return {"seed": SEED, "runs": RUNS, "t_end": T_END, "finished": finished,
            "passages": passages, "steps": steps, "worst_drift": drift,
            "wall_s": time.perf_counter() - start}  # fmt: skip


def block(r: dict) -> str:
    t_end = f"{r['t_end']:.0e}".replace("e+0", "e")
    return (
        f"{START}\nMeasured by `docs/passages.py`: {r['finished']} of {r['runs']} random bodies "
        f"and states (seed {r['seed']}) reach `t = {t_end}` at `rtol = 1e-10`, through at least "
        f"{r['passages']} approaches to within 0.01 of the vertical; the worst relative drift of "
        f"energy and Jellett's integral is {r['worst_drift']:.1e}.\n{END}"
    )


def main(argv: list[str]) -> None:
    r = measure()
    write_bytes_atomic(ROOT / "docs" / "passages.json", json.dumps(r, indent=1).encode())
    path = ROOT / "docs" / "guide" / "models.md"
    text = path.read_text()
    head, rest = text.split(START, 1)
    tail = rest.split(END, 1)[1]
    write_bytes_atomic(path, (head + block(r) + tail).encode())
    print(block(r))


if __name__ == "__main__":
    main(sys.argv[1:])
