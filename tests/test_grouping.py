"""The suite's own assumption about pytest-xdist: under ``--dist loadgroup`` the tests of one
``xdist_group`` run on one worker. Modules whose fixtures are expensive (periodic orbits, the
notebook tour, the chaos atlas) share them through a group; pytest 9.2's structured node ids
broke that silently (pytest-dev/pytest-xdist#1386), each split module then computed its fixture
on both workers. A real pytest process on a small module, as the README's test command runs."""

import json
import os
import subprocess
import sys

MODULE = """
import os
import pytest

pytestmark = pytest.mark.xdist_group("one")


@pytest.mark.parametrize("i", range(8))
def test_where(i):
    folder = os.environ["GROUPING_OUT"]
    with open(os.path.join(folder, f"ran-{i}"), "w") as fh:
        fh.write(os.environ["PYTEST_XDIST_WORKER"])
"""


def test_a_group_runs_on_one_worker(tmp_path):
    (tmp_path / "test_grouped.py").write_text(MODULE)
    base = tmp_path / "base"
    proc = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-n", "2", "--dist", "loadgroup", "-p",
         "no:cacheprovider", "--basetemp", str(base), "test_grouped.py"],
        cwd=tmp_path, capture_output=True, text=True, timeout=300,
        env=os.environ | {"GROUPING_OUT": str(tmp_path)},
    )  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    workers = {p.name: p.read_text() for p in tmp_path.glob("ran-*")}
    assert len(workers) == 8, json.dumps(workers)
    assert len(set(workers.values())) == 1, workers
