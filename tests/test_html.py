"""The notebook views' building blocks (rollingtop._html): numbers, escaping, plurals."""

import math

from rollingtop._html import Num, block, count, number, row_table, table

from .html_view import read


def test_numbers_are_shown_to_their_digits_and_missing_ones_as_a_dash():
    assert number(math.pi) == "3.14159" and number(math.pi, 3) == "3.14"
    assert number(None) == number(math.nan) == "–"
    assert number(math.inf) == "inf" and number(-math.inf) == "-inf"
    assert number(True) == "yes" and number(False) == "no" and number(7) == "7"
    assert count(1, "centre") == "1 centre" and count(2, "branch", "branches") == "2 branches"


def test_text_is_escaped_and_tables_read_back():
    html = block("T <1>", "a & b", [("s", table(["x", "note"], [[Num(1 / 3, 2), "<b>"]])),
                                     ("r", row_table({"a": 1.5}))])  # fmt: skip
    assert "&lt;b&gt;" in html and "T &lt;1&gt;" in html and "a &amp; b" in html
    view = read(html)
    assert (view.title, view.subtitle) == ("T <1>", "a & b")
    assert view.table("s") == [["x", "note"], ["0.33", "<b>"]]
    assert view.records("r") == [{"a": "1.5"}]
