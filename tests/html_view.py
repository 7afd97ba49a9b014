"""Reads back the notebook views (``_repr_html_``, :mod:`rollingtop._html`) with the standard
library's HTML parser, so that tests compare the values a view shows with values computed
otherwise: its title and subtitle, each section's tables (rows of cell texts, the header
first) and its lines of text."""

from dataclasses import dataclass, field
from html.parser import HTMLParser


@dataclass
class View:
    title: str = ""
    subtitle: str = ""
    #: (section name or "", rows): every table in order, under the section it follows.
    tables: list[tuple[str, list[list[str]]]] = field(default_factory=list)
    #: Lines of text outside the tables.
    texts: list[str] = field(default_factory=list)

    def table(self, section: str) -> list[list[str]]:
        """The rows of the one table under ``section``."""
        (rows,) = [rows for name, rows in self.tables if name == section]
        return rows

    def records(self, section: str) -> list[dict[str, str]]:
        """The rows of the table under ``section`` keyed by its header."""
        header, *rows = self.table(section)
        return [dict(zip(header, row, strict=True)) for row in rows]


class _Parser(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.view = View()
        self.section = ""
        self.what: str | None = None  # where the text goes: title, subtitle, section, text
        self.rows: list[list[str]] | None = None
        self.cell: list[str] | None = None
        self.text: list[str] = []

    def handle_starttag(self, tag, attrs):
        cls = dict(attrs).get("class", "")
        if tag == "style":
            self.what = "style"
        elif tag == "span" and cls in ("rt-title", "rt-sub"):
            self.what = cls
        elif tag == "div" and cls == "rt-section":
            self.what, self.text = "section", []
        elif tag == "div" and cls == "" and self.rows is None:
            self.what, self.text = "text", []
        elif tag == "table":
            self.rows = []
        elif tag == "tr" and self.rows is not None:
            self.rows.append([])
        elif tag in ("td", "th"):
            self.cell = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self.cell is not None:
            self.rows[-1].append("".join(self.cell).strip())
            self.cell = None
        elif tag == "table":
            self.view.tables.append((self.section, self.rows))
            self.rows, self.section = None, ""
        elif tag in ("span", "style"):
            self.what = None
        elif tag == "div" and self.what == "section":
            self.section, self.what = "".join(self.text).strip(), None
        elif tag == "div" and self.what == "text":
            if "".join(self.text).strip():
                self.view.texts.append("".join(self.text).strip())
            self.what = None

    def handle_data(self, data):
        if self.cell is not None:
            self.cell.append(data)
        elif self.what == "rt-title":
            self.view.title += data
        elif self.what == "rt-sub":
            self.view.subtitle += data
        elif self.what in ("section", "text"):
            self.text.append(data)


def read(html: str) -> View:
    """The view that ``html`` shows."""
    parser = _Parser()
    parser.feed(html)
    parser.close()
    return parser.view


def num(text: str) -> float:
    """A number as a view shows it (a dash: NaN)."""
    return float("nan") if text == "–" else float(text)
