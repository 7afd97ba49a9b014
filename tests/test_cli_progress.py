"""Progress of the long commands (verify, rotation, section, atlas): a bar on stderr when it is a
terminal, nothing when it is piped.

capsys makes stderr a pipe; rich's ``TTY_COMPATIBLE=1`` (with a ``TERM`` that is not dumb) makes
it count as a terminal, so the same run shows the bar. The bar is transient: drawn, then erased
with control codes, which capsys keeps.
"""

import json

import pytest

from .conftest import EXAMPLES, local_cluster
from .test_cli import run_cli

FIG5 = str(EXAMPLES / "fig5.toml")
CHAOTIC = str(EXAMPLES / "chaotic.toml")
#: The control code that erases a line (how the transient bar leaves).
ERASE_LINE = "\x1b[2K"


@pytest.fixture
def piped(monkeypatch):
    """stderr a pipe, whatever the environment running the tests says."""
    for name in ("TTY_COMPATIBLE", "TTY_INTERACTIVE", "FORCE_COLOR"):
        monkeypatch.delenv(name, raising=False)


@pytest.fixture
def terminal(monkeypatch):
    """stderr (and stdout) counted as an interactive terminal."""
    monkeypatch.setenv("TTY_COMPATIBLE", "1")
    monkeypatch.setenv("TTY_INTERACTIVE", "1")
    monkeypatch.setenv("TERM", "xterm-256color")
    monkeypatch.setenv("COLUMNS", "100")


@pytest.fixture
def few_claims(monkeypatch):
    """``verify`` deciding three stand-in claims, reporting each through ``progress``."""
    import rollingtop.symbolic
    from rollingtop.symbolic import ClaimResult

    def verify(models, progress=None):
        results = []
        for k in range(3):
            results.append(ClaimResult(f"claim {k}", models[0], "proved",
                                       "exact simplification", 0.0))  # fmt: skip
            if progress is not None:
                progress(k + 1, 3)
        return results

    monkeypatch.setattr(rollingtop.symbolic, "verify", verify)


def _section(tmp_path):
    return ["section", CHAOTIC, "-o", str(tmp_path / "s.png"), "--crossings", "300",
            "--trajectories", "2"]  # fmt: skip


def _rotation():
    return ["rotation", FIG5, "--resolution", "5"]


def test_piped_runs_show_no_progress(capsys, tmp_path, piped, few_claims):
    """Piped, stderr stays empty and stdout holds the results only. Each command runs once
    before: a cold cache's compile notice belongs on stderr (the section's chaos kernels are
    not among those the suite compiles first, so the test failed when it ran before any other
    that compiles them)."""
    for args in (["verify", "--model", "rough"], _rotation(), _section(tmp_path)):
        assert run_cli(capsys, *args)[0] == 0
        code, out, err = run_cli(capsys, *args)
        assert code == 0, err
        assert err == ""
        assert "\x1b" not in out


def test_verify_shows_progress_on_a_terminal(capsys, terminal, few_claims):
    code, out, err = run_cli(capsys, "verify", "--model", "rough")
    assert code == 0, err
    assert "claims decided" in err and "3/3" in err
    assert err.rstrip().endswith(ERASE_LINE)  # the bar is erased when done
    assert "claims decided" not in out


def test_section_shows_progress_on_a_terminal(capsys, tmp_path, terminal):
    code, out, err = run_cli(capsys, *_section(tmp_path))
    assert code == 0, err
    assert "crossings found" in err and "600/600" in err
    assert out.splitlines()[0].startswith("600 crossings of 2 trajectories")


def test_rotation_shows_progress_on_a_terminal(capsys, terminal):
    code, out, err = run_cli(capsys, *_rotation(), "--json")
    assert code == 0, err
    assert "rotation numbers" in err and "5/5" in err  # one step per column of C2
    assert json.loads(out)["N_range"] is not None


@pytest.fixture(scope="module")
def client():
    from distributed import Client

    with local_cluster(1) as cluster, Client(cluster) as c:
        yield c


@pytest.mark.parametrize("on_terminal", [False, True])
def test_atlas_progress_only_on_a_terminal(capsys, tmp_path, monkeypatch, client, on_terminal):
    """The atlas on an in-process cluster (the command's own starts worker processes): its bar
    counts the cells on a terminal, and nothing shows when piped."""
    import rollingtop.atlas

    real = rollingtop.atlas.atlas

    def in_process(spec, output, *, workers, scheduler, chunk, progress, scheduler_timeout):
        return real(spec, output, client=client, chunk=2, progress=progress)

    monkeypatch.setattr(rollingtop.atlas, "atlas", in_process)
    for name in ("TTY_COMPATIBLE", "TTY_INTERACTIVE", "FORCE_COLOR"):
        monkeypatch.delenv(name, raising=False)
    if on_terminal:
        monkeypatch.setenv("TTY_COMPATIBLE", "1")
        monkeypatch.setenv("TTY_INTERACTIVE", "1")
        monkeypatch.setenv("TERM", "xterm-256color")
    spec = tmp_path / "spec.toml"
    spec.write_text("[body]\nR = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5\n"
                    '[contact]\nmodel = "meridian"\n[level]\nM3 = 1.0\nC1 = 0.5\nC2 = -2.0\n'
                    "[axes]\nC2 = [-2.0, -1.0]\nC1 = [0.0, 0.5]\n")  # fmt: skip
    code, out, err = run_cli(capsys, "atlas", str(spec), "-o", str(tmp_path / "a.nc"), "--json")
    assert code == 0, err
    assert json.loads(out)["classified"] == 4
    if on_terminal:
        assert "cells" in err and "4/4" in err
    else:
        assert err == ""
