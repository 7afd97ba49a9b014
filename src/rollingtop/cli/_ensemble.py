"""``rollingtop ensemble``: many initial states of one scenario's body and model, in parallel."""

from __future__ import annotations

import json
from typing import Any

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import atol_option, json_option, rtol_option, scenario_argument

__all__ = ["ensemble"]


def _print_summary(summary: dict[str, Any]) -> None:
    click.echo(
        f"{summary['n']} trajectories of the {summary['model']} model to t = {summary['t_end']:g} "
        f"on {summary['threads']} threads: {summary['wall_time_s']:.3f} s "
        f"({summary['trajectories_per_second']:.1f} per second, "
        f"+{summary['compile_time_s']:.2f} s compile/load), {summary['failed']} failed, "
        f"{summary['contact_lost']} lose contact"
    )
    for name, drift in summary["max_rel_drift"].items():
        absolute = summary["max_abs_drift"][name]
        rel = "-" if drift is None else f"{drift:.2e}"
        absolute = "-" if absolute is None else f"{absolute:.2e}"
        click.echo(f"  {name}: max |drift| {absolute}, relative to the largest value {rel}")


@click.command()
@scenario_argument
@click.option(
    "--initial",
    "initial_csv",
    type=click.Path(dir_okay=False),
    default=None,
    help="CSV of initial conditions: columns gamma1..3, omega1..3, alpha1..3, "
    "position1..2, v1..3, the model's free components (v_tau, v_nu, v_horizontal1..2) or "
    "theta; missing ones take the scenario's values.",
)
@click.option(
    "--grid",
    type=str,
    default=None,
    help="Cartesian grid instead of a file: 'omega3=1:3:20,v_tau=-0.5:0.5:50'.",
)
@click.option("-o", "--output", type=click.Path(), default=None, help="Write OUT.nc.")
@click.option("--t-end", type=float, default=None, help="End time (overrides the scenario).")
@rtol_option
@atol_option
@click.option(
    "--samples",
    type=click.IntRange(min=2),
    default=None,
    help="Keep this many samples per trajectory in OUT.nc (default: final states).",
)
@click.option(
    "--threads",
    type=click.IntRange(min=1),
    default=None,
    help="Threads (default: all cores; more than the cores are reduced to them, with a note).",
)
@json_option
def ensemble(
    scenario: str,
    initial_csv: str | None,
    grid: str | None,
    output: str | None,
    t_end: float | None,
    rtol: float | None,
    atol: float | None,
    samples: int | None,
    threads: int | None,
    as_json: bool,
) -> None:
    """Integrate many initial states in parallel (the scenario's body and model)."""
    from rollingtop.ensemble import ensemble_from_scenario, grid_table, read_table
    from rollingtop.io import check_output_path
    from rollingtop.scenario import load_scenario

    if (initial_csv is None) == (grid is None):
        raise BadInput("give exactly one of --initial FILE.csv and --grid SPEC")
    if output is not None:
        check_output_path(output, (".nc",))
    sc = load_scenario(scenario).with_overrides(t_end=t_end, rtol=rtol, atol=atol)
    if initial_csv is not None:
        columns = read_table(initial_csv)
    else:
        assert grid is not None  # one of the two, checked above
        columns = grid_table(grid, samples)
    n = len(next(iter(columns.values())))
    with _output.counting("ensemble", n) as progress:
        result = ensemble_from_scenario(
            sc, columns, progress=progress, samples=samples, threads=threads
        )
    if threads is not None and result.threads < threads:  # the library used the cores it has
        cores = result.threads
        _output.note(f"--threads {threads} is more than the {cores} cores available; used {cores}")
    if output is not None:
        result.to_netcdf(output)
    summary = result.summary()
    if as_json:
        click.echo(json.dumps(summary))
        return
    _print_summary(summary)
    if output is not None:
        click.echo(f"wrote {output}")
