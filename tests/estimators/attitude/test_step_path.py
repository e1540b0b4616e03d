"""The AttitudeEstimator's per-step path (Python floats, preallocated F and P, the error state's
prediction skipped, F's constant entries and Q Δt rebuilt only when Δt or the sized gyro noise
changes) against a straightforward reference: filterpy's ``KalmanFilter`` predicting and
updating with F, Q and H built afresh every step, the quaternion kernels of ``frames``."""
import math

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from marinefmu.estimators.attitude import estimator as att
from marinefmu.estimators.attitude.estimator import AttitudeEstimator, AttitudeEstimatorParams, aid_update
from marinefmu.estimators.noise_meter import WhiteNoiseMeter
from marinefmu.frames import euler_to_quat, level_angles, quat_from_rotvec, quat_mul, quat_to_euler, quat_to_rot
from marinefmu.sea.motion_model import REAL_INDEX, VesselMotion, VesselMotionParams


class Reference:
    """The estimator's equations written plainly on numpy arrays and filterpy (module docstring
    of :mod:`marinefmu.estimators.attitude.estimator`)."""

    def __init__(self, p: AttitudeEstimatorParams) -> None:
        self.p = p
        self.q = euler_to_quat(*p.init_euler)
        self.bias, self.vel, self.pos = np.zeros(3), np.zeros(2), np.zeros(2)
        self.last_gyro = None
        self.levelling, self.level_steps, self.level_sum = p.init == "level", 0, np.zeros(3)
        self.q_rel = np.array([1.0, 0.0, 0.0, 0.0])
        self.since_aid = 0.0
        self.kf = KalmanFilter(dim_x=8, dim_z=4)
        self.kf.P = np.diag([p.pos_sigma ** 2] * 2 + [p.vel_sigma ** 2] * 2 + [math.radians(2.0) ** 2] * 2
                            + [p.gyro_bias_sigma ** 2] * 2)
        self.kf.H = np.hstack((np.eye(4), np.zeros((4, 4))))
        self.kf.R = np.diag([p.pos_sigma ** 2] * 2 + [p.vel_sigma ** 2] * 2)
        self.q_diag = np.diag([0.0, 0.0] + [p.acc_noise ** 2] * 2 + [0.0] * 4)
        self.acc_mean, self.leak_v, self.ms_v, self.weight, self.stats_time = None, np.zeros(2), np.zeros(2), 0.0, 0.0
        self.meter = WhiteNoiseMeter(att.STATS_TAU)
        self.set_gyro_noise(p.gyro_noise, p.gyro_bias_sigma)

    def set_gyro_noise(self, n: float, sigma_b: float) -> None:
        self.q_diag[4, 4] = self.q_diag[5, 5] = n ** 2
        self.q_diag[6, 6] = self.q_diag[7, 7] = 2.0 * sigma_b ** 2 / self.p.gyro_bias_tau

    @staticmethod
    def integrate(q, omega, dt):
        qn = quat_mul(q, quat_from_rotvec(omega * dt))
        return qn / math.sqrt(qn @ qn)

    def step(self, gyro, acc, dt):
        p = self.p
        gyro, acc = np.array(gyro, dtype=float), np.array(acc, dtype=float)
        if p.aid_sizing == "auto":
            self.meter.push(gyro, dt)
        omega = 0.5 * ((gyro if self.last_gyro is None else self.last_gyro) + gyro) - self.bias
        self.last_gyro = gyro
        if self.levelling:
            if self.level_steps > 0:
                self.q_rel = self.integrate(self.q_rel, omega, dt)
            self.level_sum += quat_to_rot(self.q_rel) @ acc
            self.level_steps += 1
            if self.level_steps * dt >= p.level_time - 1e-9:
                roll, pitch = level_angles(self.level_sum / self.level_steps)
                self.q = quat_mul(euler_to_quat(roll, pitch, p.init_euler[2]), self.q_rel)
                self.levelling = False
            return quat_to_euler(self.q)
        self.q = self.integrate(self.q, omega, dt)
        if p.mode == 0:
            return quat_to_euler(self.q)
        rot = quat_to_rot(self.q)
        f_n = rot @ acc
        self.pos += self.vel * dt + 0.5 * f_n[:2] * dt * dt
        self.vel += f_n[:2] * dt
        if p.aid_sizing == "auto":
            a_h = f_n[:2]
            if self.acc_mean is None:
                self.acc_mean = a_h.copy()
            self.acc_mean += (dt / att.LEAK_TAU) * (a_h - self.acc_mean)
            self.leak_v += (a_h - self.acc_mean - self.leak_v / att.LEAK_TAU) * dt
            beta = dt / att.STATS_TAU
            self.ms_v += beta * (self.leak_v ** 2 - self.ms_v)
            self.weight += beta * (1.0 - self.weight)
            self.stats_time += dt
        F = np.zeros((8, 8))
        F[0:2, 2:4] = np.eye(2)
        F[2:4, 4:6] = [[0.0, -f_n[2]], [f_n[2], 0.0]]
        F[4:6, 6:8] = -rot[0:2, 0:2]
        F[6:8, 6:8] = -np.eye(2) / p.gyro_bias_tau
        self.kf.F, self.kf.Q = np.eye(8) + F * dt, self.q_diag * dt
        self.kf.predict()
        self.since_aid += dt
        if self.since_aid >= 1.0 / p.aid_rate - 1e-9:
            self.since_aid = 0.0
            if p.aid_sizing == "auto" and self.stats_time >= att.LEAK_TAU:
                sigma_v = np.maximum(att.SIGMA_V_MIN, att.AID_GAIN * np.sqrt(self.ms_v / self.weight))
                self.kf.R = np.diag(np.concatenate(((att.POS_RATIO * sigma_v) ** 2, sigma_v ** 2)))
            if p.aid_sizing == "auto" and self.meter.time >= att.NOISE_SETTLE:
                n = max(att.GYRO_NOISE_MIN, self.meter.density(dt))
                self.set_gyro_noise(n, p.gyro_bias_sigma * n / p.gyro_noise)
            self.kf.update(np.concatenate((self.pos, self.vel)))
            dx = self.kf.x.ravel()
            self.pos -= dx[0:2]
            self.vel -= dx[2:4]
            self.q = quat_mul(quat_from_rotvec(np.array([dx[4], dx[5], 0.0])), self.q)
            self.q /= math.sqrt(self.q @ self.q)
            self.bias[0:2] += dx[6:8]
            self.kf.x[:] = 0.0
        return quat_to_euler(self.q)


@pytest.fixture(scope="module")
def record():
    m = VesselMotion(VesselMotionParams.from_flat({"vessel.preset": "polar_supply", "sea.hs": 2.5, "sea.tp": 9.0,
                                                   "imu.x": 5.0, "imu.y": 1.0, "imu.z": -3.0}))
    y = np.array([m.step((k + 1) * 0.01, 0.01) for k in range(9000)])
    return (y[:, [REAL_INDEX[f"imu.gyro.{a}"] for a in "xyz"]], y[:, [REAL_INDEX[f"imu.acc.{a}"] for a in "xyz"]])


@pytest.mark.parametrize("params", [
    AttitudeEstimatorParams(),
    AttitudeEstimatorParams(aid_sizing="fixed", vel_sigma=1.0, pos_sigma=3.0, aid_rate=10.0),
    AttitudeEstimatorParams(mode=0, init="given", init_euler=(0.01, -0.02, 0.3)),
], ids=["defaults", "system", "gyro-only"])
def test_the_step_path_equals_the_plain_reference(record, params):
    """90 s of a vessel in waves, the step changed in the middle (so F's Δt entries and Q Δt are
    rebuilt) and the gyro's noise sized from 10 s on (Q changes at every aid): the angles and the
    covariance agree with the reference to 1e-12."""
    gyro, acc = record
    est, ref = AttitudeEstimator(params), Reference(params)
    for k in range(len(gyro)):
        dt = 0.01 if k < 6000 else 0.02
        r = est.step(gyro[k], acc[k], dt)
        e = ref.step(gyro[k], acc[k], dt)
        np.testing.assert_allclose((r.roll, r.pitch, r.yaw), e, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(est.q, ref.q, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(est.bias, ref.bias, rtol=0.0, atol=1e-15)
    if params.mode == 1:
        np.testing.assert_allclose(est.kf.P, ref.kf.P, rtol=1e-10, atol=1e-18)
        np.testing.assert_allclose(est.kf.R, ref.kf.R, rtol=1e-12)
        np.testing.assert_allclose(est._q_dt, ref.q_diag * 0.02, rtol=1e-12, atol=0.0)  # for the next step


def test_the_update_equals_filterpy():
    rng = np.random.default_rng(3)
    for _ in range(20):
        a = rng.normal(size=(8, 8))
        P = a @ a.T + 0.1 * np.eye(8)
        R = np.diag(rng.uniform(0.1, 2.0, 4))
        z = rng.normal(size=(4, 1))
        kf = KalmanFilter(dim_x=8, dim_z=4)
        kf.P, kf.R, kf.H = P.copy(), R.copy(), np.hstack((np.eye(4), np.zeros((4, 4))))
        kf.update(z)
        dx, p_post = aid_update(P, R, z)
        np.testing.assert_allclose(dx, kf.x, rtol=1e-12, atol=1e-14)
        np.testing.assert_allclose(p_post, kf.P, rtol=1e-12, atol=1e-14)


def test_a_state_restored_mid_run_rebuilds_the_derived_arrays(record):
    """Q Δt and F's Δt entries are derived: a fresh estimator given the state of one that ran
    with auto-sized gyro noise continues bit for bit the same."""
    gyro, acc = record
    a = AttitudeEstimator(AttitudeEstimatorParams())
    for k in range(3000):
        a.step(gyro[k], acc[k], 0.01)
    b = AttitudeEstimator(AttitudeEstimatorParams())
    b.set_state(a.get_state())
    for k in range(3000, 3500):
        assert a.step(gyro[k], acc[k], 0.01) == b.step(gyro[k], acc[k], 0.01)
    np.testing.assert_array_equal(a._q_dt, b._q_dt)
    np.testing.assert_array_equal(a.kf.P, b.kf.P)


@pytest.mark.parametrize("gyro,acc,match", [
    ((np.nan, 0.0, 0.0), (0.0, 0.0, -9.8), "non-finite"),
    ((0.0, 0.0, 0.0), (0.0, np.inf, -9.8), "non-finite"),
    ((0.0, -10.5, 0.0), (0.0, 0.0, -9.8), "gyro sample beyond"),
    ((0.0, 0.0, 0.0), (150.0, 0.0, -150.0), "specific force beyond"),
])
def test_bad_samples_take_the_full_check(gyro, acc, match):
    est = AttitudeEstimator(AttitudeEstimatorParams(init="given"))
    assert est.step((0.0, 0.0, 0.0), (0.0, 0.0, -9.8), 0.01).warning is None
    assert est.step((10.0, -10.0, 0.0), (0.0, 198.0, -9.8), 0.01).warning is None  # at the limits: good
    r = est.step(gyro, acc, 0.01)
    assert match in r.warning and not r.valid
