"""``rollingtop periodic``: the relative periodic orbits on the level of the scenario's state
(:func:`rollingtop.chaos.periodic_orbits`)."""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any, TypeVar

import click

from rollingtop.cli import _output
from rollingtop.cli._options import json_option, scenario_argument

__all__ = ["find_orbits", "periodic", "seeding_options"]

F = TypeVar("F", bound=Callable[..., Any])


def seeding_options(func: F) -> F:
    """The options that seed the search for orbits (``periodic``, ``continue``)."""
    for option in reversed(_SEEDING):
        func = option(func)
    return func


_SEEDING = [
    click.option(
        "--returns",
        type=click.IntRange(1, 12),
        default=4,
        show_default=True,
        help="Largest number of section crossings per period sought.",
    ),
    click.option(
        "--trajectories",
        type=click.IntRange(1, 1000),
        default=16,
        show_default=True,
        help="Seeding trajectories sampled on the level (the scenario's state first).",
    ),
    click.option(
        "--settle",
        type=click.IntRange(3, 100_000),
        default=300,
        show_default=True,
        help="Crossings each seeding trajectory runs before its last ones seed Newton.",
    ),
    click.option(
        "--seed", type=click.IntRange(0), default=0, show_default=True, help="Sampling seed."
    ),
    click.option(
        "--grid-seeds",
        type=click.IntRange(0, 200),
        default=12,
        show_default=True,
        help="Also seed Newton from an N x N grid of the section plane on the level (orbits no "
        "trajectory settles onto; 0: none).",
    ),
]


def find_orbits(
    scenario: str, returns: int, trajectories: int, settle: int, seed: int, grid_seeds: int
) -> tuple[Any, Any]:
    """The scenario and the orbits on its level (:func:`rollingtop.chaos.periodic_orbits`);
    ``BadInput`` for a ``settle`` too short for ``returns``."""
    from rollingtop.chaos.periodic import periodic_orbits
    from rollingtop.cli._errors import BadInput
    from rollingtop.scenario import load_scenario

    if settle < 2 * returns + 1:
        raise BadInput(f"--settle {settle} must be at least 2 * --returns + 1 = {2 * returns + 1}")
    sc = load_scenario(scenario)
    found = periodic_orbits(
        sc.body,
        sc.model,
        sc.require_state(),
        returns=returns,
        trajectories=trajectories,
        settle=settle,
        seed=seed,
        grid=grid_seeds,
    )
    return sc, found


@click.command()
@scenario_argument
@seeding_options
@click.option(
    "-o", "--output", type=click.Path(), default=None, help="Also draw them: FIG.png, .svg, .pdf."
)
@json_option
def periodic(
    scenario: str,
    returns: int,
    trajectories: int,
    settle: int,
    seed: int,
    grid_seeds: int,
    output: str | None,
    as_json: bool,
) -> None:
    """Relative periodic orbits on the level of the scenario's state (its energy and the model's
    other integrals): fixed points of the Poincare section's map after 1 to --returns crossings,
    seeded by the section's trajectories, solved by Newton, with the section map's multipliers
    on the level and their type (attracting, repelling, saddle, elliptic, neutral); and the
    relative equilibria (gamma3 constant) of a model without a reduction, with their
    eigenvalues."""
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES

    if output is not None:
        check_output_path(output, FIGURE_SUFFIXES)
    _, found = find_orbits(scenario, returns, trajectories, settle, seed, grid_seeds)
    if output is not None:
        from rollingtop.plot.periodic import periodic_figure

        _output.write_figure_and_data(periodic_figure(found), output)
    if as_json:
        click.echo(json.dumps(found.to_dict()))
        return
    level = ", ".join(f"{k} = {v:.6g}" for k, v in found.level.items())
    click.echo(f"{len(found)} periodic orbits of the {found.model} model on the level {level}")
    rule = "".join(f", {k} = {v:g}" for k, v in found.parameters.items())
    for k, o in enumerate(found, 1):
        mu = ", ".join(f"{abs(m):.4g}" for m in o.multipliers) or "none on the level"
        flag = f" (through the vertical: depends on the model's rule there{rule})" * (
            o.through_vertical
        )
        click.echo(
            f"  {k}: {o.returns} returns, period {o.period:.10g}, {o.type} (|multipliers| {mu}, "
            f"{o.multipliers_from}, spread {o.multiplier_spread:.1g}), gamma3 = {o.x[0]:.6g}, "
            f"w_n = {o.x[1]:.6g}, closure {o.closure:.1g}{flag}"
        )
    for e in found.steady:
        ev = ", ".join(f"{v.real:.4g}{v.imag:+.4g}i" for v in e.eigenvalues)
        click.echo(
            f"  steady: gamma3 = {e.z[0]:.6g}, w_n = {e.z[2]:.6g}, w3 = {e.z[3]:.6g}, "
            f"{e.type} (eigenvalues {ev})"
        )
    if output is not None:
        click.echo(f"wrote {output}")
