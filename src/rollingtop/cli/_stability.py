"""``rollingtop stability``: the stability of the vertical spins of a body under its model, or
under every model that takes it."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING, Any

import click

from rollingtop._checks import short_repr
from rollingtop.cli import _output
from rollingtop.cli._errors import BadInput
from rollingtop.cli._options import ModelChoice, json_option, scenario_argument
from rollingtop.contact import MODELS, ContactModel

if TYPE_CHECKING:
    from rich.table import Table

    from rollingtop.body import SphericalTop

__all__ = ["stability"]

#: The ``--model`` value that asks for every registered model that takes the body.
ALL = "all"


class ModelOrAll(ModelChoice):
    """A contact model by its registered name (the :class:`~rollingtop.contact.ContactModel`),
    or ``all`` (the string :data:`ALL`)."""

    name = "model|all"

    def __init__(self) -> None:
        super().__init__()
        self.choices = (*self.choices, ALL)

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if value == ALL:
            return ALL
        if isinstance(value, ContactModel) or (isinstance(value, str) and value in MODELS):
            return super().convert(value, param, ctx)
        self.fail(
            f"unknown contact model {short_repr(value)} (known: {', '.join(MODELS)}, or {ALL})",
            param,
            ctx,
        )


def _pairs(values: Any) -> list[list[float]]:
    return [[float(z.real), float(z.imag)] for z in values]


def _model_summary(body: SphericalTop, model: ContactModel, omega3: float | None) -> dict[str, Any]:
    """``{"model", "vertical_spin"[, "eigenvalues"]}`` of ``body`` under ``model``; raises the
    library's :class:`~rollingtop.StabilityError` where the model has no such answer."""
    from rollingtop.stability import vertical_spin_eigenvalues, vertical_spins

    spins = vertical_spins(body, model)
    summary: dict[str, Any] = {"model": model.name, "vertical_spin": [v.to_dict() for v in spins]}
    if omega3 is not None:
        summary["eigenvalues"] = {
            "omega3": omega3,
            **{
                v.pole: _pairs(vertical_spin_eigenvalues(body, model, omega3, v.pole))
                for v in spins
            },
        }
    return summary


def _every_model(body: SphericalTop, omega3: float | None) -> list[dict[str, Any]]:
    """:func:`_model_summary` under every model that takes ``body``
    (:func:`rollingtop.contact.models_for`); a model without an answer gives
    ``{"model", "refused": reason}``."""
    from rollingtop.contact import models_for
    from rollingtop.stability import StabilityError

    out = []
    for model in models_for(body):
        try:
            out.append(_model_summary(body, model, omega3))
        except StabilityError as exc:
            out.append({"model": model.name, "refused": str(exc)})
    return out


def _table(summaries: list[dict[str, Any]], title: str) -> Table:
    from rich.table import Table

    several = len(summaries) > 1
    table = Table(title=title)
    cols = ("model",) * several + (
        "pole on the plane",
        "CoM above centre",
        "stable for w3 above",
        "closed form",
    )
    for col in cols:
        table.add_column(col, justify="left" if col in ("model", "pole on the plane") else "right")
    for s in summaries:
        for v in s.get("vertical_spin", []):
            closed = v["omega3_closed_form"]
            table.add_row(
                *(s["model"],) * several,
                v["pole"],
                "yes" if v["com_above_centre"] else "no",
                f"{v['omega3_critical']:.10g}",
                "-" if closed is None else f"{closed:.10g}",
            )
    return table


@click.command()
@scenario_argument
@json_option
@click.option(
    "--model",
    "model",
    type=ModelOrAll(),
    default=None,
    help="Contact model (default: the scenario's), or 'all': every registered model "
    "that takes the body.",
)
@click.option(
    "--omega3",
    type=float,
    default=None,
    help="Also give the eigenvalues of the linearisation at this spin rate.",
)
def stability(
    scenario: str, as_json: bool, model: ContactModel | str | None, omega3: float | None
) -> None:
    """Stability of the vertical spins (a pole on the plane, the axis vertical) of the scenario's
    body under its contact model (--model: another, or all): the spin rate above which each is
    linearly stable."""
    from rollingtop.scenario import load_scenario

    if omega3 is not None and not math.isfinite(omega3):
        raise BadInput(f"--omega3 {omega3!r}: must be finite")
    sc = load_scenario(scenario)
    if model == ALL:
        summaries = _every_model(sc.body, omega3)
        title = "vertical spins, every model that takes the body"
    else:
        chosen = sc.model if model is None else model
        assert isinstance(chosen, ContactModel)
        summaries = [_model_summary(sc.body, chosen, omega3)]
        title = f"vertical spins, model {chosen.name}"
    if as_json:
        click.echo(json.dumps({"models": summaries} if model == ALL else summaries[0]))
        return
    _output.console().print(_table(summaries, title))
    for s in summaries:
        if "refused" in s:
            click.echo(f"{s['model']}: {s['refused']}")
    for s in summaries:
        for pole, values in s.get("eigenvalues", {}).items():
            if pole == "omega3":
                continue
            ev = ", ".join(f"{z[0]:+.6g}{z[1]:+.6g}i" for z in values)
            which = f"{s['model']} model, " if len(summaries) > 1 else ""
            click.echo(f"eigenvalues at w3 = {omega3:g}, {which}{pole} pole: {ev}")
