"""Exceptions and warnings raised by rollingtop.

Every error a user can cause by bad input derives from :class:`RollingTopError` (a
``ValueError``), so that the command-line interface can report it as one line and exit with
status 2 without a traceback.
"""


class RollingTopError(ValueError):
    """Base class of every input error raised by rollingtop."""


class BodyError(RollingTopError):
    """The body parameters are physically inadmissible."""


class ContactModelError(RollingTopError):
    """Unknown contact model name."""


class InitialStateError(RollingTopError):
    """The initial conditions are inconsistent with the body or the contact model."""


class ScenarioError(RollingTopError):
    """A scenario file (or its overrides) is malformed."""


class OutputError(RollingTopError):
    """An output file cannot be written."""


class IntegrationError(RuntimeError):
    """The integrator could not reach the requested end time."""


class NotFiniteAtStart(IntegrationError):
    """The initial state or its derivative is not finite: the integrator took no step (the
    caller, who knows the body, may name the input that overflows)."""


class Interrupted(KeyboardInterrupt):
    """A run was stopped by a signal (SIGINT or SIGTERM); ``signum`` says which.

    The command-line interface reports it as one line and exits with ``128 + signum``
    (130 for SIGINT, 143 for SIGTERM).
    """

    def __init__(self, signum: int, message: str = "") -> None:
        super().__init__(message or f"interrupted by signal {signum}")
        self.signum = int(signum)


class ContactLostWarning(UserWarning):
    """The normal reaction turned negative: the body would leave the plane."""


#: Characters a quoted value keeps in a message (:func:`short_repr`).
QUOTE_CHARS = 80


def short_path(path: object, limit: int = QUOTE_CHARS) -> str:
    """A path quoted for an error message, cut at its start where it is long (``'…/out/a.nc'``):
    its end names the file."""
    text = str(path)
    if len(repr(text)) <= limit:
        return repr(text)
    cut = limit - 3
    while cut > 1 and len(repr("…" + text[len(text) - cut :])) > limit:  # escapes: more room
        cut -= 1
    return repr("…" + text[len(text) - cut :])


def short_repr(value: object, limit: int = QUOTE_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters (with an ellipsis), for error messages."""
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 4 * limit:
        try:
            return f"<integer of {len(str(abs(value)))} digits>"
        except ValueError:  # longer than Python converts to text
            return f"<integer of about {int(value.bit_length() * 0.30103)} digits>"
    if isinstance(value, str) and len(repr(value)) > limit:  # cut inside its quotes
        cut = limit - 3
        while cut > 0 and len(repr(value[:cut] + "…")) > limit:  # escapes take more room
            cut -= 1
        return repr(value[:cut] + "…")
    if isinstance(value, list | tuple | dict) and len(value) > limit:
        return f"<{type(value).__name__} of {len(value)} items>"
    try:
        text = repr(value)
    except (RecursionError, ValueError):
        return f"<{type(value).__name__}>"
    return text if len(text) <= limit else text[: limit - 1] + "…"
