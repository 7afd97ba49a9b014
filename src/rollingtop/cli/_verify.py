"""``rollingtop verify``: the equations' claims, machine-checked with sympy."""

from __future__ import annotations

import json

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import ModelChoice, json_option
from rollingtop.contact import MODELS, ContactModel

__all__ = ["verify"]

#: Exit status when a claim is not proved.
EXIT_FAILED = 1


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
    results = run_claims(tuple(m.name for m in models) or tuple(MODELS))
    if as_json:
        click.echo(json.dumps({"claims": [r.to_dict() for r in results]}))
    else:
        from rich.table import Table

        table = Table(title="rollingtop verify")
        for col in ("claim", "model", "result", "method", "time (s)"):
            table.add_column(col, justify="right" if col == "time (s)" else "left")
        for r in results:
            colour = "green" if r.result == "proved" else "red"
            table.add_row(
                r.name, r.model, f"[{colour}]{r.result}[/{colour}]", r.method, f"{r.seconds:.2f}"
            )
        _output.console().print(table)
    if any(r.result != "proved" for r in results):
        ctx.exit(EXIT_FAILED)
