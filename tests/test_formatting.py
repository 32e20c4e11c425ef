"""A value with its uncertainty, as every report writes it (``core.formatting.plus_minus``).

The rule: σ with two significant digits, the value rounded to σ's last
digit; forces in kN or MN; a shared exponent for magnitudes far from 1; no
usable σ, the value alone with a few significant digits.
"""

import math

import pytest

from stcs_ident.core.formatting import MISSING, plus_minus


@pytest.mark.parametrize("value, sigma, unit, expected", [
    # the example: 9.6 ± 0.0015 hid the digits the σ supports
    (9.59843, 0.00152, "kg", "9.5984 ± 0.0015 kg"),
    (-9.59843, 0.00152, "kg", "-9.5984 ± 0.0015 kg"),
    # σ rounded up to the next decade keeps two significant digits, not three
    (1.0, 0.0996, "", "1.00 ± 0.10"),
    # σ larger than the value: the value keeps σ's decimal place, and a rounded zero has no sign
    (0.3, 5.2, "", "0.3 ± 5.2"),
    (-0.001, 5.2, "m", "0.0 ± 5.2 m"),
    # a σ of 10 or more rounds the value to tens, hundreds, ...
    (53730.0, 5600.0, "", "53700 ± 5600"),
    # a very small σ: all the digits it supports
    (5.2, 7e-5, "m", "5.200000 ± 0.000070 m"),
    # a negative σ is read as its magnitude
    (9.59843, -0.00152, "kg", "9.5984 ± 0.0015 kg"),
])
def test_value_carries_the_digits_its_sigma_supports(value, sigma, unit, expected):
    assert plus_minus(value, sigma, unit) == expected


@pytest.mark.parametrize("value, sigma, unit, expected", [
    (1248700.0, 4213.0, "N", "1.2487 ± 0.0042 MN"),
    (412345.0, 2480.0, "N", "412.3 ± 2.5 kN"),
    (-1248700.0, 4213.0, "N", "-1.2487 ± 0.0042 MN"),
    (999.96, 0.02, "N", "999.960 ± 0.020 N"),
    (53730.0, 5600.0, "N/m", "53.7 ± 5.6 kN/m"),
    (117338.3, 520.0, "N m^2", "117.34 ± 0.52 kN m^2"),
    # the prefix follows σ when the value is smaller than it
    (20.0, 3400.0, "N", "0.0 ± 3.4 kN"),
    # beyond 10⁹ N a shared exponent reads better than a prefix
    (3.553e21, 1.0e19, "N m/rad", "(3.553 ± 0.010)e+21 N m/rad"),
    # other units are never prefixed
    (1500.0, 12.0, "m", "1500 ± 12 m"),
])
def test_forces_take_an_engineering_prefix(value, sigma, unit, expected):
    assert plus_minus(value, sigma, unit) == expected


@pytest.mark.parametrize("value, sigma, expected", [
    (1.2e-7, 3e-9, "(1.200 ± 0.030)e-07"),
    (4.2e8, 1.3e6, "(4.200 ± 0.013)e+08"),
    (-4.2e8, 1.3e6, "(-4.200 ± 0.013)e+08"),
    # σ sets the exponent when it is the larger
    (2.0e-6, 3.1e-4, "(0.0 ± 3.1)e-04"),
])
def test_magnitudes_far_from_one_share_an_exponent(value, sigma, expected):
    assert plus_minus(value, sigma) == expected


@pytest.mark.parametrize("sigma", [None, math.nan, math.inf, -math.inf])
def test_no_usable_sigma_gives_the_value_alone(sigma):
    assert plus_minus(9.59843, sigma, "kg") == "9.6 kg"
    assert plus_minus(9.59843, sigma, "kg", digits=5) == "9.5984 kg"
    assert plus_minus(1248700.0, sigma, "N", digits=5) == "1.2487 MN"


def test_zero_sigma_is_said_not_hidden():
    assert plus_minus(9.59843, 0.0, "kg") == "9.6 ± 0 kg"
    assert plus_minus(0.0, 0.0) == "0 ± 0"


@pytest.mark.parametrize("value", [None, math.nan])
def test_missing_value(value):
    assert plus_minus(value, 0.1, "kg") == MISSING


def test_infinite_value_is_written_out_unprefixed():
    assert plus_minus(math.inf, 1.0, "N") == "inf N"
    assert plus_minus(-math.inf, None) == "-inf"


def test_more_sigma_digits_on_request():
    assert plus_minus(9.59843, 0.00152, "kg", sigma_digits=1) == "9.598 ± 0.002 kg"
    assert plus_minus(9.59843, 0.00152, "kg", sigma_digits=3) == "9.59843 ± 0.00152 kg"
