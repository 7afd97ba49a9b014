"""rollingtop: dynamics of rolling spherical tops under nonholonomic constraints.

Implements A. A. Kilin, T. B. Ivanova, "The Integrable Problem of the Rolling Motion of a
Dynamically Symmetric Spherical Top with One Nonholonomic Constraint", Russian Journal of
Nonlinear Dynamics 19(1), 2023, 3-17 (doi:10.20537/nd221205), and its neighbour contact models.
"""

from importlib import metadata as _metadata

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

try:  # the one version string: pyproject.toml, read from the installed metadata
    __version__ = _metadata.version("rollingtop")
except _metadata.PackageNotFoundError:  # a source tree on sys.path, not installed
    __version__ = "0+unknown"

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
