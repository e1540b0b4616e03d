"""The AttitudeEstimator's auto-sized gyro noise (``aid_sizing = "auto"``): it finds the grade of
the IMU it is given from the gyro's second differences, keeps the configured bias-to-noise
ratio, stays positive on a noiseless input, and leaves ``"fixed"`` as given."""
from __future__ import annotations

import math

import numpy as np
import pytest

from marinefmu.bench.cases import case_record
from marinefmu.estimators.attitude import estimator as att
from marinefmu.estimators.attitude.estimator import AttitudeEstimator, AttitudeEstimatorParams
from marinefmu.frames import G
from marinefmu.sea.motion_model import stack
from marinefmu.sea.sensors import IMU_GRADES

DT = 0.01


def run(params: AttitudeEstimatorParams, gyro: np.ndarray, acc: np.ndarray) -> AttitudeEstimator:
    est = AttitudeEstimator(params)
    for k in range(len(gyro)):
        est.step(gyro[k], acc[k], DT)
    return est


@pytest.mark.parametrize("grade", sorted(IMU_GRADES))
def test_the_sized_gyro_noise_is_the_grades(grade):
    """120 s of the small research vessel in the Hs 6 m, Tp 14 s sea with the IMU far forward and
    high (the most rotation of the ``defaults`` grid): the sized density is the grade's within
    3 % (the running mean of d² over ~12,000 effective samples has a 1.3 % standard deviation,
    0.65 % on the density; the motion's own second difference adds < 0.5 % at the mru grade),
    and the bias σ keeps the configured ratio to it exactly."""
    rec = case_record("research36", 6.0, 14.0, "far", duration=120.0, extra={"imu.grade": grade})
    est = run(AttitudeEstimatorParams(), stack(rec, "imu.gyro"), stack(rec, "imu.acc"))
    p = est.params
    assert est.gyro_noise_used == pytest.approx(IMU_GRADES[grade].gyro_noise, rel=0.03)
    assert est.gyro_bias_sigma_used == pytest.approx(p.gyro_bias_sigma * est.gyro_noise_used / p.gyro_noise, rel=1e-12)
    np.testing.assert_allclose(np.diag(est._q_diag)[4:8],
                               [est.gyro_noise_used ** 2] * 2 + [2 * est.gyro_bias_sigma_used ** 2 / p.gyro_bias_tau] * 2,
                               rtol=1e-12)


def test_a_noiseless_input_gets_the_floor_not_zero():
    """Ten minutes of constant input (a recording of a unit at rest, no noise): the density is the
    floor, the process noise and covariance stay positive and everything finite."""
    n = 60_000
    gyro = np.zeros((n, 3))
    acc = np.tile([0.0, 0.0, -G], (n, 1))
    est = run(AttitudeEstimatorParams(), gyro, acc)
    assert est.gyro_noise_used == att.GYRO_NOISE_MIN
    assert np.all(np.diag(est._q_diag)[2:] > 0.0)
    assert np.all(np.linalg.eigvalsh(0.5 * (est.kf.P + est.kf.P.T)) > 0.0)
    assert np.all(np.isfinite(est.q)) and np.all(np.isfinite(est.bias))


def test_fixed_keeps_the_noise_as_given_and_bad_samples_do_not_enter_the_sizing():
    """White MEMS-like noise of a known density with a NaN every 997 samples (held, not used):
    the auto sizing finds the density within 3 %; ``"fixed"`` keeps the parameters."""
    rng = np.random.default_rng(11)
    n, density = 20_000, 2e-4
    gyro = density / math.sqrt(DT) * rng.standard_normal((n, 3))
    acc = np.array([0.0, 0.0, -G]) + 7e-4 / math.sqrt(DT) * rng.standard_normal((n, 3))
    gyro[::997] = np.nan
    auto = run(AttitudeEstimatorParams(), gyro, acc)
    assert auto.gyro_noise_used == pytest.approx(density, rel=0.03)
    fixed = run(AttitudeEstimatorParams(aid_sizing="fixed"), gyro, acc)
    p = fixed.params
    assert (fixed.gyro_noise_used, fixed.gyro_bias_sigma_used) == (p.gyro_noise, p.gyro_bias_sigma)
    assert np.diag(fixed._q_diag)[4] == p.gyro_noise ** 2
