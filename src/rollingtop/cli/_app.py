"""The ``rollingtop`` command group: errors reported in one place, signals handled, Python
warnings as one line each, help on a bare ``rollingtop``."""

from __future__ import annotations

from typing import Any

import click

from rollingtop._signals import handle_signals
from rollingtop.cli._compile_notice import compile_notices
from rollingtop.cli._errors import reported
from rollingtop.cli._output import warnings_as_lines
from rollingtop.io import published_on_success

__all__ = ["CommandLine", "cli"]


class CommandLine(click.Group):
    """A click group whose commands report every error they meet as one line
    (:func:`rollingtop.cli._errors.reported`) and stop cleanly on SIGINT or SIGTERM
    (:func:`rollingtop._signals.handle_signals`); the files a command writes appear only when it
    succeeds (:func:`rollingtop.io.published_on_success`)."""

    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        with reported():  # the group's own options
            return super().parse_args(ctx, args)

    def invoke(self, ctx: click.Context) -> Any:
        # a command: its options, then its run; its files appear only if it succeeds
        with reported(), handle_signals(), published_on_success():
            return super().invoke(ctx)


@click.group(
    cls=CommandLine,
    invoke_without_command=True,
    context_settings={"help_option_names": ["-h", "--help"]},
)
@click.version_option(package_name="rollingtop")
@click.pass_context
def cli(ctx: click.Context) -> None:
    """Rolling spherical tops under nonholonomic constraints (Kilin & Ivanova 2023)."""
    if ctx.invoked_subcommand is None:  # a bare ``rollingtop``: the help, on stdout
        click.echo(ctx.get_help())
        ctx.exit()
    ctx.with_resource(warnings_as_lines())
    ctx.with_resource(compile_notices())
