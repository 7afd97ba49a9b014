"""Body parameters: validated once, every violation reported together."""

import pytest

from rollingtop import BodyError, SphericalTop

from .conftest import PAPER_BODY


def test_defaults_and_derived(paper_body):
    assert paper_body.I2 == paper_body.I1 == 0.3
    assert paper_body.symmetric
    # no shell, the contact model's slots at 0 (its defaults)
    assert list(paper_body.params) == [1.0, 1.0, 1.0, 0.1, 0.3, 0.3, 0.5, 0.0, 0.0, 0, 0, 0, 0]
    # rho(gamma3) = I1 + m (a3^2 + R^2 + 2 a3 R gamma3)  (paper eq. 3.3)
    assert paper_body.rho(0.5) == pytest.approx(0.3 + 1.0 * (0.01 + 1.0 + 0.1))
    assert not SphericalTop(**PAPER_BODY, I2=0.4).symmetric


def test_all_violations_reported_together():
    with pytest.raises(BodyError) as err:
        SphericalTop(R=-1.0, m=0.0, g=-9.8, a3=0.1, I1=0.3, I3=0.7)
    msg = str(err.value)
    for part in (
        "R = -1 must be > 0",
        "m = 0 must be > 0",
        "g = -9.8 must be >= 0",
        "I3 = 0.7 violates the rigid-body triangle inequality I3 <= I1 + I2 = 0.6",
    ):
        assert part in msg
    assert msg.count(";") == 3


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        (dict(a3=1.0), r"a3 = 1 violates \|a3\| < R = 1"),
        (dict(a3=-1.5), r"a3 = -1.5 violates \|a3\| < R"),
        (dict(I1=0.0), "I1 = 0 must be > 0"),
        (
            dict(I2=0.9),
            "I2 = 0.9 violates the rigid-body triangle inequality I2 <= I1 \\+ I3 = 0.8",
        ),
        (dict(m=float("nan")), "m = nan must be a finite real number"),
        (dict(R="1"), "R = '1' must be a finite real number"),
        (dict(g=True), "g = True must be a finite real number"),
    ],
)
def test_single_violation(changes, message):
    with pytest.raises(BodyError, match=message):
        SphericalTop(**(PAPER_BODY | changes))


def test_zero_gravity_and_flat_inertia_allowed():
    SphericalTop(R=1, m=1, g=0, a3=0, I1=0.25, I2=0.25, I3=0.5)  # thin-disc limit, equality
