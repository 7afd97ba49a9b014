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
