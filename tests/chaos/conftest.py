"""Shared cases of the chaos tests."""

import pytest

from rollingtop import SphericalTop, get_model, initial_state

#: A non-symmetric body (I1 != I2, centre of mass displaced along e3) on the smooth plane, from a
#: state whose motion is chaotic: maximal Lyapunov exponent ~0.13 (tangent dynamics and two
#: nearby trajectories agree, tests/chaos/test_lyapunov.py); the normal force stays above 0.6.
CHAOTIC_BODY = dict(R=1.0, m=1.0, g=1.0, a3=0.2, I1=0.2, I2=0.5, I3=0.6)
CHAOTIC_INITIAL = dict(gamma=(0.6, 0.0, 0.8), omega=(0.2, 0.6, 0.3))


@pytest.fixture
def chaotic():
    body = SphericalTop(**CHAOTIC_BODY)
    model = get_model("smooth")
    return body, model, initial_state(body, model, **CHAOTIC_INITIAL)
