"""``rollingtop verify``: the equations' claims, machine-checked with sympy."""

from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import ModelChoice, json_option
from rollingtop.contact import MODELS, ContactModel

if TYPE_CHECKING:
    from rich.table import Table

    from rollingtop.symbolic import ClaimResult

__all__ = ["verify"]

#: Exit status when a claim is not proved.
EXIT_FAILED = 1
#: Width of the table when stdout is not a terminal.
PIPED_WIDTH = 100


#: The methods' long names (:func:`rollingtop.symbolic.claims.decide`), shortened in the table.
_SHORT_METHODS = (
    (re.compile(r"^exact simplification$"), "simplified"),
    (re.compile(r"^exact evaluation at (\d+) random rational points$"), r"\1 random points"),
    (re.compile(r"^exact evaluation: (.*) at a random rational point$"), r"\1 at a point"),
)
#: Below the table: what the short methods stand for (``--json`` gives the long names).
CAPTION = (
    "every method is exact: simplified = cancelled to zero; N random points = evaluated "
    "in rational arithmetic at N random rational points; nonzero at a point = a rational "
    "counterexample"
)


def _short_method(method: str) -> str:
    """``method`` in a few words (``exact evaluation at 4 random rational points``:
    ``4 random points``); a method not known here unchanged."""
    for pattern, short in _SHORT_METHODS:
        if pattern.match(method):
            return pattern.sub(short, method)
    return method


def _table(results: list[ClaimResult]) -> Table:
    """The claims' table: the claim wraps (at word boundaries), the other columns do not."""
    from rich.table import Table

    table = Table(title="rollingtop verify", caption=CAPTION)
    table.add_column("claim")
    for col in ("model", "result", "method"):
        table.add_column(col, no_wrap=True)
    table.add_column("time (s)", justify="right", no_wrap=True)
    for r in results:
        colour = "green" if r.result == "proved" else "red"
        table.add_row(
            r.name,
            r.model,
            f"[{colour}]{r.result}[/{colour}]",
            _short_method(r.method),
            f"{r.seconds:.2f}",
        )
    return table


@click.command()
@click.option(
    "--model",
    "models",
    type=ModelChoice(),
    multiple=True,
    help="Model(s) to verify (default: all).",
)
@json_option
@click.pass_context
def verify(ctx: click.Context, models: tuple[ContactModel, ...], as_json: bool) -> None:
    """Machine-check the equations' claims with sympy: first integrals, identities, the reduced
    system (3.3) and its invariant measure."""
    try:
        from rollingtop.symbolic import verify as run_claims
    except ImportError as exc:  # pragma: no cover - sympy missing
        raise BadInput(f"verify needs sympy ({exc}): pip install rollingtop[symbolic]") from None
    with _output.counting("claims decided", None) as progress:
        results = run_claims(tuple(m.name for m in models) or tuple(MODELS), progress=progress)
    if as_json:
        click.echo(json.dumps({"claims": [r.to_dict() for r in results]}))
    else:
        _output.console(piped_width=PIPED_WIDTH).print(_table(results))
    if any(r.result != "proved" for r in results):
        ctx.exit(EXIT_FAILED)
