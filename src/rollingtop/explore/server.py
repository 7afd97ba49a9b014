"""Serving the explore page with Panel's own server (Bokeh's Tornado server).

:func:`serve` compiles what the page needs first (the model's kernel, by a short trajectory;
the plotting imports), then listens, prints the one line ``serving at http://HOST:PORT/`` and
runs until it is interrupted; on the way out the server stops and the page's worker threads
are shut down, so nothing keeps running.
"""

from __future__ import annotations

import errno
import logging
import signal
import socket
import subprocess
import sys
import threading
import webbrowser
from collections.abc import Callable
from typing import Any

from rollingtop._errors import Interrupted, ScenarioError
from rollingtop.explore.path import path_view
from rollingtop.explore.view import ExploreState, cached_level_view

__all__ = ["CHROMIUM_FLAGS", "LOOPBACK", "TIMED_CHANGE_JS", "serve", "spawn", "warm_up"]

#: Flags for a headless chromium driving the page (scripts and tests; root, a closed network):
#: without the background-networking ones chromium tries to reach Google at every start.
CHROMIUM_FLAGS = (
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
)
#: For scripts and tests that time the page (``page.evaluate(TIMED_CHANGE_JS, [index, value,
#: want, limit_ms])`` in playwright): set the text input number ``index`` (document order,
#: shadow roots included) to ``value``, fire its change event and wait for a leaf element whose
#: text contains ``want``; the milliseconds between the two, measured in the page with
#: ``performance.now()`` and polled each animation frame (-1 after ``limit_ms``).
TIMED_CHANGE_JS = """
async ([index, value, want, limit]) => {
  const walk = (root, out) => {
    for (const el of root.querySelectorAll('*')) {
      out.push(el);
      if (el.shadowRoot) walk(el.shadowRoot, out);
    }
    return out;
  };
  const shows = () => walk(document, []).some(
    el => !el.shadowRoot && el.childElementCount === 0 && el.textContent.includes(want));
  const input = walk(document, []).filter(e => e.tagName === 'INPUT')[index];
  input.value = value;
  const t0 = performance.now();
  input.dispatchEvent(new Event('change', {bubbles: true}));
  return await new Promise(resolve => {
    const tick = () => {
      if (shows()) resolve(performance.now() - t0);
      else if (performance.now() - t0 > limit) resolve(-1);
      else requestAnimationFrame(tick);
    };
    tick();
  });
}
"""
#: Addresses that only this machine reaches.
LOOPBACK = ("127.0.0.1", "localhost", "::1")


def warm_up(base: ExploreState) -> None:
    """Compute once what the first page load needs, so that it is quick: the level's plots,
    and a short trajectory (the model's compiled kernel, from the numba cache or compiled now,
    with the command line's notice)."""
    if not base.reduces:
        return  # a section compiles on the page's first request (its kernel's notice then)
    view = cached_level_view(base)
    x = view.steady[0][0] if view.steady else float(view.U_x[len(view.U_x) // 2])
    try:
        path_view(base, x, 0.0, t_end=0.1)
    except ScenarioError:  # a steady motion on a pole level, say: the page refuses it too
        pass


def _check_address(host: str, port: int) -> None:
    """A :class:`ScenarioError` when ``host:port`` cannot be bound (tried and released)."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
        family, _, _, _, address = infos[0]
        with socket.socket(family, socket.SOCK_STREAM) as sock:
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.bind(address)
    except OSError as err:
        hint = "choose another --port" if err.errno == errno.EADDRINUSE else "check --host"
        raise ScenarioError(
            f"cannot serve at {host}:{port}: {err.strerror or err} ({hint})"
        ) from None


#: Digits of an integer a query value may have: more than Tornado's 64 KiB request header.
MAX_QUERY_DIGITS = 70_000


def serve(
    base: ExploreState,
    *,
    port: int,
    host: str,
    open_browser: bool,
    look: str = "plain",
    echo: Callable[[str], None] = print,
) -> None:
    """Serve the page for ``base`` at ``http://host:port/`` until interrupted.

    Raises
    ------
    ScenarioError
        The port cannot be bound (in use, or not permitted).
    """
    import panel as pn

    from rollingtop.explore._work import new_executor
    from rollingtop.explore.app import ExplorePage

    _check_address(host, port)  # before compiling: a busy port is said at once
    # Panel reads every all-digit query value as an int, which Python refuses beyond 4300
    # digits (an HTTP 500 and a traceback for ?C2=<5000 digits>): allow as many as a request
    # line can hold, so that the page says what is wrong with the value (parse_query).
    sys.set_int_max_str_digits(max(sys.get_int_max_str_digits(), MAX_QUERY_DIGITS))
    # a tab closed while a result was on its way is not the user's concern
    logging.getLogger("bokeh.server.views.ws").setLevel(logging.ERROR)
    warm_up(base)
    workers = new_executor()  # this server's, shared by its sessions

    def page() -> Any:  # a closed tab's session goes 5 s after it closes (Bokeh's default: 15)
        view = ExplorePage(base, look, executor=workers)
        pn.state.on_session_destroyed(lambda _: view.close())  # its data go with the session
        return view.layout

    origins = [f"{host}:{port}"] + (
        [f"localhost:{port}", f"127.0.0.1:{port}"] if host in LOOPBACK else []
    )
    ours = signal.getsignal(signal.SIGINT)  # Panel installs its own; the command's stays
    try:
        server = pn.serve(
            page,
            port=port,
            address=host,
            show=False,
            start=False,
            title="rollingtop explore",
            websocket_origin=origins,
            verbose=False,
            check_unused_sessions_milliseconds=2000,
            unused_session_lifetime_milliseconds=5000,
        )
    except OSError as err:
        hint = "choose another --port" if err.errno == errno.EADDRINUSE else "check --host"
        raise ScenarioError(
            f"cannot serve at {host}:{port}: {err.strerror or err} ({hint})"
        ) from None
    finally:
        signal.signal(signal.SIGINT, ours)
    url = f"http://{host}:{port}/"
    # SIGINT and SIGTERM stop the event loop (a handler that raised would be caught and logged
    # by asyncio when it lands inside a callback); the signal is raised once the loop is out
    caught: list[int] = []

    def stop(signum: int, frame: Any) -> None:
        caught.append(signum)
        server.io_loop.asyncio_loop.call_soon_threadsafe(server.io_loop.stop)

    previous = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        server.start()
        echo(f"serving at {url}")
        sys.stdout.flush()
        if open_browser:
            webbrowser.open(url)
        server.io_loop.start()
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        server.stop()
        workers.shutdown(wait=False, cancel_futures=True)
    if caught:
        raise Interrupted(caught[0])


def spawn(
    scenario: str | None = None,
    *,
    port: int | None = None,
    timeout: float = 120.0,
    args: tuple[str, ...] = (),
) -> tuple[subprocess.Popen[str], str]:
    """Start ``rollingtop explore`` in a child process (``--no-browser``; a free port unless
    ``port``) and wait for its ``serving at`` line: ``(process, url)``. For scripts and tests
    that drive the page in a browser; stop the process with SIGINT.

    Raises
    ------
    RuntimeError
        The process ended, or printed no ``serving at`` line within ``timeout`` seconds (its
        stderr in the message).
    """
    if port is None:
        with socket.socket() as sock:
            sock.bind(("127.0.0.1", 0))
            port = int(sock.getsockname()[1])
    cmd = [
        sys.executable,
        "-m",
        "rollingtop",
        "explore",
        *([scenario] if scenario else []),
        "--no-browser",
        "--port",
        str(port),
        *args,
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines: list[str] = []
    reader = threading.Thread(
        target=lambda: lines.append(proc.stdout.readline()),  # type: ignore[union-attr]
        daemon=True,
    )
    reader.start()
    reader.join(timeout)
    line = lines[0].strip() if lines else ""
    if not line.startswith("serving at "):
        proc.kill()
        _, err = proc.communicate(timeout=10)
        raise RuntimeError(f"rollingtop explore did not start within {timeout:g} s: {err.strip()}")
    return proc, line.removeprefix("serving at ")
