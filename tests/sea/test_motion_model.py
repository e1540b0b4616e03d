"""VesselMotion model: exact kinematics, IMU and GNSS models, independent-CR mode, bad input."""
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from marinefmu.errors import ParameterError, RaoFileError
from marinefmu.frames import GRAVITY_N
from marinefmu.sea.motion_model import REAL_INDEX, VesselMotion, VesselMotionParams
from marinefmu.sea.sensors import GnssParams, ImuParams

QUIET = {"imu.acc_noise": 0.0, "imu.gyro_noise": 0.0, "imu.acc_bias_instability": 0.0,
         "imu.gyro_bias_instability": 0.0, "gnss.sigma_h": 0.0, "gnss.sigma_v": 0.0}
ARM = {"imu.x": 12.0, "imu.y": -3.0, "imu.z": -6.0}


def model(**flat):
    return VesselMotion(VesselMotionParams.from_flat(flat))


def out(y, name):
    return y[REAL_INDEX[name]]


def pos_vel_acc(m, t, prefix):
    y = m.peek(t)
    return (np.array([out(y, f"truth.{prefix}.{a}") for a in "ned"]),
            np.array([out(y, f"truth.{prefix}_vel.{a}") for a in "ned"]),
            np.array([out(y, f"truth.{prefix}_acc.{a}") for a in "ned"]))


@pytest.mark.parametrize("prefix", ["cog", "imu", "point"])
@pytest.mark.parametrize("mode", [0, 1])
def test_position_velocity_acceleration_are_exact_derivatives(prefix, mode):
    m = model(**{"sea.hs": 4.0, "sea.tp": 8.0, "sea.spreading": 5.0, "vessel.mode": mode, "vessel.cr.x": 4.0,
                 "vessel.cr.z": -2.0, "vessel.speed": 3.0, **ARM})
    h = 1e-3
    for t in (10.0, 123.4, 987.6):
        p_m, v_m, _ = pos_vel_acc(m, t - h, prefix)
        p_p, v_p, _ = pos_vel_acc(m, t + h, prefix)
        p0, v0, a0 = pos_vel_acc(m, t, prefix)
        # central differences: error ~ h²/6 · |d³x/dt³| ≈ 1e-7 for these motions
        np.testing.assert_allclose((p_p - p_m) / (2 * h), v0, atol=2e-6)
        np.testing.assert_allclose((v_p - v_m) / (2 * h), a0, atol=2e-6)


def test_body_rates_and_angular_accelerations_are_exact_derivatives_of_attitude():
    m = model(**{"sea.hs": 5.0, "sea.tp": 9.0, "sea.heading": 2.0, "sea.spreading": 3.0})
    h = 1e-4
    for t in (50.0, 400.0):
        def att(tt):
            y = m.peek(tt)
            return Rotation.from_euler("ZYX", [out(y, "truth.yaw"), out(y, "truth.pitch"), out(y, "truth.roll")])

        def rate(tt):
            y = m.peek(tt)
            return np.array([out(y, f"truth.rate.{a}") for a in "xyz"])

        # body rate from the relative rotation R(t−h)ᵀ R(t+h) = exp(2h [ω×])
        w_fd = (att(t - h).inv() * att(t + h)).as_rotvec() / (2 * h)
        np.testing.assert_allclose(w_fd, rate(t), atol=1e-9)
        y = m.peek(t)
        np.testing.assert_allclose((rate(t + h) - rate(t - h)) / (2 * h),
                                   [out(y, f"truth.ang_acc.{a}") for a in "xyz"], atol=1e-8)


def test_noise_free_imu_reads_the_specific_force_at_its_lever_arm():
    """Independent check: IMU position from scipy's Rotation, differentiated twice numerically."""
    m = model(**{"sea.hs": 4.0, "sea.tp": 8.0, "sea.heading": 2.4, **ARM, **QUIET})
    arm = np.array([ARM["imu.x"], ARM["imu.y"], ARM["imu.z"]])
    h = 1e-3

    def imu_position(tt):
        y = m.peek(tt)
        r = Rotation.from_euler("ZYX", [out(y, "truth.yaw"), out(y, "truth.pitch"), out(y, "truth.roll")])
        return np.array([out(y, f"truth.cog.{a}") for a in "ned"]) + r.apply(arm), r

    for k in range(1, 2001, 400):
        t = k * 0.01
        y = m.step(t, 0.01)
        measured = np.array([out(y, f"imu.acc.{a}") for a in "xyz"])
        np.testing.assert_array_equal(measured, [out(y, f"truth.imu_f.{a}") for a in "xyz"])
        p_m, _ = imu_position(t - h)
        p_p, _ = imu_position(t + h)
        p0, r = imu_position(t)
        a_fd = (p_p - 2 * p0 + p_m) / h**2
        np.testing.assert_allclose(measured, r.inv().apply(a_fd - GRAVITY_N), atol=2e-5)
        np.testing.assert_array_equal([out(y, f"imu.gyro.{a}") for a in "xyz"], [out(y, f"truth.rate.{a}") for a in "xyz"])


def test_gnss_antenna_separations_are_constant():
    m = model(**{"sea.hs": 6.0, "sea.tp": 10.0, "sea.heading": 2.0, **QUIET})
    arms = np.array(GnssParams().antennas)
    expected = np.linalg.norm(arms[:, None] - arms[None], axis=-1)
    for k in range(1, 3001, 7):
        y = m.step(k * 0.01, 0.01)
        ant = np.array([[out(y, f"gnss.ant{i}.{a}") for a in "ned"] for i in range(1, 5)])
        np.testing.assert_allclose(np.linalg.norm(ant[:, None] - ant[None], axis=-1), expected, atol=1e-9)


def test_gnss_fixes_arrive_at_the_configured_rate_and_drop_out_in_the_window():
    m = model(**{"gnss.rate": 2.0, "gnss.dropout.start": 10.0, "gnss.dropout.duration": 5.0})
    fixes, valid = [], []
    for k in range(1, 2001):
        y = m.step(k * 0.01, 0.01)
        ok, new, _ = m.boolean_outputs()
        if new:
            fixes.append(k * 0.01)
        valid.append((k * 0.01, ok, out(y, "gnss.ant1.d")))
    # epochs t_k = k/2 for k = 0 … 40: epoch 0 is reported on the first step (t = 0.01 s)
    assert len(fixes) == 41
    assert np.allclose(np.diff(fixes[1:]), 0.5)
    in_window = [(t, ok, d) for t, ok, d in valid if 10.0 <= t < 15.0]
    assert not any(ok for _, ok, _ in in_window)
    assert len({d for _, _, d in in_window}) == 1  # last fix held
    assert all(ok for t, ok, _ in valid if t >= 15.0)


def test_gnss_jump_offsets_every_antenna_inside_the_window():
    base = {**QUIET, "gnss.rate": 10.0}
    a = model(**base)
    b = model(**base, **{"gnss.jump.start": 5.0, "gnss.jump.duration": 2.0, "gnss.jump.n": 30.0, "gnss.jump.d": -12.0})
    for k in range(1, 1001):
        ya, yb = a.step(k * 0.01, 0.01), b.step(k * 0.01, 0.01)
        t_fix = math.floor(k * 0.01 * 10 + 1e-9) / 10
        jump = (30.0, 0.0, -12.0) if 5.0 <= t_fix < 7.0 else (0.0, 0.0, 0.0)
        for i in range(1, 5):
            for ax, j in zip("ned", jump):
                assert out(yb, f"gnss.ant{i}.{ax}") - out(ya, f"gnss.ant{i}.{ax}") == pytest.approx(j, abs=1e-9)


def test_imu_white_noise_and_bias_statistics():
    m = model(**{"imu.acc_noise": 7e-4, "imu.gyro_noise": 5e-5, "imu.acc_bias.x": 0.02, "imu.gyro_bias.z": -0.001,
                 "imu.acc_bias_instability": 0.0, "imu.gyro_bias_instability": 0.0, "sensors.seed": 3})
    dt, n = 0.01, 40000
    err = np.empty((n, 6))
    for k in range(n):
        y = m.step((k + 1) * dt, dt)
        err[k] = [out(y, f"imu.acc.{a}") - out(y, f"truth.imu_f.{a}") for a in "xyz"] + \
                 [out(y, f"imu.gyro.{a}") - out(y, f"truth.rate.{a}") for a in "xyz"]
    # per-sample σ = N/√Δt; with 40,000 samples the sample std is within 1.5 % (5 standard errors)
    np.testing.assert_allclose(err.std(axis=0), [7e-3] * 3 + [5e-4] * 3, rtol=0.015)
    np.testing.assert_allclose(err.mean(axis=0), [0.02, 0, 0, 0, 0, -0.001], atol=5 * 7e-3 / math.sqrt(n))


def test_gauss_markov_bias_has_the_configured_spread_and_correlation_time():
    from marinefmu.sea.sensors import Imu

    p = ImuParams(acc_noise=0.0, gyro_noise=0.0, acc_bias_instability=5e-4, gyro_bias_instability=5e-5, bias_tau=50.0)
    runs = np.array([[Imu(p, np.random.default_rng(s)).gm_bias for s in range(2000)]])[0]
    # the state starts from the stationary distribution: σ within 5 % over 2,000 seeds (×3 axes)
    np.testing.assert_allclose(runs[:, :3].std(), 5e-4, rtol=0.05)
    np.testing.assert_allclose(runs[:, 3:].std(), 5e-5, rtol=0.05)
    # one-step autocorrelation of the exact discretisation is e^{−Δt/τ}
    imu, b = Imu(p, np.random.default_rng(1)), []
    for _ in range(200000):
        imu.measure(np.zeros(3), [0.0, 0.0, 0.0], 1.0)
        b.append(imu.gm_bias[0])
    b = np.array(b)
    assert np.corrcoef(b[:-1], b[1:])[0, 1] == pytest.approx(math.exp(-1 / 50), abs=0.005)


def test_independent_rotation_mode_gives_a_rotation_free_centre():
    cr = (4.0, 1.0, -2.0)
    m = model(**{"sea.hs": 3.0, "sea.tp": 7.0, "sea.heading": 2.3, "vessel.preset": "research36", "vessel.mode": 1,
                 "vessel.cr.x": cr[0], "vessel.cr.y": cr[1], "vessel.cr.z": cr[2], **QUIET})
    y = m.peek(0.0)
    assert [out(y, f"truth.cr.{a}") for a in "xyz"] == list(cr)
    assert m.boolean_outputs()[2] is True
    t = np.arange(0.0, 3 * 3600.0, 0.5)
    x = m.series.series(t)
    trans_acc, rot_acc = x[:, 12:15], x[:, 15:18]
    # translations (of the CR) and rotations come from independent realisations (own frequencies and
    # phases), so their sample correlation decays with record length: < 0.1 for every pair over 3 h
    corr = np.corrcoef(np.hstack([trans_acc, rot_acc]).T)[:3, 3:]
    assert np.abs(corr[np.isfinite(corr)]).max() < 0.1
    # in RAO mode translations and rotations share the waves (surge and pitch are in phase),
    # so the same check fails there: it has teeth
    x0 = model(**{"sea.hs": 3.0, "sea.tp": 7.0, "sea.heading": 2.3, "vessel.preset": "research36"}).series.series(t)
    corr0 = np.corrcoef(x0[:, 12:18].T)[:3, 3:]
    assert np.abs(corr0[np.isfinite(corr0)]).max() > 0.3


def test_state_save_and_restore_reproduces_the_noise():
    m = model()
    for k in range(1, 101):
        m.step(k * 0.01, 0.01)
    state = m.get_state()
    first = [m.step(k * 0.01, 0.01) for k in range(101, 201)]
    m.set_state(state)
    assert [m.step(k * 0.01, 0.01) for k in range(101, 201)] == first


def test_unknown_parameter_name_suggests_the_closest():
    with pytest.raises(ParameterError, match=r"unknown VesselMotion parameter\(s\): 'sea.hz' \(did you mean 'sea.hs'\?\)"):
        VesselMotionParams.from_flat({"sea.hz": 2.0})


@pytest.mark.parametrize(
    "flat,match",
    [
        ({"imu.acc_noise": -1e-3}, r"imu\.acc_noise = -0\.001 is out of range: must be in \[0\.0, 1\.0\]"),
        ({"gnss.sigma_h": -0.1}, r"gnss\.sigma_h"),
        ({"imu.gyro_bias_instability": float("nan")}, r"imu\.gyro_bias_instability = nan is not finite"),
        ({"vessel.preset": "Agulhas"}, r"vessel\.preset = 'Agulhas' is not allowed"),
        ({"vessel.mode": 2}, r"vessel\.mode = 2 is out of range: must be in \[0, 1\]"),
        ({"vessel.speed": -1.0}, r"vessel\.speed"),
        ({"gnss.rate": 0.0}, r"gnss\.rate = 0\.0 is out of range"),
        ({"gnss.ant2.x": 10.0, "gnss.ant2.y": -4.0}, r"gnss\.ant1 and gnss\.ant2 are closer than 0\.1 m"),
        ({"point.x": float("inf")}, r"point"),
    ],
)
def test_bad_parameters_are_refused_with_name_and_range(flat, match):
    with pytest.raises(ParameterError, match=match):
        VesselMotionParams.from_flat(flat)


def test_unreadable_rao_file_is_refused_when_the_model_is_built(tmp_path):
    with pytest.raises(RaoFileError, match="vessel.rao_file"):
        model(**{"vessel.rao_file": str(tmp_path / "nope.csv")})


def test_rao_file_drives_the_motion(tmp_path):
    from marinefmu.sea.vessel import preset_raos, save_rao_csv

    save_rao_csv(preset_raos("semisub"), tmp_path / "semi.csv")
    a = model(**{"vessel.preset": "semisub"}).peek(30.0)
    b = model(**{"vessel.rao_file": str(tmp_path / "semi.csv")}).peek(30.0)
    np.testing.assert_allclose(a, b, atol=1e-12)
