"""Arguments and options shared by several commands, and the contact-model choice."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import click

from rollingtop._checks import short_repr
from rollingtop.contact import MODELS, ContactModel

__all__ = [
    "ModelChoice",
    "atol_option",
    "figure_output",
    "json_option",
    "parse_range",
    "rtol_option",
    "scenario_argument",
    "t_end_option",
]


if TYPE_CHECKING:
    _Choice = click.Choice[str]
else:  # click < 8.2: not generic
    _Choice = click.Choice


class ModelChoice(_Choice):
    """A contact model, by its name in the registry (:data:`rollingtop.contact.MODELS`).

    The value is the :class:`~rollingtop.contact.ContactModel` itself; help and completion list
    the registered names; an unknown name is refused as the library refuses it.
    """

    name = "model"

    def __init__(self) -> None:
        super().__init__(tuple(MODELS))

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        if isinstance(value, ContactModel):
            return value
        if isinstance(value, str) and value in MODELS:
            return MODELS[value]
        self.fail(
            f"unknown contact model {short_repr(value)} (known: {', '.join(MODELS)})", param, ctx
        )


scenario_argument = click.argument("scenario", type=click.Path(dir_okay=False))
json_option = click.option(
    "--json", "as_json", is_flag=True, help="Print exactly one JSON object on stdout."
)
t_end_option = click.option(
    "--t-end", type=float, default=None, help="End time (overrides the scenario)."
)
rtol_option = click.option("--rtol", type=float, default=None, help="Relative tolerance.")
atol_option = click.option("--atol", type=float, default=None, help="Absolute tolerance.")
figure_output = click.option(
    "-o", "--output", type=click.Path(), required=True, help="FIG.png, .svg or .pdf."
)


def parse_range(flag: str, text: str | None) -> tuple[float, float] | None:
    """``"LO,HI"`` as two finite, increasing numbers (``None`` for no option); ``BadInput``
    naming ``flag`` otherwise (``bifurcation``'s ranges, ``continue --range``)."""
    from rollingtop.cli._errors import BadInput

    if text is None:
        return None
    parts = text.split(",")
    try:
        lo, hi = (float(x) for x in parts)
    except ValueError:
        raise BadInput(f"{flag} {short_repr(text)}: expected two numbers LO,HI") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise BadInput(f"{flag} {short_repr(text)}: expected finite LO < HI")
    return lo, hi
