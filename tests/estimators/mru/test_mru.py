"""The MotionReferenceUnit against VesselMotion's truth, its refusals, its bad samples, its
heading aid and its state."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from marinefmu import MotionReferenceUnit, MotionReferenceUnitParams, ParameterError
from marinefmu.bench.cases import DT, case_record
from marinefmu.bench.mru import rate_case, run_mru
from marinefmu.estimators.attitude.estimator import AttitudeEstimatorParams
from marinefmu.estimators.heave.common import HeaveObserverParams
from marinefmu.estimators.mru.goals import rms_about_mean
from marinefmu.estimators.mru.unit import RECOVERY
from marinefmu.sea.motion_model import point_truth, stack

ARMS = ((20.0, 5.0, -5.0), (59.0, 0.0, -10.0))


@pytest.fixture(scope="module")
def polar():
    """polar_supply in Hs 3 m / Tp 10 s, IMU at the COG, 400 s, and the unit's run on it."""
    rec = case_record("polar_supply", 3.0, 10.0, "cog", duration=400.0)
    return rec, run_mru(rec, MotionReferenceUnitParams(points=ARMS))


def errors_cm(rec, out, row, arm, k0=15000):
    pos, _ = point_truth(rec, arm)
    lag = int(round(float(out["delay"]) / DT))
    rt = 100 * rms_about_mean(out["position"][k0:, row] - pos[k0:])
    delayed = 100 * rms_about_mean(out["delayed"][k0 + lag:, row] - pos[k0:len(pos) - lag])
    return rt, delayed, 100 * np.std(pos[k0:], axis=0)


def test_real_time_and_delayed_motion_at_the_imu_meet_the_goals(polar):
    """At the IMU (surge / sway / heave std 25 / 33 / 56 cm): real-time heave within the goal
    max(2 cm, 2.5 %), surge and sway within 2.5 and 4.5 cm (measured 2.23 / 3.60 cm on this
    record from 150 s; the goal max(2 cm, 5 %) is 2 cm: the attitude's tilt error, g·ε in the
    horizontal acceleration, is most of the gap), and the delayed outputs below half the
    real-time error on every axis."""
    rec, out = polar
    rt, delayed, std = errors_cm(rec, out, 0, (0.0, 0.0, 0.0))
    assert rt[2] <= max(2.0, 0.025 * std[2])
    assert rt[0] <= 2.5 and rt[1] <= 4.5
    assert np.all(delayed <= 0.5 * rt)


def test_a_monitoring_point_adds_its_lever_arms_motion(polar):
    """20 m forward (heave std 61 cm): heave within 2.5 cm, no more than 0.6 cm worse than at
    the IMU (the attitude's error times 21 m); the point's motion differs from the IMU's by
    decimetres, so a transfer left out would miss by that."""
    rec, out = polar
    rt_imu, _, _ = errors_cm(rec, out, 0, (0.0, 0.0, 0.0))
    rt, delayed, std = errors_cm(rec, out, 1, ARMS[0])
    assert rt[2] <= 2.5 and rt[2] <= rt_imu[2] + 0.6
    assert np.all(delayed <= rt)
    imu, _ = point_truth(rec, (0.0, 0.0, 0.0))
    point, _ = point_truth(rec, ARMS[0])
    assert 100 * np.std(point[:, 2] - imu[:, 2]) > 10 * rt[2]


def band_rms(x: np.ndarray, lo: float, hi: float) -> float:
    """RMS of ``x`` (sampled at DT) between ``lo`` and ``hi`` rad/s (Welch, 20 s segments)."""
    from scipy import signal

    f, p = signal.welch(x - x.mean(), fs=1.0 / DT, nperseg=int(20.0 / DT))
    w = 2.0 * np.pi * f
    return float(np.sqrt(np.sum(p[(w >= lo) & (w < hi)]) * (f[1] - f[0])))


def test_a_points_rate_carries_the_gyros_noise_and_no_more(polar):
    """59.8 m from the IMU: the heave rate's error between 5 and 20 rad/s (where a heave
    compensator's feedforward still reaches its winch) is within 1.15 × the gyro's own noise
    times the arm, [R (ω_measured − ω_true) × r]_d from the truth (measured 1.0 ×; a quartic
    fit differentiating the estimated angles left 2.2 ×: the attitude's corrections), and the
    rate errs under 0.5 cm/s in the wave band, 0.2-2 rad/s (measured 0.36 cm/s, the fit 0.66;
    the point's heave rate std is 85 cm/s)."""
    rec, out = polar
    arm = np.array(ARMS[1])
    k0 = 15000
    _, vel = point_truth(rec, ARMS[1])
    err = out["velocity"][k0:, 2, 2] - vel[k0:, 2]
    angles = np.column_stack([rec["truth.roll"], rec["truth.pitch"], rec["truth.yaw"]])[k0:]
    from marinefmu.frames import rot_nb
    gyro_error = stack(rec, "imu.gyro")[k0:] - stack(rec, "truth.rate")[k0:]
    floor = np.array([rot_nb(*a)[2] @ np.cross(w, arm) for a, w in zip(angles, gyro_error)])
    assert band_rms(err, 5.0, 20.0) <= 1.15 * band_rms(floor, 5.0, 20.0)
    assert 100 * band_rms(err, 0.2, 2.0) <= 0.5


def test_the_turn_rate_is_the_derivative_of_the_wave_frequency_turn():
    """``turn_rate_rows`` of the body rate and the slow yaw rate is dR/dt of R = R_nb(φ, θ, ψ_w)
    for a body turning slowly (ψ = ψ_s + ψ_w, ψ̇_s = 0.5°/s) while it rolls, pitches and yaws
    in waves: against a central difference, to its O(Δt²) error."""
    from marinefmu.estimators.mru.level_frame import turn_rate_rows
    from marinefmu.frames import rot_nb

    def angles(t):
        return (0.1 * math.sin(0.7 * t), 0.05 * math.sin(0.9 * t + 1.0), 0.03 * math.sin(0.6 * t + 2.0))

    def rates(t):                                    # φ̇, θ̇ and the wave yaw's ψ̇_w
        return (0.07 * math.cos(0.7 * t), 0.045 * math.cos(0.9 * t + 1.0), 0.018 * math.cos(0.6 * t + 2.0))

    slow = math.radians(0.5)
    h = 1e-5
    for t in (0.0, 3.3, 17.0):
        (phi, theta, psi_w), (dphi, dtheta, dpsi_w) = angles(t), rates(t)
        dpsi = slow + dpsi_w                         # the whole yaw's rate, as the gyro sees it
        body = (dphi - dpsi * math.sin(theta),
                dtheta * math.cos(phi) + dpsi * math.cos(theta) * math.sin(phi),
                -dtheta * math.sin(phi) + dpsi * math.cos(theta) * math.cos(phi))
        rot = rot_nb(phi, theta, psi_w)
        expected = (rot_nb(*angles(t + h)) - rot_nb(*angles(t - h))) / (2 * h)
        np.testing.assert_allclose(np.reshape(turn_rate_rows(tuple(rot.ravel()), body, slow), (3, 3)), expected,
                                   rtol=0, atol=1e-9)


def test_roll_and_pitch_are_the_attitude_estimators(polar):
    """Same IMU, same estimator at its defaults: the angles are its own to the last bit."""
    from marinefmu.estimators.attitude.estimator import estimate_attitude

    rec, out = polar
    att = estimate_attitude(stack(rec, "imu.gyro"), stack(rec, "imu.acc"), DT, AttitudeEstimatorParams())
    np.testing.assert_array_equal(out["roll"], att["roll"])
    np.testing.assert_array_equal(out["pitch"], att["pitch"])


@pytest.mark.parametrize("points, named", [
    (((0.0, 0.0, 0.0), (150.0, 150.0, 0.0)), "mp2"),
    (((math.nan, 0.0, 0.0),), "mp1"),
    (((0.0, math.inf, 0.0),), "mp1"),
    (((1.0, 0.0, 0.0),) * 5, "points"),
])
def test_bad_monitoring_points_are_refused_naming_them(points, named):
    with pytest.raises(ParameterError, match=named):
        MotionReferenceUnitParams(points=points)


def test_other_refusals_name_the_parameter():
    with pytest.raises(ParameterError, match="heading_tau"):
        MotionReferenceUnitParams(heading_tau=0.0)
    with pytest.raises(ParameterError, match="motion.model"):
        MotionReferenceUnitParams(motion=HeaveObserverParams(model="band"))


def short_params(**kw):
    return MotionReferenceUnitParams(motion=HeaveObserverParams(window=45.0, omega_min=0.3, smoother_lag=10.0),
                                     points=((20.0, 0.0, -5.0),), **kw)


@pytest.fixture(scope="module")
def short():
    return case_record("polar_supply", 3.0, 10.0, "cog", duration=120.0)


def test_a_bad_sample_holds_warns_and_recovers(short):
    """NaN, Inf and an absurd specific force after the filters are designed: valid false, a
    warning, every output finite; valid again on the next good sample."""
    gyro, acc = stack(short, "imu.gyro"), stack(short, "imu.acc")
    mru = MotionReferenceUnit(short_params(), quiet=True)
    bad_at = {9000: math.nan, 9500: math.inf, 10000: 1e6}
    seen = []
    for k in range(len(acc)):
        a = acc[k].copy()
        if k in bad_at:
            a[k % 3] = bad_at[k]
        r = mru.step(gyro[k], a, DT)
        for v in (r.position, r.velocity, r.heave_acc, r.delayed_position):
            assert np.all(np.isfinite(v))
        assert math.isfinite(r.roll) and math.isfinite(r.yaw)
        if k in bad_at:
            seen.append((r.valid, r.motion_valid, r.warning is not None))
        elif k - 1 in bad_at:
            assert r.valid and not r.motion_valid           # the angles at once, the motion after RECOVERY samples
        elif k - 1 - RECOVERY in bad_at:
            assert r.valid and r.motion_valid
    assert seen == [(False, False, True)] * 3


def test_the_outputs_are_zero_until_their_flags_first_hold(short):
    """Before ``motion_valid`` every motion output is zero, and the delayed outputs stay zero
    until ``delayed_valid`` (the filters have run through the time they refer to), at the IMU
    and at the point; from then on they move."""
    gyro, acc = stack(short, "imu.gyro"), stack(short, "imu.acc")
    mru = MotionReferenceUnit(short_params(), quiet=True)
    seen = {"motion": False, "delayed": False}
    for k in range(len(acc)):
        r = mru.step(gyro[k], acc[k], DT)
        seen["motion"] |= r.motion_valid
        seen["delayed"] |= r.delayed_valid
        if not seen["motion"]:
            assert not np.any(r.position) and not np.any(r.velocity) and not np.any(r.heave_acc)
        if not seen["delayed"]:
            assert not np.any(r.delayed_position), k
    assert seen["delayed"] and np.all(np.abs(r.delayed_position[:, 2]) > 0.0)


def test_a_heading_input_turns_the_yaw_to_north(short):
    """A heading 0.5 rad off the gyro-integrated yaw: after 3 τ of the aid the yaw output is
    within 0.05 rad of it (e^-3 of the offset), and roll, pitch and motion are unchanged."""
    gyro, acc = stack(short, "imu.gyro"), stack(short, "imu.acc")
    heading = short["truth.yaw"] + 0.5
    plain, aided = MotionReferenceUnit(short_params(), quiet=True), MotionReferenceUnit(short_params(heading_tau=10.0),
                                                                                        quiet=True)
    for k in range(len(acc)):
        a = plain.step(gyro[k], acc[k], DT)
        b = aided.step(gyro[k], acc[k], DT, float(heading[k]), k > 1000)
    assert not a.heading_used and b.heading_used
    assert abs(math.remainder(b.yaw - heading[-1], 2 * math.pi)) < 0.05
    assert b.roll == a.roll and np.array_equal(b.position, a.position)


def test_a_restored_state_continues_bit_identically(short):
    gyro, acc = stack(short, "imu.gyro"), stack(short, "imu.acc")
    mru = MotionReferenceUnit(short_params(), quiet=True)
    for k in range(6000):
        mru.step(gyro[k], acc[k], DT)
    copy = MotionReferenceUnit(short_params(), quiet=True)
    copy.set_state(mru.get_state())
    for k in range(6000, 7000):
        a, b = mru.step(gyro[k], acc[k], DT), copy.step(gyro[k], acc[k], DT)
        assert np.array_equal(a.position, b.position) and a.yaw == b.yaw and a.motion_valid == b.motion_valid
    assert a.motion_valid


def test_a_step_size_change_restarts_with_a_warning(short):
    gyro, acc = stack(short, "imu.gyro"), stack(short, "imu.acc")
    mru = MotionReferenceUnit(short_params(), quiet=True)
    for k in range(100):
        mru.step(gyro[k], acc[k], DT)
    r = mru.step(gyro[100], acc[100], 2 * DT)
    assert "step size changed" in r.warning and not r.valid and mru.k == 1


def test_steps_taken_as_differences_of_late_absolute_times_are_one_step(short):
    """A master may pass t_{k+1} − t_k (FMPy does): 56 h into a run at 100 Hz those differ from
    0.01 s by up to 2·10⁻⁹ of the step, a rounding of t: no restart (a tolerance of 10⁻⁹
    restarted on a third of these steps)."""
    gyro, acc = stack(short, "imu.gyro"), stack(short, "imu.acc")
    times = 200000.0 + DT * np.arange(1001)                # as FMPy's start + n × interval
    steps = np.diff(times)
    assert np.mean(np.abs(steps / DT - 1.0) > 1e-9) > 0.2   # the wobble the tolerance has to pass
    mru = MotionReferenceUnit(short_params(), quiet=True)
    warnings = [mru.step(gyro[k], acc[k], float(dt)).warning for k, dt in enumerate(steps)]
    assert mru.k == len(steps) and not any(warnings)


@pytest.mark.parametrize("dt, says", [(0.0, "> 0"), (-0.01, "> 0"), (math.nan, "finite"), (math.inf, "finite")])
def test_a_step_that_is_no_step_is_refused_naming_it_and_nothing_changes(short, dt, says):
    """A step that is not a finite number > 0 is refused, first or mid-run, with a message
    naming ``dt`` and its range; the unit is left as it was and continues bit-identically."""
    gyro, acc = stack(short, "imu.gyro"), stack(short, "imu.acc")
    with pytest.raises(ParameterError, match="dt") as refused:
        MotionReferenceUnit(short_params(), quiet=True).step(gyro[0], acc[0], dt)
    assert says in str(refused.value)
    mru, twin = MotionReferenceUnit(short_params(), quiet=True), MotionReferenceUnit(short_params(), quiet=True)
    for k in range(200):
        mru.step(gyro[k], acc[k], DT)
        twin.step(gyro[k], acc[k], DT)
    with pytest.raises(ParameterError, match="dt"):
        mru.step(gyro[200], acc[200], dt)
    assert mru.k == 200 and mru.dt == DT
    a, b = mru.step(gyro[200], acc[200], DT), twin.step(gyro[200], acc[200], DT)
    assert a.roll == b.roll and a.warning is None


@pytest.mark.parametrize("dt, motion", [(0.5, True), (0.6, False)])
def test_at_a_step_whose_nyquist_is_inside_the_band_only_the_angles_are_given(dt, motion, caplog):
    """0.6 s: π/0.6 = 5.2 rad/s, below omega_max = 6 rad/s. The unit runs (an FMI host may use
    any step) and says why in the log; the angles level and are valid, the motion never is,
    also after a gap. At 0.5 s (π/0.5 = 6.3 rad/s) the same sea gives the motion."""
    rec = case_record("polar_supply", 3.0, 10.0, "cog", duration=400.0, dt=dt)
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    acc[len(acc) // 2] = np.nan                                # a gap half way
    mru = MotionReferenceUnit(short_params())
    with caplog.at_level("WARNING", logger="marinefmu.estimators.mru.unit"):
        flags = [mru.step(gyro[k], acc[k], dt) for k in range(len(acc))]
    assert bool([rec for rec in caplog.records if "Nyquist" in rec.getMessage()]) is not motion
    assert flags[-1].valid and any(r.motion_valid for r in flags) is motion
    assert (flags[-1].motion_valid and flags[-1].delayed_valid) is motion
    assert MotionReferenceUnitParams().longest_step == pytest.approx(math.pi / 6.0)


def test_a_step_coarser_than_measured_runs_with_a_warning(short, caplog):
    """0.25 s (4 Hz) is below the Nyquist limit but coarser than the 10 Hz the accuracy is
    measured at: it runs, and the log says so once."""
    mru = MotionReferenceUnit(short_params())
    with caplog.at_level("WARNING", logger="marinefmu.estimators.mru.unit"):
        for _ in range(3):
            r = mru.step((0.0, 0.0, 0.0), (0.0, 0.0, -9.80665), 0.25)
    coarse = [rec for rec in caplog.records if "coarser than" in rec.getMessage()]
    assert len(coarse) == 1 and "0.25 s" in coarse[0].getMessage() and r.warning is None


def test_at_10_hz_the_unit_meets_every_goal(caplog):
    """The bench's rate case (polar_supply, Hs 3 m / Tp 10 s, IMU at the COG, the four
    monitoring points up to 59.8 m) sampled at 10 Hz, the coarsest rate measured: the joint
    filter takes over at the same time as at 100 Hz (its rows and refits are in seconds), and
    from then every location's real-time surge, sway and heave meets its goal (without the
    causal bound, which would only raise the heave goal), the delayed outputs the real-time
    goal, and roll and pitch stay within 0.02° (0.010-0.017° at 100 Hz across the bench)."""
    with caplog.at_level("WARNING"):
        r = rate_case(10.0, duration=1200.0)
    assert not [rec for rec in caplog.records if rec.name.startswith("marinefmu")]
    assert r["joint_from_s"] == pytest.approx(840.0, abs=1.0) and r["scored_from_s"] >= 840.0
    for p in r["points"]:
        assert np.all(np.array(p["rt_cm"]) <= p["goal_cm"]), p
        assert np.all(np.array(p["delayed_cm"]) <= p["goal_cm"]), p
    assert max(r["roll_deg"], r["pitch_deg"]) <= 0.02


def test_the_level_rotation_the_low_pass_and_the_turn_map_are_the_general_ones_written_out():
    """``level_rows`` is Rz(ψ̄)ᵀ R_nb(q) and ``rot_nb_rows`` R_nb (to rounding); the float
    low-pass is scipy's ``lfilter`` of two first-order stages (from zero, and from the first
    sample), through a state save; ``turn_map`` gives (R − I) r of every arm."""
    from scipy.signal import lfilter

    from marinefmu.estimators.mru.level_frame import SlowLowPass, level_rows, turn_map, yaw_rotation
    from marinefmu.frames import euler_to_quat, quat_to_rot, rot_nb, rot_nb_rows

    for yaw_ref, angles in ((0.3, (0.05, -0.02, 1.1)), (-2.9, (0.2, 0.1, -3.0)), (math.pi, (0.0, 0.0, 0.0))):
        q = euler_to_quat(*angles)
        np.testing.assert_allclose(np.reshape(level_rows(yaw_ref, tuple(q)), (3, 3)),
                                   yaw_rotation(yaw_ref) @ quat_to_rot(q), rtol=0, atol=1e-15)
        np.testing.assert_allclose(np.reshape(rot_nb_rows(*angles), (3, 3)), quat_to_rot(q), rtol=0, atol=1e-15)
        arms = np.array([[25.0, -3.0, -8.0], [0.0, 0.0, 0.0], [-40.0, 12.0, 5.0]])
        rot = rot_nb(*angles)
        np.testing.assert_allclose((turn_map(arms) @ (rot - np.eye(3)).ravel()).reshape(3, 3),
                                   arms @ rot.T - arms, rtol=0, atol=1e-13)
    rng = np.random.default_rng(4)
    x = rng.normal(size=(500, 2))
    alpha = 1.0 - math.exp(-0.01 / 30.0)
    for from_zero in (True, False):
        lp = SlowLowPass(30.0, from_zero=from_zero)
        out = []
        for k, v in enumerate(x):
            out.append(lp.push(list(v), 0.01))
            if k == 250:
                restored = SlowLowPass(30.0, from_zero=from_zero)
                restored.set_state(json.loads(json.dumps(lp.get_state())))
                lp = restored
        # from zero: both stages start at 0; else the first sample starts both and is returned as is
        given, start = (x, np.zeros(2)) if from_zero else (x[1:], x[0])
        expected = given
        for _ in range(2):
            expected = lfilter([alpha], [1.0, alpha - 1.0], expected, axis=0, zi=[(1.0 - alpha) * start])[0]
        np.testing.assert_allclose(out, expected if from_zero else np.vstack([x[:1], expected]), rtol=1e-12, atol=1e-15)


def test_the_scalar_low_pass_and_the_location_map_repeat_the_general_ones():
    """``SlowLowPass.push_one`` is ``push`` of a one-entry list bit for bit (its start, a step
    change and a state save included), and ``location_map`` turns a row of [R − I, the IMU's
    motion] into the IMU's motion and the IMU's motion plus (R − I) r at every arm."""
    from marinefmu.estimators.mru.level_frame import SlowLowPass, location_map
    from marinefmu.frames import rot_nb

    x = np.random.default_rng(5).normal(size=300)
    for from_zero in (True, False):
        general, scalar = SlowLowPass(30.0, from_zero=from_zero), SlowLowPass(30.0, from_zero=from_zero)
        for k, v in enumerate(x):
            dt = 0.01 if k < 150 else 0.02
            assert scalar.push_one(float(v), dt) == general.push([float(v)], dt)[0]
            if k == 200:
                scalar.set_state(json.loads(json.dumps(scalar.get_state())))
    arms = np.array([[25.0, -3.0, -8.0], [-40.0, 12.0, 5.0]])
    rot, imu = rot_nb(0.05, -0.02, 0.3), np.array([0.4, -0.7, 1.2])
    at = (np.concatenate([(rot - np.eye(3)).ravel(), imu]) @ location_map(arms)).reshape(3, 3)
    np.testing.assert_allclose(at, np.vstack([imu, imu + arms @ rot.T - arms]), rtol=0, atol=1e-13)


def test_the_gyros_tilt_is_the_complementary_filter_and_keeps_the_gyros_wave_band():
    """``GyroTilt`` is c_k = (1 − α)(c_{k−1} + Δt (u_{k−1} + u_k)/2) + α a_k (scipy's
    ``lfilter``, through a state save). On a roll of a 10 s wave plus a slow list, with the
    attitude's angle carrying a 10 s error of 0.01° and a 0.5° step at 100 s, and the gyro's rate
    exact, a − c is the high-pass of the attitude's error: the step decaying as e^{−t/τ} and
    the wave-band error to within 2 % of its amplitude (measured 1.4 %: the first-order
    crossover's phase at 10 s, 1/(ωτ) = 1.6 %), and nothing of the motion itself."""
    from scipy.signal import lfilter

    from marinefmu.estimators.mru.level_frame import GyroTilt

    dt, tau = 0.01, 100.0
    t = np.arange(0.0, 1000.0, dt)
    w = 2.0 * math.pi / 10.0
    true = np.radians(3.0) * np.sin(w * t) + np.radians(1.0) * np.sin(2.0 * math.pi * t / 600.0)
    rate = np.gradient(true, dt)
    wave_error = np.radians(0.01) * np.sin(w * t + 0.7)
    step = np.radians(0.5) * (t >= 100.0)
    measured = true + wave_error + step
    tilt = GyroTilt(tau)
    out = []
    for k in range(len(t)):
        out.append(tilt.push(rate[k], -rate[k], measured[k], -measured[k], dt))
        if k == 4000:
            restored = GyroTilt(tau)
            restored.set_state(json.loads(json.dumps(tilt.get_state())))
            tilt = restored
    out = np.array(out)
    alpha = 1.0 - math.exp(-dt / tau)
    c = lfilter([1.0], [1.0, alpha - 1.0], (1.0 - alpha) * dt * (rate[:-1] + rate[1:]) / 2 + alpha * measured[1:],
                zi=[(1.0 - alpha) * measured[0]])[0]
    np.testing.assert_allclose(out[1:, 0], measured[1:] - c, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out[:, 1], -out[:, 0], rtol=0, atol=1e-15)
    settled = t >= 900.0
    step_left = step[settled] * np.exp(-(t[settled] - 100.0) / tau)
    assert np.max(np.abs(out[settled, 0] - wave_error[settled] - step_left)) <= 0.02 * np.radians(0.01)


def test_the_gyros_tilt_holds_its_difference_through_a_gap_and_wraps_the_roll():
    """Through bad samples (``hold``) the attitude coasts and the gyro's tilt integrates
    nothing: the first good sample after the gap returns the difference before it, and the
    next ones continue from there (at most 1e-6 rad away, the step's own change) rather than
    jumping by the 0.5 s of roll the attitude moved. A roll crossing ±π keeps the difference
    small (wrapped), as does the refusal of a crossover shorter than 10 s."""
    from marinefmu.estimators.mru.level_frame import GyroTilt

    dt, w = 0.01, 2.0 * math.pi / 10.0
    tilt = GyroTilt(100.0)
    t = np.arange(0.0, 60.0, dt)
    roll, rate = np.radians(3.0) * np.sin(w * t), np.radians(3.0) * w * np.cos(w * t)
    offset = np.radians(0.01)
    out = []
    for k in range(len(t)):
        if 3000 <= k < 3050:                      # 0.5 s of bad samples
            tilt.hold()
            out.append(None)
            continue
        out.append(tilt.push(rate[k], 0.0, roll[k] + offset, 0.0, dt))
    before, after = out[2999][0], out[3050][0]
    assert after == before
    assert max(abs(out[k][0] - before) for k in range(3050, 3100)) < 1e-6
    assert abs(roll[3050] - roll[2999]) > np.radians(0.5)          # what a jump would have been
    wrap = GyroTilt(100.0)
    for k, a in enumerate(np.linspace(3.1, 3.2, 100)):             # roll through +π into −π
        d = wrap.push(0.1 / 100 / dt, 0.0, math.remainder(a, 2 * math.pi), 0.0, dt)
    assert abs(d[0]) < 1e-3
    with pytest.raises(ParameterError, match="tilt_tau"):
        MotionReferenceUnitParams(tilt_tau=5.0)


def test_the_horizontal_filters_take_the_gyros_tilt_noise_as_noise():
    """With the gyro's tilt the surge and sway filters' offset random walk adds g N_g and the
    bias's density at ``omega_min`` (``horizontal_params``): q_h = 6.4e-4 m/s²/√s at the
    defaults against the heave filter's 1e-4; with ``tilt_tau = 0`` all three filters have the
    motion's parameters."""
    from marinefmu.estimators.mru.unit import horizontal_params
    from marinefmu.frames import G

    p = MotionReferenceUnitParams()
    a, m = p.attitude, p.motion
    expected = math.sqrt(m.offset_noise**2 + G**2 * (a.gyro_noise**2 + 2 * a.gyro_bias_sigma**2
                                                     / (a.gyro_bias_tau * m.omega_min**2)))
    mru = MotionReferenceUnit(p, quiet=True)
    surge, sway, heave = (axis.params.offset_noise for axis in mru.axes)
    assert surge == sway == pytest.approx(expected, rel=1e-12) and 6.3e-4 < expected < 6.5e-4
    assert heave == m.offset_noise and horizontal_params(p).offset_noise == surge
    off = MotionReferenceUnit(MotionReferenceUnitParams(tilt_tau=0.0), quiet=True)
    assert all(axis.params is off.params.motion for axis in off.axes)


@pytest.fixture(scope="module")
def high_sea():
    """polar_supply in Hs 6 m / Tp 14 s, IMU at the COG, 1200 s: the joint filter's first fit
    comes at about 840 s (two taught rows per weight after the first delayed output)."""
    rec = case_record("polar_supply", 6.0, 14.0, "cog", duration=1200.0)
    return rec, run_mru(rec, MotionReferenceUnitParams()), run_mru(rec, MotionReferenceUnitParams(motion_model="axis"))


def test_the_joint_filter_meets_the_goals_at_the_imu_where_the_axis_filters_miss(high_sea):
    """Once taught (``joint``, from 840 s), the real-time surge, sway and heave at the IMU are
    within max(2 cm, 5 %) and max(2 cm, 2.5 %) of the truth's std (std 83 / 91 / 151 cm, goals
    4.1 / 4.5 / 3.8 cm; measured 2.2 / 2.4 / 2.5 cm); the axis filters alone, over the same
    samples, miss surge and sway by more than 30 % (5.7 / 7.6 cm: the attitude's tilt error,
    module docstring of ``marinefmu.estimators.mru.joint``). Before the fit the unit's outputs
    are the axis filters' own."""
    rec, joint, axis = high_sea
    k0 = int(np.argmax(joint["joint"]))
    assert joint["joint"][k0:].all() and 700.0 <= k0 * DT <= 900.0
    np.testing.assert_array_equal(joint["position"][:k0], axis["position"][:k0])
    goal = np.array([0.05, 0.05, 0.025])
    rt, _, std = errors_cm(rec, joint, 0, (0.0, 0.0, 0.0), k0)
    rt_axis, _, _ = errors_cm(rec, axis, 0, (0.0, 0.0, 0.0), k0)
    assert np.all(rt <= np.maximum(2.0, goal * std)), (rt, std)
    assert np.all(rt_axis[:2] > 1.3 * np.maximum(2.0, goal[:2] * std[:2])), rt_axis


def heeled(rec: dict, start: float, duration: float, angle: float) -> dict:
    """``rec`` with the vessel heeled by ``angle`` [rad] more, smoothly over ``duration`` s from
    ``start`` (a crane's load, ballast): R_nb → R_nb Rx(φ_h) about the COG, where the IMU is,
    so its specific force turns by Rx(φ_h)ᵀ and its gyro reads the body rate so turned plus
    φ̇_h about x; the translations are the record's."""
    t = (np.arange(len(rec["imu.acc.x"])) + 1) * DT
    s = np.clip((t - start) / duration, 0.0, 1.0)
    phi = angle * (s - np.sin(2 * np.pi * s) / (2 * np.pi))
    rate = np.where((s > 0) & (s < 1), angle / duration * (1 - np.cos(2 * np.pi * s)), 0.0)
    c, sn = np.cos(phi), np.sin(phi)
    out = dict(rec)
    for name, extra in (("imu.acc", 0.0), ("imu.gyro", rate)):
        x, y, z = stack(rec, name).T
        out[f"{name}.x"], out[f"{name}.y"], out[f"{name}.z"] = x + extra, c * y + sn * z, -sn * y + c * z
    return out


def test_a_heel_leaves_the_motion_to_the_axis_filters_until_the_joint_filters_memory_has_passed_it(high_sea):
    """A 2° heel over 30 s at 960 s (the joint filter taught, in Hs 6 m), which the joint filter
    was never taught: while the heel is in its memory it departs from the axis filters, is
    withheld (``joint`` false, the axis filters' outputs given) and comes back after. The
    real-time errors at the IMU over the 240 s from the heel stay within 4 × those of the same
    samples unheeled (measured 3.6 / 6.3 / 6.7 cm, 1.8 / 3.5 / 2.9 ×: the 24 s the joint filter
    takes to depart by GATE × the usual difference, then the axis filters'); the joint filter
    left on and free to answer the heel (no slow rows, no check) erred 40 / 209 / 43 cm,
    19-106 ×. Roll stays within 0.1° (measured 0.04°: the attitude's own aid while the
    reference is withheld; 0.18° with the joint filter's)."""
    rec, plain, _ = high_sea
    start = 960.0
    heel = np.radians(2.0)
    out = run_mru(heeled(rec, start, 30.0, heel), MotionReferenceUnitParams())
    k0 = int(start / DT)
    rt, _, _ = errors_cm(rec, out, 0, (0.0, 0.0, 0.0), k0)
    rt_plain, _, _ = errors_cm(rec, plain, 0, (0.0, 0.0, 0.0), k0)
    assert np.all(rt <= 4.0 * rt_plain), (rt, rt_plain)
    withheld = ~out["joint"][k0:]
    assert withheld.any() and out["joint"][-1] and plain["joint"][k0:].all()
    t = (np.arange(len(out["roll"])) + 1) * DT
    s = np.clip((t - start) / 30.0, 0.0, 1.0)
    roll_true = rec["truth.roll"] + heel * (s - np.sin(2 * np.pi * s) / (2 * np.pi))
    assert np.degrees(np.sqrt(np.mean((out["roll"][k0:] - roll_true[k0:]) ** 2))) < 0.1


def turned(rec: dict, start: float, duration: float, angle: float) -> dict:
    """``rec`` with the vessel turned by ``angle`` [rad] about the vertical through the COG's
    mean position, smoothly over ``duration`` s from ``start`` (a heading change on DP): the
    whole motion p → Rz(ψ_h) p, so the IMU's specific force gains R_nbᵀ (2ψ̇_h J ṗ + ψ̈_h J p +
    ψ̇_h² J² p) (J = [ẑ×], p the IMU's position in the record) and its gyro R_nbᵀ ẑ ψ̇_h. In the
    frame of the new heading the motion is the record's."""
    from marinefmu.frames import rot_nb

    t = (np.arange(len(rec["imu.acc.x"])) + 1) * DT
    s = np.clip((t - start) / duration, 0.0, 1.0)
    inside = (s > 0) & (s < 1)
    rate = np.where(inside, angle / duration * (1 - np.cos(2 * np.pi * s)), 0.0)
    accel = np.where(inside, angle / duration * 2 * np.pi / duration * np.sin(2 * np.pi * s), 0.0)
    R = np.array([rot_nb(*a) for a in zip(rec["truth.roll"], rec["truth.pitch"], rec["truth.yaw"])])
    p, v = stack(rec, "truth.imu", "ned"), stack(rec, "truth.imu_vel", "ned")

    def J(x):
        return np.column_stack([-x[:, 1], x[:, 0], np.zeros(len(x))])

    extra = 2 * rate[:, None] * J(v) + accel[:, None] * J(p) + rate[:, None] ** 2 * J(J(p))
    out = dict(rec)
    acc = stack(rec, "imu.acc") + np.einsum("nji,nj->ni", R, extra)
    gyro = stack(rec, "imu.gyro") + R[:, 2, :] * rate[:, None]
    for i, a in enumerate("xyz"):
        out[f"imu.acc.{a}"], out[f"imu.gyro.{a}"] = acc[:, i], gyro[:, i]
    return out


def test_a_heading_change_leaves_the_heave_to_the_axis_filters(high_sea):
    """A 30° heading change over 60 s at 960 s: the joint filter, never taught a turn, departs
    and is withheld; the heave at the IMU, which a turn does not reach, stays within 2 × the
    unturned run's over the 240 s from the turn (measured 3.7 cm, 1.6 ×; the joint filter left
    free, no slow rows and no check, erred 76 cm, 33 ×). Surge and sway are the axis filters'
    in the level frame of the mean heading, which lags the turn (20 / 26 cm here; the docs
    page's Limits): not asserted."""
    rec, plain, _ = high_sea
    out = run_mru(turned(rec, 960.0, 60.0, np.radians(30.0)), MotionReferenceUnitParams())
    k0 = int(960.0 / DT)
    rt, _, _ = errors_cm(rec, out, 0, (0.0, 0.0, 0.0), k0)
    rt_plain, _, _ = errors_cm(rec, plain, 0, (0.0, 0.0, 0.0), k0)
    assert rt[2] <= 2.0 * rt_plain[2], (rt, rt_plain)
    assert (~out["joint"][k0:]).any() and out["joint"][-1]


def test_the_gyros_tilt_takes_the_attitudes_in_band_error_out_of_surge_and_sway(high_sea):
    """``tilt_tau`` (the horizontal axes' tilt from the integrated gyro in the wave band,
    ``GyroTilt``) against ``tilt_tau = 0`` (the attitude's own tilt), from the joint filter's
    takeover: the real-time surge and sway at the IMU err at most 0.75 × as much (measured 0.60 /
    0.70: 2.21 / 2.36 cm against 3.71 / 3.37), the delayed at most 0.6 × (measured 0.49 / 0.33),
    and heave, which the tilt does not enter, within 5 % (2.46 against 2.49 cm: the joint
    filter's heave rows see the attitude through its aid reference)."""
    rec, joint, _ = high_sea
    attitude_tilt = run_mru(rec, MotionReferenceUnitParams(tilt_tau=0.0))
    k0 = int(np.argmax(joint["joint"]))
    rt, delayed, _ = errors_cm(rec, joint, 0, (0.0, 0.0, 0.0), k0)
    rt_0, delayed_0, _ = errors_cm(rec, attitude_tilt, 0, (0.0, 0.0, 0.0), k0)
    assert np.all(rt[:2] <= 0.75 * rt_0[:2]), (rt, rt_0)
    assert np.all(delayed[:2] <= 0.6 * delayed_0[:2]), (delayed, delayed_0)
    assert abs(rt[2] - rt_0[2]) <= 0.05 * rt_0[2]
    with pytest.raises(ParameterError, match="tilt_tau"):
        MotionReferenceUnitParams(tilt_tau=-1.0)


def test_without_the_aid_reference_the_attitude_is_the_axis_units(high_sea):
    """``aid_reference = False``: the joint filter still gives the real-time motion, but the
    attitude never takes its reference, so roll and pitch are those of the unit without a joint
    filter to the last bit; with it (the default) they differ once the joint filter has taken
    over."""
    rec, joint, axis = high_sea
    unreferenced = run_mru(rec, MotionReferenceUnitParams(aid_reference=False))
    np.testing.assert_array_equal(unreferenced["roll"], axis["roll"])
    np.testing.assert_array_equal(unreferenced["pitch"], axis["pitch"])
    k0 = int(np.argmax(unreferenced["joint"]))
    assert k0 > 0 and unreferenced["joint"][k0:].all()
    assert np.any(joint["roll"][k0:] != axis["roll"][k0:])
    with pytest.raises(ParameterError, match="aid_reference"):
        MotionReferenceUnitParams(aid_reference="yes")


def test_after_a_gap_the_motion_is_invalid_until_the_filters_have_read_past_it(high_sea):
    """A 0.5 s gap (NaN accelerations) with the joint filter running, in Hs 6 m:
    ``motion_valid`` is false through it and for RECOVERY × 0.5 s = 60 s after,
    ``delayed_valid`` for the delay more; once valid again, the IMU's real-time motion is
    within its goals (with the joint filter's channels zeroed in the gap rather than held, it
    erred 25-80 cm for that minute); and the attitude keeps the joint filter's aid reference
    on every aid after the gap, while the filter's rows still hold it (dropping it there left
    roll and pitch 5 × worse for the minute in Hs 3 m)."""
    rec, _, _ = high_sea
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    mru = MotionReferenceUnit(quiet=True)
    k0, gap, span = 96000, 50, 9000
    for k in range(k0):
        mru.step(gyro[k], acc[k], DT)
    hold = int(RECOVERY * gap)
    flags, pos, referenced = [], [], []
    for k in range(k0, k0 + span):
        a = acc[k] if not k0 <= k < k0 + gap else np.full(3, np.nan)
        r = mru.step(gyro[k], a, DT)
        flags.append((r.motion_valid, r.delayed_valid))
        pos.append(r.position[0])
        referenced.append(mru.attitude.aid_reference is not None)
    motion, delayed = np.array(flags).T
    back = gap + hold
    assert not motion[:back].any() and motion[back:].all()
    assert not delayed[:back + mru.lag_steps].any() and delayed[back + mru.lag_steps:].all()
    truth, _ = point_truth(rec, (0.0, 0.0, 0.0))
    rt = 100 * rms_about_mean(np.array(pos)[back:] - truth[k0 + back:k0 + span])
    std = 100 * np.std(truth[k0:k0 + span], axis=0)
    assert np.all(rt <= np.maximum(2.0, np.array([0.05, 0.05, 0.025]) * std)), (rt, std)
    assert all(referenced[gap + int(1.0 / DT):])         # from the first aid after the gap on


def test_after_a_gyro_gap_the_angles_wait_for_the_motion(high_sea):
    """A 0.5 s gyro gap (NaN rates) with the joint filter running, in Hs 6 m: the attitude coasts
    on the last good rate (0.17° off at the gap's end) and its aid's reference comes from the
    joint filter, which carries the coast error until it has read past the gap; so ``valid``
    (the angles) is false through the gap and for RECOVERY × 0.5 s = 60 s after, as
    ``motion_valid``, and from then on roll and pitch are within 0.02° of the uninterrupted
    run's (measured 0.008°; valid from the first good sample they were 0.065-0.08° off for
    the 20 s after). The unit turns the AttitudeEstimator's own recovery off: on the joint
    filter's reference the inflated covariance swung the angles by up to 17° after a 2 s gap.
    A single bad gyro sample costs only its own step: its coast error's bound is within the
    tilt's standard deviation."""
    rec, joint, _ = high_sea
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    mru = MotionReferenceUnit(quiet=True)
    assert not mru.attitude.recover_from_gyro_gaps
    k0, gap, span = 96000, 50, 9000
    for k in range(k0):
        mru.step(gyro[k], acc[k], DT)
    angles, dev = [], []
    for k in range(k0, k0 + span):
        r = mru.step(gyro[k] if not k0 <= k < k0 + gap else np.full(3, np.nan), acc[k], DT)
        angles.append((r.valid, r.motion_valid))
        dev.append(max(abs(r.roll - joint["roll"][k]), abs(r.pitch - joint["pitch"][k])))
    valid, motion = np.array(angles).T
    back = gap + int(RECOVERY * gap)
    assert not valid[:back].any() and valid[back:].all()
    assert not motion[:back].any() and motion[back:].all()
    dev = np.degrees(dev)
    assert dev[gap] > 0.1 and dev[gap:back].max() > 0.05          # what the flag covered
    assert dev[back:].max() < 0.02, dev[back:].max()
    # a single bad gyro sample: its coast error is within the tilt's own uncertainty
    k = k0 + span
    assert not mru.step(np.full(3, np.nan), acc[k], DT).valid
    assert mru.step(gyro[k + 1], acc[k + 1], DT).valid


def test_a_deep_copy_continues_as_the_original(high_sea):
    """copy.deepcopy (and pickle) copy a view's data apart from its base: the Wiener group's
    slab and its axes' running sums, the joint filter's gathered nodes. The copy re-links them,
    or its real-time motion would drift from the original's from the first step (by 2-15 mm at
    once), which a script that branches a run would take for the effect of its change."""
    import copy as copying
    rec, _, _ = high_sea
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    mru = MotionReferenceUnit(quiet=True)
    k0 = 92000
    for k in range(k0):
        mru.step(gyro[k], acc[k], DT)
    assert mru.joint.ready
    twin = copying.deepcopy(mru)
    for k in range(k0, k0 + 3000):
        a, b = mru.step(gyro[k], acc[k], DT), twin.step(gyro[k], acc[k], DT)
        assert np.array_equal(a.position, b.position) and (a.roll, a.pitch) == (b.roll, b.pitch), k


def test_a_state_restored_while_the_joint_filter_runs_continues_bit_identically(high_sea):
    """Saved at 1000 s (the joint filter fitted, blended and the attitude's aid reference set),
    through JSON, and restored into a new unit: the next 130 s are the same to the last bit,
    through two rounds of the four filters' designs (every 60 s, each its own offset) and a
    refit of the joint filter (every 120 s)."""
    rec, _, _ = high_sea
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    mru = MotionReferenceUnit(quiet=True)
    k0 = 100000
    for k in range(k0):
        r = mru.step(gyro[k], acc[k], DT)
    assert r.joint and mru.joint.blended and mru.attitude.aid_reference is not None
    copy = MotionReferenceUnit(quiet=True)
    copy.set_state(json.loads(json.dumps(mru.get_state())))
    fit = mru.joint.weights
    for k in range(k0, k0 + 13000):
        a, b = mru.step(gyro[k], acc[k], DT), copy.step(gyro[k], acc[k], DT)
        assert (a.roll, a.pitch, a.joint, a.wave_period) == (b.roll, b.pitch, b.joint, b.wave_period), k
        np.testing.assert_array_equal(a.position, b.position)
        np.testing.assert_array_equal(a.velocity, b.velocity)
        np.testing.assert_array_equal(a.delayed_position, b.delayed_position)
    assert mru.joint.weights is not fit and copy.joint.weights is not fit       # refitted in both
