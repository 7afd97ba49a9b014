"""The numbers the docs state between a script's markers are the script's output for its saved
results: a hand edit of a block, or results saved without the blocks rewritten, fails here
(``docs/long_runs.py``, ``docs/passages.py``)."""

import importlib.util
import json
import sys

import pytest

from .conftest import ROOT


def _script(name):
    spec = importlib.util.spec_from_file_location(f"docs_{name}", ROOT / "docs" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    try:
        spec.loader.exec_module(module)
    finally:
        sys.modules.pop(spec.name, None)
    return module


def _between(path, start, end):
    text = path.read_text()
    assert text.count(start) == 1, f"{path}: no single block {start!r}"
    return start + text.split(start, 1)[1].split(end, 1)[0] + end


@pytest.mark.parametrize(
    ("name", "pages"),
    [
        ("long_runs", ("docs/guide/accuracy.md", "README.md")),
        ("passages", ("docs/guide/models.md",)),
    ],
)
def test_each_block_is_its_script_output_for_the_saved_results(name, pages):
    script = _script(name)
    results = json.loads((ROOT / "docs" / f"{name}.json").read_text())
    expected = script.block(results)
    for page in pages:
        assert _between(ROOT / page, script.START, script.END) == expected, page


def test_the_oblique_familys_blocks_are_their_scripts_output():
    """docs/oblique_search.py's table in the models guide, docs/oblique_map.py's table and
    answer on the oblique family's page, for their saved JSON."""
    search = _script("oblique_search")
    rows = json.loads((ROOT / "docs" / "oblique_search.json").read_text())
    models = ROOT / "docs" / "guide" / "models.md"
    assert _between(models, search.START, search.END) == search.block(rows)
    atlas = _script("oblique_map")
    data = json.loads((ROOT / "docs" / "oblique_map.json").read_text())
    page = ROOT / "docs" / "guide" / "oblique.md"
    assert _between(page, atlas.START, atlas.END) == atlas.block(data)
    assert _between(page, atlas.ANSWER_START, atlas.ANSWER_END) == atlas.answer_block(data)
