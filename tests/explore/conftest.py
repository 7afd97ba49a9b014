"""A real browser for the explore page: pytest-playwright driving Debian's chromium (never a
downloaded build), and the page served by ``rollingtop explore`` in a child process."""

import os
import shutil
import signal

import pytest

from rollingtop.explore.server import CHROMIUM_FLAGS

from ..conftest import EXAMPLES


def chromium_path():
    """``ROLLINGTOP_BROWSER``, else ``chromium`` on the PATH; ``None`` if neither."""
    return os.environ.get("ROLLINGTOP_BROWSER") or shutil.which("chromium")


@pytest.fixture(scope="session")
def browser_type_launch_args(browser_type_launch_args):
    """pytest-playwright's launch arguments with Debian's chromium. Without one the browser
    tests are skipped -- except under ``CI=true``, where a missing browser fails the run."""
    path = chromium_path()
    if path is None:
        message = ("no chromium: apt-get install chromium, or set ROLLINGTOP_BROWSER to a "
                   "chromium executable")  # fmt: skip
        if os.environ.get("CI") == "true":
            pytest.fail(message)
        pytest.skip(message)
    return {**browser_type_launch_args, "executable_path": path, "args": list(CHROMIUM_FLAGS)}


@pytest.fixture(scope="module")
def served():
    """``rollingtop explore examples/fig5.toml`` on a free port: ``(process, url)``. Stopped by
    SIGINT at the end; the test of that is in test_browser.py (nothing may keep running)."""
    from rollingtop.explore.server import spawn

    proc, url = spawn(str(EXAMPLES / "fig5.toml"))
    yield proc, url
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=15)
        except Exception:  # noqa: BLE001 -- never leave a server behind
            proc.kill()
            proc.wait()
