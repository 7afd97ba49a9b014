"""``rollingtop simulate``: one run of a scenario, its integrals, constraints and reactions."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

import click
import numpy as np

from rollingtop.cli import _output
from rollingtop.cli._errors import NotHeld
from rollingtop.cli._options import (
    ModelChoice,
    atol_option,
    json_option,
    rtol_option,
    scenario_argument,
    t_end_option,
)
from rollingtop.contact import ContactModel

if TYPE_CHECKING:
    from rich.table import Table

    from rollingtop.scenario import Scenario
    from rollingtop.trajectory import Trajectory

__all__ = ["run_scenario", "simulate"]


def run_scenario(sc: Scenario, **options: Any) -> Trajectory:
    """:func:`rollingtop.simulate` of ``sc`` with a progress bar on a terminal and its warnings
    as lines (``options``: those of :func:`rollingtop.simulate`)."""
    from rollingtop.contact import get_model
    from rollingtop.integrate.driver import compile_code
    from rollingtop.simulate import simulate as run

    compiled = 0.0
    if sc.y0 is not None and np.all(np.isfinite(sc.y0)):
        # compile before the bar, so that the compile notice has the terminal to itself; a
        # state the run then refuses (huge values) must not warn here first
        with np.errstate(all="ignore"):
            code = get_model(options.get("model") or sc.model).kernel_code(sc.body, sc.y0)
        held = options.get("project_integrals")
        held = sc.integration.project_integrals if held is None else held
        model = get_model(options.get("model") or sc.model)
        if not (held and model.own_inertia):  # else refused by the run, before any compiling
            compiled = compile_code(code, held=bool(held), events=options.get("events") is not None)
    with _output.timing(sc.integration.t_end) as progress:
        traj = _output.with_warnings_reported(lambda: run(sc, progress=progress, **options))
    # the compilation belongs to the run's statistics, wherever it happened
    traj.stats["compile_time_s"] = float(traj.stats.get("compile_time_s", 0.0)) + compiled
    return traj


def _compile_ahead(path: str, model: ContactModel | None) -> None:
    """On a cold first run, compile in two processes while the scenario's initial state is
    projected (:func:`rollingtop.integrate.driver.compile_ahead`, run just before that
    projection): for the scenario's model (or ``model``), its plain stepper, where the file has
    an initial state and does not hold its integrals by projection, and a helper may run."""
    import tomllib

    from rollingtop._compiled import group_of, run_before_projection
    from rollingtop.contact import DEFAULT_MODEL, get_model
    from rollingtop.integrate._compile_helper import may_fork
    from rollingtop.integrate.driver import compile_ahead
    from rollingtop.io import read_input_text
    from rollingtop.scenario import MAX_SCENARIO_BYTES

    if not may_fork():
        return
    try:  # read as load_scenario reads it: a device or a huge file is not read here either
        data = tomllib.loads(read_input_text(path, "scenario", MAX_SCENARIO_BYTES))
        if "initial" not in data or data.get("integration", {}).get("project_integrals"):
            return
        code = (model or get_model(data.get("contact", {}).get("model", DEFAULT_MODEL))).code
    except Exception:  # noqa: BLE001 - whatever is wrong, load_scenario says it in one line
        return
    run_before_projection(group_of(code).package, lambda: compile_ahead(code))


def _integrals_table(summary: dict[str, Any]) -> Table:
    from rich.table import Table

    table = Table(title=f"{summary['model']} model, t = 0 .. {summary['t_end']:g}")
    for col in ("integral", "initial", "final", "max |drift|", "relative"):
        table.add_column(col, justify="right" if col != "integral" else "left")
    for name, row in summary["integrals"].items():
        rel = row["max_rel_drift"]
        table.add_row(
            name,
            f"{row['initial']:.15g}",
            f"{row['final']:.15g}",
            f"{row['max_abs_drift']:.2e}",
            "-" if rel is None else f"{rel:.2e}",
        )
    return table


def _level_line(level: dict[str, Any]) -> str:
    """The level of the motion and the energy it implies
    (:meth:`rollingtop.scenario.Scenario.level_summary`), in one line."""
    where = "of [level]" if level["source"] == "[level]" else "of the initial state"
    skip = ("h", "energy", "energy_formula", "spin_energy", "mgR", "source")
    named = ", ".join(
        f"{k} = {v:.10g}" for k, v in level.items() if k not in skip and v is not None
    )
    h, mgR, energy = (f"{level[k]:.10g}" for k in ("h", "mgR", "energy"))
    terms = [h] + ([] if level["spin_energy"] is None else [f"{level['spin_energy']:.10g}"])
    return (
        f"level {where}: h = {h} ({named}); energy = {level['energy_formula']} = "
        f"{' + '.join([*terms, mgR])} = {energy}"
    )


def _print_report(summary: dict[str, Any]) -> None:
    console = _output.console()
    console.print(_integrals_table(summary))
    if "level" in summary:
        click.echo(_level_line(summary["level"]))
    c, r, s = summary["constraints"], summary["reactions"], summary["stats"]
    lost = r["contact_lost_at"]
    console.print(
        f"constraints: max |residual| {c['max_abs_residual']:.2e}, "
        f"orthonormality error {c['orthonormality_max_error']:.2e}\n"
        f"reactions: min normal force {r['min_normal_force']:.6g}, friction coefficient needed "
        f"{r['max_friction_ratio']:.6g}"
        + ("" if lost is None else f", CONTACT LOST at t = {lost:.6g}")
        + f"\nsteps {s['steps']} (+{s['rejected_steps']} rejected), {s['rhs_evals']} rhs "
        f"evaluations, {s['wall_time_s']:.3f} s (+{s['compile_time_s']:.2f} s compile/load)"
        + (
            ""
            if "projection_passes" not in s
            else f"\nprojection onto the integrals: {s['projection_passes']} passes, the energy "
            f"left for later at {s['projection_deferred']} steps (turning points)"
        ),
        highlight=False,
    )


@click.command()
@scenario_argument
@t_end_option
@rtol_option
@atol_option
@click.option("--samples", type=int, default=None, help="Number of output samples.")
@click.option(
    "--model",
    type=ModelChoice(),
    default=None,
    help="Contact model, overriding the scenario's (its state is projected onto the model's "
    "constraints).",
)
@click.option(
    "-o", "--output", type=click.Path(), default=None, help="Write samples to OUT.nc or OUT.csv."
)
@click.option(
    "--project-integrals",
    is_flag=True,
    default=None,
    help="Hold the model's integrals at their initial values by projection after "
    "every step ([integration] project_integrals).",
)
@json_option
def simulate(
    scenario: str,
    t_end: float | None,
    rtol: float | None,
    atol: float | None,
    samples: int | None,
    model: ContactModel | None,
    output: str | None,
    project_integrals: bool | None,
    as_json: bool,
) -> None:
    """Simulate SCENARIO.toml and print its integrals, constraints and reactions."""
    from rollingtop.io import check_output_path
    from rollingtop.scenario import load_scenario
    from rollingtop.simulate import switch_model
    from rollingtop.trajectory import OUTPUT_SUFFIXES

    if output is not None:
        check_output_path(output, OUTPUT_SUFFIXES)
    if not project_integrals:
        _compile_ahead(scenario, model)
    sc = load_scenario(scenario).with_overrides(
        t_end=t_end,
        rtol=rtol,
        atol=atol,
        samples=samples,
        project_integrals=project_integrals or None,
    )
    if model is not None and model is not sc.model:
        sc, change = switch_model(sc, model)
        dv, dw = math.hypot(*change[:3]), math.hypot(*change[3:])
        _output.note(
            f"initial state projected onto the {sc.model.name} model's constraints (velocities "
            f"changed by |dv| = {dv:.3g}, |d omega| = {dw:.3g})"
        )
    traj = run_scenario(sc)
    if output is not None:
        traj.save(output)
    summary = traj.summary()
    level = sc.level_summary()
    if level is not None:
        summary["level"] = level
    if as_json:
        click.echo(json.dumps(summary))
    else:
        _print_report(summary)
        if output is not None:
            click.echo(f"wrote {output}")
    held = summary.get("projection")
    if held is not None and not held["held"]:
        if held["max_rel_drift"] is None:
            row = summary["integrals"][held["worst"]]
            why = (
                f"drift {row['max_abs_drift']:.2e}, which cannot be measured against its "
                "natural size (beyond double precision)"
            )
        else:
            why = (
                f"drift {held['max_rel_drift']:.2e} of its natural size, above "
                f"{held['tolerance']:g}"
            )
        raise NotHeld(
            f"the projection did not hold {held['worst']}: {why}"
            + ("" if output is None else f" (written to {output} all the same)")
        )
