"""``rollingtop compare-classification``: every reduced model's view of one body and one state,
side by side."""

from __future__ import annotations

import json

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import figure_output, json_option, scenario_argument

__all__ = ["compare_classification"]


@click.command("compare-classification")
@scenario_argument
@figure_output
@json_option
@click.option(
    "--points",
    type=int,
    default=121,
    show_default=True,
    help="Grid points of each model's critical values.",
)
def compare_classification(scenario: str, output: str, as_json: bool, points: int) -> None:
    """Each integrable model's classification of the scenario's motion, side by side.

    The body and the initial attitude and angular velocity come from the scenario's [initial]
    table (the scenario's own model keeps its whole state; the others get the centre of mass's
    velocity from their constraints, and rubber rolling drops omega's part along the normal).
    For each model with a reduction (meridian, smooth, rough, rubber): U(gamma3) and the
    state's energy, the phase portrait with the orbit through the state, and the critical
    values of the reduced energy along one integral of its level (the bifurcation set), the
    state's level marked. Prints each model's level, orbit and steady
    motions.
    """
    from rollingtop.io import check_output_path
    from rollingtop.plot import FIGURE_SUFFIXES, save_figure
    from rollingtop.plot.classification import classification_figure
    from rollingtop.reduction.classify import classify_models
    from rollingtop.scenario import load_scenario

    if not 3 <= points <= 2001:
        raise BadInput(f"--points {points}: must be between 3 and 2001")
    check_output_path(output, FIGURE_SUFFIXES)
    sc = load_scenario(scenario)
    if sc.initial is None:
        raise BadInput(
            "compare-classification needs an [initial] table (a state to start every model from)"
        )
    y0 = sc.require_state()
    own = (sc.model.name, y0) if sc.model.reduction else None
    refused: dict[str, str] = {}
    classes = classify_models(sc.body, y0[12:15], y0[3:6], n=points, own=own, refused=refused)
    if not classes:
        reasons = "; ".join(f"{k}: {v}" for k, v in refused.items())
        raise BadInput(f"compare-classification: no model reduces this state ({reasons})")
    save_figure(classification_figure(classes), output)
    if as_json:
        click.echo(json.dumps({"models": [c.to_dict() for c in classes], "refused": refused}))
        return
    for name, reason in refused.items():
        click.echo(f"{name}: not classified ({reason})", err=True)
    from rich.table import Table

    table = Table(title="the same body and state under each reduced model")
    for col in (
        "model",
        "level",
        "h",
        "gamma3_min",
        "gamma3_max",
        "period",
        "delta_psi",
        "steady motions",
    ):
        table.add_column(col, justify="left" if col in ("model", "level") else "right")
    for c in classes:
        o = c.orbit
        level = ", ".join(f"{k} = {v:.6g}" for k, v in c.level.values().items())
        kinds = ", ".join(f"{m.type} {m.gamma3:.4f}" for m in c.steady)
        dpsi = c.delta_psi
        table.add_row(
            c.model,
            level,
            f"{c.h:.6g}",
            *(
                ("-", "-", "-")
                if o is None
                else (f"{o.gamma3_min:.8g}", f"{o.gamma3_max:.8g}", f"{o.period:.10g}")
            ),
            "-" if dpsi is None else f"{dpsi:.8g}",
            kinds or "none",
        )
    _output.console().print(table)
    for c in classes:
        if c.note:
            click.echo(f"{c.model}: {c.note}")
    click.echo(f"wrote {output}")
