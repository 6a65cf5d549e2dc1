"""The shared argument checks: what passes, what is refused, and the message."""

import math

import numpy as np
import pytest

from swarmtopo._validate import fraction, non_negative, non_negative_int, positive, positive_int
from swarmtopo.errors import InputError


@pytest.mark.parametrize("check, value, expected", [
    (positive, 2, 2.0), (positive, np.float32(0.5), 0.5), (positive, np.int64(7), 7.0),
    (non_negative, 0, 0.0), (non_negative, 1e300, 1e300),
    (fraction, 0, 0.0), (fraction, 1, 1.0), (fraction, np.float64(0.25), 0.25),
    (positive_int, 1, 1), (positive_int, np.int32(5), 5),
    (non_negative_int, 0, 0), (non_negative_int, np.uint8(3), 3),
])
def test_accepted_values_come_back_as_plain_python(check, value, expected):
    out = check("x", value)
    assert out == expected and type(out) is type(expected)


def test_inf_only_where_allowed():
    assert positive("tau", math.inf, allow_inf=True) == math.inf
    with pytest.raises(InputError, match="tau must be a positive finite number"):
        positive("tau", math.inf)
    with pytest.raises(InputError, match="tau must be a positive number or inf"):
        positive("tau", -math.inf, allow_inf=True)


@pytest.mark.parametrize("check, value, message", [
    (positive, 0, "must be a positive finite number"),
    (positive, -1.5, "must be a positive finite number"),
    (positive, math.nan, "must be a positive finite number"),
    (positive, True, "must be a number"),
    (positive, "3", "must be a number"),
    (positive, None, "must be a number"),
    (non_negative, -1e-12, "must be a finite number >= 0"),
    (non_negative, math.inf, "must be a finite number >= 0"),
    (non_negative, math.nan, "must be a finite number >= 0"),
    (fraction, 1.0000001, "must be in [0, 1]"),
    (fraction, -0.1, "must be in [0, 1]"),
    (fraction, math.nan, "must be in [0, 1]"),
    (positive_int, 0, "must be a positive integer"),
    (positive_int, 2.0, "must be a positive integer"),
    (positive_int, True, "must be a positive integer"),
    (positive_int, np.bool_(True), "must be a positive integer"),
    (non_negative_int, -1, "must be a non-negative integer"),
    (non_negative_int, 1.5, "must be a non-negative integer"),
])
def test_refused_values_are_named_and_quoted(check, value, message):
    with pytest.raises(InputError) as info:
        check("speed", value)
    assert info.value.reason == f"speed {message}"
    assert info.value.value is value
