"""docs/tour.ipynb, the notebook tour of the paper, run as a user runs it (nbclient, in docs/, on
a kernel of this interpreter): no cell errs, each view and figure comes out, and the numbers it
shows are those the library gives here for the same level (about 10 s on 2 cores with numba's
cache warm)."""

import json
import sys

import nbformat
import pytest

from rollingtop import load_scenario
from rollingtop.reduction import orbits, steady_motions

from .conftest import EXAMPLES, ROOT
from .html_view import num, read

#: One pytest-xdist worker runs this module
#: (the tour is executed once, by a module fixture;
#: split over two workers, the fixture would run on each).
pytestmark = pytest.mark.xdist_group("notebook")

# the test extra's nbclient runs the tour on ipykernel's kernel
nbclient = pytest.importorskip("nbclient", reason="needs the test extra: nbclient, ipykernel")
pytest.importorskip("ipykernel", reason="needs the test extra: nbclient, ipykernel")

TOUR = ROOT / "docs" / "tour.ipynb"
#: Seconds any one cell may take (the whole tour: about 10).
CELL_TIMEOUT = 120


@pytest.fixture(scope="module")
def tour(tmp_path_factory):
    """The tour, executed on a kernel that runs this interpreter: a ``python3`` kernel spec of
    its own (first on JUPYTER_PATH) names ``sys.executable``, and a last cell reports the
    kernel's interpreter."""
    jupyter = tmp_path_factory.mktemp("jupyter")
    spec = jupyter / "kernels" / "python3"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "Python 3 (this interpreter)", "language": "python",
    }))  # fmt: skip
    nb = nbformat.read(TOUR, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell("import sys\nprint(sys.executable)"))
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("JUPYTER_PATH", str(jupyter))
        where = {"metadata": {"path": str(TOUR.parent)}}  # the tour's own folder, as Jupyter
        nbclient.NotebookClient(nb, kernel_name="python3", timeout=CELL_TIMEOUT,
                                resources=where).execute()  # fmt: skip
    return nb


def cell(nb, name):
    """The cell of the tour whose id is ``name``."""
    (found,) = [c for c in nb.cells if c.get("id") == name]
    return found


def html(nb, name):
    (out,) = [o for o in cell(nb, name).outputs if "text/html" in o.get("data", {})]
    return out["data"]["text/html"]


def test_the_tour_is_stored_clean():
    nb = nbformat.read(TOUR, as_version=4)
    nbformat.validate(nb)
    for c in nb.cells:
        if c.cell_type == "code":
            assert c.outputs == [] and c.execution_count is None


def test_the_tour_runs_on_this_interpreter_without_an_error(tour):
    *_, last = tour.cells
    assert [o["text"].strip() for o in last.outputs] == [sys.executable]
    for c in tour.cells:
        if c.cell_type == "code":
            assert all(o["output_type"] != "error" for o in c.outputs), c.source


def test_the_tour_shows_the_steady_motions_and_orbits_of_fig5(tour):
    """The counts and the period it shows are those of the library for examples/fig5.toml."""
    sc = load_scenario(EXAMPLES / "fig5.toml")
    level = sc.level_set()
    motions = steady_motions(level)
    assert len(motions) == 3
    view = read(html(tour, "steady-motions"))
    assert view.subtitle.startswith(f"{len(motions)} steady motions: 2 centres, 1 saddle")
    assert read(html(tour, "level")).texts[0].startswith(f"{len(motions)} steady motions")
    found = orbits(level, sc.level_h())
    view = read(html(tour, "orbits"))
    assert view.subtitle.startswith(f"{len(found)} orbits on {level.describe()}")
    shown = [num(row["period"]) for row in view.records("")]
    assert shown == pytest.approx([o.period for o in found], rel=1e-11)
    (printed,) = cell(tour, "period").outputs
    assert printed["text"].strip().endswith(f"{found[0].period:.12g}")


def test_the_tour_shows_the_trajectorys_drift_and_every_figure(tour):
    view = read(html(tour, "trajectory"))
    drift = {r["integral"]: num(r["max |I - I0| / size"])
             for r in view.records("first integrals along the samples")}  # fmt: skip
    assert set(drift) == {"energy", "lagrange", "jellett", "area", "F6"}
    assert max(drift.values()) < 1e-9  # rtol 1e-12 over t = 20
    assert read(html(tour, "diagram")).subtitle.endswith("1 fold, 4 regions")
    for name in ("level-plot", "steady-motions-plot", "orbits-plot", "diagram-plot",
                 "trajectory-plot", "models-plot", "atlas-plot"):  # fmt: skip
        assert any("image/png" in o.get("data", {}) for o in cell(tour, name).outputs), name
    models = [read(o["data"]["text/html"]) for o in cell(tour, "models").outputs]
    assert [v.texts[0].split(" model")[0] for v in models] == ["meridian", "smooth", "rough",
                                                               "rubber"]  # fmt: skip
