"""rollingtop._kernel_cache and the template's instances: a cached kernel never outlives a source
compiled into it, and never serves another model.

The edits are made in a copy of the source tree, run by real processes that share one cache
folder (``NUMBA_CACHE_DIR``), as a user who edits a model would run them. Each process compiles
only what its script calls: one model's right-hand side, or its plain stepper.
"""

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from rollingtop import _compiled, _kernel_cache
from rollingtop._compiled import _instances

from .conftest import COMPILE_LISTENER, ROOT, local_cluster

SRC = ROOT / "src"
#: The smooth model's state and step of examples/smooth.toml, by hand (no scenario parsing).
SCRIPT = (
    COMPILE_LISTENER
    + r"""
import numpy as np
from rollingtop import SphericalTop, initial_state
from rollingtop._compiled import for_model
from rollingtop._compiled._kernel import new_workspace
from rollingtop._jit import call

model, what = sys.argv[1], sys.argv[2]
body = SphericalTop(R=1.0, m=1.0, g=1.0, a3=0.1, I1=0.3, I3=0.5)
free = {"smooth": {"v_horizontal": (0.3, -0.2)}, "rough": {}, "meridian": {"v_tau": 0.25}}
y = initial_state(body, model, gamma=(0.0, 0.6, 0.8), omega=(0.7, -0.3, 2.0), free=free[model])
k = for_model(model)
out = {}
if what == "rhs":
    dy = np.zeros_like(y)
    call(k.dynamics.rhs, k._dispatch.CODES[0], body.params, y.copy(), dy, call(new_workspace))
    out["dy"] = dy.tolist()
else:
    from rollingtop.integrate.driver import integrate
    r = integrate(k._dispatch.CODES[0], body.params, y, np.linspace(0, 2, 3), rtol=1e-8,
                  atol=1e-10)
    out["steps"] = int(r.steps)
    out["y"] = r.y[-1].tolist()
out["compiled"] = compiled
print(json.dumps(out))
"""
)


def _copy_tree(tmp_path: Path) -> Path:
    """A copy of the package's sources, without any ``__pycache__``."""
    root = tmp_path / "src"
    shutil.copytree(SRC, root, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    return root


def _run(src: Path, cache: Path, model: str, what: str, extra_env=None) -> tuple[dict, str]:
    env = os.environ | {"NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(src)}
    env |= extra_env or {}
    proc = subprocess.run([sys.executable, "-c", SCRIPT, model, what], cwd=src.parent, env=env,
                          capture_output=True, text=True, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1]), proc.stderr


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert text.count(old) == 1, old
    path.write_text(text.replace(old, new))


def _ours(compiled: list[str], prefix: str) -> list[str]:
    return [name for name in compiled if name.startswith(prefix)]


def test_an_edit_of_a_model_recompiles_that_model_and_no_other(tmp_path):
    """The issue's experiment: a second process loads the smooth model's right-hand side from
    the cache without compiling anything; after the model's ``accel`` is made to zero the
    accelerations, a process with the same cache folder computes the edited physics (the
    linear and angular accelerations zero, the kinematics unchanged), recompiling the smooth
    model's kernels and none of rough's, whose entries the next process loads unchanged."""
    src, cache = _copy_tree(tmp_path), tmp_path / "cache"
    first, _ = _run(src, cache, "smooth", "rhs")
    assert _ours(first["compiled"], "rollingtop._compiled.smooth.dynamics.rhs")
    again, _ = _run(src, cache, "smooth", "rhs")
    # loaded machine code is the compiled code: the same numbers to the last bit (so are the
    # kinematics the edit leaves alone, and the rough model's entries below)
    assert again["compiled"] == [] and again["dy"] == first["dy"]
    rough, _ = _run(src, cache, "rough", "rhs")
    assert not _ours(rough["compiled"], "rollingtop._compiled.smooth")

    _edit(src / "rollingtop" / "contact" / "smooth.py",
          "    return rhs_contact(p, y, dy, ws, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)\n",
          "    n = rhs_contact(p, y, dy, ws, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)\n"
          "    for i in range(6):\n        dy[i] = 0.0\n    return n\n")  # fmt: skip
    edited, _ = _run(src, cache, "smooth", "rhs")
    assert _ours(edited["compiled"], "rollingtop._compiled.smooth.dynamics.rhs")
    before, after = np.array(first["dy"]), np.array(edited["dy"])
    assert np.max(np.abs(before[:6])) > 0.1 and np.all(after[:6] == 0.0)
    np.testing.assert_array_equal(after[6:15], before[6:15])  # gamma' = gamma x w etc.
    rough_again, _ = _run(src, cache, "rough", "rhs")
    assert rough_again["compiled"] == [] and rough_again["dy"] == rough["dy"]


@pytest.mark.slow
def test_an_edit_of_a_shared_module_recompiles_the_stepper(tmp_path):
    """The step-size controller's safety factor lives in a shared module (``_dop853.py``),
    compiled into every model's stepper: with the same cache folder, changing it changes the
    number of steps of the same run (and a second process loads the new result)."""
    src, cache = _copy_tree(tmp_path), tmp_path / "cache"
    first, _ = _run(src, cache, "smooth", "run")
    _edit(src / "rollingtop" / "_compiled" / "_dop853.py", "\nSAFETY = 0.9\n", "\nSAFETY = 0.5\n")
    edited, _ = _run(src, cache, "smooth", "run")
    assert _ours(edited["compiled"], "rollingtop._compiled.smooth.stepper.run")
    assert edited["steps"] > 1.3 * first["steps"], (first["steps"], edited["steps"])
    again, _ = _run(src, cache, "smooth", "run")
    assert again["compiled"] == [] and again["steps"] == edited["steps"]


def test_an_edit_of_a_compile_option_alone_recompiles(tmp_path):
    """A decorator's options (here ``nogil`` on the template's ``rhs``) change the machine code
    but neither a function's bytecode nor its module's digest: they are in each entry's key
    (``_kernel_cache.options_key``), so the edited kernel is compiled, not loaded."""
    src, cache = _copy_tree(tmp_path), tmp_path / "cache"
    first, _ = _run(src, cache, "smooth", "rhs")
    assert _ours(first["compiled"], "rollingtop._compiled.smooth.dynamics.rhs")
    _edit(src / "rollingtop" / "_compiled" / "_template" / "dynamics.py",
          "@kernel\ndef rhs(", "@compiled(nogil=True, _nrt=False)\ndef rhs(")  # fmt: skip
    edited, _ = _run(src, cache, "smooth", "rhs")
    assert "rollingtop._compiled.smooth.dynamics.rhs" in edited["compiled"]
    assert edited["dy"] == first["dy"]  # the same physics, compiled again
    again, _ = _run(src, cache, "smooth", "rhs")
    assert again["compiled"] == []


def test_the_options_key_is_the_same_in_every_process():
    """A set of options (``fastmath``) iterates in a per-process order: the key sorts it."""
    script = (
        "from rollingtop._kernel_cache import options_key\n"
        "print(options_key({'fastmath': {'contract', 'nnan', 'ninf', 'arcp'}, 'nogil': True}))\n"
    )
    keys = set()
    for seed in ("1", "2", "3"):
        env = os.environ | {"PYTHONHASHSEED": seed}
        proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env,
                              capture_output=True, text=True, timeout=120, check=True)  # fmt: skip
        keys.add(proc.stdout)
    assert len(keys) == 1, keys


def test_two_models_never_share_an_entry(tmp_path):
    """The template's ``rhs`` instantiated for two models has one file, name and line: with
    numba's own cache the second model would load the first's machine code. Here each module
    has a folder of its own and its own stamp, and the rough model's right-hand side computed
    after the smooth model's, in the same cache folder, is the one computed with an empty
    cache."""
    src = _copy_tree(tmp_path)
    alone, _ = _run(src, tmp_path / "alone", "rough", "rhs")
    shared = tmp_path / "shared"
    _run(src, shared, "smooth", "rhs")
    after, _ = _run(src, shared, "rough", "rhs")
    assert _ours(after["compiled"], "rollingtop._compiled.rough.dynamics.rhs")
    assert after["dy"] == alone["dy"]  # the same kernel on the same state: the same bits
    index = {p.parent.parent.name for p in (shared / "rollingtop").rglob("dynamics.rhs-*.nbi")}
    assert {"rollingtop._compiled.smooth.dynamics", "rollingtop._compiled.rough.dynamics"} <= index
    # data files are named by their key, not numbered from the index a process last read
    data = [p.name for p in (shared / "rollingtop").rglob("dynamics.rhs-*.nbc")]
    named = re.compile(r"dynamics\.rhs-\d+\.py\d+\.[0-9a-f]{16}\.nbc")
    assert data and all(named.fullmatch(n) for n in data), data


def test_a_fresh_process_imports_a_models_kernels_by_name(tmp_path):
    """A Dask worker (a real one, in its own process) imports an instantiated module by its
    name alone, as numba does when it rebuilds a cached function's environment, and runs it."""
    distributed = pytest.importorskip("distributed")
    name = "rollingtop._compiled.rough.dynamics"

    def rhs_by_name(module_name):
        import importlib

        import numpy as np

        from rollingtop._compiled._kernel import new_workspace
        from rollingtop._jit import call
        from rollingtop._layout import WARMUP_PARAMS

        dynamics = importlib.import_module(module_name)
        code = importlib.import_module(module_name.rsplit(".", 1)[0])._dispatch.CODES[0]
        y = np.zeros(18)
        y[6:15] = (1, 0, 0, 0, 0.8, -0.6, 0, 0.6, 0.8)
        y[3:6] = (0.1, 0.2, 0.3)
        dy = np.zeros(18)
        call(dynamics.rhs, code, np.array(WARMUP_PARAMS), y, dy, call(new_workspace))
        return dynamics.__file__, dy.tolist()

    with local_cluster(1, processes=True, local_directory=str(tmp_path)) as cluster:
        with distributed.Client(cluster) as client:
            file, dy = client.submit(rhs_by_name, name).result(timeout=300)
    assert Path(file) == _instances.TEMPLATE / "dynamics.py"
    assert rhs_by_name(name)[1] == pytest.approx(dy, rel=0, abs=0)  # the same kernel: exact


def test_an_unwritable_cache_folder_runs_with_one_notice(tmp_path):
    """``NUMBA_CACHE_DIR`` below a regular file cannot be made (even by root): the command
    still runs, caching in the next folder of numba's order, and says so in one line."""
    src, blocker = _copy_tree(tmp_path), tmp_path / "a-file"
    blocker.write_text("")
    env = os.environ | {"NUMBA_CACHE_DIR": str(blocker / "cache"), "PYTHONPATH": str(src)}
    cmd = [sys.executable, "-m", "rollingtop", "simulate", str(ROOT / "examples" / "smooth.toml"),
           "--t-end", "0.5", "--json"]  # fmt: skip
    proc = subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["t_end"] == 0.5
    notices = [line for line in proc.stderr.splitlines() if "cannot write" in line]
    assert len(notices) == 1, proc.stderr
    fallback = src / "rollingtop" / "__pycache__" / "kernels"
    assert str(blocker / "cache") in notices[0] and str(fallback) in notices[0]
    assert any(fallback.rglob("*.nbi"))


def test_no_writable_folder_compiles_without_a_cache_and_one_notice(tmp_path):
    """When no folder of numba's order can be written, the kernels compile in memory: the run
    succeeds, with one warning, and the compile notice says every run compiles."""
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    script = (
        "import warnings, numpy as np\n"
        "from pathlib import Path\n"
        "from rollingtop import _kernel_cache, _jit\n"
        f"_kernel_cache.candidates = lambda: [Path({str(blocker)!r}) / 'a', "
        f"Path({str(blocker)!r}) / 'b']\n"
        "with warnings.catch_warnings(record=True) as caught:\n"
        "    warnings.simplefilter('always')\n"
        "    from rollingtop._compiled import for_model, message\n"
        "    from rollingtop._compiled._kernel import new_workspace\n"
        "    from rollingtop._layout import WARMUP_PARAMS\n"
        "    k = for_model('rough')\n"
        "    y = np.zeros(18); y[6:15] = (1, 0, 0, 0, 0.8, -0.6, 0, 0.6, 0.8)\n"
        "    _jit.call(k.dynamics.rhs, k._dispatch.CODES[0], np.array(WARMUP_PARAMS), y,"
        " np.zeros(18), _jit.call(new_workspace))\n"
        "print(len(caught), caught[0].message)\n"
        "print(message('rough', 'integrator'))\n"
    )
    env = os.environ | {"NUMBA_CACHE_DIR": str(tmp_path / "unused")}
    proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env, capture_output=True,
                          text=True, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    first, second = proc.stdout.strip().splitlines()
    assert first.startswith("1 no folder for compiled kernels can be written")
    assert "every run compiles them" in second
    assert not (tmp_path / "unused").exists()


def test_first_writable_skips_what_cannot_be_made(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    root, failures = _kernel_cache.first_writable([blocker / "x", tmp_path / "ok"])
    assert root == tmp_path / "ok" and root.is_dir()
    assert [p for p, _ in failures] == [blocker / "x"]
    assert _kernel_cache.first_writable([blocker / "y"])[0] is None


def test_the_instances_keep_the_templates_lines_and_file():
    """Tracebacks, ``inspect`` and coverage point at the template: every instantiated module
    is compiled under the template's file name, from a text with the template's lines (changed
    within lines only), and its functions start on the template's lines."""
    for group in _compiled.GROUPS:
        for module in _instances.SUBMODULES:
            if module == "_dispatch":
                continue
            text, filename = _instances.module_source(group, module)
            template = Path(filename).read_text().splitlines()
            lines = text.splitlines()
            assert len(lines) == len(template)
            changed = [i for i, (a, b) in enumerate(zip(lines, template, strict=True)) if a != b]
            assert all("_template" in template[i] or "False" in template[i]
                       or "stepper import" in template[i] for i in changed)  # fmt: skip
    package = _compiled.for_model("smooth")
    run = package.stepper.run_rows
    func = getattr(run, "py_func", run)
    assert func.__code__.co_filename == str(_instances.TEMPLATE / "stepper.py")
    assert package.stepper_held.HELD and package.stepper_held.EVENTS
    assert package.stepper_events.EVENTS and not package.stepper_events.HELD
    assert not package.stepper.HELD and not package.stepper.EVENTS


def test_the_key_of_a_models_kernels_covers_its_sources_and_no_other_models():
    """The modules reached from the smooth model's stepper: the template's instances of its own
    package, the model's module and helpers, the shared compiled modules -- and no other
    model's; the keys of two models' instances differ."""
    from rollingtop import _jit

    _jit.load_numba()
    smooth = _compiled.for_model("smooth")
    reached = _kernel_cache.closure(smooth.stepper.__name__)
    assert {"rollingtop.contact.smooth", "rollingtop._compiled._dop853",
            "rollingtop._compiled.smooth._dispatch", "rollingtop._compiled.smooth.dynamics",
            "rollingtop._jit"} <= set(reached)  # fmt: skip
    others = {g.package for g in _compiled.GROUPS} - {"smooth"}
    assert not [m for m in reached if m.split(".")[-1] in others or
                (m.count(".") >= 3 and m.split(".")[2] in others)]  # fmt: skip
    rough = _compiled.for_model("rough")
    assert _kernel_cache.module_digest(smooth.stepper.__name__) != _kernel_cache.module_digest(
        rough.stepper.__name__
    )
    held = _kernel_cache.module_digest(smooth.stepper_held.__name__)
    assert held != _kernel_cache.module_digest(smooth.stepper.__name__)


def test_an_edit_after_the_import_does_not_stamp_the_old_code(tmp_path):
    """A long-lived process (a notebook, a worker) imports the smooth model, the file is then
    edited, and only then does the process compile: its entries are keyed on the code it
    compiled (read from memory), so a fresh process with the same cache folder compiles and
    runs the edited physics instead of loading the old machine code."""
    src, cache = _copy_tree(tmp_path), tmp_path / "cache"
    smooth = src / "rollingtop" / "contact" / "smooth.py"
    edited = smooth.read_text().replace(
        "    return rhs_contact(p, y, dy, ws, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)\n",
        "    n = rhs_contact(p, y, dy, ws, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)\n"
        "    for i in range(6):\n        dy[i] = 0.0\n    return n\n",
    )
    script = SCRIPT.replace(
        "model, what = sys.argv[1], sys.argv[2]",
        "model, what = sys.argv[1], sys.argv[2]\n"
        "import pathlib, rollingtop._compiled\n"
        "rollingtop._compiled.for_model(model)\n"
        f"pathlib.Path({str(smooth)!r}).write_text({edited!r})",
    )
    env = os.environ | {"NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(src)}
    proc = subprocess.run([sys.executable, "-c", script, "smooth", "rhs"], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    old = json.loads(proc.stdout.strip().splitlines()[-1])
    assert np.max(np.abs(np.array(old["dy"][:6]))) > 0.1  # the code it had imported
    new, _ = _run(src, cache, "smooth", "rhs")
    assert _ours(new["compiled"], "rollingtop._compiled.smooth.dynamics.rhs")
    assert np.all(np.array(new["dy"][:6]) == 0.0)


def test_the_key_is_the_same_in_every_process_and_ignores_line_numbers():
    """Two processes with different hash seeds compute the same digests (no set order, address
    or path in the key); a function moved down by a comment keeps its part of the key."""
    script = (
        "from rollingtop import _compiled, _jit, _kernel_cache as kc\n"
        "_jit.load_numba()\n"
        "k = _compiled.for_model('rough')\n"
        "print(kc.module_digest(k.stepper.__name__), kc.module_digest(k.chaos.__name__))\n"
    )
    digests = set()
    for seed in ("1", "2"):
        env = os.environ | {"PYTHONHASHSEED": seed}
        proc = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env,
                              capture_output=True, text=True, timeout=300)  # fmt: skip
        assert proc.returncode == 0, proc.stderr
        digests.add(proc.stdout.strip())
    assert len(digests) == 1
    text = 'def f(x):\n    "doc"\n    return x + len({"a", "b", "c"})\n'
    a, b = {}, {}
    exec(compile(text, "a.py", "exec"), a)
    exec(compile("# moved\n\n" + text, "b.py", "exec"), b)
    assert _kernel_cache._code(a["f"].__code__) == _kernel_cache._code(b["f"].__code__)


def test_a_models_key_reaches_the_flag_intrinsic_and_no_other_model():
    """numba intrinsics (the stop flag's atomic read, ``_flags.read_flag``) are followed to
    their module like dispatchers; the module's state (lists, dicts) is neither hashed nor
    followed, so the registry of every dispatcher does not pull other models in; a global
    replaced in a module changes its part of the key in the same process."""
    from rollingtop import _jit

    _jit.load_numba()
    _compiled.for_model("meridian")  # another model imported: never part of rough's key
    stepper = _compiled.for_model("rough").stepper  # its loop polls the stop flag
    reached = _kernel_cache.closure(stepper.__name__)
    assert "rollingtop._compiled._flags" in reached
    assert not [m for m in reached if "meridian" in m or "smooth" in m], reached
    from rollingtop._compiled import _dop853

    before = _kernel_cache.module_digest(stepper.__name__)
    saved = _dop853.SAFETY
    try:
        _dop853.SAFETY = 0.5
        assert _kernel_cache.module_digest(stepper.__name__) != before
    finally:
        _dop853.SAFETY = saved
    assert _kernel_cache.module_digest(stepper.__name__) == before


def test_old_versions_of_a_module_are_pruned(tmp_path):
    folder = tmp_path / "rollingtop._compiled.smooth.dynamics"
    for i in range(6):
        (folder / f"{i:016x}").mkdir(parents=True)
        os.utime(folder / f"{i:016x}", (1000 + i, 1000 + i))
    _kernel_cache.prune(folder, keep=3)
    assert sorted(p.name for p in folder.iterdir()) == [f"{i:016x}" for i in (3, 4, 5)]
