"""Command line: the simulate contract, and one clear line with exit status 2 for bad input."""

import json
import os
import re
import subprocess
import sys

import pytest

from rollingtop.cli import main

from .conftest import EXAMPLES, scenario_text

#: A [level]'s energy h + M3^2/(2 I3) + m g R and its terms (O(1)): a few roundings, relative.
LEVEL_RTOL = 1e-15


def run_cli(capsys, *args):
    with pytest.raises(SystemExit) as exc:
        main(list(args))
        raise SystemExit(0)
    out, err = capsys.readouterr()
    return exc.value.code, out, err


def test_simulate_json_end_to_end(tmp_path):
    """Real process: stdout is exactly one JSON object with the documented keys."""
    out_file = tmp_path / "run.nc"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "rollingtop",
            "simulate",
            str(EXAMPLES / "paper.toml"),
            "--t-end",
            "5",
            "--rtol",
            "1e-11",
            "-o",
            str(out_file),
            "--json",
        ],
        capture_output=True,
        text=True,
        check=False,
        env=os.environ | {"COLUMNS": "120"},
    )
    assert proc.returncode == 0, proc.stderr
    summary = json.loads(proc.stdout)
    assert summary["model"] == "meridian" and summary["t_end"] == 5.0
    assert set(summary["integrals"]) == {"energy", "lagrange", "jellett", "area", "F6"}
    for row in summary["integrals"].values():
        assert row["max_abs_drift"] < 1e-9
    assert summary["final"]["t"] == 5.0
    assert out_file.stat().st_size > 0
    assert proc.stderr == ""


def test_simulate_table(capsys):
    code, out, _ = run_cli(capsys, "simulate", str(EXAMPLES / "rough.toml"), "--t-end", "2")
    assert code == 0
    assert "routh" in out and "jellett" in out and "friction coefficient needed" in out


def test_model_override(capsys):
    code, out, _ = run_cli(
        capsys,
        "simulate",
        str(EXAMPLES / "rough.toml"),
        "--t-end",
        "1",
        "--model",
        "smooth",
        "--json",
    )
    assert code == 0 and json.loads(out)["model"] == "smooth"


@pytest.mark.parametrize(
    ("setup", "args", "message"),
    [
        (None, ["simulate", "absent.toml"], "cannot read scenario 'absent.toml'"),
        ("[body\n", [], "invalid TOML"),
        (scenario_text(contact='model = "ice"'), [], "unknown contact model 'ice'"),
        (scenario_text(extra="a = 1"), [], r"unknown table \[extra\]"),
        (
            scenario_text(body="R = 1.0\nm = -1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI3 = 0.5"),
            [],
            "inadmissible body: m = -1 must be > 0",
        ),
        (
            scenario_text(initial="gamma = [0.0, 0.6, 0.7]\nomega = [0.0, 0.0, 1.0]"),
            [],
            "gamma .* is not a unit vector",
        ),
        (
            scenario_text(
                initial="gamma = [0.0, 0.6, 0.8]\nomega = [0.0, 0.0, 1.0]\nalpha = [0.0, 0.6, 0.8]"
            ),
            [],
            "alpha .* is not orthogonal to gamma",
        ),
        (
            scenario_text(
                body="R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.1\nI1 = 0.3\nI2 = 0.35\nI3 = 0.5",
                initial="gamma = [0.0, 0.0, -1.0]\nomega = [0.0, 0.0, 1.0]",
            ),
            [],
            "symmetry axis is vertical .* not dynamically symmetric",
        ),
        (scenario_text(), ["--rtol", "x"], "Invalid value for '--rtol'"),
        (scenario_text(), ["--rtol", "2"], r"rtol = 2 must lie in \[1e-15, 0.1\]"),
        (scenario_text(), ["-o", "{tmp}/no/such/dir/out.nc"], "does not exist"),
        (scenario_text(), ["-o", "{tmp}/out.xlsx"], "unknown output format '.xlsx'"),
        (scenario_text(), ["--frobnicate"], "No such option.*--frobnicate"),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, monkeypatch, setup, args, message):
    monkeypatch.chdir(tmp_path)
    if setup is not None:
        (tmp_path / "s.toml").write_text(setup)
        args = ["simulate", "s.toml", *[a.format(tmp=tmp_path) for a in args]]
    code, out, err = run_cli(capsys, *args)
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("rollingtop: error: ")
    assert re.search(message, lines[0]), lines[0]
    assert "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == (["s.toml"] if setup else [])


def test_unwritable_output_refused_before_running(tmp_path, capsys):
    if os.geteuid() == 0:
        target = tmp_path / "dir.nc"
        target.mkdir()  # root may write anywhere: use a folder in the way instead
        expected = "it is a folder"
    else:
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        target = locked / "out.nc"
        expected = "permission denied"
    code, _, err = run_cli(capsys, "simulate", str(EXAMPLES / "paper.toml"), "-o", str(target))
    assert code == 2 and expected in err


def test_contact_loss_warns_on_stderr(tmp_path, capsys):
    text = scenario_text(
        body="R = 1.0\nm = 1.0\ng = 1.0\na3 = 0.5\nI1 = 0.3\nI3 = 0.5",
        initial="gamma = [0.0, 0.6, 0.8]\nomega = [1.4, 0.0, 0.3]",
        integration="t_end = 4.0",
    )
    (tmp_path / "s.toml").write_text(text)
    code, out, err = run_cli(capsys, "simulate", str(tmp_path / "s.toml"), "--json")
    assert code == 0
    assert json.loads(out)["reactions"]["contact_lost_at"] == pytest.approx(2.8305379, abs=1e-6)
    assert err.startswith("rollingtop: warning: the normal reaction turns negative at t = 2.83")


def test_simulate_model_projects_like_compare(capsys):
    """--model on a scenario whose free velocity belongs to another model: the state is
    projected as `compare` does, a note says by how much, stdout stays one JSON object."""
    from rollingtop import load_scenario
    from rollingtop.simulate import simulate_models

    paper = str(EXAMPLES / "paper.toml")
    code, out, err = run_cli(capsys, "simulate", paper, "--t-end", "0.5", "--model", "rough",
                             "--json")  # fmt: skip
    assert code == 0, err
    summary = json.loads(out)
    assert summary["model"] == "rough" and out.count("\n") == 1
    (note,) = err.splitlines()
    assert re.fullmatch(
        r"rollingtop: note: initial state projected onto the rough model's constraints "
        r"\(velocities changed by \|dv\| = [0-9.e+-]+, \|d omega\| = [0-9.e+-]+\)",
        note,
    ), note
    sc = load_scenario(paper).with_overrides(t_end=0.5)
    expected = simulate_models(sc, models=("rough",))["rough"].summary()
    # the same projection and integration in both: exact equality is the claim
    assert summary["final"] == expected["final"]
    assert summary["integrals"]["energy"]["initial"] == expected["integrals"]["energy"]["initial"]
    # the scenario's own model: nothing to say
    code, out, err = run_cli(capsys, "simulate", paper, "--t-end", "0.1", "--model", "meridian")
    assert code == 0 and err == ""


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["simulate", "{paper}", "--samples", "1000000000000"], "needs about 931.3 TiB of memory"),
        (["simulate", "/dev/zero"], "not a regular file (it is a character device)"),
        (["simulate", "{fifo}"], "not a regular file (it is a FIFO)"),
        (["simulate", "{paper}", "--t-end", "z" * 5000], "'" + "z" * 80 + "…' is not a valid"),
        (["simulate", "{paper}", "--model", "z" * 5000], "unknown contact model 'zzz"),
        (["ensemble", "{paper}", "--grid", "omega3=1:2:2", "--samples", "10000000000"],
         "--grid (2 trajectories of 10000000000 samples) needs about 7.9 TiB of memory"),
        (["ensemble", "{paper}", "--grid", "omega3=1:3:100000,v_tau=0:1:100000"],
         "--grid (10000000000 trajectories) needs about 37.3 TiB of memory"),
        (["ensemble", "{paper}", "--initial", "{binary}"], "not UTF-8 text"),
        (["ensemble", "{paper}", "--initial", "{fifo}"], "not a regular file (it is a FIFO)"),
        (["ensemble", "{paper}", "--initial", "{inf}"], "'1e400' is not a finite number"),
        (["path", "{paper}", "-o", "{tmp}/p.png", "--periods", "inf"], "--periods inf must lie"),
        (["animate", "{paper}", "-o", "{tmp}/a.gif", "--duration", "1e9"], "more than 100000"),
        (["portrait", "{paper}", "-o", "{tmp}/p.png", "--h-levels", "1,nan"], "must be finite"),
        (["orbits", "{paper}", "--h", "inf"], "--h inf must be finite"),
    ],
)  # fmt: skip
def test_hostile_input_refused_in_one_line(tmp_path, capsys, args, message):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    (tmp_path / "binary.csv").write_bytes(b"\xff\xfeomega3\n\x80\n")
    (tmp_path / "inf.csv").write_text("omega3\n1e400\n")
    before = sorted(p.name for p in tmp_path.iterdir())
    names = dict(paper=EXAMPLES / "paper.toml", fifo=fifo, binary=tmp_path / "binary.csv",
                 inf=tmp_path / "inf.csv", tmp=tmp_path)  # fmt: skip
    code, out, err = run_cli(capsys, *[a.format(**names) for a in args])
    assert code == 2 and out == ""
    (line,) = err.splitlines()
    assert line.startswith("rollingtop: error: ") and message in line, line
    assert len(line) < 400
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_line_breaks_in_a_message_are_escaped(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(scenario_text() + '\n["a\\nb\\u2028c"]\nx = 1\n')
    code, _, err = run_cli(capsys, "simulate", str(tmp_path / "s.toml"))
    assert code == 2
    (line,) = err.splitlines()
    assert "unknown table ['a\\nb\\u2028c']" in line


def test_threads_above_the_cores_are_reduced_with_a_note(capsys):
    import numba

    cores = numba.config.NUMBA_NUM_THREADS
    code, out, err = run_cli(capsys, "ensemble", str(EXAMPLES / "paper.toml"), "--grid",
                             "omega3=1:2:2", "--t-end", "0.01", "--threads", str(cores + 7),
                             "--json")  # fmt: skip
    assert code == 0
    assert json.loads(out)["threads"] == cores
    assert err == (
        f"rollingtop: note: --threads {cores + 7} is more than the {cores} cores available; "
        f"used {cores}\n"
    )


class RecordingBar:
    """Stands in for the rich progress bar that compare shows on a terminal."""

    def __init__(self, label):
        self.label, self.tasks, self.updates = label, [], []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return None

    def add_task(self, description, total):
        self.tasks.append((description, total))
        return len(self.tasks) - 1

    def update(self, task, completed):
        self.updates.append((task, completed))


def test_compare_progress_bar_follows_each_model(tmp_path, capsys, monkeypatch):
    """On a terminal, compare shows one bar per model, each rising from 0 to t_end (it used to
    show one bar of t_end that never moved: the progress callback was dropped)."""
    from rollingtop.cli import _output
    from rollingtop.contact import MODELS

    bars = []
    monkeypatch.setattr(_output, "progress_bar", lambda label: bars.append(RecordingBar(label))
                        or bars[-1])  # fmt: skip
    code, out, err = run_cli(capsys, "compare", str(EXAMPLES / "paper.toml"), "-o",
                             str(tmp_path / "c.png"), "--t-end", "0.5")  # fmt: skip
    assert code == 0, err
    (bar,) = bars
    assert "{task.description}" in bar.label
    takes_it = [name for name, m in MODELS.items() if not m.own_inertia]  # no shell: not the pair
    assert bar.tasks == [(name, 0.5) for name in takes_it]
    for task in range(len(takes_it)):
        done = [t for k, t in bar.updates if k == task]
        assert done and done == sorted(done) and done[-1] == 0.5


def test_bare_command_prints_help(capsys):
    code, out, err = run_cli(capsys)
    # click >= 8.4.2 writes [COMMAND] for a group that runs without one
    assert code == 0 and err == ""
    assert re.match(r"Usage: rollingtop \[OPTIONS\] \[?COMMAND\]?", out)
    assert "warmup" in out and "simulate" in out


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--frobnicate"], "No such option '--frobnicate'"),
        (["frob"], "No such command 'frob'"),
        (["simulate"], "Missing argument 'SCENARIO'"),
        (["verify", "--model", "ice"], "unknown contact model 'ice' (known: meridian, smooth"),
    ],
)
def test_usage_errors_are_one_line(capsys, args, message):
    code, out, err = run_cli(capsys, *args)
    assert code == 2 and out == ""
    assert err.splitlines() == [f"rollingtop: error: {err.split('error: ', 1)[1].rstrip()}"]
    assert message in err


def test_model_choices_come_from_the_registry(capsys):
    from rollingtop.contact import MODELS

    code, out, _ = run_cli(capsys, "simulate", "--help")
    assert code == 0 and f"[{'|'.join(MODELS)}]" in out


def test_simulate_relates_the_level_h_to_the_energy(capsys):
    """Fig. 5's scenario gives [level] h = 4: the report prints h beside the energy it implies,
    E = h + M3^2/(2 I3) + m g R = 4 + 1 + 1 = 6 (docs/model.md), which the integrated energy
    integral confirms; a level of the initial state is labelled so; the rough model's level is
    its own; a model without a reduction has none."""
    fig5 = str(EXAMPLES / "fig5.toml")
    code, out, err = run_cli(capsys, "simulate", fig5, "--t-end", "0.5")
    assert code == 0, err
    assert ("level of [level]: h = 4 (M3 = 1, C1 = 0.5, C2 = -2); energy = h + M3^2/(2 I3) "
            "+ m g R = 4 + 1 + 1 = 6") in out.splitlines()  # fmt: skip
    code, out, err = run_cli(capsys, "simulate", fig5, "--t-end", "0.5", "--json")
    summary = json.loads(out)
    # M3, C1, C2, h: copied from the file; the energy and its terms: computed
    assert summary["level"] == {"M3": 1.0, "C1": 0.5, "C2": -2.0, "h": 4.0,
                                "energy": pytest.approx(6.0, rel=LEVEL_RTOL),
                                "energy_formula": "h + M3^2/(2 I3) + m g R",
                                "spin_energy": pytest.approx(1.0, rel=LEVEL_RTOL),
                                "mgR": pytest.approx(1.0, rel=LEVEL_RTOL),
                                "source": "[level]"}  # fmt: skip
    assert summary["integrals"]["energy"]["initial"] == pytest.approx(6.0, abs=1e-12)
    code, out, err = run_cli(capsys, "simulate", str(EXAMPLES / "paper.toml"), "--t-end", "0.5",
                             "--json")  # fmt: skip
    level = json.loads(out)["level"]
    assert level["source"] == "initial state" and level["h"] == pytest.approx(0.4849, abs=1e-12)
    assert level["energy"] == pytest.approx(json.loads(out)["integrals"]["energy"]["initial"],
                                             abs=1e-12)  # fmt: skip
    # the rough model's own level (jellett, routh) and its energy, E = h + m g R
    code, out, err = run_cli(capsys, "simulate", str(EXAMPLES / "rough.toml"), "--t-end", "0.5",
                             "--json")  # fmt: skip
    level = json.loads(out)["level"]
    assert {"jellett", "routh"} <= set(level) and level["energy_formula"] == "h + m g R"
    assert level["energy"] == pytest.approx(json.loads(out)["integrals"]["energy"]["initial"],
                                             abs=1e-12)  # fmt: skip
    code, out, err = run_cli(capsys, "simulate", str(EXAMPLES / "parallel.toml"), "--t-end",
                             "0.5", "--json")  # fmt: skip
    assert code == 0 and "level" not in json.loads(out)


def test_verify_table_fits_100_columns_when_piped(capsys, monkeypatch):
    """Piped (capsys is no terminal), the verify table is at most 100 columns wide (it was
    about 160): the long claims wrap, the methods are shortened and explained below it."""
    import rollingtop.symbolic
    from rollingtop.symbolic import ClaimResult

    results = [
        ClaimResult("reduced system (3.3): gamma3' follows from the full equations", "meridian",
                    "proved", "exact simplification", 0.01),
        ClaimResult("pair's system for (u', lambda) regular: det = I3 rho_pair N (I1 I3 m R^2 "
                    "s^2 rho at ms = Js = 0)", "shell-rotor", "proved",
                    "exact evaluation at 4 random rational points", 12.5),
        ClaimResult("lagrange integral not conserved", "rubber", "proved",
                    "exact evaluation: nonzero (-0.123457) at a random rational point", 0.2),
    ]  # fmt: skip
    monkeypatch.setattr(rollingtop.symbolic, "verify", lambda models, progress=None: results)
    code, out, err = run_cli(capsys, "verify")
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert max(len(line) for line in lines) == 100
    rows = [[cell.strip() for cell in line.split("│")[2:6]] for line in lines if "proved" in line]
    assert rows == [["meridian", "proved", "simplified", "0.01"],
                    ["shell-rotor", "proved", "4 random points", "12.50"],
                    ["rubber", "proved", "nonzero (-0.123457) at a point", "0.20"]]  # fmt: skip
    assert "N random points = evaluated in rational" in out
    code, out, err = run_cli(capsys, "verify", "--json")
    assert json.loads(out)["claims"][1]["method"] == "exact evaluation at 4 random rational points"
