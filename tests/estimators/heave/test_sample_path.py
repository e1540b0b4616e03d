"""The heave estimators' per-sample path: :func:`read_sample`'s float check against the full
array check, the bank's answer before its first model, and the WienerHeave's (roll, pitch)
ring through a JSON state."""
import json
import math

import numpy as np
import pytest

from marinefmu.estimators.heave.bank import OscillatorBankHeave
from marinefmu.estimators.heave.common import HeaveObserverParams, _bad_sample, read_sample
from marinefmu.estimators.heave.wiener import WienerHeave
from marinefmu.estimators.samples import MAX_TILT


@pytest.mark.parametrize("acc,roll,pitch", [
    ((0.1, -0.2, -9.8), 0.05, -0.03),
    ([0.1, -0.2, -9.8], 0.05, -0.03),
    (np.array([0.1, -0.2, -9.8]), np.float64(0.05), -0.03),
    ((0.0, 199.5, 0.0), 0.0, 0.0),                 # inside the limit, beyond the float margin
    ((0.0, 200.5, 0.0), 0.0, 0.0),
    ((math.nan, 0.0, -9.8), 0.0, 0.0),
    ((0.0, math.inf, -9.8), 0.0, 0.0),
    ((0.0, 0.0, -9.8), math.nan, 0.0),
    ((0.0, 0.0, -9.8), 0.0, MAX_TILT + 1e-9),
    ((0.0, 0.0, -9.8), -MAX_TILT, MAX_TILT),       # at the limit: good
    (-9.8, 0.0, 0.0),                              # f_z only
    (np.float64(-9.8), 0.02, 0.0),                 # f_z as numpy's float
    (np.array([-9.8]), 0.0, 0.0),
    (-199.5, 0.0, 0.0),                            # f_z beyond the float margin
    (1e12, 0.0, 0.0),
    (math.nan, 0.0, 0.0),
    (-math.inf, 0.0, 0.0),
    (-9.8, math.nan, 0.0),
    (-9.8, 0.0, MAX_TILT + 1e-9),
    (-10, 0.0, 0.0),                               # an int
    ((1.0, 2.0), 0.0, 0.0),                        # a bad shape
])
def test_the_float_check_agrees_with_the_array_check(acc, roll, pitch):
    f, r, p, warning = read_sample(acc, roll, pitch)
    full = np.asarray(acc, dtype=float).reshape(-1)
    full = np.array([0.0, 0.0, full[0]]) if full.shape == (1,) else full if full.shape == (3,) else np.full(3, math.nan)
    assert warning == _bad_sample(full, float(roll), float(pitch))
    np.testing.assert_array_equal(np.asarray(f, dtype=float), full)
    assert (r, p) == (float(roll), float(pitch)) and type(r) is float


def test_before_its_first_model_the_bank_answers_invalid_and_says_why_a_sample_was_bad():
    bank = OscillatorBankHeave(HeaveObserverParams(model="band", window=60.0), quiet=True)
    first = bank.step((0.0, 0.0, -9.8), 0.01, 0.0, 0.01)
    assert not first.valid and first.warning is None and first.modes == 0 and first.heave == 0.0
    bad = bank.step((math.nan, 0.0, -9.8), 0.01, 0.0, 0.01)
    assert not bad.valid and bad.warning == "non-finite acceleration or angle sample"
    assert bad == first.__class__(**{**first.__dict__, "warning": bad.warning})
    assert bank.step(-9.8, 0.01, 0.0, 0.01) == first
    assert bank.model is None and bank.k == 3


def test_the_angle_ring_round_trips_through_json():
    rng = np.random.default_rng(2)
    t = np.arange(1, 9001) * 0.01
    acc = np.column_stack((0.2 * np.sin(0.7 * t), 0.1 * np.cos(0.9 * t), -9.80665 + 0.8 * np.sin(0.6 * t)))
    acc += rng.normal(0.0, 0.01, acc.shape)
    roll, pitch = 0.05 * np.sin(0.6 * t), 0.03 * np.cos(0.5 * t)
    params = HeaveObserverParams(window=60.0, point=(40.0, -2.0, -5.0))
    a = WienerHeave(params, quiet=True)
    for k in range(7000):
        a.step(acc[k], roll[k], pitch[k], 0.01)
    b = WienerHeave(params, quiet=True)
    b.set_state(json.loads(json.dumps(a.get_state())))
    for k in range(7000, 9000):
        assert a.step(acc[k], roll[k], pitch[k], 0.01) == b.step(acc[k], roll[k], pitch[k], 0.01)
