"""rollingtop: dynamics of rolling spherical tops under nonholonomic constraints.

Implements A. A. Kilin, T. B. Ivanova, "The Integrable Problem of the Rolling Motion of a
Dynamically Symmetric Spherical Top with One Nonholonomic Constraint", Russian Journal of
Nonlinear Dynamics 19(1), 2023, 3-17 (doi:10.20537/nd221205), and its neighbour contact models.
"""

from typing import Any

from rollingtop._errors import (
    BodyError,
    ContactLostWarning,
    ContactModelError,
    InitialStateError,
    IntegrationError,
    OutputError,
    RollingTopError,
    ScenarioError,
)
from rollingtop._warmup import warmup
from rollingtop.body import SphericalTop
from rollingtop.contact import MODELS, ContactModel, get_model
from rollingtop.dynamics.integrals import INTEGRALS
from rollingtop.dynamics.state import initial_state
from rollingtop.ensemble import EnsembleResult, simulate_ensemble
from rollingtop.scenario import InitialConditions, IntegrationOptions, Scenario, load_scenario
from rollingtop.simulate import simulate, simulate_models
from rollingtop.trajectory import Trajectory


def __getattr__(name: str) -> Any:
    """``__version__``, read on first use (PEP 562): importlib.metadata costs every command a
    twentieth of a second at start-up, and few ask for the version."""
    if name == "__version__":
        from importlib import metadata

        try:  # the one version string: pyproject.toml, read from the installed metadata
            version = metadata.version("rollingtop")
        except metadata.PackageNotFoundError:  # a source tree on sys.path, not installed
            version = "0+unknown"
        globals()["__version__"] = version
        return version
    raise AttributeError(f"module 'rollingtop' has no attribute {name!r}")


__all__ = [
    "BodyError",
    "ContactLostWarning",
    "ContactModel",
    "ContactModelError",
    "EnsembleResult",
    "INTEGRALS",
    "InitialConditions",
    "InitialStateError",
    "IntegrationError",
    "IntegrationOptions",
    "MODELS",
    "OutputError",
    "RollingTopError",
    "Scenario",
    "ScenarioError",
    "SphericalTop",
    "Trajectory",
    "__version__",
    "get_model",
    "initial_state",
    "load_scenario",
    "simulate",
    "simulate_ensemble",
    "simulate_models",
    "warmup",
]
