"""``rollingtop warmup``: compile every kernel once, so that later commands start fast."""

from __future__ import annotations

import json

import click

from rollingtop.cli import _output
from rollingtop.cli._options import json_option

__all__ = ["warmup"]


@click.command()
@json_option
def warmup(as_json: bool) -> None:
    """Compile every kernel once (or load it from numba's cache), so that later commands start
    fast; print the seconds each group of kernels took."""
    from rollingtop._warmup import warmup as compile_all

    with _output.status("compiling") as show:
        seconds = compile_all(progress=show)
    total = sum(seconds.values())
    if as_json:
        click.echo(json.dumps({"groups": seconds, "total_s": total}))
        return
    width = max(map(len, seconds), default=0)
    for name, s in seconds.items():
        click.echo(f"{name:<{width}}  {s:8.2f} s")
    click.echo(f"{'total':<{width}}  {total:8.2f} s")
