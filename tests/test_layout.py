"""The habits of the codebase that a test can hold: no module over MAX_LINES lines, and no
comparison of a contact model's name outside the contact package (each model has one home:
rollingtop.contact)."""

import re
from pathlib import Path

import rollingtop
from rollingtop.contact import MODELS

SRC = Path(rollingtop.__file__).parent
MAX_LINES = 400


def test_no_module_is_over_the_line_limit():
    long = {str(p.relative_to(SRC)): n for p in SRC.rglob("*.py")
            if (n := len(p.read_text().splitlines())) > MAX_LINES}  # fmt: skip
    assert not long, f"modules over {MAX_LINES} lines: {long}"


def test_no_model_name_is_compared_outside_the_contact_package():
    names = "|".join(re.escape(n) for n in MODELS)
    quoted = rf"""["']({names})["']"""
    compare = re.compile(rf"(==|!=|\bin)\s*[\(\[\{{]?\s*{quoted}|{quoted}\s*(==|!=|\bin\b)")
    found = []
    for p in SRC.rglob("*.py"):
        if "contact" in p.relative_to(SRC).parts[:1]:
            continue
        for k, line in enumerate(p.read_text().splitlines(), 1):
            if compare.search(line):
                found.append(f"{p.relative_to(SRC)}:{k}: {line.strip()}")
    assert not found, "model names compared outside rollingtop.contact:\n" + "\n".join(found)
