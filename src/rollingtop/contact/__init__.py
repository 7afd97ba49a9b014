"""Contact models, chosen by name.

Each module declares one model: its compiled constraint rows (``rows``) and a
:class:`~rollingtop.contact._base.ContactModel` describing it. Adding a model means adding a
module here, its entry in :data:`MODELS` and one branch in
:func:`rollingtop.dynamics._kernel.constraint_rows`.
"""

from rollingtop._errors import ContactModelError
from rollingtop.contact import meridian, rough, smooth
from rollingtop.contact._base import ContactModel

MODELS: dict[str, ContactModel] = {m.name: m for m in (meridian.MODEL, smooth.MODEL, rough.MODEL)}

__all__ = ["MODELS", "ContactModel", "get_model"]


def get_model(name: str | ContactModel) -> ContactModel:
    """The contact model called ``name`` (one of :data:`MODELS`)."""
    if isinstance(name, ContactModel):
        return name
    try:
        return MODELS[name]
    except (KeyError, TypeError):
        raise ContactModelError(
            f"unknown contact model {name!r} (known: {', '.join(MODELS)})"
        ) from None
