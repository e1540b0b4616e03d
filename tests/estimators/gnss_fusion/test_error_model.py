"""``pos_std`` of the GNSS + accelerometer fusion between fixes: the error covariance of the filter
as it runs (estimators.gnss_fusion.error_model), against its closed forms and against simulated truth."""
import json
import math

import numpy as np
import pytest

from marinefmu.estimators.gnss_fusion import error_model as fusion_error
from marinefmu.estimators.gnss_fusion.error_model import FusionError, pi_gains
from marinefmu.estimators.gnss_fusion.antenna_attitude import antenna_attitude_std
from marinefmu.estimators.gnss_fusion import filter as gnss_fusion
from marinefmu.estimators.gnss_fusion.filter import GnssAccFusionParams, GnssAccFusion, process_noise, transition
from marinefmu.papers import paper001


def run(est: GnssAccFusion, rec: dict, ks: range) -> np.ndarray:
    """Step ``est`` over the samples ``ks`` of a paper001 record; (len, 6) pos and pos_std."""
    use = rec["gnss_new"] & rec["gnss_valid"]
    out = []
    for k in ks:
        r = est.step(rec["acc"][k], rec["gnss"][k] if use[k] else None, paper001.DT, rec["gyro"][k])
        out.append([*r.pos, *r.pos_std])
    return np.array(out)


def error_model(acc_arm: np.ndarray | None = None, dt: float = 0.01) -> FusionError:
    """A :class:`FusionError` on the paper-001 antennas (accelerometer at ``acc_arm``, default the
    antennas' centroid) with the sensors' default noises, its model set for ``dt`` s steps of the
    9-state filter (bias random walk 1e-5 m/s²/√s)."""
    ant = np.array(paper001.ANT)
    err = FusionError(ant, ant.mean(axis=0) if acc_arm is None else acc_arm, 7e-4, 5e-5, (0.01, 0.015),
                      5e-5, 50.0, 30.0)
    f, g = transition(dt, True)
    full = process_noise(dt, err.q_true, 1e-5)
    acc = np.zeros_like(full)
    acc[:6, :6] = full[:6, :6]
    err.set_model(f, g, acc, full - acc, dt)
    return err


def test_with_the_filters_own_noises_it_is_the_filters_covariance(monkeypatch):
    """The Joseph form with the filter's own (optimal) gain and the filter's own noises is the
    filter's covariance: with ``acc_noise``² = q and the centroid's noise σ²/4 = r/Δt the
    covariance as run must equal filterpy's P after every step (no coast, so no pseudo-fix;
    the consistency check held at the sensor's noise; the attitude exact to 1e-12 rad, so that
    its share, which the filter does not model, vanishes)."""
    monkeypatch.setattr(fusion_error, "MAX_Q_SCALE", 1.0)
    monkeypatch.setattr(gnss_fusion, "antenna_attitude_std", lambda *a: np.full(3, 1e-12))
    p = paper001.params(coast="inertial")
    sigma = 2.0 * math.sqrt(p.r / paper001.DT)
    est = GnssAccFusion(GnssAccFusionParams(antennas=p.antennas, acc_lever_arm=p.acc_lever_arm, coast="inertial",
                                     q=p.q, q_down=p.q_down, r=p.r, noise_sizing="fixed",
                                     acc_noise=math.sqrt(p.q), antenna_sigma_h=sigma, antenna_sigma_v=sigma,
                                     gyro_noise=1e-12, gyro_bias_sigma=1e-12))
    rec = paper001.simulate(30.0, {"gnss.rate": 5.0})
    use = rec["gnss_new"] & rec["gnss_valid"]
    worst = 0.0
    for k in range(len(rec["acc"])):
        est.step(rec["acc"][k], rec["gnss"][k] if use[k] else None, paper001.DT, rec["gyro"][k])
        if est.error.P is not None:
            worst = max(worst, float(np.max(np.abs(est.error.P - est.kf.P)) / np.max(np.abs(est.kf.P))))
    assert est.error.P is not None and worst < 1e-9, worst


def test_the_attitude_loop_variance_matches_a_monte_carlo_of_the_pi_loop():
    """Step 2's covariance of the PI attitude loop against 4000 simulated loops of one axis:
    gyro white noise (5e-5 rad/s/√Hz, per sample N/√Δt at 100 Hz) and Gauss-Markov bias
    (5e-5 rad/s, 50 s), fixes once a second with 1.9 mrad noise, pulled with k_p = 2/τ and
    k_i = 1/τ² (τ 30 s) as :func:`~marinefmu.estimators.gnss_fusion.filter.pi_pull`. After 300 s the
    attitude error's variance before and after a pull agrees to 5 % (the Monte Carlo's own
    scatter: √(2/4000) = 2.2 %)."""
    rng = np.random.default_rng(7)
    runs, dt, steps, tau, sig_fix = 4000, 0.01, 100, 30.0, 1.9e-3
    noise, sb, tb = 5e-5, 5e-5, 50.0
    err = error_model(dt=dt)
    err.start(np.eye(9), np.full(3, sig_fix), np.eye(3))
    eps = rng.normal(0.0, sig_fix, runs)          # the attitude starts on a fix
    b = rng.normal(0.0, sb, runs)                 # true bias; the estimate starts at 0
    b_hat = np.zeros(runs)
    phi = math.exp(-dt / tb)
    for _ in range(300):
        for _ in range(steps):
            b = phi * b + sb * math.sqrt(1 - phi * phi) * rng.standard_normal(runs)
            eps -= (b - b_hat) * dt + noise / math.sqrt(dt) * rng.standard_normal(runs) * dt
            err.predict()
        prior, model_prior = np.var(eps), err.eps_var[0]
        e = eps + sig_fix * rng.standard_normal(runs)            # the fix's measure of ε
        eps -= 2.0 / tau * e
        b_hat -= 1.0 / tau**2 * e
        err.attitude_fix(np.full(3, sig_fix), 1.0)
    assert abs(np.var(eps) / err.eps_var[0] - 1.0) < 0.05, (np.var(eps), err.eps_var[0])
    assert abs(prior / model_prior - 1.0) < 0.05, (prior, model_prior)


@pytest.mark.parametrize("case", list(paper001.POS_STD_CASES))
def test_pos_std_between_fixes_tells_the_error(case):
    """Error over ``pos_std`` per axis, 100-300 s without a gap, on the first seed of each case of
    ``paper001.POS_STD_CASES`` (1 Hz and 10 Hz on the paper-001 set-up, the uncorrected
    acceleration, the buoy, the held attitude). Measured RMS 0.89 / 0.88 / 0.99 (1 Hz), 0.89 /
    0.80 / 1.00 (10 Hz), 0.84 / 1.05 / 1.27 uncorrected (east off by g·sin(roll), 14.5 cm RMS:
    without the consistency check 14 there), 0.76 / 0.76 / 0.99 the buoy, 0.91 / 1.04 / 1.03
    the held attitude (1.53 down if the model leaves out the vessel's rotation since the fix).
    Bounds RMS 0.7-1.3 and beyond 2 at most 10 % of the time (Gaussian 4.6 %): the error is
    correlated over seconds to tens of seconds, so 200 s hold some twenty independent samples,
    whose RMS scatters by ±16 % (1σ) and the fraction beyond 2 by ±4.7 %. The filter's own
    covariance as ``pos_std`` (3-8.5 cm on errors of 0.7 cm) would read RMS 0.13-0.19 at 1 Hz;
    the attitude's share added as independent of the position error would read 0.76 / 0.73 at
    1 Hz and 0.66 / 0.61 on the buoy horizontally, the latter failing the lower bound
    (docs/decisions/gnss-fusion-pos-std.md). Every epoch is accepted (the uncorrected case runs
    ungated, as the paper)."""
    rate, seeds, kw, setup = paper001.POS_STD_CASES[case]
    r = paper001.pos_std_run(rate, seeds[0], kw, setup)
    rms_z, beyond = np.array(r["rms_z"]), np.array(r["beyond_2"])
    assert r["fix"] == 1.0
    assert np.all((rms_z > 0.7) & (rms_z < 1.3)) and np.all(beyond < 0.10), (case, rms_z, beyond)


def test_the_joint_covariance_tells_how_position_and_attitude_errors_go_together():
    """The output's east error and the roll error ε_N (true minus estimated attitude about north)
    are correlated: an attitude error moves the acceleration by g·ε and the fix's accelerometer
    point by ε over the arm, and the filter follows both. The joint covariance (module docstring
    of ``error_model``) predicts the correlation coefficient; the time series of seed 1 over
    100-300 s must show it to ±0.15 (measured on seeds 1-6: 0.27 / 0.34 / 0.33 / 0.31 / 0.23 /
    0.43 against the model's 0.37 on each; a model adding the two as independent says 0)."""
    rec = paper001.simulate(300.0, {"gnss.rate": 1.0, "sea.seed": 1, "sensors.seed": 1})
    est = GnssAccFusion(paper001.params())
    use = rec["gnss_new"] & rec["gnss_valid"]
    out = []
    for k in range(len(rec["acc"])):
        r = est.step(rec["acc"][k], rec["gnss"][k] if use[k] else None, paper001.DT, rec["gyro"][k])
        if k >= int(100 / paper001.DT):
            j, nx = est.error.joint, len(est.error.joint) - 9
            m = np.zeros((2, nx + 9))               # east output error, ε_N
            m[0] = est.error.output_map(gnss_fusion.quat_to_rot(est.q))[1]
            m[1, nx] = 1.0
            c = m @ j @ m.T
            out.append([r.pos[1] - rec["cog"][k][1], rec["euler"][k][0] - r.euler[0], c[0, 1] / math.sqrt(c[0, 0] * c[1, 1])])
    o = np.array(out)
    measured, model = np.corrcoef(o[:, 0], o[:, 1])[0, 1], float(np.mean(o[:, 2]))
    assert 0.2 < model < 0.6 and abs(measured - model) < 0.15, (measured, model)


def test_calibration_reads_z_as_stated():
    """``paper001.calibration`` on a made-up error: z = 1, 2, 3, 4 on one axis."""
    err = np.array([[1.0, 0.0, 0.0], [-2.0, 0.0, 0.0], [3.0, 0.0, 0.0], [4.0, 0.0, 0.0]])
    c = paper001.calibration(err, np.ones((4, 3)))
    assert c["rms_z"][0] == pytest.approx(math.sqrt(7.5)) and c["beyond_2"][0] == 0.5 and c["beyond_3"][0] == 0.25
    assert c["rms_z"][1] == 0.0 and c["rms_error_m"][0] == pytest.approx(math.sqrt(7.5))


@pytest.mark.parametrize("propagation", ["gyro", "hold"])
def test_state_round_trips_through_json_mid_gap(propagation):
    """get_state → JSON → set_state on a new estimator, 5 s into a GNSS dropout: the two then give
    the same positions and ``pos_std`` to the last bit, through the gap and after it (with a
    held attitude the measured rate variance of its model goes along)."""
    rec = paper001.simulate(230.0, {"gnss.rate": 1.0, "gnss.dropout.start": 200.0, "gnss.dropout.duration": 20.0})
    a = GnssAccFusion(paper001.params(propagation=propagation))
    run(a, rec, range(20500))
    assert (a.error.rate_var is None) == (propagation == "gyro")
    b = GnssAccFusion(paper001.params(propagation=propagation))
    b.set_state(json.loads(json.dumps(a.get_state())))
    rest = range(20500, len(rec["acc"]))
    out_a, out_b = run(a, rec, rest), run(b, rec, rest)
    assert np.array_equal(out_a, out_b)
    assert np.all(np.isfinite(out_a)) and np.all(out_a[:, 3:] > 0.0)


def test_the_consistency_check_raises_the_noise_only_when_the_innovations_say_so():
    """Step 4: innovations at their predicted size leave the acceleration noise at the sensor's;
    three times it (variance ratio 9) raise it; they never take it below the sensor's."""
    err = error_model()                           # the accelerometer at the centroid: S = 0
    err.start(np.diag([1e-4] * 3 + [1e-2] * 3 + [1e-6] * 3), np.full(3, 1e-3), np.eye(3))
    h = np.hstack((np.eye(3), np.zeros((3, 6))))
    k = np.zeros((9, 3))
    s = np.sqrt(np.diag(h @ err.P @ h.T) + err.r_true)
    err.fix(0.1 * s, k, h, 1.0, np.eye(3))
    assert np.all(err.q_scale == 1.0)
    err.fix(np.array([3.0, 1.0, 0.0]) * s, k, h, 1.0, np.eye(3))
    assert err.q_scale[0] == pytest.approx(1.0 + 8.0 / fusion_error.NIS_MEMORY) and err.q_scale[1] == 1.0
    assert err.q_scale[2] == 1.0


def test_the_attitude_pull_is_capped_only_after_a_gap():
    """The fusion pulls its attitude with the PI's gain capped by the one-step Kalman gain of
    the attitude error's covariance. At 1 Hz in steady state (paper-001 antennas: fix attitude
    1.9 / 0.75 / 0.46 mrad about N / E / D) the Kalman gain is 0.11 / 0.35 / 0.58, above the
    PI's 0.067, so the cap changes nothing; 30 s after the last pull the attitude has drifted
    to about 1.7 mrad, the PI's gain is 1 (the fix would replace the attitude) and the cap is
    0.46 / 0.83 / 0.93: the weak axis keeps half of its propagated attitude."""
    std = antenna_attitude_std(np.array(paper001.ANT), np.eye(3), 0.01, 0.015)
    err = error_model()
    err.start(np.eye(9), std, np.eye(3))
    for _ in range(300):
        for _ in range(100):
            err.predict()
        err.attitude_fix(std, 1.0)
    for _ in range(100):
        err.predict()
    steady = err.attitude_gain(std)
    for _ in range(2900):
        err.predict()
    after_gap = err.attitude_gain(std)
    assert np.all(steady > pi_gains(1.0, 30.0)[0])
    assert pi_gains(30.0, 30.0)[0] == 1.0 and np.all(after_gap < 0.95) and after_gap[0] < 0.5
    np.testing.assert_allclose(after_gap, [0.463, 0.832, 0.927], atol=0.01)


def test_the_held_attitude_grows_by_the_rotation_its_rate_model_says():
    """``propagation="hold"``: between fixes ε integrates the vessel's rate ω, a Gauss-Markov
    process (``loop_transition``). Started at ε = 0 with ω stationary, the covariance after 1 s
    of 0.01 s steps must be the closed form rate variance × 2τ²(x − 1 + e^(−x)) (to 1 %, the
    steps' first-order integration of ω), with the cross-axis covariance of the rate carried
    as measured."""
    rate = np.array([[4e-4, 1e-4, 0.0], [1e-4, 2e-4, 0.0], [0.0, 0.0, 1e-4]])
    a, q = fusion_error.loop_transition(0.01, 5e-5, 50.0, 5e-5, False, rate)
    p = np.zeros((9, 9))
    p[3:6, 3:6] = rate
    for _ in range(100):
        p = a @ p @ a.T + q
    expected = rate * fusion_error.held_rotation_var(1.0)
    assert np.allclose(p[:3, :3], expected, rtol=0.01, atol=0.0), (p[:3, :3], expected)
    assert np.allclose(p[3:6, 3:6], rate, rtol=1e-9)        # ω stays stationary
    assert fusion_error.held_rotation_var(1e-3) == pytest.approx(1e-6, rel=1e-3)   # ≈ t² for t ≪ τ


def test_the_held_attitude_measures_the_rate_from_fix_to_fix():
    """``FusionError.held_rotation``: the rotation between consecutive fixes' attitudes, less
    both fixes' noise, over the rotation variance per unit rate variance. A constant change c
    over 1 s with fix noise s gives (c² − 2s²)/held_rotation_var(1) exactly; the gyro loop
    ignores it."""
    ant = np.array(paper001.ANT)
    held = FusionError(ant, ant.mean(axis=0), 7e-4, 5e-5, (0.01, 0.015), 5e-5, 50.0, None)
    change, std = np.array([0.02, -0.01, 0.003]), np.array([2e-3, 1e-3, 5e-4])
    for _ in range(5):
        held.held_rotation(change, 1.0, std)
    expected = (np.outer(change, change) - 2 * np.diag(std**2)) / fusion_error.held_rotation_var(1.0)
    assert np.allclose(held.rate_var, expected, rtol=1e-12)
    gyro = error_model()
    gyro.held_rotation(change, 1.0, std)
    assert gyro.rate_var is None


def test_the_output_variance_on_its_two_blocks_is_the_full_product_and_the_step_reuses_the_fix_turned_rotation():
    """``position_var`` reads only the position and attitude blocks of the joint covariance:
    it must equal diag(M J Mᵀ) with the whole output map M (:meth:`FusionError.output_map`) to
    rounding (1e-12 relative; the other columns of M are zeros). The step's output reuses the
    rotation of its propagated attitude unless a fix has turned the attitude since: the output
    must equal one made from the attitude as it stands, on fix steps and between them, and
    the output's floats their numpy forms."""
    rec = paper001.simulate(60.0, {"gnss.rate": 1.0, "sea.seed": 2, "sensors.seed": 2})
    est = GnssAccFusion(paper001.params())
    assert np.linalg.norm(est.error.acc_arm) > 0.5          # the attitude block matters
    use = rec["gnss_new"] & rec["gnss_valid"]
    fixes = checked = 0
    for k in range(len(rec["acc"])):
        r = est.step(rec["acc"][k], rec["gnss"][k] if use[k] else None, paper001.DT, rec["gyro"][k])
        if k < 1000 or k % 7 and not use[k]:
            continue
        rot = gnss_fusion.quat_to_rot(est.q)
        m = est.error.output_map(rot)
        full = np.einsum("ij,jk,ik->i", m, est.error.joint, m)
        np.testing.assert_allclose(est.error.position_var(rot), full, rtol=1e-12, atol=0.0)
        arm = rot @ est.error.acc_arm
        assert est.error.position_var(rot, tuple(arm.tolist())) == est.error.position_var(rot)
        w = np.asarray(rec["gyro"][k], dtype=float)
        again = est._result(r.fix, r.valid, r.warning, w)
        assert again.pos == r.pos and again.vel == r.vel and again.pos_std == r.pos_std
        # the output on floats against its numpy form: x − R̂ l, v − R̂ ((ω − b) × l), √var
        x = est.kf.x.ravel()
        np.testing.assert_allclose(r.pos, x[:3] - arm, rtol=0, atol=1e-12)
        np.testing.assert_allclose(r.vel, x[3:6] - rot @ np.cross(w - est.gyro_bias, est.error.acc_arm), rtol=0, atol=1e-14)
        if est.coast_var is None:
            np.testing.assert_allclose(r.pos_std, np.sqrt(full), rtol=1e-12, atol=0)
        fixes += bool(r.fix)
        checked += 1
    assert fixes >= 40 and checked >= 600, (fixes, checked)
