"""rollingtop._compiled: the packages by kernel code, and the announcement of a compilation."""

import numpy as np
import pytest
from numba import njit

from rollingtop import _compiled
from rollingtop.cli._compile_notice import CommandLineNotifier
from rollingtop.contact import KERNELS, MODELS


def test_every_kernel_code_has_one_package_and_the_packages_cover_the_registry():
    seen = []
    for group in _compiled.GROUPS:
        assert _compiled.for_code(group.codes[0]).PACKAGE == group.package
        assert _compiled.for_code(group.codes[0])._dispatch.CODES == group.codes
        seen += group.codes
    assert sorted(seen) == [k.code for k in KERNELS]
    for name, model in MODELS.items():
        assert _compiled.for_model(name).PACKAGE == _compiled.group_of(model.code).package
        assert [p.MODEL for p in _compiled.packages_of(name)] == [name] * len(
            {_compiled.group_of(k.code).package for k in model.kernels}
        )
    with pytest.raises(ValueError, match="unknown kernel code 99"):
        _compiled.for_code(99)


def test_by_package_groups_indices_in_order_of_first_appearance():
    meridian = MODELS["meridian"]
    south = meridian.kernels[1].code
    codes = [south, meridian.code, MODELS["rough"].code, meridian.code, south]
    got = [(k.PACKAGE, idx.tolist()) for k, idx in _compiled.by_package(codes)]
    assert got == [("meridian_variants", [0, 4]), ("meridian", [1, 3]), ("rough", [2])]
    assert _compiled.by_package(np.zeros(0, dtype=np.int64)) == []


class Recorder:
    def __init__(self):
        self.events = []

    def start(self, message, first):
        self.events.append(("start", message, first))

    def step(self, function, seconds):
        self.events.append(("step", function))

    def done(self, seconds):
        self.events.append(("done",))


@pytest.fixture
def recorder():
    rec = Recorder()
    previous = _compiled.set_notifier(rec)
    yield rec
    _compiled.set_notifier(previous)


def test_a_compilation_is_announced_once_and_a_loaded_function_not_at_all(recorder):
    """Uncached functions compiled inside the block: the first block announces (first=True),
    a block with nothing to compile says nothing, a later compilation of the same package and
    group resumes without a second announcement."""

    @njit
    def f(x):
        return x + 1

    @njit
    def g(x):
        return 2 * x

    with _compiled.compiling("smooth", "test-group"):
        assert f(1) == 2
    starts = [e for e in recorder.events if e[0] == "start"]
    assert starts == [("start", _compiled.message("the smooth model's", "test-group"), True)]
    assert "compiling the smooth model's test-group kernels (first run only" in starts[0][1]
    assert ("step", "test_a_compilation_is_announced_once_and_a_loaded_function_not_at_all"
            ".<locals>.f") in recorder.events  # fmt: skip
    assert recorder.events[-1] == ("done",)
    recorder.events.clear()
    with _compiled.compiling("smooth", "test-group"):
        assert f(2) == 3  # compiled already: nothing to say
    assert recorder.events == []
    with _compiled.compiling(_compiled.for_model("smooth"), "test-group"):
        assert g(2) == 4
    assert recorder.events[0][0] == "start" and recorder.events[0][2] is False


def test_the_command_line_prints_the_first_announcement_only(capsys):
    notifier = CommandLineNotifier()
    notifier.start("compiling the rough model's integrator kernels (first run only)", True)
    notifier.step("run", 1.0)
    notifier.done(2.0)
    notifier.start("compiling the rough model's integrator kernels (first run only)", False)
    notifier.done(1.0)
    out, err = capsys.readouterr()
    assert out == ""
    assert err == "rollingtop: compiling the rough model's integrator kernels (first run only)\n"


def test_the_estimate_and_the_variants_label():
    """The estimates are the measured ones (benchmarks/compile_estimates.py writes them), one
    for every group the library announces."""
    assert set(_compiled.ESTIMATES) == {"dynamics", "integrator", "held integrator",
                                        "event integrator", "chaos"}  # fmt: skip
    assert all(0.0 < s < 600.0 for s in _compiled.ESTIMATES.values())
    about = f"about {_compiled.ESTIMATES['integrator']:.0f} s"
    assert about in _compiled.message("meridian", "integrator")
    label = _compiled.group_of(MODELS["meridian"].kernels[1].code).label
    assert label == "the meridian model's variants (south, north)"


def test_the_variants_package_runs_each_pole_variant_by_its_code():
    """south and north differ only in their carried direction's rate: the variant read from the
    code must be the right one (an offset error would swap them). The rate, written here from
    the meridian model's docstring: south M3 / (I1 (1 + gamma3)), north -M3 / (I1 (1 - gamma3))."""
    from rollingtop._compiled._kernel import new_workspace
    from rollingtop.body import SphericalTop

    meridian = MODELS["meridian"]
    body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)
    y = np.zeros(18)
    c, s = np.cos(0.4), np.sin(0.4)
    y[6:15] = (1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)  # gamma = (0, s, c)
    y[3:6] = (0.2, -0.1, 1.7)
    M3, g3 = body.I3 * y[5], y[14]
    expected = {"south": M3 / (body.I1 * (1 + g3)), "north": -M3 / (body.I1 * (1 - g3))}
    for kernel in meridian.kernels[1:]:
        dy = np.zeros(18)
        dynamics = _compiled.for_code(kernel.code).dynamics
        dynamics.rhs(kernel.code, body.params, y.copy(), dy, new_workspace())
        assert dy[17] == pytest.approx(expected[kernel.variant], rel=1e-14)
