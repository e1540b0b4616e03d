"""The fusion's per-step sample checks on floats against the full array checks."""
import math

import numpy as np
import pytest

from marinefmu.estimators.samples import (MAX_RATE, MAX_SPECIFIC_FORCE, force_beyond_limit, force_sample_good,
                                         rate_beyond_limit, rate_sample_good)

EDGES = [0.0, -9.8, 0.99 * MAX_SPECIFIC_FORCE, 0.999 * MAX_SPECIFIC_FORCE, MAX_SPECIFIC_FORCE,
         MAX_SPECIFIC_FORCE * (1 + 1e-15), 1e12, math.nan, math.inf, -math.inf]


@pytest.mark.parametrize("value", EDGES)
@pytest.mark.parametrize("axis", [0, 2])
def test_the_force_check_agrees_with_the_full_check(value, axis):
    f = np.array([0.1, -0.2, -9.8])
    f[axis] = value
    full = bool(np.all(np.isfinite(f))) and force_beyond_limit(f) is None
    assert force_sample_good(f) is full


@pytest.mark.parametrize("value", [0.0, 0.3, MAX_RATE, -MAX_RATE, math.nextafter(MAX_RATE, 11.0), -11.0, 1e12,
                                   math.nan, math.inf, -math.inf])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_the_rate_check_agrees_with_the_full_check(value, axis):
    w = np.array([0.01, -0.02, 0.03])
    w[axis] = value
    full = bool(np.all(np.isfinite(w))) and rate_beyond_limit(w) is None
    assert rate_sample_good(w) is full
