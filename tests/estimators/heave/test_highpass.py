"""The classical heave estimator sample by sample (HeaveObserver model = "highpass", the
baseline of the heave-compensation goals, docs/heave_compensation.md): the same filter as the
offline function, its stated response, its handling of bad samples and its parameters."""
import json
import math

import numpy as np
import pytest
from scipy import signal

from marinefmu.errors import ParameterError
from marinefmu.estimators.heave.bank import OscillatorBankHeave
from marinefmu.estimators.heave.common import HeaveObserverParams
from marinefmu.estimators.heave.highpass import HighpassHeave
from marinefmu.estimators.heave.observer import build_heave_model
from marinefmu.estimators.numerics import highpass_double_integration, highpass_sections

DT = 0.01
G = 9.80665


def _record(seconds=400.0, seed=3):
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, DT)
    return t, 0.8 * np.sin(0.7 * t) + 0.3 * np.sin(1.3 * t + 1.0) + 0.01 * rng.standard_normal(len(t))


def test_streaming_filter_is_the_offline_one_and_its_rate_the_derivative():
    t, az = _record()
    hp = HighpassHeave(HeaveObserverParams(model="highpass", highpass_cutoff=0.1))
    out = [hp.step((0.0, 0.0, a - G), 0.0, 0.0, DT) for a in az]
    heave = np.array([r.heave for r in out])
    rate = np.array([r.heave_rate for r in out])
    # a_v = f_z + g: the only difference is the rounding of −g + g (measured 2e-11 m)
    np.testing.assert_allclose(heave, highpass_double_integration(az, DT, 0.1), rtol=0, atol=1e-9)
    np.testing.assert_allclose(rate, signal.sosfilt(highpass_sections(0.1, DT, rate=True), az), rtol=0, atol=1e-9)
    # the rate is the heave's derivative: central difference of the heave, away from the start
    np.testing.assert_allclose(np.gradient(heave, DT)[20000:-1], rate[20000:-1], atol=2e-4)


def test_sections_have_the_analytic_response_at_every_order():
    """s^{n−2}/B(s) (rate: s^{n−1}/B(s)) to the bilinear warp (ωΔt)²/12 per integration
    (measured ≤ 1.5e-4 at ωΔt = 0.03)."""
    w = np.array([0.05, 0.3, 1.0, 3.0])
    for order in range(2, 9):
        _, den = signal.butter(order, 0.1, "highpass", analog=True)
        for rate in (False, True):
            num = np.zeros(order - 1 + rate)
            num[0] = 1.0
            analytic = np.polyval(num, 1j * w) / np.polyval(den, 1j * w)
            _, digital = signal.sosfreqz(highpass_sections(0.1, DT, order, rate), worN=w * DT)
            assert np.max(np.abs(digital / analytic - 1)) < 2e-4, (order, rate)


def test_a_sinusoid_comes_out_as_the_stated_response_at_the_point():
    """Steady state on a pure heave sinusoid: the estimate is H(ω) times the truth, at the IMU
    and (no rotation) at any point."""
    w, amp = 0.7, 1.5
    t = np.arange(0.0, 600.0, DT)
    hp = HighpassHeave(HeaveObserverParams(model="highpass", highpass_cutoff=0.1, point=(50.0, 0.0, -15.0)))
    out = [hp.step((0.0, 0.0, -G - amp * w * w * math.sin(w * tk)), 0.0, 0.0, DT) for tk in t]
    h = complex(hp.response(w))
    expected = amp * np.imag(h * np.exp(1j * w * t))
    later = t > 400.0      # the start from rest (a 1 m/s step of velocity) decays as exp(−4t/settle_time)
    for field in ("heave", "point_heave"):
        np.testing.assert_allclose(np.array([getattr(r, field) for r in out])[later], expected[later], atol=2e-4)
    assert 0.6 < abs(h) < 1.0 and np.angle(h) > 0.3     # the long-wave error of the classical filter: 21° lead
    assert not out[int(hp.settle_time / DT) - 2].valid and out[int(hp.settle_time / DT) + 1].valid


def test_a_bad_sample_is_held_flagged_and_the_state_round_trips(caplog):
    hp = HighpassHeave(HeaveObserverParams(model="highpass", highpass_cutoff=0.2))
    _, az = _record(150.0)
    for a in az:
        hp.step((0.0, 0.0, a - G), 0.0, 0.0, DT)
    twin = HighpassHeave(hp.params)
    twin.set_state(json.loads(json.dumps(hp.get_state())))
    held = hp.step((0.0, 0.0, az[-1] - G), 0.0, 0.0, DT)
    with caplog.at_level("WARNING"):
        bad = twin.step((math.nan, 0.0, -G), 0.0, 0.0, DT)
    assert held.valid and not bad.valid and "non-finite" in bad.warning and "holding" in caplog.text
    assert bad.heave == held.heave and bad.heave_rate == held.heave_rate   # the last good sample, held
    assert twin.step((0.0, 0.0, -G), 0.0, 0.0, DT) == hp.step((0.0, 0.0, -G), 0.0, 0.0, DT)


def test_the_model_switch_and_its_parameters():
    assert isinstance(build_heave_model(HeaveObserverParams(model="highpass")), HighpassHeave)
    assert isinstance(build_heave_model(HeaveObserverParams(model="band")), OscillatorBankHeave)
    with pytest.raises(ParameterError, match="model = .highpass. is not an observer model"):
        OscillatorBankHeave(HeaveObserverParams(model="highpass"))
    with pytest.raises(ParameterError, match=r"highpass_cutoff = 6\.0 is out of range"):
        HeaveObserverParams(model="highpass", highpass_cutoff=6.0)
    with pytest.raises(ParameterError, match="highpass_order = 9 is out of range"):
        HeaveObserverParams(model="highpass", highpass_order=9)
