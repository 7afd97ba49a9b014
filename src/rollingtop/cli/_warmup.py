"""``rollingtop warmup``: compile the models' kernels once, so that later commands start fast."""

from __future__ import annotations

import json
import time

import click

from rollingtop.cli._options import json_option
from rollingtop.contact import MODELS

__all__ = ["warmup"]


@click.command()
@click.option(
    "--model",
    "models",
    multiple=True,
    type=click.Choice(list(MODELS)),
    help="A model to compile (repeat the option for several; default: every model).",
)
@click.option(
    "--processes",
    type=click.IntRange(min=1),
    default=None,
    help="Packages compiled at once, one process each (default: the CPUs).",
)
@json_option
def warmup(models: tuple[str, ...], processes: int | None, as_json: bool) -> None:
    """Compile each model's kernels once (or load them from numba's cache), one process per
    compiled package (a model's own kernel, its variants') in parallel, so that later commands
    start fast; print each model's seconds."""
    from rollingtop._warmup import warmup as compile_models

    names = list(models) or list(MODELS)
    start = time.perf_counter()
    click.echo(
        f"rollingtop: compiling the kernels of {len(names)} model"
        f"{'s' if len(names) != 1 else ''} ({', '.join(names)}), "
        "one process per compiled package, the longest first; cached kernels load in a second",
        err=True,
    )

    def report(name: str, seconds: dict[str, float]) -> None:
        if not as_json:
            click.echo(f"{name:<12} {sum(seconds.values()):8.2f} s", err=False)

    seconds = compile_models(names, processes=processes, progress=report)
    total = time.perf_counter() - start
    if as_json:
        out = {m: {**groups, "total_s": sum(groups.values())} for m, groups in seconds.items()}
        click.echo(json.dumps({"models": out, "total_s": total}))
        return
    click.echo(f"{'total':<12} {total:8.2f} s (wall)")
