"""The AttitudeEstimator's auto-sized aiding: what it measures, where it ends up, and that it
beats fixed settings it replaces on a vessel in waves."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from marinefmu.bench.cases import case_record
from marinefmu.bench.defaults import attitude_rms_deg
from marinefmu.errors import ParameterError
from marinefmu.estimators.attitude import estimator as att
from marinefmu.estimators.attitude.estimator import AttitudeEstimator, AttitudeEstimatorParams
from marinefmu.frames import G
from marinefmu.sea.motion_model import stack

DT = 0.01


@pytest.fixture(scope="module")
def waves() -> dict[str, np.ndarray]:
    """Research vessel, Hs 3 m / Tp 10 s, IMU at the COG (a case of the ``defaults`` bench), 450 s."""
    return case_record("research36", 3.0, 10.0, "cog", duration=450.0)


def run(params: AttitudeEstimatorParams, gyro: np.ndarray, acc: np.ndarray) -> AttitudeEstimator:
    est = AttitudeEstimator(params)
    for k in range(len(gyro)):
        est.step(gyro[k], acc[k], DT)
    return est


def sized_sigma_v(est: AttitudeEstimator) -> np.ndarray:
    """σ_v [m/s] (north, east) of the last pseudo-measurement."""
    return np.sqrt(np.diag(est.kf.R)[2:4])


def test_at_rest_the_aiding_tightens_to_near_its_floor():
    """A vessel at rest: only sensor noise and the filter's own small tilt error (g·ε, which the
    leaky integrator also sees) are left to size the aid, which ends 10-20 times tighter than
    ``vel_sigma`` (measured 0.05 / 0.095 m/s north / east)."""
    rng = np.random.default_rng(7)
    n = 12000
    gyro = 5e-5 / math.sqrt(DT) * rng.standard_normal((n, 3))
    acc = np.array([0.0, 0.0, -G]) + 7e-4 / math.sqrt(DT) * rng.standard_normal((n, 3))
    est = run(AttitudeEstimatorParams(), gyro, acc)
    sigma_v = sized_sigma_v(est)
    assert np.all(sigma_v >= att.SIGMA_V_MIN) and np.all(sigma_v <= 2.5 * att.SIGMA_V_MIN), sigma_v
    np.testing.assert_allclose(np.sqrt(np.diag(est.kf.R)[0:2]), att.POS_RATIO * sigma_v, rtol=1e-12)


def test_a_surging_sensor_is_sized_from_its_velocity():
    """Level sensor surging as a sinusoid of 8 s and 1 m/s² amplitude: the wave velocity's RMS
    is A/(ω√2) = 0.90 m/s, which the leaky integrator sees within its gain 1/√(1 + 1/(ωτ)²)
    (0.1 % low at 8 s) and the running window's ripple; σ_v north = AID_GAIN × that to 3 %, σ_v
    east at the floor."""
    w, amp = 2.0 * math.pi / 8.0, 1.0
    t = np.arange(1, 30001) * DT
    acc = np.column_stack((amp * np.sin(w * t), np.zeros_like(t), np.full_like(t, -G)))
    est = run(AttitudeEstimatorParams(init="given"), np.zeros((len(t), 3)), acc)
    sigma_v = sized_sigma_v(est)
    assert sigma_v[0] == pytest.approx(att.AID_GAIN * amp / (w * math.sqrt(2.0)), rel=0.03), sigma_v
    assert sigma_v[1] <= 2.0 * att.SIGMA_V_MIN, sigma_v


def test_auto_sizing_beats_fixed_settings_on_a_vessel_in_waves(waves):
    base = AttitudeEstimatorParams()
    auto = max(attitude_rms_deg(waves, base))
    fixed = {v: max(attitude_rms_deg(waves, replace(base, aid_sizing="fixed", vel_sigma=v, pos_sigma=3.0 * v)))
             for v in (0.25, 1.0, 3.0)}
    # measured: auto 0.029 deg; fixed 0.25 / 1 / 3 m/s 0.05-0.09 / 0.033-0.036 / 0.045-0.05 deg
    assert auto <= 0.035, auto
    assert auto <= 1.15 * min(fixed.values()), (auto, fixed)
    assert auto < fixed[3.0] and auto < fixed[0.25], (auto, fixed)


def test_bad_samples_never_poison_the_sizing(waves):
    gyro, acc = stack(waves, "imu.gyro")[:8000].copy(), stack(waves, "imu.acc")[:8000].copy()
    acc[5000:5100] = np.nan
    gyro[6000] = np.inf
    est = run(AttitudeEstimatorParams(), gyro, acc)
    r = np.diag(est.kf.R)
    assert np.all(np.isfinite(r)) and np.all(r > 0.0), r
    assert np.all(np.isfinite(est.q))


def test_state_round_trip_continues_identically(waves):
    gyro, acc = stack(waves, "imu.gyro")[:7000], stack(waves, "imu.acc")[:7000]
    a = run(AttitudeEstimatorParams(), gyro[:5000], acc[:5000])
    b = AttitudeEstimator(AttitudeEstimatorParams())
    b.set_state(a.get_state())
    ra = [a.step(gyro[k], acc[k], DT) for k in range(5000, 7000)]
    rb = [b.step(gyro[k], acc[k], DT) for k in range(5000, 7000)]
    assert [r.q for r in ra] == [r.q for r in rb]


def test_an_unknown_sizing_is_refused_naming_the_choices():
    with pytest.raises(ParameterError, match=r"aid_sizing = 'adaptive' is not allowed: must be one of 'auto', 'fixed'"):
        AttitudeEstimatorParams(aid_sizing="adaptive")
