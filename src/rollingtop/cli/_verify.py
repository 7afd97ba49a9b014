"""``rollingtop verify``: the equations' claims, machine-checked with sympy."""

from __future__ import annotations

import json
import re
from typing import TYPE_CHECKING, Any

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


#: The paper's body: what ``verify --search`` searches without ``--body``.
PAPER_BODY = {"R": 1.0, "m": 1.0, "g": 1.0, "a3": 0.1, "I1": 0.3, "I3": 0.5}


def _search_table(result: Any) -> Table:
    from rich.table import Table

    body = ", ".join(f"{n} = {v}" for n, v in result.body)
    roots = ", ".join(f"{a:.6g}" for a in result.density_angles) or "none"
    table = Table(
        title=f"oblique family, {body}",
        caption=(
            f"a density of gamma3 alone: only where {result.obstruction.as_expr()} = 0 "
            f"(phi = {roots}), symbolically in t = tan(phi/2). Columns: upper bound / what the "
            "classical integrals account for (equal: nothing else in that class; density "
            "bound 0: none); coefficients any functions of gamma3"
        ),
    )
    for col in ("phi", "t", "density deg 0..N", "linear", "quadratic", "integrals"):
        table.add_column(col, no_wrap=col != "integrals")
    for a in result.angles:
        dens = [a.bounds[k] for k in sorted(a.bounds) if k.startswith("density")]
        table.add_row(
            f"{a.angle:.4f}",
            str(a.t),
            " ".join(map(str, dens)),
            f"{a.bounds['linear']} / {a.known['linear']}",
            f"{a.bounds['quadratic']} / {a.known['quadratic']}",
            ", ".join(a.integrals),
        )
    return table


def _search(bodies: tuple[str, ...], as_json: bool) -> None:
    """``verify --search``: :func:`rollingtop.symbolic.oblique_search.search` for each body."""
    from rollingtop.scenario import load_scenario
    from rollingtop.symbolic.oblique_search import DEFAULT_T, search

    chosen = []
    for path in bodies:
        body = load_scenario(path).body
        if body.I1 != body.I2 or body.has_shell:
            raise BadInput(
                f"{path}: the search needs a dynamically symmetric body (I1 = I2) without a shell"
            )
        chosen.append({k: getattr(body, k) for k in PAPER_BODY})
    results = []
    for values in chosen or [PAPER_BODY]:
        with _output.counting("angles searched", len(DEFAULT_T)) as progress:
            done = (lambda k: progress(k, len(DEFAULT_T))) if progress else None
            results.append(search(values, progress=done))
    if as_json:
        click.echo(json.dumps({"search": [r.to_dict() for r in results]}))
        return
    console = _output.console(piped_width=PIPED_WIDTH)
    for r in results:
        console.print(_search_table(r))


@click.command()
@click.option(
    "--model",
    "models",
    type=ModelChoice(),
    multiple=True,
    help="Model(s) to verify (default: all).",
)
@click.option(
    "--search",
    "search",
    is_flag=True,
    help="Search the oblique family (every constraint angle phi) for an invariant measure and "
    "integrals linear or quadratic in the velocities, instead of checking the claims.",
)
@click.option(
    "--body",
    "bodies",
    type=click.Path(exists=True, dir_okay=False),
    multiple=True,
    help="With --search: a scenario file whose [body] to search (repeatable; default: the "
    "paper's body).",
)
@json_option
@click.pass_context
def verify(
    ctx: click.Context,
    models: tuple[ContactModel, ...],
    search: bool,
    bodies: tuple[str, ...],
    as_json: bool,
) -> None:
    """Machine-check the equations' claims with sympy: first integrals, identities, the reduced
    system (3.3) and its invariant measure. With --search, search the oblique family for an
    invariant measure and integrals, by angle."""
    if bodies and not search:
        raise BadInput("--body is an option of --search")
    if search:
        if models:
            raise BadInput("--search searches the oblique family: leave out --model")
        _search(bodies, as_json)
        return
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
