"""The generated stage module: in step with its generator and the tableau."""

import numpy as np
import pytest

from rollingtop._compiled import _dop853_codegen
from rollingtop._compiled._dop853_stages import scaled_errors, stage
from rollingtop._compiled._dop853_tableau import E3, E5, N_STAGES_EXTENDED, A, B

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


def test_thirteenth_stage_is_the_solution():
    """The stepper forms the new point with ``stage(K, 12, ...)``: first same as last. Both rows
    are literals of the tableau, so they are the same numbers exactly."""
    assert np.array_equal(A[12, :12], B)


def test_scaled_errors_equal_tableau_sums():
    rng = np.random.default_rng(7)
    K = rng.standard_normal((N_STAGES_EXTENDED, 18))
    y, ynew = rng.standard_normal(18), rng.standard_normal(18)
    rtol, atol = 1e-3, 1e-5
    err5, err3 = np.empty(18), np.empty(18)
    scaled_errors(K, y, ynew, rtol, atol, err5, err3)
    scale = atol + np.maximum(np.abs(y), np.abs(ynew)) * rtol
    # relative to the quotient: the sums carry a few ulps of their largest term
    np.testing.assert_allclose(err5 * scale, E5 @ K[:13], rtol=0, atol=STAGE_TOL)
    np.testing.assert_allclose(err3 * scale, E3 @ K[:13], rtol=0, atol=STAGE_TOL)
