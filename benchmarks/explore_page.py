"""The explore page's responsiveness in a real browser (issue 25): the redraw after a slider
change and the click-to-start trajectory; and the server's memory over many sessions (issue 36).

Run:  python benchmarks/explore_page.py [--changes 16] [--clicks 5] [--sessions 100] [--write]

``rollingtop explore examples/fig5.toml`` in a child process, Debian's chromium (headless,
pytest-playwright's library) on it. A change of ``C2`` across the fold (-1 and -2, each 0.001
lower than the last, so that the server has no view of it cached: the count of steady motions
goes 1, 3, 1, ...) is timed in the page, from the input's change event to the
updated readout (``rollingtop.explore.server.TIMED_CHANGE_JS``); a click on the phase portrait
is timed from the click to the trajectory's summary. Medians and ranges are printed; with
``--write`` they go into ``benchmarks/results.json`` (``explore``) and into the block between
the markers of ``docs/guide/explore.md``. The issue's bounds (300 ms and 1 s) are compared
here, never in a test.

Sessions: a fresh server; 5 sessions opened and closed (Bokeh's client, ``pull_session``) to
warm it, its resident memory read from ``/proc``; then ``--sessions`` more, in rounds of 25,
the memory read 8 s after each round (a closed session is dropped 5 s after it closes). The
issue's bound: 100 sessions grow the server by < 20 MB.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import signal
import statistics
import sys
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import replace_between, write_atomically  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results.json"
PAGE = ROOT / "docs" / "guide" / "explore.md"
START = "<!-- explore-latency:start (written by benchmarks/explore_page.py --write) -->"
END = "<!-- explore-latency:end -->"
#: The text input of C2 among the page's inputs (the body's R, m, a3, I1, I3, g; M3, C1, C2).
C2_INPUT = 8
#: Issue 25's bounds, compared in the printout.
REDRAW_BOUND_MS, PATH_BOUND_MS = 300.0, 1000.0


def measure(changes: int, clicks: int) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    from rollingtop.explore.server import CHROMIUM_FLAGS, TIMED_CHANGE_JS, spawn

    browser_path = os.environ.get("ROLLINGTOP_BROWSER") or shutil.which("chromium")
    if browser_path is None:
        raise SystemExit("no chromium: apt-get install chromium (or set ROLLINGTOP_BROWSER)")
    proc, url = spawn(str(ROOT / "examples" / "fig5.toml"))
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=browser_path, args=list(CHROMIUM_FLAGS))
            page = browser.new_page(viewport={"width": 1400, "height": 950})
            page.goto(url)
            page.get_by_text("steady motions: 3").first.wait_for(timeout=60_000)
            redraw = []
            for k in range(changes):  # a new C2 each time: no view the server has cached
                lo, hi = -1.0 - 0.001 * k, -2.0 - 0.001 * k
                value, want = (
                    (repr(lo), "steady motions: 1")
                    if k % 2 == 0
                    else (repr(hi), "steady motions: 3")
                )
                ms = page.evaluate(TIMED_CHANGE_JS, [C2_INPUT, value, want, 10_000])
                if ms < 0:
                    raise SystemExit(f"change {k}: no redraw within 10 s")
                redraw.append(ms)
            path = []
            for k in range(clicks):  # a fresh page each time: no summary of an earlier click
                page.goto(url)
                page.get_by_text("steady motions: 3").first.wait_for(timeout=60_000)
                box = page.locator(".bk-Canvas").nth(0).bounding_box()
                t0 = time.perf_counter()
                page.mouse.click(box["x"] + (0.30 + 0.02 * k) * box["width"],
                                 box["y"] + 0.55 * box["height"])  # fmt: skip
                page.get_by_text("trajectory: t = 0 .. 20").first.wait_for(timeout=10_000)
                path.append((time.perf_counter() - t0) * 1000)
            browser.close()
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=30)
    return {
        "scenario": "examples/fig5.toml",
        "redraw_ms": _spread(redraw),
        "path_ms": _spread(path),
        "cores": os.cpu_count(),
        "date": datetime.now(UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
    }


def _spread(xs: list[float]) -> dict[str, Any]:
    return {"median": statistics.median(xs), "min": min(xs), "max": max(xs), "all": xs}


def _rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS"):
            return int(line.split()[1]) / 1024
    raise SystemExit("no VmRSS in /proc: the session measurement needs Linux")


def sessions(n: int, rounds_of: int = 25, settle_s: float = 8.0) -> dict[str, Any]:
    import panel  # noqa: F401  (registers Panel's models with Bokeh's client)
    from bokeh.client import pull_session

    from rollingtop.explore.server import spawn

    proc, url = spawn(str(ROOT / "examples" / "fig5.toml"))

    def cycle(k: int) -> None:
        for _ in range(k):
            pull_session(url=url).close()

    try:
        cycle(5)
        time.sleep(settle_s)
        base = _rss_mb(proc.pid)
        growth, done = [], 0
        while done < n:
            k = min(rounds_of, n - done)
            cycle(k)
            done += k
            time.sleep(settle_s)
            growth.append([done, _rss_mb(proc.pid) - base])
    finally:
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=30)
    return {"base_mb": base, "growth_mb": growth}


def block(res: dict[str, Any]) -> str:
    r, p = res["redraw_ms"], res["path_ms"]
    return (
        f"Measured {res['date']} on a {res['cores']}-core machine: a change of `C2` redraws the "
        f"readout in {r['median']:.0f} ms (median of {len(r['all'])} changes; "
        f"{r['min']:.0f}-{r['max']:.0f} ms; the issue's bound: {REDRAW_BOUND_MS:.0f} ms), and a "
        f"click-to-start trajectory of 20 time units appears in {p['median']:.0f} ms (median of "
        f"{len(p['all'])} clicks; {p['min']:.0f}-{p['max']:.0f} ms; bound: "
        f"{PATH_BOUND_MS:.0f} ms)."
    ) + (_sessions_text(res["sessions"]) if "sessions" in res else "")


def _sessions_text(s: dict[str, Any]) -> str:
    n, grown = s["growth_mb"][-1]
    steps = ", ".join(f"{mb:+.1f} MB after {k}" for k, mb in s["growth_mb"])
    return (
        f" Sessions opened and closed: the server ({s['base_mb']:.0f} MB after 5) grew by "
        f"{grown:.1f} MB over {n} more ({steps}; the issue's bound: < 20 MB for 100)."
    )


def write(res: dict[str, Any]) -> None:
    results = json.loads(RESULTS.read_text()) if RESULTS.exists() else {}
    results["explore"] = res
    # its date is its own (results["dates"] dates the performance page's parts)
    write_atomically(RESULTS, json.dumps(results, indent=2))
    write_atomically(PAGE, replace_between(PAGE.read_text(), START, END, block(res), PAGE))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--changes", type=int, default=16)
    ap.add_argument("--clicks", type=int, default=5)
    ap.add_argument("--sessions", type=int, default=100, help="0: skip the memory part")
    ap.add_argument("--write", action="store_true", help="update results.json and the docs page")
    args = ap.parse_args()
    res = measure(args.changes, args.clicks)
    if args.sessions > 0:
        res["sessions"] = sessions(args.sessions)
    print(block(res))
    if args.write:
        write(res)
        print(f"wrote {RESULTS.name} and {PAGE.relative_to(ROOT)}", file=sys.stderr)


if __name__ == "__main__":
    main()
