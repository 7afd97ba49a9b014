"""``rollingtop basins``: which attracting orbit each start of a grid on the level's section
reaches (:func:`rollingtop.basins.basin_map`), on Dask."""

from __future__ import annotations

import json

import click

from rollingtop.cli import _output
from rollingtop.cli._options import figure_output, json_option, scenario_argument

__all__ = ["basins"]


@click.command()
@scenario_argument
@figure_output
@click.option(
    "--grid",
    type=click.IntRange(2, 400),
    default=24,
    show_default=True,
    help="Grid points per axis of the section plane.",
)
@click.option(
    "--crossings",
    type=click.IntRange(1, 10**6),
    default=200,
    show_default=True,
    help="Crossings each start runs before it is labelled.",
)
@click.option(
    "--sheet",
    type=click.IntRange(0, 1),
    default=0,
    show_default=True,
    help="Which of the level's two states at a grid point (in order of the free "
    "velocity component).",
)
@click.option(
    "--workers",
    type=click.IntRange(1, 256),
    default=None,
    help="Worker processes of the embedded local Dask cluster (default: cores).",
)
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Run on an existing Dask cluster (tcp://host:port).",
)
@click.option(
    "--trajectories",
    type=click.IntRange(1, 1000),
    default=16,
    show_default=True,
    help="Trajectories whose settled crossings give the attractors (rollingtop periodic).",
)
@click.option(
    "--settle",
    type=click.IntRange(3, 100_000),
    default=300,
    show_default=True,
    help="Crossings those trajectories run first.",
)
@click.option("--netcdf", type=click.Path(), default=None, help="Also write the labels: OUT.nc.")
@json_option
def basins(
    scenario: str,
    output: str,
    grid: int,
    crossings: int,
    sheet: int,
    workers: int | None,
    scheduler: str | None,
    trajectories: int,
    settle: int,
    netcdf: str | None,
    as_json: bool,
) -> None:
    """Basins of attraction on the level of the scenario's state: each point of a grid on the
    Poincare section's plane (gamma3, w_n) starts on the level, runs --crossings crossings and
    is labelled by the attracting orbit (rollingtop periodic) it reaches."""
    import numpy as np

    from rollingtop.basins import LABELS, basin_map
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES
    from rollingtop.scenario import load_scenario

    check_output_path(output, FIGURE_SUFFIXES)
    if netcdf is not None:
        check_output_path(netcdf, (".nc",))
    sc = load_scenario(scenario)
    with _output.counting("starts labelled", grid * grid) as progress:
        ds = basin_map(
            sc.body,
            sc.model,
            sc.require_state(),
            grid=grid,
            crossings=crossings,
            sheet=sheet,
            workers=workers,
            scheduler=scheduler,
            trajectories=trajectories,
            settle=settle,
            progress=progress,
        )
    from rollingtop.plot.basins import basins_figure

    _output.write_figure_and_data(basins_figure(ds), output, ds, netcdf)  # both or neither
    label = ds["label"].values
    attractors = json.loads(ds.attrs["attractors"])
    counts = {str(k): int(np.sum(label == k)) for k in range(len(attractors))}
    counts |= {name: int(np.sum(label == code)) for code, name in LABELS.items()}
    summary = {
        "model": ds.attrs["model"],
        "level": {k[6:]: v for k, v in ds.attrs.items() if k.startswith("level_")},
        "grid": grid,
        "crossings": crossings,
        "sheet": sheet,
        "attractors": [{"returns": a["returns"], "period": a["period"]} for a in attractors],
        "counts": counts,
    }
    if as_json:
        click.echo(json.dumps(summary))
        return
    click.echo(f"{grid} x {grid} starts on the {summary['model']} level, sheet {sheet}:")
    for k, a in enumerate(attractors):
        returns = f"{a['returns']} return{'s' * (a['returns'] != 1)}"
        click.echo(
            f"  attractor {k + 1} ({returns}, period {a['period']:.6g}): {counts[str(k)]} starts"
        )
    for name in LABELS.values():
        click.echo(f"  {name}: {counts[name]}")
    click.echo(f"wrote {output}" + ("" if netcdf is None else f" and {netcdf}"))
