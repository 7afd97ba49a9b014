"""``rollingtop continue``: follow a relative periodic orbit of the scenario's level in a body
parameter or the energy (:func:`rollingtop.chaos.continue_orbit`)."""

from __future__ import annotations

import json
import math

import click

from rollingtop.chaos.continuation import PARAMETERS
from rollingtop.cli import _output
from rollingtop.cli._options import json_option, parse_range, scenario_argument
from rollingtop.cli._periodic import find_orbits, seeding_options

__all__ = ["continue_"]


def _check_own_value(scenario: str, param: str, bounds: tuple[float, float]) -> None:
    """``BadInput`` unless the range holds the scenario's own value of ``param`` (its body's, or
    its state's energy: the level the orbits lie on)."""
    from rollingtop.chaos.continuation import body_with
    from rollingtop.cli._errors import BadInput
    from rollingtop.dynamics.integrals import evaluate
    from rollingtop.scenario import load_scenario

    sc = load_scenario(scenario)
    if param == "energy":
        y = sc.require_state()
        own = float(evaluate(sc.body, y[None], ["energy"], model=sc.model)["energy"][0])
    else:
        own = float(getattr(body_with(sc.body, "energy", 0.0), param))
    if not bounds[0] <= own <= bounds[1]:
        raise BadInput(
            f"--range {bounds[0]:g},{bounds[1]:g} must hold the scenario's own {param} = {own:.6g}"
        )


@click.command("continue")
@scenario_argument
@click.option(
    "--orbit",
    "number",
    type=click.IntRange(1),
    required=True,
    help="The orbit to follow: its number in `rollingtop periodic`'s list (from 1).",
)
@click.option(
    "--param", type=click.Choice(PARAMETERS), required=True, help="The parameter to vary."
)
@click.option(
    "--range",
    "span",
    required=True,
    help="A,B: the parameter's range (it holds the scenario's own value).",
)
@click.option(
    "--points",
    type=click.IntRange(2, 10_000),
    default=40,
    show_default=True,
    help="Points at most each way.",
)
@click.option(
    "--step",
    type=click.FloatRange(min=0.0, min_open=True),
    default=None,
    help="First arclength step (default: a twentieth of the range); it adapts.",
)
@click.option(
    "--doubling/--no-doubling",
    default=True,
    show_default=True,
    help="Follow the doubled branch from the first period doubling.",
)
@seeding_options
@click.option(
    "-o", "--output", type=click.Path(), default=None, help="Also draw it: FIG.png, .svg, .pdf."
)
@json_option
def continue_(
    scenario: str,
    number: int,
    param: str,
    span: str,
    points: int,
    step: float | None,
    doubling: bool,
    returns: int,
    trajectories: int,
    settle: int,
    seed: int,
    grid_seeds: int,
    output: str | None,
    as_json: bool,
) -> None:
    """Follow orbit --orbit of `rollingtop periodic`'s list as --param goes over --range, by
    pseudo-arclength continuation with the level's integrals held (their unfolding parameters
    reported, 0 to round-off): the period and the multipliers along the branch, the folds,
    period doublings and Neimark-Sacker points located, and the doubled branch followed from
    the first period doubling."""
    from rollingtop.chaos.continuation import continue_orbit
    from rollingtop.cli._errors import BadInput
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES

    bounds = parse_range("--range", span)
    if bounds is None:  # pragma: no cover - click requires the option
        raise BadInput("--range is required")
    if output is not None:
        check_output_path(output, FIGURE_SUFFIXES)
    if step is not None and not math.isfinite(step):
        raise BadInput(f"--step {step!r} must be a finite positive number")
    _check_own_value(scenario, param, bounds)  # before the search for orbits (seconds)
    sc, found = find_orbits(scenario, returns, trajectories, settle, seed, grid_seeds)
    if number > len(found):
        raise BadInput(f"--orbit {number}: the level has {len(found)} orbits (rollingtop periodic)")
    branch = continue_orbit(
        sc.body,
        sc.model,
        found[number - 1],
        param=param,
        bounds=bounds,
        step=step,
        max_points=points,
        doubling=doubling,
    )
    if output is not None:
        from rollingtop.plot.continuation import branch_figure

        _output.write_figure_and_data(branch_figure(branch), output)
    if as_json:
        click.echo(json.dumps(branch.to_dict()))
        return
    lo = min(p.param for p in branch.points)
    hi = max(p.param for p in branch.points)
    click.echo(
        f"orbit {number} ({branch.returns} returns) of the {branch.model} model followed in "
        f"{param} from {lo:.6g} to {hi:.6g}: {len(branch.points)} points, largest unfolding "
        f"parameter {branch.max_unfolding:.1g}; stopped towards smaller {param}: "
        f"{branch.stopped[0]}, towards larger: {branch.stopped[1]}"
    )
    for br in (branch, branch.doubled):
        if br is None:
            continue
        if br is branch.doubled:
            click.echo(f"  the doubled branch ({br.returns} returns): {len(br.points)} points")
        for b in br.bifurcations:
            mu = ", ".join(f"{m.real:.6g}{m.imag:+.6g}i" for m in b.point.multipliers)
            where = "" if b.converged else ", not converged: the nearer end"
            click.echo(
                f"  {b.kind} at {param} = {b.point.param:.8g} (between {b.bracket[0]:.8g} and "
                f"{b.bracket[1]:.8g}{where}), period {b.point.period:.8g}, multipliers {mu}"
            )
    if branch.doubling:
        click.echo(f"  the doubled branch: {branch.doubling}")
    if output is not None:
        click.echo(f"wrote {output}")
