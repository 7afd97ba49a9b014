"""``rollingtop stability``: the stability of the vertical spins of a body under its model."""

from __future__ import annotations

import json
import math
from typing import Any

import click

from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import json_option, scenario_argument

__all__ = ["stability"]


def _pairs(values: Any) -> list[list[float]]:
    return [[float(z.real), float(z.imag)] for z in values]


@click.command()
@scenario_argument
@json_option
@click.option("--omega3", type=float, default=None,
              help="Also give the eigenvalues of the linearisation at this spin rate.")  # fmt: skip
def stability(scenario: str, as_json: bool, omega3: float | None) -> None:
    """Stability of the vertical spins (a pole on the plane, the axis vertical) of the scenario's
    body under its contact model: the spin rate above which each is linearly stable."""
    from rollingtop.dynamics.stability import vertical_spin_eigenvalues, vertical_spins
    from rollingtop.scenario import load_scenario

    if omega3 is not None and not math.isfinite(omega3):
        raise BadInput(f"--omega3 {omega3!r}: must be finite")
    sc = load_scenario(scenario)
    spins = vertical_spins(sc.body, sc.model)
    summary: dict[str, Any] = {"model": sc.model.name,
                               "vertical_spin": [v.to_dict() for v in spins]}  # fmt: skip
    if omega3 is not None:
        summary["eigenvalues"] = {"omega3": omega3, **{
            v.pole: _pairs(vertical_spin_eigenvalues(sc.body, sc.model, omega3, v.pole))
            for v in spins}}  # fmt: skip
    if as_json:
        click.echo(json.dumps(summary))
        return
    from rich.table import Table

    table = Table(title=f"vertical spins, model {sc.model.name}")
    for col in ("pole on the plane", "CoM above centre", "stable for w3 above", "closed form"):
        table.add_column(col, justify="left" if col.startswith("pole") else "right")
    for v in spins:
        closed = "-" if v.omega3_closed_form is None else f"{v.omega3_closed_form:.10g}"
        table.add_row(v.pole, "yes" if v.com_above_centre else "no",
                      f"{v.omega3_critical:.10g}", closed)  # fmt: skip
    _output.console().print(table)
    if omega3 is not None:
        for v in spins:
            ev = ", ".join(f"{z[0]:+.6g}{z[1]:+.6g}i" for z in summary["eigenvalues"][v.pole])
            _output.console().print(f"eigenvalues at w3 = {omega3:g}, {v.pole} pole: {ev}")
