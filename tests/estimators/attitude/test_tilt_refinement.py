"""Post-processed tilt refinement: a slow tilt error is removed exactly from a synthetic wave
record, the gyro-noise floor matches its closed form on VesselMotion, bad input."""
import logging

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from marinefmu.errors import ParameterError
from marinefmu.estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
from marinefmu.estimators.attitude.tilt_refinement import refine_tilt, tilt_rms_bound_deg
from marinefmu.papers.paper000_semisub import AIDING
from marinefmu.frames import G
from marinefmu.sea.motion_model import REAL_INDEX, VesselMotion, VesselMotionParams

DT = 0.1


def wave_record(seconds=1200.0, scale=1.0):
    """True attitude and specific force of a body rolling, pitching and accelerating at
    0.08-0.12 Hz, and an estimate of it carrying a slow (0.002 Hz + offset) tilt error."""
    t = np.arange(int(seconds / DT)) * DT
    w = 2 * np.pi * t
    euler = np.column_stack((0.05 * np.sin(0.1 * w), 0.03 * np.sin(0.08 * w + 1.0), 0.2 + 0.02 * np.sin(0.11 * w)))
    true = Rotation.from_euler("ZYX", euler[:, ::-1])
    acc_n = np.column_stack((0.5 * np.sin(0.1 * w), 0.4 * np.cos(0.09 * w), 0.3 * np.sin(0.12 * w)))
    f_b = true.inv().apply(acc_n - [0.0, 0.0, G])
    eps = np.column_stack((np.radians(0.5) * np.sin(0.002 * w) + np.radians(0.3),
                           np.radians(-0.4) * np.cos(0.0015 * w), np.zeros_like(t)))
    estimate = Rotation.from_rotvec(-scale * eps) * true
    return true, estimate, f_b


def tilt_error_deg(a, b, keep):
    ea = a.as_euler("ZYX")[keep, ::-1]
    eb = b.as_euler("ZYX")[keep, ::-1]
    return np.degrees(np.abs(ea[:, :2] - eb[:, :2]).max())


def test_a_slow_tilt_error_is_removed_from_a_wave_record():
    true, estimate, f_b = wave_record()
    keep = slice(int(200 / DT), -int(200 / DT))  # 4/cutoff from the ends: the filter's edges
    assert tilt_error_deg(estimate, true, keep) > 0.5
    refined = Rotation.from_quat(refine_tilt(estimate.as_quat(scalar_first=True), f_b, DT, 0.02), scalar_first=True)
    # 0.002 Hz passes the 0.02 Hz Butterworth with gain 1 - 5e-9; the 0.08-0.12 Hz motion is
    # attenuated by (0.02/0.08)^8 = 1.5e-5 (0.5 m/s² -> 8e-6 m/s², 4e-5 deg); two passes
    # leave (ε²)² of the linearisation error: measured 5e-5 deg (the edges' tails included).
    assert tilt_error_deg(refined, true, keep) < 1e-4


def test_the_second_pass_removes_the_small_angle_error_of_a_large_tilt():
    true, estimate, f_b = wave_record(scale=8.0)  # up to 6.4 deg, like hours of a raw MEMS gyro
    keep = slice(int(200 / DT), -int(200 / DT))
    errors = [tilt_error_deg(Rotation.from_quat(refine_tilt(estimate.as_quat(scalar_first=True), f_b, DT, 0.02,
                                                            iterations=n), scalar_first=True), true, keep)
              for n in (1, 2)]
    assert errors[1] < 1e-4 and errors[0] > 1e-2, errors  # measured 5.5e-5 and 0.0145 deg


def test_gyro_noise_floor_matches_its_closed_form_on_vessel_motion():
    """Semi-submersible, Hs 10 m, with gyro errors only (white noise and 10 deg/h bias
    instability): the real-time filter with the paper-000 reproduction's slow fixed aiding keeps ~0.07 deg, the refinement leaves what the
    gyro puts above the cutoff (closed form of tilt_rms_bound_deg) plus the filter's own
    wave-band leakage (0.002-0.003 deg noise-free)."""
    values = {"vessel.preset": "semisub", "sea.hs": 10.0, "sea.tp": 12.0, "sea.heading": 2.6, "sea.seed": 1,
              "imu.x": 41.0, "imu.y": 35.0, "imu.z": -35.0, "imu.acc_noise": 0.0, "imu.acc_bias_instability": 0.0}
    m = VesselMotion(VesselMotionParams.from_flat(values))
    y = np.array([m.step((k + 1) * 0.01, 0.01) for k in range(90000)])
    get = lambda names: y[:, [REAL_INDEX[n] for n in names]]  # noqa: E731
    gyro, acc = get([f"imu.gyro.{a}" for a in "xyz"]), get([f"imu.acc.{a}" for a in "xyz"])
    truth = get(["truth.roll", "truth.pitch"])
    p = AttitudeEstimatorParams(init_euler=(0.0, 0.0, float(y[0, REAL_INDEX["truth.yaw"]])), **AIDING)
    att = estimate_attitude(gyro, acc, 0.01, p)
    refined = Rotation.from_quat(refine_tilt(att["q"], acc, 0.01, 0.02), scalar_first=True).as_euler("ZYX")[:, :0:-1]
    keep = slice(20000, 80000)
    before = np.degrees(np.sqrt(np.mean((np.c_[att["roll"], att["pitch"]][keep] - truth[keep]) ** 2, axis=0)))
    after = np.degrees(np.sqrt(np.mean((refined[keep] - truth[keep]) ** 2, axis=0)))
    floor = np.hypot(tilt_rms_bound_deg(p.gyro_noise, p.gyro_bias_sigma, p.gyro_bias_tau, 0.02), 0.003)
    assert np.all(before > 0.04), before
    assert np.all(after < 1.5 * floor), (after, floor)  # floor 0.0054 deg


@pytest.mark.parametrize("kwargs,match", [
    ({"cutoff": 0.0}, r"cutoff = 0.0 is out of range: must be in \(0.0, 5.0\) \[Hz\]"),
    ({"cutoff": 5.0}, r"cutoff = 5.0 is out of range"),
    ({"dt": -0.1}, r"dt = -0.1 is out of range: must be > 0"),
    ({"iterations": 0}, r"iterations = 0 is out of range"),
])
def test_bad_settings_are_refused_by_name(kwargs, match):
    _, estimate, f_b = wave_record(60.0)
    args = {"dt": DT, "cutoff": 0.02, **kwargs}
    with pytest.raises(ParameterError, match=match):
        refine_tilt(estimate.as_quat(scalar_first=True), f_b, **args)


def test_short_records_and_bad_shapes_are_refused():
    q = np.tile([1.0, 0.0, 0.0, 0.0], (499, 1))
    f = np.tile([0.0, 0.0, -G], (499, 1))
    with pytest.raises(ParameterError, match=r"too short .* 1/cutoff = 50 s \(500 samples\)"):
        refine_tilt(q, f, DT)
    with pytest.raises(ParameterError, match=r"q must be \(N, 4\)"):
        refine_tilt(q, f[:10], DT)
    with pytest.raises(ParameterError, match="no finite sample"):
        refine_tilt(np.tile(q, (2, 1)), np.full((998, 3), np.nan), DT)


def test_bad_samples_are_bridged_with_a_warning(caplog):
    true, estimate, f_b = wave_record()
    f_b[3000:3005] = np.nan
    f_b[4000] = [1e6, 0.0, 0.0]
    with caplog.at_level(logging.WARNING):
        q = refine_tilt(estimate.as_quat(scalar_first=True), f_b, DT, 0.02)
    assert "6 of 12000 acc samples" in caplog.text
    assert np.all(np.isfinite(q))
    keep = slice(int(200 / DT), -int(200 / DT))
    assert tilt_error_deg(Rotation.from_quat(q, scalar_first=True), true, keep) < 1e-3
