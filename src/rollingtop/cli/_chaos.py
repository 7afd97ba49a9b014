"""``rollingtop section`` (Poincare sections) and ``rollingtop chaos`` (Lyapunov exponent and
MEGNO), for the scenario's body, model and initial state."""

from __future__ import annotations

import json
import math
from typing import Any

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import (
    atol_option,
    figure_output,
    json_option,
    rtol_option,
    scenario_argument,
    t_end_option,
)

__all__ = ["chaos", "section"]


def _hold(value: str | None) -> list[str] | None:
    if value is None:
        return None
    names = [n.strip() for n in value.split(",") if n.strip()]
    if not names:
        raise BadInput(f"--hold {value!r}: give integral names separated by commas")
    return names


#: Trajectories named one by one when some stop early (``--json`` lists every one).
MAX_NAMED = 10


def _count(n: int, one: str, many: str) -> str:
    """``1 trajectory``, ``2 trajectories``."""
    return f"{n} {one if n == 1 else many}"


def _stopped_lines(stopped: list[dict[str, Any]], crossings: int) -> list[str]:
    """The lines naming the trajectories that stopped before ``crossings`` crossings
    (:func:`rollingtop.chaos.section.stopped_early`): a count, then one line each (index,
    initial values, crossings found, where and why it stopped), at most :data:`MAX_NAMED`."""
    if not stopped:
        return []

    def vec(x: list[float]) -> str:
        return "[" + ", ".join(f"{v:.6g}" for v in x) + "]"

    lines = [
        f"{_count(len(stopped), 'trajectory', 'trajectories')} stopped before "
        f"{_count(crossings, 'crossing', 'crossings')}:"
    ]
    for s in stopped[:MAX_NAMED]:
        found = _count(s["crossings"], "crossing", "crossings")
        lines.append(
            f"  trajectory {s['trajectory']} (gamma = {vec(s['gamma'])}, omega = "
            f"{vec(s['omega'])}): {found}, stopped at t = {s['t_last']:.6g}: "
            f"{s['reason']}"
        )
    if len(stopped) > MAX_NAMED:
        lines.append(f"  ... and {len(stopped) - MAX_NAMED} more (--json lists every one)")
    return lines


@click.command()
@scenario_argument
@figure_output
@click.option(
    "--crossings",
    type=int,
    default=1000,
    show_default=True,
    help="Crossings of the section per trajectory.",
)
@click.option(
    "--trajectories",
    type=int,
    default=16,
    show_default=True,
    help="Trajectories on the scenario's level (its own state first).",
)
@click.option(
    "--hold",
    default=None,
    metavar="NAMES",
    help="Integrals held on the level, comma-separated (default: all of the "
    "model's; the energy always).",
)
@click.option("--seed", type=int, default=0, show_default=True, help="Seed of the sampling.")
@click.option("--netcdf", type=click.Path(), default=None, help="Also write the crossings: OUT.nc.")
@click.option(
    "--t-max",
    type=click.FloatRange(min=0.0, min_open=True),
    default=None,
    help="Stop each trajectory at this time even with fewer crossings (motions that "
    "settle, e.g. onto a steady spin, cross no more).",
)
@click.option(
    "--max-gap-steps",
    type=click.IntRange(min=1),
    default=None,
    help="Stop a trajectory after this many accepted steps without a new crossing "
    "(default 100000: hundreds of turns of gamma3 at the default tolerance).",
)
@rtol_option
@atol_option
@json_option
def section(
    scenario: str,
    output: str,
    crossings: int,
    trajectories: int,
    hold: str | None,
    seed: int,
    netcdf: str | None,
    t_max: float | None,
    max_gap_steps: int | None,
    rtol: float | None,
    atol: float | None,
    as_json: bool,
) -> None:
    """Poincare section w_tau = 0 (upward: the minima of gamma3) in the plane (gamma3, w_n), of
    trajectories sampled on the level set of the scenario's initial state (same energy and
    other integrals of its model)."""
    from rollingtop.chaos import poincare_section, section_summary
    from rollingtop.chaos.section import MAX_GAP_STEPS
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES
    from rollingtop.scenario import load_scenario

    check_output_path(output, FIGURE_SUFFIXES)
    if netcdf is not None:
        check_output_path(netcdf, (".nc",))
    sc = load_scenario(scenario).with_overrides(rtol=rtol, atol=atol)
    y0 = sc.require_state()
    with _output.counting("crossings found", trajectories * crossings) as progress:
        ds = poincare_section(
            sc.body,
            sc.model,
            y0,
            crossings=crossings,
            trajectories=trajectories,
            hold=_hold(hold),
            seed=seed,
            t_max=math.inf if t_max is None else t_max,
            max_gap_steps=max_gap_steps or MAX_GAP_STEPS,
            rtol=sc.integration.rtol,
            atol=sc.integration.resolved_atol,
            progress=progress,
        )
    from rollingtop.plot.section import section_figure

    # the figure and the crossings, both or neither
    _output.write_figure_and_data(section_figure(ds), output, ds, netcdf)
    summary = section_summary(ds)
    if summary["contact_lost"]:
        click.echo(
            f"rollingtop: warning: {summary['contact_lost']} of {summary['trajectories']} "
            "trajectories need a negative normal force at some time (the body would leave "
            "the plane; the model keeps the contact): drawn with open circles",
            err=True,
        )
    if as_json:
        click.echo(json.dumps(summary))
        return
    found, K = summary["crossings_found"], summary["trajectories"]
    worst = summary["max_abs_w_tau"]
    click.echo(
        f"{found} crossings of {K} trajectories (model {summary['model']}, held: "
        f"{', '.join(summary['held'])})"
        + ("" if worst is None else f"; max |w_tau| at the crossings {worst:.2g}")
    )
    for line in _stopped_lines(summary["stopped_early"], crossings):
        click.echo(line)
    click.echo(f"wrote {output}" + ("" if netcdf is None else f" and {netcdf}"))


@click.command()
@scenario_argument
@t_end_option
@click.option(
    "--samples", type=int, default=1000, show_default=True, help="Sample times of the time series."
)
@click.option(
    "-o", "--output", type=click.Path(), default=None, help="Write the time series: OUT.nc."
)
@click.option(
    "--figure", type=click.Path(), default=None, help="Draw the time series: FIG.png, .svg or .pdf."
)
@click.option(
    "--phase-volume",
    "volume_samples",
    type=click.IntRange(min=2),
    default=None,
    metavar="N",
    help="Also the time average of the divergence of the vector field (phase-volume "
    "drift; 0 where a smooth invariant measure exists), sampled at N times.",
)
@rtol_option
@atol_option
@json_option
def chaos(
    scenario: str,
    t_end: float | None,
    samples: int,
    output: str | None,
    figure: str | None,
    volume_samples: int | None,
    rtol: float | None,
    atol: float | None,
    as_json: bool,
) -> None:
    """Maximal Lyapunov exponent and MEGNO along the scenario's motion, from its tangent
    dynamics: lambda(t_end) (-> 0 like ln t / t for quasi-periodic motion) and the mean MEGNO
    <Y>(t_end) (-> 2 for quasi-periodic motion, ~ lambda t / 2 for chaotic)."""
    from rollingtop.chaos import chaos_indicators
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES
    from rollingtop.scenario import load_scenario

    if output is not None:
        check_output_path(output, (".nc",))
    if figure is not None:
        check_output_path(figure, FIGURE_SUFFIXES)
    sc = load_scenario(scenario).with_overrides(t_end=t_end, rtol=rtol, atol=atol)
    opts = sc.integration
    with _output.status("chaos:") as show:
        if show is not None:
            show(f"tangent dynamics to t = {opts.t_end:g}")
        result = chaos_indicators(
            sc.body,
            sc.model,
            sc.require_state(),
            t_end=opts.t_end,
            samples=samples,
            rtol=opts.rtol,
            atol=opts.resolved_atol,
        )
    if output is not None:
        result.to_netcdf(output)
    if figure is not None:
        from rollingtop.plot import save_figure
        from rollingtop.plot.section import indicators_figure

        save_figure(indicators_figure(result), figure)
    summary = result.summary()
    if volume_samples is not None:
        from rollingtop.chaos.divergence import phase_volume

        with _output.status("phase volume:") as show:
            if show is not None:
                show(f"divergence at {volume_samples} times")
            volume = phase_volume(
                sc.body,
                sc.model,
                sc.require_state(),
                t_end=opts.t_end,
                samples=volume_samples,
                rtol=opts.rtol,
                atol=opts.resolved_atol,
            )
        summary["phase_volume"] = volume.summary()
    if as_json:
        click.echo(json.dumps(summary))
        return
    click.echo(
        f"model {summary['model']}, t = {summary['t_end']:g}: maximal Lyapunov exponent "
        f"{summary['lyapunov']:.6g}, mean MEGNO <Y> = {summary['megno']:.6g} "
        f"(Y = {summary['megno_instantaneous']:.6g}); {summary['steps']} steps"
    )
    if volume_samples is not None:
        click.echo(
            f"mean divergence (phase-volume drift) "
            f"{summary['phase_volume']['mean_divergence']:.6g} on a manifold of "
            f"dimension {summary['phase_volume']['dimension']}"
        )
    for path in (output, figure):
        if path is not None:
            click.echo(f"wrote {path}")
