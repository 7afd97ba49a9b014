"""Measure what the compile notice estimates: the seconds each group of the paper's model's
kernels takes to compile with an empty cache, each group in a fresh process; and the seconds of
each compiled package in a worker of ``rollingtop warmup`` (the order it hands them out in).

The command line announces a cold compilation with an estimate
(``rollingtop: compiling the meridian model's integrator kernels (first run only, about 9 s)``);
:data:`rollingtop._compiled.ESTIMATES` reads the numbers from
``src/rollingtop/_compiled/estimates.json``, which this script writes (``--write``; also run by
``run_benchmarks.py --only cold_start --write-docs``). Each group is triggered the way the
library first compiles it, and timed by the compiled core's notifier (from numba's first compile
event in the block to its end: imports and loading excluded).

    python benchmarks/compile_estimates.py [--write]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
TARGET = ROOT / "src" / "rollingtop" / "_compiled" / "estimates.json"

#: The groups the library announces (:func:`rollingtop._compiled.compiling`), in order.
GROUPS = ("dynamics", "integrator", "held integrator", "event integrator", "chaos")

CHILD = r"""
import json, re, sys
import numpy as np
from rollingtop import _compiled

what = sys.argv[1]
blocks = []


class Record:
    def start(self, message, first):
        blocks.append([re.search(r"model's (.+) kernels", message).group(1), 0.0])

    def step(self, function, seconds):
        pass

    def done(self, seconds):
        blocks[-1][1] = seconds


_compiled.set_notifier(Record())
from rollingtop._compiled._kernel import new_workspace
from rollingtop._jit import call
from rollingtop._layout import N_STATE, WARMUP_PARAMS

code = _compiled.for_model("meridian")._dispatch.CODES[0]
y = np.zeros(N_STATE)
y[6:15] = (1.0, 0.0, 0.0, 0.0, 0.8, -0.6, 0.0, 0.6, 0.8)
y[3:6] = (0.1, 0.2, 0.3)
if what == "dynamics":  # the shading of a portrait: reactions along states (near_pole)
    with _compiled.compiling("meridian", "dynamics"):
        call(_compiled.for_code(code).dynamics.contact_forces, code, np.array(WARMUP_PARAMS),
             y[None, :].copy(), np.zeros((1, 2)))
elif what == "chaos":
    from rollingtop import SphericalTop
    from rollingtop.chaos.lyapunov import chaos_indicators
    body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)
    with _compiled.compiling("meridian", "integrator"):  # the check of the state: not chaos
        call(_compiled.for_code(code).dynamics.project, code, body.params, y, call(new_workspace))
    chaos_indicators(body, "meridian", y, t_end=0.01, samples=1)
else:
    from rollingtop.integrate.driver import compile_code
    compile_code(code, held=what == "held integrator", events=what == "event integrator")
print(json.dumps(sum(s for w, s in blocks if w == what)))
"""


def measure(group: str) -> float:
    """Seconds the notifier reports for ``group`` in a fresh process with an empty cache."""
    with tempfile.TemporaryDirectory() as cache:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env["NUMBA_CACHE_DIR"] = cache
        proc = subprocess.run([sys.executable, "-c", CHILD, group], env=env, cwd=ROOT,
                              capture_output=True, text=True)  # fmt: skip
    if proc.returncode != 0:
        raise SystemExit(f"measuring {group!r} failed:\n{proc.stderr}")
    return float(json.loads(proc.stdout.strip().splitlines()[-1]))


def estimates() -> dict[str, object]:
    """Every group's seconds (:data:`GROUPS`), with when they were measured."""
    seconds = {}
    for group in GROUPS:
        seconds[group] = round(measure(group), 1)
        print(f"  {group}: {seconds[group]} s", flush=True)
    return {
        "model": "meridian",
        "date": time.strftime("%Y-%m-%d", time.gmtime()),
        "written_by": "benchmarks/compile_estimates.py --write",
        "seconds": seconds,
        "packages": package_seconds(),
    }


PACKAGE_CHILD = r"""
import json, sys, time
from rollingtop._warmup import warm_package

start = time.perf_counter()
warm_package(sys.argv[1])
print(json.dumps(time.perf_counter() - start))
"""


def package_seconds() -> dict[str, float]:
    """Seconds each compiled package's kernels take in a worker of ``rollingtop warmup`` (one
    process, no helper; the pieces every model shares already cached, as they are after the
    first package), each in a fresh process: the order in which warmup hands them out."""
    from rollingtop._compiled import GROUPS as PACKAGES
    from rollingtop.integrate._compile_helper import ENV

    seconds = {}
    with tempfile.TemporaryDirectory() as cache:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env |= {"NUMBA_CACHE_DIR": cache, ENV: "0"}
        shared = "from rollingtop.integrate.driver import compile_shared; compile_shared()"
        subprocess.run([sys.executable, "-c", shared], env=env, cwd=ROOT, check=True)
        for group in PACKAGES:
            proc = subprocess.run([sys.executable, "-c", PACKAGE_CHILD, group.package], env=env,
                                  cwd=ROOT, capture_output=True, text=True)  # fmt: skip
            if proc.returncode != 0:
                raise SystemExit(f"measuring {group.package!r} failed:\n{proc.stderr}")
            seconds[group.package] = round(float(proc.stdout.strip().splitlines()[-1]), 1)
            print(f"  package {group.package}: {seconds[group.package]} s", flush=True)
    return seconds


def write(result: dict[str, object], path: Path = TARGET) -> None:
    path.write_text(json.dumps(result, indent=2) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--write", action="store_true", help=f"write {TARGET.relative_to(ROOT)}")
    args = parser.parse_args()
    result = estimates()
    if args.write:
        write(result)
        print(f"wrote {TARGET.relative_to(ROOT)}")
    else:
        print(json.dumps(result, indent=2))


if __name__ == "__main__":
    main()
