"""Paper 002's centre-of-rotation estimator: measurement model against a finite-difference
rigid body, the paper's eq. 11 after the frame change, the angle and derivative kernels,
convergence against VesselMotion's known CR, two-sensor agreement, the angle-error study, and
bad input."""
import logging
import math

import numpy as np
import pytest

from marinefmu.errors import MarineFmuError
from marinefmu.estimators.centre_of_rotation.filter import (
    CentreOfRotation, CentreOfRotationParams, eq11_specific_force, leaky_angle_step, lever_matrix,
    predicted_specific_force,
)
from marinefmu.estimators.centre_of_rotation import filter as cr_filter
from marinefmu.estimators.centre_of_rotation.centred_window import (
    CentredWindow, derivative_gain_error, derivative_increment_gain, derivative_noise_gain, window_samples,
)
from marinefmu.papers import paper002
from marinefmu.frames import G, attitude_kinematics, body_to_euler_rates, euler_rates_to_body, rot_nb

# 8th-order central difference for a second derivative (truncation ~h^8, round-off ~1e-11 here)
FD2 = np.array([-1 / 560, 8 / 315, -1 / 5, 8 / 5, -205 / 72, 8 / 5, -1 / 5, 8 / 315, -1 / 560])
OFFSET = np.array([-5.0, 2.0, 3.5])  # CR relative to the sensor [m, b]


def _euler(t):
    """Analytic attitude (angles, rates, accelerations) of a rolling, pitching, yawing body."""
    amp, w, ph = np.array([0.15, 0.08, 0.1]), np.array([0.7, 0.9, 0.4]), np.array([0.3, 1.1, -0.5])
    return amp * np.sin(w * t + ph), amp * w * np.cos(w * t + ph), -amp * w * w * np.sin(w * t + ph)


def _cr(t):
    """Analytic CR position [m, NED] and its acceleration."""
    amp, w = np.array([0.8, 0.5, 1.2]), np.array([0.6, 0.8, 1.0])
    return amp * np.sin(w * t), -amp * w * w * np.sin(w * t)


def _sensor_position(t):
    return _cr(t)[0] - rot_nb(*_euler(t)[0]) @ OFFSET


@pytest.mark.parametrize("t", [0.0, 3.7, 12.25])
def test_measurement_model_matches_a_finite_difference_rigid_body(t):
    h = 0.01
    acc_sensor = sum(c * _sensor_position(t + (i - 4) * h) for i, c in enumerate(FD2)) / h ** 2
    e, ed, edd = _euler(t)
    rot, w, a = attitude_kinematics(list(e), list(ed), list(edd))
    measured = rot.T @ (acc_sensor - np.array([0.0, 0.0, G]))
    model = predicted_specific_force(rot, _cr(t)[1], OFFSET, w, a)
    assert np.max(np.abs(model - measured)) < 1e-9
    # the paper's model (no centripetal term) misses ω × (ω × o): visible at this resolution
    paper = predicted_specific_force(rot, _cr(t)[1], OFFSET, w, a, centripetal=False)
    assert np.max(np.abs(paper - measured)) > 1e-4
    assert np.allclose(paper - model, np.cross(w, np.cross(w, OFFSET)), atol=1e-12)


def test_eq11_as_printed_equals_ours_after_the_frame_change():
    """Paper frames are ours rotated by π about x (y port, z up): C = diag(1, -1, -1) maps body
    and world vectors, roll keeps its sign, pitch and yaw flip, and the paper's r points from
    the CR to the sensor (r = -o). Eq. 11 drops ψ̈, so α_z = 0 here."""
    rng = np.random.default_rng(3)
    c = np.diag([1.0, -1.0, -1.0])
    for _ in range(5):
        roll, pitch, yaw = rng.uniform(-0.4, 0.4, 3)
        alpha = np.array([*rng.normal(0.0, 0.05, 2), 0.0])
        acc_cr = rng.normal(0.0, 1.0, 3)
        ours = predicted_specific_force(rot_nb(roll, pitch, yaw), acc_cr, OFFSET, rng.normal(0.0, 0.1, 3), alpha,
                                        centripetal=False)
        paper = eq11_specific_force((roll, -pitch, -yaw), (alpha[0], -alpha[1], 0.0), c @ acc_cr, c @ -OFFSET)
        assert np.allclose(paper, c @ ours, atol=1e-12)


def test_lever_matrix_is_the_cross_products():
    w, a = np.array([0.1, -0.2, 0.05]), np.array([0.03, 0.01, -0.02])
    assert np.allclose(lever_matrix(w, a) @ OFFSET, np.cross(a, OFFSET) + np.cross(w, np.cross(w, OFFSET)), atol=1e-15)
    assert np.allclose(lever_matrix(w, a, centripetal=False) @ OFFSET, np.cross(a, OFFSET), atol=1e-15)


def test_euler_rates_invert_the_body_rates():
    euler, ed = np.array([0.3, -0.2, 1.0]), np.array([0.05, -0.02, 0.01])
    w, _ = euler_rates_to_body(euler, ed, np.zeros(3))
    assert np.allclose(body_to_euler_rates(list(euler), list(w)), ed, atol=1e-15)


def test_high_pass_angle_settles_at_rate_over_cutoff():
    """A constant roll rate (a gyro bias) integrates to φ = p/ω_c instead of growing."""
    euler, fc, p = [0.0, 0.0, 0.0], 0.01, 1e-4
    for _ in range(100_000):  # 1000 s = 63 time constants at 100 Hz
        euler = leaky_angle_step(euler, [p, 0.0, 0.0], 0.01, fc)
    assert euler[0] == pytest.approx(p / (2 * math.pi * fc), rel=1e-9)


def test_savgol_derivative_is_exact_for_a_quartic():
    dt, win = 0.01, CentredWindow(1, 31, 0.01, polyorder=4)
    x = lambda t: 1.0 - 2.0 * t + 0.5 * t ** 2 + 0.3 * t ** 3 - 0.1 * t ** 4  # noqa: E731
    for k in range(31):
        out = win.push([x(k * dt)])
    tc = 15 * dt
    assert out[2][0] == pytest.approx(-2.0 + tc + 0.9 * tc ** 2 - 0.4 * tc ** 3, abs=1e-9)
    assert out[0][0] == x(tc) and win.delay == pytest.approx(0.15)


def test_derivative_noise_and_loss_kernels():
    """Σd² and Σ(Δd)² against seeded white noise (2 % at 200,000 samples), the loss against the
    derivative of a sampled sine."""
    dt, n = 0.01, window_samples(2.0, 0.01, 4)
    noise = np.random.default_rng(5).normal(0.0, 1.0, 200_000)
    w = CentredWindow(1, n, dt, 4)
    d = np.array([out[2][0] for x in noise if (out := w.push([x])) is not None])
    assert np.var(d) == pytest.approx(derivative_noise_gain(n, dt, 4), rel=0.02)
    assert np.var(np.diff(d)) == pytest.approx(derivative_increment_gain(n, dt, 4), rel=0.02)
    omega = 2 * math.pi * 0.25
    w = CentredWindow(1, n, dt, 4)
    outs = [w.push([math.sin(omega * k * dt)]) for k in range(n)]
    tc = (n // 2) * dt
    assert outs[-1][2][0] == pytest.approx((1 - derivative_gain_error(n, dt, 4, omega)) * omega * math.cos(omega * tc),
                                           rel=1e-9)
    assert derivative_gain_error(n, dt, 4, 0.0) == 0.0
    assert 0 < derivative_gain_error(n, dt, 4, 0.5 * omega) < derivative_gain_error(n, dt, 4, omega) < 0.1


def _noisy_rotation(n, start=0, gyro_noise=5e-5, dt=0.01):
    """A slow small rotation (0.1 Hz, α ≈ 4e-3 rad/s²) sensed by a gyro of white-noise density
    ``gyro_noise`` [rad/s/√Hz] and a noiseless accelerometer: the noise dominates Δα."""
    rng = np.random.default_rng(11 + start)
    for k in range(start, start + n):
        t = (k + 1) * dt
        gyro = np.array([0.006 * math.sin(0.63 * t), 0.004 * math.cos(0.55 * t), 0.001 * math.sin(0.4 * t)])
        yield [0.05 * math.sin(0.6 * t), 0.04 * math.cos(0.5 * t), -G], gyro + rng.normal(0, gyro_noise / math.sqrt(dt), 3)


def test_auto_window_grows_when_gyro_noise_dominates_and_survives_a_state_round_trip():
    est = CentreOfRotation()
    for acc, gyro in _noisy_rotation(5_900):
        est.step(acc, gyro, 0.01)
    assert est.window_s == 1.5                      # sized only after 60 s filtered
    saved = est.get_state()
    rest = [est.step(acc, gyro, 0.01) for acc, gyro in _noisy_rotation(1_000, start=5_900)]
    assert est.window_s > 3.0 and est.window.n == window_samples(est.window_s, 0.01, 4)
    assert rest[-1].delay == pytest.approx(est.window.delay)
    # the centre moved back: the samples it passes again are not filtered twice (valid false)
    assert any(not r.valid for r in rest[200:]) and rest[-1].valid
    other = CentreOfRotation()
    other.set_state(saved)
    assert [other.step(acc, gyro, 0.01) for acc, gyro in _noisy_rotation(1_000, start=5_900)] == rest
    fixed = CentreOfRotation(CentreOfRotationParams(diff_sizing="fixed"))
    for acc, gyro in _noisy_rotation(6_300):
        fixed.step(acc, gyro, 0.01)
    assert fixed.window_s == 1.5 and fixed.window.n == window_samples(1.5, 0.01, 4)


def test_auto_window_brings_a_far_imu_on_a_large_ship_near_the_floor():
    """polar_supply, Hs 3 m / Tp 10 s, IMU 51 m from the CR, MEMS gyro, 600 s: the 1.5 s window
    leaves the final estimate 6.0 m above the record's floor (the gyro noise in α pulls it to the
    sensor; docs/decisions/centre-of-rotation-defaults.md); the window sized from the data
    (3-4 s here) leaves 0.63 m. Limit 0.8 m."""
    from marinefmu.bench.cases import case_record, placements
    from marinefmu.bench.defaults_cr import CR, cr_errors
    sensor = placements("polar_supply")["far"]
    rec = case_record("polar_supply", 3.0, 10.0, "far",
                      extra={"vessel.mode": 1, **{f"vessel.cr.{a}": v for a, v in zip("xyz", CR)}})
    r = cr_errors(rec, sensor, paper002.truth_floor(rec, sensor))
    assert r["valid"] > 0.99
    assert r["merit"] < 0.8, r


def test_auto_window_stays_short_for_a_clean_gyro():
    """Without gyro noise only the derivative's loss counts: the shortest window is chosen."""
    est = CentreOfRotation()
    for acc, gyro in _noisy_rotation(6_300, gyro_noise=0.0):
        est.step(acc, gyro, 0.01)
    assert est.window_s == cr_filter.WINDOW_CHOICES[0]


# ---- against known truth (VesselMotion, vessel.mode 1, default MEMS noise, 10 minutes) ----------
@pytest.fixture(scope="module")
def convergence():
    return paper002.convergence()


def test_both_sensors_reach_the_floor_of_the_record(convergence):
    """The filter settles where the record's sample correlation puts any estimator of its model
    (the floor, computed from exact data): within 0.1 m per axis with MEMS noise and the
    high-pass angles (measured 0.06 / 0.09 m in y). The floor itself is 0.5 m in y here, which is
    why the absolute 0.1 m goal needs weaker translations (next test) or longer records."""
    for name in paper002.SENSORS:
        r = convergence[name]
        assert np.all(np.abs(r["error"] - r["floor"]) < 0.1), (name, r)


def test_two_sensors_on_one_rigid_body_agree(convergence):
    """The floor is the same for every sensor position, so the CR estimates agree (0.2 m goal;
    measured 0.06 m)."""
    assert np.all(np.abs(convergence["agreement"]["final"]) < 0.2)
    assert np.all(np.abs(convergence["agreement"]["mean"]) < 0.2)


def test_offset_error_below_10_cm_when_the_floor_allows():
    """Translations 20x weaker than the rotations' lever effects (floor 0.03 m): the estimate
    is within 0.1 m of the true CR after 10 minutes with MEMS noise (measured 0.058 m)."""
    res = paper002.weak_translation()
    for name in paper002.SENSORS:
        assert np.all(np.abs(res[name]["error"]) < 0.1), (name, res[name])


def test_angle_errors_in_phase_with_the_motion_move_the_cr_height():
    """Paper 002's z discrepancy: a constant misalignment is absorbed (|Δz| < 5 cm at 1°), an
    error proportional to the angle is not (|Δz| > 1 m at 1° RMS; measured 3.4 m), the
    high-pass angles add 0.4 m at 0.05 Hz, and the drift-corrected attitude removes it.
    5 minutes per run here (the example runs 10: 3.5 m)."""
    rows = {r[0]: r for r in paper002.angle_errors(duration=300.0)["rows"]}
    assert abs(rows["misaligned 1.0°"][4]) < 0.05
    assert abs(rows["proportional 1.0°"][4]) > 1.0
    assert abs(rows["proportional 0.1°"][4]) < abs(rows["proportional 1.0°"][4]) / 5
    assert abs(rows["high-pass 0.05 Hz"][4]) > 5 * abs(rows["high-pass 0.005 Hz"][4])
    assert np.all(np.abs(rows["AttitudeEstimator"][2:]) < 0.05)


# ---- bad input ----------------------------------------------------------------------------------
@pytest.mark.parametrize("field,value,message", [
    ("acc_sigma", 0.0, "acc_sigma = 0.0 is out of range"),
    ("acc_rw", -1.0, "acc_rw = -1.0 is out of range"),
    ("offset_rw", 0.0, "offset_rw = 0.0 is out of range"),
    ("offset_sigma0", 0.0, "offset_sigma0 = 0.0 is out of range"),
    ("hp_cutoff", 0.0, "hp_cutoff = 0.0 is out of range"),
    ("hp_cutoff", -0.1, "hp_cutoff = -0.1 is out of range"),
    ("diff_window", 0.0, "diff_window = 0.0 is out of range"),
    ("angles", "gyro", "angles = 'gyro' is not allowed"),
    ("diff_sizing", "sometimes", "diff_sizing = 'sometimes' is not allowed"),
    ("centripetal", "yes", "centripetal must be True or False"),
])
def test_bad_parameters_are_refused_by_name(field, value, message):
    with pytest.raises(MarineFmuError, match=message):
        CentreOfRotationParams(**{field: value})


def _drive(est, n, start=0, bad=None):
    rng = np.random.default_rng(start)
    out = []
    for k in range(start, start + n):
        t = (k + 1) * 0.01
        acc = [0.3 * math.sin(t), 0.2 * math.cos(0.7 * t), -G + 0.1 * math.sin(1.3 * t)] + rng.normal(0, 0.01, 3)
        gyro = [0.02 * math.cos(0.9 * t), 0.01 * math.sin(0.6 * t), 0.0]
        if bad is not None and k == bad[0]:
            acc[bad[1]] = bad[2]
        out.append(est.step(acc, gyro, 0.01, [0.01, 0.0, 0.0]))
    return out


@pytest.mark.parametrize("value", [math.nan, math.inf, 1e6])
def test_bad_sample_holds_with_valid_false_and_a_warning(value, caplog):
    est = CentreOfRotation()
    _drive(est, 300)
    with caplog.at_level(logging.WARNING):
        r = _drive(est, 2, start=300, bad=(300, 1, value))
    assert not r[0].valid and r[0].warning is not None and r[1].valid
    assert all(np.isfinite(v) for f in ("offset", "offset_std", "acc_cr", "acc_cr_n", "euler") for v in getattr(r[0], f))
    assert "holding the last good sample" in caplog.text


def test_nan_angle_input_is_a_bad_sample():
    est = CentreOfRotation(CentreOfRotationParams(angles="input"))
    _drive(est, 300)
    r = est.step([0.0, 0.0, -G], [0.0, 0.0, 0.0], 0.01, [math.nan, 0.0, 0.0])
    assert not r.valid and "roll, pitch or yaw" in r.warning


def test_first_sample_bad_gives_invalid_zero_output():
    r = CentreOfRotation().step([math.nan, 0.0, -G], [0.0, 0.0, 0.0], 0.01)
    assert not r.valid and r.offset == (0.0, 0.0, 0.0)


def test_step_size_change_restarts_the_window():
    est = CentreOfRotation(CentreOfRotationParams(diff_window=0.1))
    _drive(est, 50)
    r = est.step([0.0, 0.0, -G], [0.0, 0.0, 0.0], 0.02)
    assert not r.valid and "step size changed" in r.warning


def test_state_round_trip_reproduces_the_run():
    est = CentreOfRotation()
    _drive(est, 400)
    saved = est.get_state()
    first = _drive(est, 100, start=400)
    other = CentreOfRotation()
    other.set_state(saved)
    assert _drive(other, 100, start=400) == first


# ---- the per-step float path against the array forms it writes out ----------------------------
def test_joseph_update_equals_filterpy_update():
    from filterpy.kalman import KalmanFilter
    rng = np.random.default_rng(21)
    kf = KalmanFilter(dim_x=6, dim_z=3)
    a = rng.normal(size=(6, 6))
    kf.P, kf.x, kf.R = a @ a.T + np.eye(6), rng.normal(size=(6, 1)), np.eye(3) * 4e-4
    for _ in range(20):
        kf.H, z = rng.normal(size=(3, 6)), rng.normal(size=(3, 1))
        x, P = cr_filter.joseph_update(kf.x, kf.P, kf.H, z, 4e-4)
        kf.update(z)
        assert np.allclose(x, kf.x, rtol=1e-12, atol=0.0) and np.allclose(P, kf.P, rtol=1e-12, atol=1e-15)


def test_inv3_equals_numpy_inverse():
    rng = np.random.default_rng(8)
    for _ in range(50):
        a = rng.normal(size=(3, 3))
        s = a @ a.T + 1e-3 * np.eye(3)
        assert np.allclose(cr_filter.inv3(s), np.linalg.inv(s), rtol=1e-9, atol=0.0)
        assert np.allclose(cr_filter.inv3(s) @ s, np.eye(3), atol=1e-9)
        assert np.allclose(cr_filter.inv3(s, 0.5), np.linalg.inv(s + 0.5 * np.eye(3)), rtol=1e-9, atol=0.0)


def test_step_equals_filterpy_on_the_array_forms():
    """Each filtered step against a filterpy KalmanFilter fed the same centre sample through
    frames.rot_nb and measurement_matrix, through a start without rotation (offset held) and
    then rotating: H equal, state, covariance and outputs to 1e-12 (the 3 × 3 inverse is
    written out; the rest is the same operations)."""
    from filterpy.kalman import KalmanFilter
    from marinefmu.frames import GRAVITY_N
    dt, n_win = 0.01, window_samples(1.5, 0.01, 4)
    p = CentreOfRotationParams(angles="input", diff_sizing="fixed", sensor=(5.0, 1.0, -3.0))
    est, ref = CentreOfRotation(p), KalmanFilter(dim_x=6, dim_z=3)
    ref.P, ref.R = est.kf.P.copy(), est.kf.R.copy()
    ref.Q = np.diag([p.acc_rw ** 2 * dt] * 3 + [p.offset_rw ** 2 * dt] * 3)
    win = CentredWindow(9, n_win, dt, 4)
    rng = np.random.default_rng(4)
    held = 0
    for k in range(5000):
        t = (k + 1) * dt
        s = 0.0 if k < 3000 else 1.0                    # no rotation for 30 s: offset held
        e, ed, edd = _euler(t)
        e, ed, edd = s * e, s * ed, s * edd
        rot, w, a = attitude_kinematics(list(e), list(ed), list(edd))
        acc = rot.T @ (_cr(t)[1] - np.array([0.0, 0.0, G])) - (np.cross(a, OFFSET) + np.cross(w, np.cross(w, OFFSET)))
        gyro = w + rng.normal(0.0, 1e-4, 3)
        r = est.step(acc, gyro, dt, e)
        centre = win.push(np.concatenate((gyro, acc, e)))
        if centre is None:
            continue
        raw, smooth, deriv = centre
        ref.predict()
        rot = rot_nb(*raw[6:9])
        ref.H = cr_filter.measurement_matrix(rot, smooth[0:3], deriv[0:3])
        if not r.valid:
            held += 1
            ref.H[:, 3:6] = 0.0
            ref.P[0:3, 3:6] = ref.P[3:6, 0:3] = 0.0
        ref.update(raw[3:6] + rot.T @ GRAVITY_N)
        assert np.array_equal(est.kf.H, ref.H), k
        assert np.allclose(est.kf.x, ref.x, rtol=1e-12, atol=1e-12), k
        assert np.allclose(est.kf.P, ref.P, rtol=1e-12, atol=1e-15), k
        ref.x, ref.P = est.kf.x.copy(), est.kf.P.copy()     # compare each step, not the drift of rounding
        acc_cr = raw[3:6] - ref.H[:, 3:6] @ ref.x[3:6, 0]
        assert np.allclose(r.acc_cr, acc_cr, rtol=1e-12, atol=1e-12), k
        assert np.array_equal(r.offset_std, np.sqrt(np.diag(ref.P)[3:6])) and r.euler == tuple(raw[6:9])
        assert r.ang_acc == tuple(deriv[0:3]) and np.array_equal(r.acc_cr_n, ref.x[0:3, 0])
    assert 2500 < held < 3000 and r.valid


@pytest.mark.parametrize("acc,gyro,euler", [
    ([0.0, 0.0, -G], [0.0, 0.0, 0.0], None), ([0.0, 0.0, -G], [0.0, 0.0, 0.0], [0.1, -0.2, 3.0]),
    ([200.0, 0.0, 0.0], [0.0, 0.0, 0.0], None), ([199.99999, 0.0, 0.0], [0.0, 0.0, 0.0], None),
    ([200.00001, 0.0, 0.0], [0.0, 0.0, 0.0], None), ([0.0, 0.0, -G], [0.0, -10.0, 0.0], None),
    ([0.0, 0.0, -G], [0.0, 10.000001, 0.0], None), ([1e308, 1e308, 0.0], [0.0, 0.0, 0.0], None),
    ([math.inf, -math.inf, 0.0], [0.0, 0.0, 0.0], None), ([0.0, 0.0, -G], [math.nan, 0.0, 0.0], None),
    ([0.0, 0.0, -G], [0.0, 0.0, 0.0], [math.nan, 0.0, 0.0]), ([0.0, 0.0, -G], [0.0, 0.0, 0.0], [0.0, 1.4, 0.0]),
    ([0.0, 0.0, -G], [0.0, 0.0, 0.0], [0.0, 0.0, 2e4]), ([0.0, 0.0, -G], [0.0, 0.0, 0.0], [math.radians(80.0), 0.0, 1e4]),
])
def test_float_sample_check_agrees_with_the_array_check(acc, gyro, euler):
    """The per-step float test passes only samples the array check passes."""
    verdict = cr_filter._bad_sample(acc, gyro, euler)
    if cr_filter._plainly_good(acc, gyro, euler):
        assert verdict is None
    else:
        assert verdict is not None or abs(math.hypot(*acc) - 200.0) < 1e-3 or not math.isfinite(sum(acc))
