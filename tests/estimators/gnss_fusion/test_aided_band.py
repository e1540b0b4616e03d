"""The GNSS-aided band observer of the dropout coast (estimators.gnss_fusion.aided_band and .wave_coast)."""
import json
import math

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from marinefmu.estimators.gnss_fusion.aided_band import FIX_SIGMA, AidedBand, Tilt, blocks_times, drift_noise
from marinefmu.estimators.heave.band_bank import band_grid, build_band_bank
from marinefmu.estimators.gnss_fusion.wave_coast import SPECTRUM_WINDOW, WaveCoast
from marinefmu.frames import rot_nb

DT = 0.05


def band_model(omega_min=0.4, omega_max=2.0, count=8, peak=0.8):
    """A band model on a JONSWAP-like heave variance per element (the coast's settings)."""
    omega = band_grid(omega_min, omega_max, count)
    variance = 0.05 * np.exp(-((omega - peak) / 0.25) ** 2)
    return build_band_bank(omega, variance, DT, 0.1, 3, 1e-3, 7e-4)


def steady_state_step(m, x, y):
    """The band observer's own recursion (heave.HeaveObserver._process, increment model)."""
    post = x + m.K * (y - float(m.C @ x))
    return m.A_bar @ post + m.J * y


def test_without_fixes_it_is_the_steady_state_band_observer():
    """Started on the model's steady-state covariance and never given a fix, the full-covariance
    filter stays at that covariance, so its band states are the steady-state observer's
    (2000 steps of seeded acceleration, to 1e-9 m of state)."""
    m = band_model()
    rng = np.random.default_rng(1)
    acc = 0.2 * np.sin(0.8 * DT * np.arange(2001)) + rng.normal(0.0, 0.01, 2001)
    f = AidedBand(drift_noise(120.0), DT)
    f.follow(m, np.zeros(m.n))
    x = np.zeros(m.n)
    for a in acc:                     # each value is the mean acceleration of its step
        f.accelerate(float(a))
        x = steady_state_step(m, x, a)
    assert np.max(np.abs(f.x[:m.n] - x)) < 1e-9
    assert np.max(np.abs(f.P[:m.n, :m.n] - m.P)) < 1e-9 * np.max(np.abs(m.P))


def test_agrees_with_a_filterpy_kalman_filter():
    """The same acceleration steps and 1 Hz fixes through filterpy's KalmanFilter (Joseph form)
    give the same state and covariance to 1e-9 relative: the written-out scalar update is the
    Kalman update."""
    m = band_model()
    n = m.n + 2
    f = AidedBand(drift_noise(120.0), DT)
    f.follow(m, np.zeros(m.n))
    kf = KalmanFilter(dim_x=n, dim_z=1, dim_u=1)
    kf.F, kf.Q, kf.B = f.F.copy(), f.Q.copy(), f.J[:, None].copy()
    kf.x, kf.P = f.x[:, None].copy(), f.P.copy()
    rng = np.random.default_rng(2)
    t = DT * np.arange(1201)
    pos = 0.3 * np.sin(0.8 * t) + 0.02 * t
    acc = -0.3 * 0.64 * np.sin(0.8 * t) + rng.normal(0.0, 0.003, len(t))
    for k in range(1, len(t)):
        y = float(acc[k])
        f.accelerate(y)
        kf.update(y, R=m.R, H=f.C[None, :])
        kf.predict(u=y)
        if k % 20 == 0:
            z = float(pos[k] + rng.normal(0.0, 0.01))
            f.fix(z, 0.0)
            kf.update(z, R=FIX_SIGMA ** 2, H=f.rows[0][None, :])
    assert np.max(np.abs(f.x - kf.x[:, 0])) < 1e-9 * np.max(np.abs(kf.x))
    assert np.max(np.abs(f.P - kf.P)) < 1e-9 * np.max(np.abs(kf.P))


def test_a_new_element_set_keeps_the_position_and_its_rate():
    """A change of the band model's elements carries the states (carry_map): position and
    rate are continuous to 1e-12 m, and an element with no predecessor starts uncorrelated."""
    old, new = band_model(count=8), band_model(omega_min=0.3, count=10)
    f = AidedBand(drift_noise(120.0), DT)
    f.follow(old, np.zeros(old.n))
    rng = np.random.default_rng(3)
    for k in range(400):
        f.accelerate(float(0.1 * math.sin(0.8 * DT * k) + rng.normal(0.0, 0.01)))
        if k % 20 == 19:
            f.fix(float(0.15 * math.sin(0.8 * DT * k) + 1.0), 0.0)
    before = (f.position(0.0), f.position(0.2))
    f.follow(new, np.zeros(new.n))
    assert f.position(0.0) == pytest.approx(before[0], abs=1e-12)
    assert f.position(0.2) == pytest.approx(before[1], abs=1e-12)
    assert np.all(np.linalg.eigvalsh(f.P) > -1e-12)


@pytest.mark.parametrize("tilt,tilt_band", [(None, False), ((5e-5, 50.0), False), ((5e-5, 50.0, 5e-5), True)])
def test_coast_state_round_trips_through_json(tilt, tilt_band):
    """Save 10 s after the first spectrum (JSON, as the FMU does), run both copies on for 50 s:
    the coast positions are bit-identical, with and without tilt states (given attitude fixes
    and PI shifts), and with the wave-tilt band (a 20 mrad roll about N, which gets a band, and
    a 0.2 mrad pitch, too weak for one: measured alone)."""
    save = SPECTRUM_WINDOW + 10.0
    t = DT * np.arange(1, int((save + 50.0) / DT) + 1)
    w = 2 * math.pi / 9.0
    acc = np.stack([-0.4 * w * w * np.sin(w * t + p) for p in (0.0, 1.0, 2.0)], axis=1)
    pos = np.stack([0.4 * np.sin(w * t + p) for p in (0.0, 1.0, 2.0)], axis=1)
    a = WaveCoast(120.0, tilt=tilt, tilt_band=tilt_band)
    b = WaveCoast(120.0, tilt=tilt, tilt_band=tilt_band)
    roll, pitch = 0.02 * np.sin(0.55 * t), 2e-4 * np.sin(0.7 * t)
    out_a, out_b = [], []
    for k in range(len(t)):
        if k == int(save / DT):
            b.set_state(json.loads(json.dumps(a.get_state())))
        for c, out in ((a, out_a), (b, out_b)):
            if c is b and k < int(save / DT):
                continue
            c.add(acc[k], DT, rot_nb(roll[k], pitch[k], 0.0))
            if k % 20 == 19:
                c.anchor(pos[k])
                c.attitude_fix(np.array([1e-3, -2e-3, 0.0]), np.array([2e-3, 1e-3, 5e-4]))
                c.shift_tilt(np.array([-1e-5, 2e-5, 0.0]), np.array([1e-7, -1e-7, 0.0]))
            if k >= int(save / DT):
                out.append(c.position())
    assert out_a[-1] is not None
    assert np.array_equal(np.array(out_a), np.array(out_b))
    if tilt_band:       # both kinds were exercised: a band about N (east filter), ε alone about E
        assert a.bands[1].n_angle > 0 and a.bands[0].angle is None and a.bands[0].weak_tilt is not None


def test_no_position_before_the_spectrum_then_one_however_long_the_gap():
    """position() is None until the band observers have their first spectrum and three fixes
    followed; after the last fix (200 s) it goes on, 100 s here (longer than ``window``, 60 s),
    within 1 cm of the 0.3 m sine (measured 0.35 / 0.35 / 0.16 cm), while position_std()
    grows from 1.0 cm at the last fix to 16 cm: at least tenfold, and always above the error."""
    c = WaveCoast(60.0)
    w = 2 * math.pi / 8.0
    given, err, std = [], [], []
    for k in range(1, int(300 / DT) + 1):
        t = k * DT
        c.add(np.full(3, -0.3 * w * w * math.sin(w * t)), DT)
        if t <= 200.0 and k % 20 == 0:
            c.anchor(np.full(3, 0.3 * math.sin(w * t)))
        if t < SPECTRUM_WINDOW:
            assert c.position() is None
        if SPECTRUM_WINDOW + 10.0 <= t and k % 100 == 0:
            z = c.position()
            given.append(z is not None)
            if t >= 200.0:
                err.append(np.abs(z - 0.3 * math.sin(w * t)))
                std.append(c.position_std())
    assert len(given) >= 23 and all(given)            # every 5 s from 190 s to 300 s
    err, std = np.array(err), np.array(std)
    assert np.max(err) < 0.01, np.max(err, axis=0)
    assert np.all(np.diff(std, axis=0) > 0) and np.all(std[-1] > 10 * std[0]), std[[0, -1]]
    assert np.all(std > err), (std[-1], err[-1])


def coast_phase(dt, period=8.0, amplitude=0.3):
    """Amplitude ratio and lag [s] of the coast position on a pure sine, fitted over the 100 s
    after the last fix (fixes once a second until 200 s)."""
    w = 2 * math.pi / period
    c = WaveCoast(60.0)
    ts, ps = [], []
    for k in range(1, int(round(300 / dt)) + 1):
        t = k * dt
        c.add(np.full(3, -amplitude * w * w * math.sin(w * t)), dt)
        if t <= 200.0 and abs(t - round(t)) < 1e-9:
            c.anchor(np.full(3, amplitude * math.sin(w * t)))
        if t >= 200.0:
            ts.append(t)
            ps.append(c.position()[0])
    ts = np.array(ts)
    (s, co, _), *_ = np.linalg.lstsq(np.c_[np.sin(w * ts), np.cos(w * ts), np.ones_like(ts)], np.array(ps), rcond=None)
    return math.hypot(s, co) / amplitude, -math.atan2(co, s) / w


def test_block_means_of_point_samples_add_no_lag():
    """At 100 Hz the coast averages five samples per 20 Hz band step; its position must not lag
    more than at 20 Hz, where each sample is a step. Measured: 11.4 ms at both (the filter's own
    lag, 0.5 % amplitude); band filters that averaged two block means again would lag 31.4 ms
    at 100 Hz, 2.5 cm on a 1 m sway at 0.8 rad/s. Bound: 2 ms apart."""
    gain_20, lag_20 = coast_phase(0.05)
    gain_100, lag_100 = coast_phase(0.01)
    assert abs(lag_100 - lag_20) < 0.002, (lag_20, lag_100)
    assert abs(gain_100 - gain_20) < 0.002, (gain_20, gain_100)
    assert lag_20 < 0.015 and abs(gain_20 - 1.0) < 0.01, (lag_20, gain_20)


def tilted_gap(seed, tilt, offset_noise, arw=0.0, model_arw=False, wave_tilt=None):
    """400 s of a two-sine sway measured through an acceleration tilted by ε(t) = 3 mrad ·
    sin(2πt/200) (a swing of the gyro-bias error), plus a random walk of density ``arw``
    [rad/s/√Hz] (the gyro's angle random walk; ``model_arw``: the tilt states know it), 1 Hz
    position and attitude fixes, a 30 s gap at 300 s where the swing moves ε by 2.8 mrad.
    ``wave_tilt``: the attitude's own tilt, a two-sine roll θ (20 and 12 mrad at 0.55 and
    0.62 rad/s) less ε, measured at every step, with a band model of the roll (``"band"``) or,
    the roll taken out, ε alone (``"weak"``, :meth:`AidedBand.weak_angle`, no roll left).
    Returns the max position error in the gap [m], the RMS error of the tilt estimate over
    the 50 s before it [rad] and its filter σ [rad]."""
    g = 9.80665
    rng = np.random.default_rng(seed)
    t = DT * np.arange(1, int(340 / DT) + 1)
    pos = 0.3 * np.sin(0.7 * t) + 0.2 * np.sin(0.9 * t + 1.0)
    walk = np.random.default_rng([seed, 1]).normal(0.0, arw * math.sqrt(DT), len(t))
    eps = 3e-3 * np.sin(2 * math.pi * t / 200) + np.cumsum(walk)
    y = -0.3 * 0.49 * np.sin(0.7 * t) - 0.2 * 0.81 * np.sin(0.9 * t + 1.0) - g * eps + rng.normal(0, 0.003, len(t))
    omega = band_grid(0.4, 2.0, 8)
    m = build_band_bank(omega, 0.05 * np.exp(-((omega - 0.8) / 0.25) ** 2), DT, 0.1, 3, offset_noise, 7e-4)
    f = AidedBand(drift_noise(120.0), DT, Tilt(-g, 5e-5, 50.0, arw if model_arw else 0.0) if tilt else None)
    f.follow(m, np.zeros(m.n))
    roll = 0.0 if wave_tilt == "weak" else 0.02 * np.sin(0.55 * t) + 0.012 * np.sin(0.62 * t + 0.5)
    if wave_tilt == "band":
        grid = band_grid(0.4, 0.8, 10)
        f.follow_angle(build_band_bank(grid, 2.6e-4 * np.exp(-((grid - 0.58) / 0.06) ** 2), DT, 0.05, 3, 1e-4, 7e-4),
                       np.zeros(61))
    elif wave_tilt == "weak":
        f.weak_angle(1e-8)
    err, tilt_err = [], []
    for k in range(1, len(t)):
        f.accelerate(float(0.5 * (y[k - 1] + y[k])))    # the step mean of the point samples
        f.wave_tilt(float(roll[k] - eps[k]) if wave_tilt == "band" else float(-eps[k]))
        in_gap = 300 <= t[k] < 330
        if k % 20 == 0 and not in_gap:
            f.fix(float(pos[k] + rng.normal(0, 0.01)), 0.0)
            f.attitude_fix(float(eps[k] + rng.normal(0, 1.9e-3)), 1.9e-3, 0.0)  # ignored without tilt
        if in_gap:
            err.append(f.position(0.0) - pos[k])
        if tilt and 250 <= t[k] < 300:
            tilt_err.append(f.x[f.n_band + 2] - eps[k])
    sigma = math.sqrt(f.P[f.n_band + 2, f.n_band + 2]) if tilt else math.nan
    return float(np.max(np.abs(err))), float(np.sqrt(np.mean(np.square(tilt_err)))) if tilt else math.nan, sigma


@pytest.mark.parametrize("seed", [4, 5, 6])
def test_tilt_states_follow_the_attitude_error_through_a_gap(seed):
    """A wandering tilt of the correcting attitude: with the tilt states (and a tight offset,
    1e-4) the gap's max error was measured 5.1 / 5.6 / 4.8 cm (seeds 4-6), against 9.1-9.3 cm
    for a loose offset (1e-3) standing in for the tilt states, and 31-33 cm for a tight
    offset without them. Bound: under 0.7 × the loose offset's. Before the gap the tilt
    estimate errs 0.16-0.27 mrad RMS, as its covariance says (0.24 mrad); bound 1.5 ×."""
    loose = tilted_gap(seed, False, 1e-3)[0]
    gap, rms, sigma = tilted_gap(seed, True, 1e-4)
    assert gap < 0.7 * loose, (gap, loose)
    assert rms < 1.5 * sigma, (rms, sigma)


def test_tilt_states_that_know_the_gyros_angle_random_walk_coast_better():
    """The tilt also takes the gyro's white noise as a random walk (5e-4 rad/s/√Hz here, a
    low-grade MEMS gyro, so that it dominates). Tilt states that know it (``Tilt.noise``) err
    what their covariance says before the gap (measured RMS / σ 0.74-1.01 over seeds 1-10)
    and err 9.2-13.5 cm in the gap (mean 11.0 cm); without it they are overconfident (σ
    0.24 mrad on 0.94-2.04 mrad, ratio 4.0-8.7) and err 14.2-53.6 cm (mean 30.1 cm). Bounds:
    RMS / σ in [0.6, 1.2] with it and over 3 without on every seed, a smaller gap error on
    every seed, and under half on average."""
    gaps, blinds = [], []
    for seed in range(1, 11):
        blind, blind_rms, blind_sigma = tilted_gap(seed, True, 1e-4, arw=5e-4)
        gap, rms, sigma = tilted_gap(seed, True, 1e-4, arw=5e-4, model_arw=True)
        assert 0.6 < rms / sigma < 1.2, (seed, rms, sigma)
        assert blind_rms / blind_sigma > 3.0, (seed, blind_rms, blind_sigma)
        assert gap < blind, (seed, gap, blind)
        gaps.append(gap)
        blinds.append(blind)
    assert np.mean(gaps) < 0.5 * np.mean(blinds), (gaps, blinds)


def test_the_attitudes_own_tilt_tells_the_tilt_states_through_a_gap():
    """The attitude's own tilt, the vessel's wave roll less ε (:meth:`AidedBand.wave_tilt`),
    is a second measurement of ε beside the acceleration, also in a gap. With the MEMS gyro's
    angle random walk (5e-5 rad/s/√Hz, known), seeds 1-10, max error in the gap (measured):
    - the acceleration alone 4.8-9.0 cm, mean 6.3 cm;
    - with a band model of the roll (:meth:`AidedBand.follow_angle`) 3.7-5.9 cm, mean 4.6 cm,
      the tilt erring what its covariance says before the gap (RMS / σ 0.65-1.12);
    - no roll, ε measured alone (:meth:`AidedBand.weak_angle`) 2.9-4.4 cm, mean 3.3 cm.
    Bounds: the band under 0.8 × the acceleration alone on average and RMS / σ in [0.6, 1.2]
    on every seed; ε alone under the acceleration alone on every seed and under 0.6 × on
    average."""
    alone, band, weak = [], [], []
    for seed in range(1, 11):
        alone.append(tilted_gap(seed, True, 1e-4, arw=5e-5, model_arw=True)[0])
        gap, rms, sigma = tilted_gap(seed, True, 1e-4, arw=5e-5, model_arw=True, wave_tilt="band")
        band.append(gap)
        assert 0.6 < rms / sigma < 1.2, (seed, rms, sigma)
        weak.append(tilted_gap(seed, True, 1e-4, arw=5e-5, model_arw=True, wave_tilt="weak")[0])
    assert np.mean(band) < 0.8 * np.mean(alone), (band, alone)
    assert np.all(np.array(weak) < np.array(alone)) and np.mean(weak) < 0.6 * np.mean(alone), (weak, alone)


def test_the_wave_tilt_band_is_stepped_element_by_element_as_the_dense_product():
    """With a wave-tilt band, the prediction takes F P Fᵀ by parts (:func:`blocks_times`); it
    equals the dense product to rounding (1e-12 of the largest variance)."""
    f = AidedBand(drift_noise(120.0), DT, Tilt(-9.8, 5e-5, 50.0, 5e-5))
    m = band_model()
    f.follow(m, np.zeros(m.n))
    grid = band_grid(0.4, 0.8, 10)
    f.follow_angle(build_band_bank(grid, 1e-4 * np.ones(10), DT, 0.05, 3, 1e-4, 7e-4), np.zeros(61))
    rng = np.random.default_rng(2)
    a = rng.normal(size=(len(f.x), len(f.x)))
    f.P = a @ a.T
    dense = f.F @ f.P @ f.F.T + f.Q
    f._predict(0.1)
    np.testing.assert_allclose(f.P, dense, rtol=0, atol=1e-12 * np.max(np.diag(dense)))


def test_a_wave_tilt_needs_the_tilt_states():
    """Without tilt states there is no ε for the attitude's tilt to measure: refused by name."""
    f = AidedBand(drift_noise(120.0), DT)
    with pytest.raises(ValueError, match="tilt states"):
        f.weak_angle(1e-8)
    with pytest.raises(ValueError, match="tilt states"):
        f.follow_angle(band_model(), np.zeros(band_model().n))
    with pytest.raises(ValueError, match="tilt_band"):
        WaveCoast(120.0, tilt_band=True)
