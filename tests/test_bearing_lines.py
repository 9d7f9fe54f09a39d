"""Bearing defect frequencies against the CWRU bearing data centre's published table."""

import pytest

from gearbody.analysis.bearing_lines import BearingFrequencies, BearingGeometry, bearing_frequencies
from gearbody.errors import InputError

INCH_M = 0.0254
# CWRU drive-end bearing 6205-2RS JEM SKF: 9 balls, d = 0.3126 in, D = 1.537 in, contact angle 0
CWRU_DE = BearingGeometry(9, 0.3126 * INCH_M, 1.537 * INCH_M, 0.0)


def test_cwru_drive_end_bearing_matches_the_published_multiples_of_shaft_speed():
    orders = bearing_frequencies(CWRU_DE)
    assert orders.bpfo_hz == pytest.approx(3.5848, abs=5e-5)
    assert orders.bpfi_hz == pytest.approx(5.4152, abs=5e-5)
    assert orders.ftf_hz == pytest.approx(0.3983, abs=5e-5)
    assert orders.bsf_hz == pytest.approx(2.3567, abs=5e-5)
    # CWRU's "BSF" 4.7135 is the rolling-element defect rate 2 BSF
    assert orders.rolling_element_defect_hz == pytest.approx(4.7135, abs=2e-4)


def test_lines_scale_with_shaft_speed_and_as_orders_divides_it_out():
    at_1797_rpm = bearing_frequencies(CWRU_DE, 1797.0 / 60.0)
    assert at_1797_rpm.bpfo_hz == pytest.approx(3.5848 * 1797.0 / 60.0, rel=2e-5)  # ~107.4 Hz
    orders = at_1797_rpm.as_orders()
    reference = bearing_frequencies(CWRU_DE)
    assert isinstance(orders, BearingFrequencies)
    for name in ("shaft_hz", "bpfo_hz", "bpfi_hz", "bsf_hz", "ftf_hz"):
        assert getattr(orders, name) == pytest.approx(getattr(reference, name), rel=1e-12)


def test_identities_between_the_lines():
    f = bearing_frequencies(CWRU_DE, 25.0)
    assert f.bpfo_hz == pytest.approx(9 * f.ftf_hz, rel=1e-12)
    assert f.bpfo_hz + f.bpfi_hz == pytest.approx(9 * 25.0, rel=1e-12)
    turning_outer = bearing_frequencies(CWRU_DE, 25.0, outer_race_rotates=True)
    assert turning_outer.ftf_hz == pytest.approx(25.0 - f.ftf_hz, rel=1e-12)
    assert (turning_outer.bpfo_hz, turning_outer.bpfi_hz, turning_outer.bsf_hz) == (
        f.bpfo_hz,
        f.bpfi_hz,
        f.bsf_hz,
    )


def test_contact_angle_reduces_the_diameter_ratio():
    angular = BearingGeometry(9, 0.3126 * INCH_M, 1.537 * INCH_M, 40.0)
    assert bearing_frequencies(angular).bpfo_hz > bearing_frequencies(CWRU_DE).bpfo_hz


@pytest.mark.parametrize(
    ("args", "word"),
    [
        ((0, 0.01, 0.05, 0.0), "n_balls"),
        ((9.5, 0.01, 0.05, 0.0), "n_balls"),
        ((9, -0.01, 0.05, 0.0), "ball_diameter_m"),
        ((9, 0.01, float("nan"), 0.0), "pitch_diameter_m"),
        ((9, 0.06, 0.05, 0.0), "smaller than pitch_diameter_m"),
        ((9, 0.01, 0.05, 90.0), "contact_angle_deg"),
        ((9, 0.01, 0.05, -1.0), "contact_angle_deg"),
    ],
)
def test_bad_geometry_is_an_input_error_naming_the_parameter(args, word):
    with pytest.raises(InputError, match=word):
        BearingGeometry(*args)


def test_bad_shaft_speed_is_an_input_error():
    with pytest.raises(InputError, match="shaft_hz"):
        bearing_frequencies(CWRU_DE, 0.0)
    with pytest.raises(InputError, match="geometry"):
        bearing_frequencies((9, 0.01, 0.05, 0.0))
