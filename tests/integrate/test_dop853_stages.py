"""The generated stage module: in step with its generator and the tableau."""

import numpy as np
import pytest

from rollingtop.integrate import _dop853_codegen
from rollingtop.integrate._dop853_stages import stage
from rollingtop.integrate._dop853_tableau import N_STAGES_EXTENDED, A

# Each stage is a sum of at most 12 terms of size ~1 times coefficients up to ~44: a few ulps of
# the largest term.
STAGE_TOL = 1e-13


def test_generated_source_matches_generator():
    """Regenerating from the tableau reproduces the committed file exactly."""
    assert _dop853_codegen.TARGET.read_text() == _dop853_codegen.render()


@pytest.mark.parametrize("s", range(1, N_STAGES_EXTENDED))
def test_stage_equals_tableau_sum(s):
    rng = np.random.default_rng(s)
    K = rng.standard_normal((N_STAGES_EXTENDED, 18))
    y = rng.standard_normal(18)
    h = 0.37
    out = np.full(18, np.nan)
    stage(K, s, y, h, out)
    expected = y + h * (A[s, :s] @ K[:s])
    np.testing.assert_allclose(out, expected, rtol=0, atol=STAGE_TOL)
