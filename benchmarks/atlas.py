"""The atlas on Dask (issue 14, section 4): cells per second on 1 and 2 workers.

Run:  python benchmarks/atlas.py [--rounds 3] [--json FILE]

One embedded local cluster per worker count (worker processes, one thread each, as
``rollingtop atlas`` starts by default); the same spec (the paper's body, ``a3 x C1 x C2`` =
4 x 6 x 250 = 6000 cells, chunks of 100) classified ``rounds`` times on each, the worker counts
interleaved round by round; the time of the classification (cluster start-up excluded, it is
reported separately); cells per second, and the parallel efficiency ``t1 / (2 t2)`` per round
and its median. The in-process classification (no Dask) is timed too, for the overhead.
"""

from __future__ import annotations

import argparse
import json
import logging
import statistics
import time
from pathlib import Path
from typing import Any

SPEC = {
    "body": {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5},
    "contact": {"model": "meridian"},
    "level": {"M3": 1.0, "C1": 0.5, "C2": -2.0},
    "axes": {
        "a3": [0.05, 0.1, 0.15, 0.2],
        "C1": [-0.8, -0.4, 0.0, 0.3, 0.6, 0.9],
        "C2": {"start": -3.0, "stop": 0.5, "num": 250},
    },
}
CHUNK = 100


def atlas_benchmark(rounds: int = 3, workers: tuple[int, ...] = (1, 2)) -> dict[str, Any]:
    from distributed import Client, LocalCluster

    from rollingtop.atlas import atlas, atlas_spec_from_dict, classify_in_process

    logging.getLogger("distributed").setLevel(logging.ERROR)
    spec = atlas_spec_from_dict(SPEC)
    classify_in_process(atlas_spec_from_dict({**SPEC, "axes": {"C2": [0.0]}}))  # imports, caches
    start = time.perf_counter()
    reference = classify_in_process(spec)
    in_process = time.perf_counter() - start
    clusters, startup = {}, {}
    for n in workers:
        t0 = time.perf_counter()
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=50)  # fmt: skip
        clusters[n] = (cluster, Client(cluster))
        startup[n] = time.perf_counter() - t0
    times: dict[int, list[float]] = {n: [] for n in workers}
    try:
        for _ in range(rounds):
            for n in workers:
                t0 = time.perf_counter()
                ds = atlas(spec, client=clusters[n][1], chunk=CHUNK)
                times[n].append(time.perf_counter() - t0)
                assert ds.identical(reference), "the atlas on Dask differs from in-process"
    finally:
        for cluster, client in clusters.values():
            client.close()
            cluster.close()
    out: dict[str, Any] = {
        "cells": spec.size, "chunk": CHUNK, "rounds": rounds,
        "in_process_s": in_process, "in_process_cells_per_s": spec.size / in_process,
        "startup_s": {str(n): startup[n] for n in workers},
        "workers": {str(n): {"times": times[n], "wall_s": statistics.median(times[n]),
                             "cells_per_s": spec.size / statistics.median(times[n])}
                    for n in workers},
    }  # fmt: skip
    if 1 in workers and 2 in workers:
        pairs = [a / (2 * b) for a, b in zip(times[1], times[2], strict=True)]
        out["parallel_efficiency_pairs"] = pairs
        out["parallel_efficiency_2"] = statistics.median(pairs)
    return out


def table(res: dict[str, Any]) -> str:
    rows = [f"| atlas: {res['cells']} cells, chunks of {res['chunk']} | wall (s) | cells/s |",
            "|---|---|---|",
            f"| in process (no Dask) | {res['in_process_s']:.2f} | "
            f"{res['in_process_cells_per_s']:.0f} |"]  # fmt: skip
    for n, w in res["workers"].items():
        rows.append(f"| Dask, {n} worker{'s' if n != '1' else ''} (start-up "
                    f"{res['startup_s'][n]:.1f} s) | {w['wall_s']:.2f} | {w['cells_per_s']:.0f} |")  # fmt: skip
    if "parallel_efficiency_2" in res:
        pairs = res["parallel_efficiency_pairs"]
        rows.append(f"| parallel efficiency on 2 workers (median of {len(pairs)}; range) | | "
                    f"{100 * res['parallel_efficiency_2']:.0f} % ({100 * min(pairs):.0f}-"
                    f"{100 * max(pairs):.0f} %) |")  # fmt: skip
    return "\n".join(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--json", metavar="FILE", help="also write the result to FILE")
    args = ap.parse_args()
    res = atlas_benchmark(args.rounds)
    if args.json:
        Path(args.json).write_text(json.dumps(res, indent=2))
    print(table(res))


if __name__ == "__main__":
    main()
