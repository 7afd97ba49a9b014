"""The reduction's commands: ``equilibria``, ``orbits`` and ``portrait`` of a level set."""

from __future__ import annotations

import json
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import figure_output, json_option, scenario_argument

if TYPE_CHECKING:
    from rich.table import Table

    from rollingtop.reduction import SteadyMotion
    from rollingtop.reduction.level import Level
    from rollingtop.survey import OrbitSurvey

__all__ = ["equilibria", "orbits", "portrait"]


def _level_of(scenario: str) -> Level:
    """The level set of the scenario file: its ``[level]``, else its initial state's."""
    from rollingtop.scenario import load_scenario

    return load_scenario(scenario).level_set()


def _level_json(level: Level, **extra: float) -> dict[str, Any]:
    """The level's own integrals (:meth:`LevelSet.values`), its model and pole case."""
    return {**level.values(), "model": level.model, "pole": level.pole, **extra}


def _num(x: float | None) -> str:
    return "-" if x is None or x != x else f"{x:.7g}"


def _steady_table(level: Level, motions: Sequence[SteadyMotion]) -> Table:
    from rich.table import Table

    M3 = level.values().get("M3")
    spin = "" if M3 is None else f" (spin w3 = {M3 / level.body.I3:.7g})"
    table = Table(title=f"steady motions on {level.describe()}{spin}")
    cols = ("gamma3", "U", "type", "omega", "period", "psi'", "|v_CoM|", "CoM radius")
    for col in cols:
        table.add_column(col, justify="left" if col == "type" else "right")
    for m in motions:
        table.add_row(
            _num(m.gamma3),
            _num(m.U),
            m.type,
            _num(m.frequency),
            _num(m.period),
            _num(m.precession_rate),
            _num(m.com_speed),
            _num(m.com_radius),
        )
    return table


@click.command()
@scenario_argument
@json_option
def equilibria(scenario: str, as_json: bool) -> None:
    """Steady motions (critical points of U) on the scenario's level set, sorted by gamma3.

    The level set is the scenario's [level] table, else the one of its initial state.
    """
    from rollingtop.reduction import steady_motions

    level = _level_of(scenario)
    motions = steady_motions(level)
    if as_json:
        click.echo(
            json.dumps({"level": _level_json(level), "equilibria": [m.to_dict() for m in motions]})
        )
    else:
        _output.console().print(_steady_table(level, motions))


def _orbits_table(level: Level, h: float, survey: Sequence[OrbitSurvey]) -> Table:
    from rich.table import Table

    energy = level.full_energy(h)
    table = Table(title=f"orbits on {level.describe()}, h = {h:g} (energy {energy:g})")
    cols = (
        "gamma3_min",
        "gamma3_max",
        "period",
        "+-",
        "delta_psi",
        "motion",
        "circle / drift",
        "note",
    )
    for col in cols:
        table.add_column(col, justify="left" if col in ("motion", "note") else "right")
    for row in survey:
        o, pm, npl = row.orbit, row.period_map, row.near_pole
        if pm is None:
            extra = ("-", o.kind, "-")
        elif pm.motion == "bounded":
            cx, cy = pm.center or (math.nan, math.nan)
            extra = (
                f"{pm.delta_psi:.10g}",
                "bounded" + (" (near-resonant)" if pm.near_resonant else ""),
                f"r = {pm.radius:.6g} about ({cx:.4g}, {cy:.4g})",
            )
        elif pm.motion == "uniform drift":
            extra = (f"{pm.delta_psi:.10g}", "uniform drift", f"|v| = {pm.drift_speed:.6g}")
        else:
            vx, vy = pm.drift_velocity or (math.nan, math.nan)
            extra = (f"{pm.delta_psi:.10g}", "drifting", f"v = ({vx:.6g}, {vy:.6g})")
        table.add_row(
            f"{o.gamma3_min:.10g}",
            f"{o.gamma3_max:.10g}",
            f"{o.period:.12g}",
            f"{o.period_error:.1e}",
            *extra,
            "; ".join(x for x in (o.note, npl.note() if npl else "") if x),
        )
    return table


@click.command()
@scenario_argument
@click.option("--h", "h", type=float, default=None, help="Reduced energy h (overrides [level]).")
@json_option
def orbits(scenario: str, h: float | None, as_json: bool) -> None:
    """Orbits on the level set (M3, C1, C2, h): turning points and periods, sorted by gamma3_min."""
    from rollingtop.scenario import load_scenario
    from rollingtop.survey import survey_orbits

    if h is not None and not math.isfinite(h):
        raise BadInput(f"--h {h:g} must be finite")
    sc = load_scenario(scenario, level_h=h)  # --h replaces [level]'s h before it is checked
    level = sc.level_set()
    h = sc.level_h() if h is None else h
    survey = survey_orbits(level, h)
    if as_json:
        rows = [row.to_dict() for row in survey]
        energy = level.full_energy(h)
        click.echo(json.dumps({"level": _level_json(level, h=h, energy=energy), "orbits": rows}))
    else:
        _output.console().print(_orbits_table(level, h, survey))


def _h_levels(text: str) -> list[float]:
    from rollingtop._checks import short_repr

    try:
        levels = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise BadInput(f"--h-levels {short_repr(text)}: expected comma-separated numbers") from None
    if not levels:
        raise BadInput("--h-levels: no value given")
    if not all(math.isfinite(x) for x in levels):
        raise BadInput(f"--h-levels {short_repr(text)}: values must be finite")
    return levels


@click.command()
@scenario_argument
@figure_output
@click.option(
    "--h-levels",
    type=str,
    default=None,
    help="Comma-separated energies h of the orbits drawn (default: a spread from the minimum of "
    "U to above the saddles, plus the separatrices).",
)
@click.option("--no-contact", is_flag=True, help="Do not shade where the normal force is < 0.")
def portrait(scenario: str, output: str, h_levels: str | None, no_contact: bool) -> None:
    """Phase portrait (gamma3, w_tau) on the scenario's level set; prints the steady motions."""
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES, phase_portrait, save_figure
    from rollingtop.reduction import steady_motions

    check_output_path(output, FIGURE_SUFFIXES)
    levels = None if h_levels is None else _h_levels(h_levels)
    level = _level_of(scenario)
    save_figure(phase_portrait(level, levels, show_contact=not no_contact), output)
    _output.console().print(_steady_table(level, steady_motions(level)))
    click.echo(f"wrote {output}")
