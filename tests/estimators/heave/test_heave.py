"""Heave observer (paper 003): spectrum and peaks, the oscillator bank's steady-state gain
against filterpy, the fixed-lag smoother against filterpy's RTS smoother, exact kernels
against VesselMotion truth, accuracy against truth, the bias step, and bad input."""
import functools
import json
import math

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter, rts_smoother

from marinefmu.errors import ParameterError
from marinefmu.papers import paper003
from marinefmu.estimators.heave.fixed_lag import FixedLagOutputs
from marinefmu.estimators.heave.bank import OscillatorBankHeave
from marinefmu.estimators.heave.common import (
    HeaveObserverParams, point_heave, vertical_acceleration,
)
from marinefmu.estimators.heave.observer import build_heave_model
from marinefmu.estimators.heave.band_bank import (band_elements, band_grid, build_band_bank, discretise, resonator,
                                            smooth_densities)
from marinefmu.estimators.heave.oscillator_bank import build_bank, carry_map, mode_noise_covariance, mode_transition
from marinefmu.frames import G, body_to_euler_rates
from marinefmu.estimators.heave.spectrum import Spectrum
from marinefmu.sea.motion_model import stack
from marinefmu.sea.waves import SeaState, realise

DT, IMU, ARM = paper003.DT, paper003.IMU, paper003.ARM


def _run(params, acc, roll, pitch, dt=DT):
    obs = build_heave_model(params)
    out = np.array([[r.heave, r.point_heave, r.delayed_heave, r.valid, r.modes, r.offset]
                    for r in (obs.step(acc[k], roll[k], pitch[k], dt) for k in range(len(acc)))])
    return out, obs


@pytest.mark.parametrize("model,measurement,tol", [
    ("peaks", "increment", 1e-3), ("peaks", "paper", 1e-3),
    # the band model's elements have a width, so a pure line is not its model: measured 8.1e-3
    # (real time) and 3.7e-3 (delayed), the price of its accuracy on real, broad seas
    # (docs/fmus/HeaveObserver.md)
    ("band", "increment", 1e-2),
])
def test_exact_sum_of_sinusoids_is_recovered(model, measurement, tol):
    dt, w, amp, ph = 0.1, np.array([0.6, 1.1]), np.array([0.5, 0.2]), np.array([0.3, 1.0])
    t = np.arange(1, 9001) * dt
    z = (amp * np.cos(np.outer(t, w) + ph)).sum(axis=1)
    acc = -(amp * w**2 * np.cos(np.outer(t, w) + ph)).sum(axis=1) - G
    out, obs = _run(HeaveObserverParams(model=model, measurement=measurement), acc, 0 * t, 0 * t, dt)
    resolution = 2 * math.pi / 120.0
    if model == "peaks":
        assert np.all(np.abs(np.array(obs._result.omega) - w) < resolution)
    assert abs(2 * math.pi / obs._result.peak_period - w[0]) < resolution
    settled = slice(3000, None)
    assert np.sqrt(np.mean((out[settled, 0] - z[settled]) ** 2)) < tol * np.std(z)
    lag = int(round(obs.delay / dt))
    assert np.sqrt(np.mean((out[3000 + lag:, 2] - z[3000:len(z) - lag]) ** 2)) < tol * np.std(z)
    assert not out[:1199, 3].any() and out[1200:, 3].all()       # valid from the first spectrum


@pytest.mark.parametrize("measurement", ["increment", "paper"])
def test_steady_state_gain_equals_filterpy_run_to_convergence(measurement):
    m = build_bank(np.array([0.5, 0.9]), 0.05, 1e-2, 1e-2, 7e-3, "exact", measurement)
    kf = KalmanFilter(dim_x=m.n, dim_z=1)
    kf.F, kf.Q, kf.H, kf.R = m.A_bar, m.Q, m.C[None, :], np.array([[m.R]])
    for _ in range(20000):
        kf.predict()
        kf.update(np.zeros((1, 1)))
    np.testing.assert_allclose(kf.K[:, 0], m.K, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(kf.P_prior, m.P, rtol=1e-6, atol=1e-14)


def test_fixed_lag_smoother_equals_rts_on_data_up_to_now():
    rng = np.random.default_rng(4)
    m = build_bank(np.array([0.6, 1.0]), 0.1, 1e-2, 1e-3, 1e-2, "exact", "paper")
    ys = rng.normal(size=300)
    lag = 25
    sm = FixedLagOutputs(lag, m.n)
    sm.set_model(np.eye(m.n), m.P, m.closed_loop, m.C, m.S)
    xp, smoothed = np.zeros(m.n), {}
    coast: set[int] = set()
    for k, y in enumerate(ys):
        sm.push(xp)
        if k in coast:
            post = xp
        else:
            innovation = y - m.C @ xp
            post = xp + m.K * innovation
            sm.correct(innovation)
        popped = sm.pop()
        if popped is not None:
            smoothed[k - lag] = popped[0]
        sm.propagate(m.A if k in coast else None)
        xp = m.A @ post
    for k in (150, 299):
        kf = KalmanFilter(dim_x=m.n, dim_z=1)      # batch_filter moves the filter: a fresh one each time
        kf.F, kf.Q, kf.H, kf.R = m.A, m.Q, m.C[None, :], np.array([[m.R]])
        kf.x = np.zeros((m.n, 1))
        kf.P = np.linalg.solve(m.A, np.linalg.solve(m.A, m.P - m.Q).T).T   # so that the first prior is P
        xs, ps, _, _ = kf.batch_filter(ys[:k + 1, None])
        xs_s, _, _, _ = rts_smoother(xs, ps, [m.A] * (k + 1), [m.Q] * (k + 1))
        np.testing.assert_allclose(smoothed[k - lag], xs_s[k - lag, :, 0], atol=1e-9)


def test_fixed_lag_table_equals_explicit_propagation_through_coasted_steps():
    """The tabulated steady-state path and its switch to explicit rows at a coasted step (and
    back lag + 1 steps later) give what propagating every row block explicitly gives."""
    rng = np.random.default_rng(5)
    m = build_bank(np.array([0.6, 1.0]), 0.1, 1e-2, 1e-3, 1e-2, "exact", "paper")
    lag, coast = 25, {60, 61, 62, 100, 200}
    sm = FixedLagOutputs(lag, 2)
    sm.set_model(m.heave_rows, m.P, m.closed_loop, m.C, m.S)
    rows, est, xp = [], [], np.zeros(m.n)        # the reference: explicit W and estimates per pending time
    got, want = [], []
    for k, y in enumerate(rng.normal(size=300)):
        sm.push(xp)
        rows.append(m.heave_rows @ m.P)
        est.append(m.heave_rows @ xp)
        post = xp
        if k not in coast:
            innovation = y - m.C @ xp
            post = xp + m.K * innovation
            sm.correct(innovation)
            est = [e + (w @ m.C) * innovation / m.S for e, w in zip(est, rows)]
        popped = sm.pop()
        if len(est) > lag:
            want.append(est.pop(0))
            rows.pop(0)
            got.append(popped[0])
        phi = m.A if k in coast else m.closed_loop
        sm.propagate(m.A if k in coast else None)
        rows = [w @ phi.T for w in rows]
        xp = m.A @ post
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-14)
    assert sm.rows is None   # back on the table


def test_carry_map_keeps_heave_heave_rate_and_offset():
    old = build_bank(np.array([0.4, 0.6, 0.9]), 0.05, 1e-2, 3e-4, 7e-4)
    new = build_bank(np.array([0.62, 1.2]), 0.05, 1e-2, 3e-4, 7e-4)
    t = carry_map(old.omega, new.omega)
    x = np.random.default_rng(1).normal(size=old.n)
    np.testing.assert_allclose(new.heave_rows @ (t @ x), old.heave_rows @ x, atol=1e-15)
    assert (t @ x)[-1] == x[-1]


@functools.lru_cache(maxsize=2)
def _record(hs, tp):
    return paper003.record(hs, tp)  # 30 min after 2 min, 20 Hz, IMU and bow point as IMU / ARM


def test_van_loan_discretisation_equals_the_closed_form_oscillator():
    """A one-stage undamped band element is the paper's mode: its Van Loan discretisation
    equals the rotation transition and the closed-form process noise."""
    a_c, g = resonator(0.7, 0.0, 1)
    a_d, q_d = discretise(a_c, g, 3e-3, 0.05)
    np.testing.assert_allclose(a_d, mode_transition(0.7, 0.05), atol=1e-13)
    np.testing.assert_allclose(q_d, mode_noise_covariance(0.7, 0.05, 3e-3), rtol=1e-9, atol=1e-18)


def test_band_element_has_the_requested_heave_variance_and_no_heave_at_low_frequency():
    m = build_band_bank(np.array([0.5]), np.array([0.04]), 0.05, 0.1, 3, 1e-4, 7e-4)
    p = np.zeros_like(m.Q)
    for _ in range(200000 // 50):          # stationary covariance of the element (offset excluded)
        p = m.A @ p @ m.A.T + m.Q
        p[-1, -1] = 0.0
    assert m.heave_rows[0] @ p @ m.heave_rows[0] == pytest.approx(0.04, rel=1e-3)
    a_c, g = resonator(0.5, 0.1, 3)        # heave response to the driving noise falls as ω² at 0
    h = [abs(np.linalg.solve(1j * w * np.eye(6) - a_c, g)[-2, 0]) for w in (1e-3, 2e-3)]
    assert h[1] / h[0] == pytest.approx(4.0, rel=1e-3)


def test_band_min_is_the_lowest_band_element():
    """The band model's grid starts at band_min (its default 0.3 rad/s keeps the observer's
    overshoot below its lowest element away from where sensor errors as heave are large:
    HeaveObserverParams.band_min); the peak search keeps omega_min."""
    dt = 0.1
    t = np.arange(1, 801) * dt
    w, amp = np.array([0.3, 0.6]), np.array([1.0, 0.5])
    acc = -(amp * w**2 * np.cos(np.outer(t, w))).sum(axis=1) - G
    lowest = {}
    for band_min in (0.25, 0.35):
        obs = OscillatorBankHeave(HeaveObserverParams(model="band", window=60.0, band_min=band_min))
        for a in acc:
            obs.step(float(a), 0.0, 0.0, dt)
        lowest[band_min] = float(obs.model.omega.min())
    assert lowest[0.35] == pytest.approx(0.35, rel=1e-12)   # the swell at 0.3 rad/s fills the grid's start
    assert lowest[0.25] == pytest.approx(0.25, rel=1e-12)


def test_band_elements_integrate_the_heave_spectrum_over_their_bands():
    """Each element's variance is the heave spectrum integrated over its band (between the
    geometric midpoints of its neighbours), each periodogram bin spread evenly over its width:
    one bin's heave variance lands on the elements its width overlaps, in proportion, and the
    elements together hold exactly the variance of the bins inside the band."""
    d = 0.01
    omega = d * np.arange(1, 301)                      # bins 0.01 … 3 rad/s
    grid = band_grid(0.3, 1.2, 9)
    mid = np.sqrt(grid[1:] * grid[:-1])
    k = 45                                             # bin at 0.46 rad/s, [0.455, 0.465]
    acc = np.zeros_like(omega)
    acc[k] = 2.0 * omega[k] ** 4                       # S_z = 2 m²/(rad/s) on that bin: 0.02 m²
    spectrum = Spectrum(omega, acc, acc, acc, acc)
    w, var = band_elements(spectrum, grid, 0.0)
    edge = mid[np.searchsorted(mid, omega[k])]          # the one element boundary inside the bin
    assert edge == pytest.approx(0.4627, abs=1e-4)
    np.testing.assert_allclose(var, 2.0 * np.array([edge - 0.455, 0.465 - edge]), rtol=1e-9)
    np.testing.assert_allclose(w, grid[[2, 3]], rtol=1e-12)
    rng = np.random.default_rng(5)
    acc = rng.uniform(0.1, 1.0, len(omega)) * omega ** 4
    acc[(omega < 0.35) | (omega > 1.15)] = 0.0         # all energy inside the band
    _, var = band_elements(Spectrum(omega, acc, acc, acc, acc), grid, 0.0)
    assert var.sum() == pytest.approx(np.sum(acc / omega ** 4) * d, rel=1e-12)
    w, var = band_elements(Spectrum(omega, acc, acc, acc, acc), grid, 0.0, "point")   # read at ω_j
    s_z = np.interp(grid, omega, acc) / grid ** 4
    inside = s_z > 0                                   # the end elements at 0.3 and 1.2 rad/s read zero
    np.testing.assert_allclose(w, grid[inside], rtol=1e-12)
    np.testing.assert_allclose(var, (s_z * np.gradient(grid))[inside], rtol=1e-12)


def test_smoothed_band_densities_keep_the_variance_and_do_not_spill_past_a_band_edge():
    """The log-domain smoothing (``band_smoothing``) fills a one-element dip from its
    neighbours, keeps Σ density·width (the window's heave variance), leaves a smooth spectrum
    alone, and, unlike an arithmetic mean, moves next to nothing across a steep band edge (the
    element on the edge's high side falls instead, by the same geometric weights)."""
    width = np.array([0.1, 0.2, 0.3, 0.4, 0.5, 0.6])
    dip = np.array([1.0, 1.0, 0.1, 1.0, 1.0, 1.0])
    out = smooth_densities(dip, width, 1)
    assert np.sum(out * width) == pytest.approx(np.sum(dip * width), rel=1e-12)
    # geometric 1-2-1 weights: log10 of the dip's row, 0 0 -1 0 0 0, becomes 0 -¼ -½ -¼ 0 0
    np.testing.assert_allclose(out / out[0], 10.0 ** -np.array([0, 0.25, 0.5, 0.25, 0, 0]), rtol=1e-12)
    flat = np.full(6, 2.5)
    np.testing.assert_allclose(smooth_densities(flat, width, 2), flat, rtol=1e-12)
    np.testing.assert_array_equal(smooth_densities(dip, width, 0), dip)
    edge = np.array([1e-8, 1e-8, 1e-6, 1.0, 1.0, 1.0])    # the sea starts at the fourth element
    out = smooth_densities(edge, width, 1)
    assert out[2] < 1e-4 * out[4]                         # arithmetic 1-2-1: a quarter of it
    # in band_elements the smoothed densities give the elements' variances, before the floor
    omega = 0.01 * np.arange(1, 301)
    acc = np.where((omega > 0.5) & (omega < 1.0), omega ** 4, 0.0)
    grid = band_grid(0.3, 1.2, 9)
    spectrum = Spectrum(omega, acc, acc, acc, acc)
    _, v0 = band_elements(spectrum, grid, 0.0)
    _, v1 = band_elements(spectrum, grid, 0.0, smoothing=1)
    assert v1.sum() == pytest.approx(v0.sum(), rel=1e-12)     # before the floor: all of it


def test_spectrum_window_grows_with_the_data_up_to_window_max():
    """The spectrum is taken over every sample so far, from ``window`` up to ``window_max``
    seconds (the paper's fixed sliding window when they are equal)."""
    dt = 0.5
    t = dt * np.arange(1, 801)
    f_z = -G - 0.5 * np.sin(0.7 * t)
    lengths = {}
    for window_max in (60.0, 200.0):
        obs = OscillatorBankHeave(HeaveObserverParams(model="band", window=60.0, window_max=window_max))
        seen = []
        for k, f in enumerate(f_z, start=1):
            obs.step(f, 0.0, 0.0, dt)
            if k in (120, 300, 800):
                seen.append(len(obs._window()) * dt)
        lengths[window_max] = seen
    assert lengths == {60.0: [60.0, 60.0, 60.0], 200.0: [60.0, 150.0, 200.0]}


def test_carry_map_of_band_elements_keeps_heave_and_rate():
    old = build_band_bank(np.array([0.4, 0.5, 0.6]), np.array([0.1, 0.2, 0.1]), 0.05, 0.1, 3, 1e-4, 7e-4)
    new = build_band_bank(np.array([0.45, 0.6]), np.array([0.2, 0.1]), 0.05, 0.1, 3, 1e-4, 7e-4)
    t = carry_map(old.omega, new.omega, new.block)
    x = np.random.default_rng(1).normal(size=old.n)
    np.testing.assert_allclose(new.heave_rows @ (t @ x), old.heave_rows @ x, atol=1e-14)


@pytest.fixture(scope="module")
def record():
    return _record(1.0, 6.0)


def test_ned_vertical_acceleration_and_point_transfer_are_exact(record):
    f, roll, pitch = stack(record, "truth.imu_f"), record["truth.roll"], record["truth.pitch"]
    a_d = np.array([vertical_acceleration(f[k], roll[k], pitch[k], "ned") for k in range(0, len(f), 97)])
    np.testing.assert_allclose(a_d, record["truth.imu_acc.d"][::97], atol=1e-9)
    rate = stack(record, "truth.rate")
    for k in range(100, len(f), 997):
        rr, pr, _ = body_to_euler_rates([roll[k], pitch[k], record["truth.yaw"][k]], list(rate[k]))
        d, v = point_heave(record["truth.imu.d"][k], record["truth.imu_vel.d"][k], ARM, roll[k], pitch[k], rr, pr)
        assert d + ARM[2] == pytest.approx(record["truth.point.d"][k], abs=1e-9)
        assert v == pytest.approx(record["truth.point_vel.d"][k], abs=1e-9)


def _errors(record, out, obs, settle=120.0):
    k0 = int(settle / DT)
    lag = int(round(obs.delay / DT))
    rms = lambda e: float(np.sqrt(np.mean(e**2)))  # noqa: E731
    ti = record["truth.imu.d"][k0:] - record["truth.imu.d"][k0:].mean()
    tp = record["truth.point.d"][k0:] - record["truth.point.d"][k0:].mean()
    return (rms(out[k0:, 0] - ti), rms(out[k0:, 1] - tp), rms(out[k0 + lag:, 2] - ti[:len(ti) - lag]),
            float(np.std(ti)), float(np.std(tp)))


def _head(rec, seconds):
    """The first ``seconds`` of a record: exactly the shorter record (VesselMotion steps in order)."""
    n = int(round(seconds / DT))
    return {k: v[:n] for k, v in rec.items()}


#: 2 min + 10 min scored: a 10-min record's errors are within 10 % of the 30-min ones (seed 3,
#: every sea below), and each sea that meets the goal over 30 min meets it over 10 min with 16 %
#: to spare or more, but for 4 / 12 (run over 30 min). The bench part heave runs the 30-min
#: checks of every sea and reports the goals met or not.
SHORT = 720.0


@pytest.fixture(scope="module")
def causal_fir_4_14():
    """The causal bound's filters for Hs 4 / Tp 14 (``paper003.fit_causal_bound``), trained on
    one 30-min record (seed 4) instead of the bench's three hours (seeds 4-6), a sixth of the
    simulation: on the checks' record 2.42 cm over 32 min and 2.41 cm over 12 min against
    2.44 / 2.44 cm. A less trained filter is no less a causal filter: its achieved error stays
    an estimate from above of the bound, on average (on one record it may come out lower)."""
    return paper003.fit_causal_bound(4.0, 14.0, train=(4,), train_duration=1800.0)


@pytest.mark.parametrize("hs,tp,model,duration,bound_factor", [
    # measured IMU / point / delayed [cm] over the record run (in brackets over 30 min after 2:
    # bench part heave, window_max 1200 s); the goals follow each record's heave std (4 / 14:
    # 2.14 / 2.58 cm over 12 min, 2.28 / 2.72 over 32)
    (1.0, 6.0, "band", SHORT, None),     # 0.26 / 0.26 / 0.12 (0.26 / 0.27 / 0.12; goals 2 / 2 / 1)
    (1.0, 6.0, "wiener", SHORT, None),   # 0.23 / 0.23 / 0.09 (0.22 / 0.22 / 0.09)
    (2.5, 9.0, "band", SHORT, None),     # 1.02 / 1.02 / 0.44 (1.03 / 1.03 / 0.43; goals 2 / 2 / 1)
    (2.5, 9.0, "wiener", SHORT, None),   # 0.91 / 0.91 / 0.26 (0.88 / 0.88 / 0.24)
    # at the goal's edge, so over the full 30 min: over 12 min the IMU error is 2.24 cm against
    # 2 cm (the spectrum window still growing); the Wiener filter runs it in ~20 s
    (4.0, 12.0, "wiener", 1920.0, None),  # 2.08 / 2.39 / 0.86 (goals 2.10 / 2.75 / 1; 2.11 with window_max 600; band 2.30: not met)
    (1.0, 14.0, "band", SHORT, None),    # 1.57 / 1.57 / 0.73 (1.58 / 1.58 / 0.70; goals 2 / 2 / 1; 1.98 with band_min 0.25)
    (1.0, 14.0, "wiener", SHORT, None),  # 1.67 / 1.67 / 0.60 (1.54 / 1.54 / 0.53)
    # the causal bound lies above the goal: 2.41 cm over 12 min, 2.42 over 32 (causal_fir_4_14).
    # Over 32 min, as the spectrum window still grows over 12 (2.91 cm there, 1.21 times the
    # bound): 2.69 / 2.76 / 1.19, 1.11 times the bound (1.106 with the bench's 3-hour bound), so
    # not the 1.1 times of the goal
    (4.0, 14.0, "wiener", 1920.0, 1.12),
    # the band model, a selectable variant, is further from it: 2.86 / 2.85 / 1.55, 1.19 times
    # the bound over 12 min (2.94 / 2.98 / 1.53 and 1.21 times over 32)
    (4.0, 14.0, "band", SHORT, 1.2),
])
def test_heave_accuracy_meets_the_goal(hs, tp, model, duration, bound_factor, record, request):
    """VesselMotion JONSWAP sea, default MEMS noise, 10 min after 2 min (30 min for the seas at
    the goal's edge): real-time heave at the IMU and at a bow point 40 m away within max(2 cm,
    2.5 % of the heave std), delayed heave within max(1 cm, 1 %) (the project's goals, beyond the
    5 cm / 5 % of commercial MRUs); the band observer and the Wiener filter (model = "wiener").

    Where no causal estimator on this IMU reaches the goal (Hs 4 / Tp 14: the causal bound,
    ``paper003.causal_bound``, lies above it) the real-time heave at the IMU is held to
    ``bound_factor`` times the bound on the same record and window (from 120 s): the goal of
    1.1 times is not met, by the default Wiener filter (1.11 times) nor by the band observer
    (1.19 times); the point follows the IMU (the same estimate moved along the true angles) and
    the delayed heave, which sees 5 s ahead, beats the bound. The 30-min figures of every sea are
    the bench's (part heave)."""
    rec = _head(record if (hs, tp) == (1.0, 6.0) else _record(hs, tp), duration)
    out, obs = _run(HeaveObserverParams(point=ARM, model=model), stack(rec, "imu.acc"), rec["truth.roll"],
                    rec["truth.pitch"])
    imu, pt, delayed, s_imu, s_pt = _errors(rec, out, obs)
    if bound_factor is None:
        assert imu <= max(0.02, 0.025 * s_imu) and pt <= max(0.02, 0.025 * s_pt)
        assert delayed <= max(0.01, 0.01 * s_imu)
        return
    bound = request.getfixturevalue(f"causal_fir_{hs:g}_{tp:g}").score(rec)["bound_cm"] / 100.0
    assert bound > max(0.02, 0.025 * s_imu)
    assert imu <= bound_factor * bound, imu / bound
    assert pt <= 1.05 * imu and delayed < bound


@pytest.mark.parametrize("model,measurement", [("band", "increment"), ("band", "paper"),
                                               ("peaks", "increment"), ("peaks", "paper")])
def test_heave_response_is_what_the_observer_does_to_a_sinusoid(model, measurement):
    """The closed-form H(ω) of :meth:`BankModel.heave_response` against the observer's own
    steps on a noise-free sampled sinusoid, 1000 s after a zero start (measured agreement
    1e-13 to 7e-13; the paper's variant 7.5e-6, its start transient)."""
    dt = 0.05
    if model == "band":
        m = build_band_bank(np.array([0.4, 0.5, 0.6, 0.75]), np.array([0.05, 0.2, 0.1, 0.03]), dt, 0.1, 3, 1e-4,
                            7e-4, measurement)
    else:
        m = build_bank(np.array([0.5, 0.8]), dt, 1e-2, 3e-4, 7e-4, "exact", measurement)
    worst = 0.0
    for w in (0.35, 0.55, 0.9):
        obs = OscillatorBankHeave(HeaveObserverParams(model=model, measurement=measurement, smoother_lag=0.0))
        obs.start(dt)
        obs._use(m)
        obs.xp, obs.x = np.zeros(m.n), np.zeros(m.n)
        t = np.arange(20000) * dt
        est = []
        for k, a in enumerate(-w**2 * np.cos(w * t)):
            obs._process(float(a), np.zeros(4))
            if k >= len(t) - 200:
                est.append(m.heave_rows[0] @ obs.x)
        h = complex(obs.response(w))
        worst = max(worst, float(np.max(np.abs(np.array(est) - np.real(h * np.exp(1j * w * t[-200:]))))))
    # the paper's undamped modes with the paper's measurement close the loop with a 380 s pole:
    # the zero-start transient is still 7.5e-6 after 1000 s; every other case is at 1e-12
    assert worst < (2e-5 if (model, measurement) == ("peaks", "paper") else 1e-11), worst


def test_heave_response_explains_the_error_of_a_perfect_accelerometer():
    """Hs 4 m / Tp 14 s with the exact specific force (no noise, no bias) and one model (a
    600 s spectrum, never re-estimated): the RMS error is sqrt(∫|H − 1|² S_z dω) of the truth's
    heave spectrum (measured 1.52 cm, predicted 1.47 cm with band_min 0.3; 1.55 / 1.48 cm with
    0.25, 1.83 / 1.76 cm with 0.35, which leaves more of the sea's low tail out; with the band
    elements' variances read at one frequency instead of integrated: 1.50 / 1.45, 1.51 / 1.46,
    1.99 / 1.91 cm; a Welch estimate of S_z over 1220 s in 819 s segments, coarser ones leak the
    peak below the band where |H − 1| is large: 1.81 cm with 205 s; bound 10 %). The part of the
    Hs 4 / Tp 14 error no better sensor removes (docs/decisions/heave-gap-to-the-bound.md)."""
    from scipy import signal

    rec = dict(_record(4.0, 14.0))
    for a in "xyz":
        rec[f"imu.acc.{a}"] = rec[f"truth.imu_f.{a}"]
    out, obs = paper003.run_observer(HeaveObserverParams(model="band", window=600.0, peak_interval=3600.0), rec)
    k0 = int(700.0 / DT)
    truth = rec["truth.imu.d"][k0:] - rec["truth.imu.d"][k0:].mean()
    measured = np.sqrt(np.mean((out[k0:, 0] - truth) ** 2))
    f, s_z = signal.welch(truth, fs=1.0 / DT, nperseg=2**14)   # fine bins: little leakage to where |H − 1| is large
    w = 2 * np.pi * f[1:]
    predicted = np.sqrt(np.sum(np.abs(obs.response(w) - 1.0) ** 2 * s_z[1:]) * f[1])
    assert measured == pytest.approx(predicted, rel=0.10)
    assert measured > 0.01     # a perfect accelerometer still leaves > 1 cm at Hs 4 m, Tp 14 s


def test_causal_fir_bound_uses_only_the_past():
    """The regression behind ``paper003.causal_bound`` (docs/decisions/heave-causal-bound.md): a
    target that is a causal filter of the block means is fitted exactly (so rows and targets line
    up), and one a block ahead of its input (a non-causal target) is not."""
    rng = np.random.default_rng(11)
    a = rng.normal(size=4000)
    blocks = a.reshape(-1, 4).mean(axis=1)
    past = np.convolve(blocks, [0.5, -0.3, 0.2])[:len(blocks)] + 0.7      # z at block k from blocks ≤ k
    ahead = np.concatenate([blocks[1:], [0.0]])                            # z at block k = block k + 1
    for target, expect_exact in ((past, True), (ahead, False)):
        z = np.repeat(target, 4)                                           # per sample; read at block ends
        pairs = [(a[:3000], z[:3000])]
        w = paper003.fit_causal_fir(pairs, 5, 4)
        x, zt, ends = paper003.fir_rows(a[3000:], z[3000:], 5, 4)
        e = np.std(x @ w - zt)
        if expect_exact:
            np.testing.assert_allclose(w, [0.0, 0.0, 0.2, -0.3, 0.5, 0.7], atol=1e-12)
            assert e < 1e-12 and ends[0] == 19
        else:
            assert e > 0.9 * np.std(zt)       # the next block is independent of the past ones


def test_causal_fir_runs_at_every_sample_and_fills_the_window_from_settle():
    """``paper003.CausalFir.heave``, which the bound scores over the checks' window: at every
    sample the filter of the blocks ending there (at the block ends what ``fir_rows`` gives),
    the shorter filter from its first full memory until the longer one's (so from ``settle``
    on, ``int(settle / DT)`` as the checks), nothing before; a settle shorter than a block is
    refused before anything is simulated."""
    rng = np.random.default_rng(12)
    a = rng.normal(size=600)
    long, short = rng.normal(size=11), rng.normal(size=6)     # 10 and 5 blocks of 8 samples, constant last
    fir = paper003.CausalFir((long, short), 8, 40 * DT)
    z = fir.heave(a)
    x, _, ends = paper003.fir_rows(a, a, 10, 8)
    np.testing.assert_allclose(z[ends], x @ long, rtol=1e-12)
    x, _, ends = paper003.fir_rows(a[3:], a[3:], 5, 8)        # blocks ending 3 samples later
    early = ends + 3 < 79
    np.testing.assert_allclose(z[ends[early] + 3], x[early] @ short, rtol=1e-12)
    assert np.isnan(z[:39]).all() and not np.isnan(z[39:]).any()
    with pytest.raises(ParameterError, match="settle = 0.1 is out of range"):
        paper003.fit_causal_bound(4.0, 14.0, settle=0.1)


@pytest.mark.parametrize("model", ["band", "wiener"])
def test_bias_step_is_absorbed_by_the_offset(record, model):
    """Paper section 3.2: +2 m/s² on the accelerometer from t = Δt, for the band observer and
    the Wiener filter (the default). (A step in mid-run: the next test.)"""
    n = int(600 / DT)  # the first 10 minutes of the record are enough for 120 s + 60 s
    acc = stack(record, "imu.acc")[:n]
    roll, pitch = record["truth.roll"][:n], record["truth.pitch"][:n]
    ref = _run(HeaveObserverParams(model=model), acc, roll, pitch)[0]
    biased = acc.copy()
    biased[1:, 2] += 2.0
    out = _run(HeaveObserverParams(model=model), biased, roll, pitch)[0]
    gained = out[-1, 5] - ref[-1, 5]
    assert gained == pytest.approx(2.0 * math.cos(roll[-1]) * math.cos(pitch[-1]), abs=0.01)   # vertical part
    after = int(120 / DT) + int(60 / DT)
    assert np.sqrt(np.mean((out[after:, 0] - ref[after:, 0]) ** 2)) < 0.01


@pytest.mark.parametrize("frame", ["ned", "body"])
def test_a_bias_step_in_mid_run_is_found_and_taken_out_by_the_wiener_filter(record, frame, caplog):
    """+0.5 m/s² from t = 300 s, along the vertical or along body z: the Wiener filter finds the
    step 5 s later (:mod:`marinefmu.estimators.heave.bias_step`), takes it out of its window and of
    its filter's input, refines its size as it ages, and its heave is then the heave of the
    run without the step: measured 1.8 mm at most from 15 s after the step, 0.12 mm from 60 s;
    the offset output has the step. The run without a step finds none. (Left in the spectrum
    window, the step would stay there as a 1/ω² density for 20 minutes: on Hs 2.5 / Tp 9, 59 cm
    RMS in the second minute after it, 2.8 cm at 5-10 minutes;
    docs/decisions/heave-wiener.md.)"""
    n = int(600 / DT)
    acc = stack(record, "imu.acc")[:n]
    roll, pitch = record["truth.roll"][:n], record["truth.pitch"][:n]
    with caplog.at_level("WARNING", logger="marinefmu"):
        ref, clean = _run(HeaveObserverParams(model="wiener"), acc, roll, pitch)
    assert clean.level == 0.0 and "bias step" not in caplog.text
    k = int(300 / DT)
    biased = acc.copy()
    if frame == "ned":   # the body components of 0.5 m/s² down
        biased[k:] += 0.5 * np.column_stack([-np.sin(pitch[k:]), np.sin(roll[k:]) * np.cos(pitch[k:]),
                                             np.cos(roll[k:]) * np.cos(pitch[k:])])
    else:
        biased[k:, 2] += 0.5
    with caplog.at_level("WARNING", logger="marinefmu"):
        out, wiener = _run(HeaveObserverParams(model="wiener"), biased, roll, pitch)
    assert "a bias step of +0.48" in caplog.text and "at t = 300.0 s (5 s ago" in caplog.text
    assert wiener.level == pytest.approx(0.5, abs=0.002)              # refined: measured 0.5007
    assert out[-1, 5] - ref[-1, 5] == pytest.approx(0.5, abs=0.002)   # the offset output
    diff = np.abs(out[:, 0] - ref[:, 0])
    assert diff[k + int(15 / DT):].max() < 0.5e-2 and diff[k + int(60 / DT):].max() < 0.05e-2


@pytest.mark.parametrize("model,corr", [("peaks", 0.98), ("band", 0.99), ("wiener", 0.99)])
def test_two_spectral_peaks_are_tracked(model, corr):
    """Swell (Tp 14 s) plus wind sea (Tp 5 s) on a heave-following buoy: the paper's model puts
    a mode on each peak and the Wiener filter reports each peak of its heave spectrum; every
    model tracks heave (8 minutes, scored after 2; correlation measured 0.986 / 0.994 / 0.996)."""
    t = np.arange(1, int(480 / DT) + 1) * DT
    z, a = np.zeros_like(t), np.zeros_like(t)
    for hs, tp, stream in ((1.0, 14.0, 0), (1.5, 5.0, 1)):
        f = realise(SeaState(hs=hs, tp=tp, seed=5), stream)
        arg = np.outer(t, f.omega) + f.phase
        z -= np.cos(arg) @ f.amplitude
        a += np.cos(arg) @ (f.amplitude * f.omega**2)
    rng = np.random.default_rng(2)
    acc = a - G + 7e-4 / math.sqrt(DT) * rng.standard_normal(len(t))
    out, obs = _run(HeaveObserverParams(model=model), acc, 0 * t, 0 * t)
    if model != "band":
        last = obs.step(acc[-1], 0.0, 0.0, DT)
        periods = 2 * math.pi / np.array(last.omega)
        assert last.modes == len(periods) >= 2
        assert np.min(np.abs(periods - 14.0)) < 0.15 * 14.0 and np.min(np.abs(periods - 5.0)) < 0.15 * 5.0
    k0 = int(120 / DT)
    assert np.corrcoef(out[k0:, 0], z[k0:])[0, 1] > corr


def test_bad_samples_coast_and_are_reported():
    obs = OscillatorBankHeave(HeaveObserverParams(model="band", window=60.0, omega_min=0.3))
    t = np.arange(1, 2001) * 0.1
    for k, tk in enumerate(t):
        acc = -0.3 * math.cos(0.8 * tk) - G
        r = obs.step(math.nan if k == 1500 else acc, 0.01, 0.02, 0.1)
        if k == 1500:
            assert not r.valid and "non-finite" in r.warning and math.isfinite(r.heave) and r.modes > 0
        elif k > 600:
            assert r.valid
    assert not obs.step(-G, 2.0, 0.0, 0.1).valid                 # absurd roll
    assert not obs.step([0.0, 0.0, 500.0], 0.0, 0.0, 0.1).valid  # absurd specific force


@pytest.mark.parametrize("field,value,message", [
    ("window", 20.0, "window = 20.0 is out of range"),
    ("window_max", 100.0, "window_max = 100.0 is out of range"),
    ("band_variance", "mean", "band_variance = 'mean' is not allowed"),
    ("band_smoothing", 6, "band_smoothing = 6 is out of range"),
    ("band_smoothing", -1, "band_smoothing = -1 is out of range"),
    ("max_modes", 0, "max_modes = 0 is out of range"),
    ("acc_noise", 0.0, "acc_noise = 0.0 is out of range"),
    ("mode_noise", -1.0, "mode_noise = -1.0 is out of range"),
    ("offset_noise", 0.0, "offset_noise = 0.0 is out of range"),
    ("omega_min", 0.0, "omega_min = 0.0 is out of range"),
    ("band_min", 0.0, "band_min = 0.0 is out of range"),
    ("band_min", 6.0, "band_min = 6.0 is out of range"),
    ("vertical", "up", "vertical = 'up' is not allowed"),
])
def test_bad_parameters_are_refused_by_name(field, value, message):
    with pytest.raises(ParameterError, match=message):
        HeaveObserverParams(**{field: value})


def test_highpass_baseline_has_the_analytic_response_and_refuses_a_bad_cutoff():
    """The classical baseline beside the observer (docs/fmus/HeaveObserver.md): its gain and
    phase on a sinusoid are those of s²/B₄(s) (the bilinear transform warps ω by (ωΔt)²/12 =
    8e-5 at ωΔt = 0.03)."""
    from scipy import signal

    from marinefmu.estimators.numerics import highpass_double_integration
    dt, w, wc = 0.05, 0.6, 0.1
    t = np.arange(0, 3000, dt)
    h = highpass_double_integration(-w**2 * np.cos(w * t), dt, wc)
    _, den = signal.butter(4, wc, btype="highpass", analog=True)
    resp = -(w**2) * (1j * w) ** 2 / np.polyval(den, 1j * w)    # s²/B(s) at jω on −ω²cos ωt: 1 if ideal
    expected = np.real(resp * np.exp(1j * w * t))
    np.testing.assert_allclose(h[30000:], expected[30000:], atol=3e-4)     # measured 1.2e-4
    assert abs(resp) < 1.0 and np.angle(resp) > 0.05          # the long-wave error it makes
    with pytest.raises(ParameterError, match="cutoff = 0.0 is out of range"):
        highpass_double_integration(np.zeros(10), dt, 0.0)


def test_track_spectrum_builds_the_same_models_as_step():
    """An observer fed by ``track_spectrum`` once it has a model (what WaveCoast does: it runs
    the model in a filter of its own) buffers the same samples and rebuilds, every
    ``peak_interval``, exactly the models that ``step`` would. Only the first model, which it
    stepped, has had its Riccati equation solved; a later one solves it when its gain is asked
    for, and then equals the stepped observer's. Before the first model it refuses, naming the
    method to call."""
    dt, p = 0.05, HeaveObserverParams(model="band", window=60.0, peak_interval=15.0, smoother_lag=0.0)
    t = dt * np.arange(1, int(200 / dt) + 1)
    f_z = -G - 0.5 * np.sin(0.7 * t) - 0.3 * np.sin(1.3 * t + 1.0)
    full, lean = OscillatorBankHeave(p), OscillatorBankHeave(p)
    with pytest.raises(RuntimeError, match="call step until model is set"):
        lean.track_spectrum(f_z[0], 0.0, 0.0)
    models = []
    for f in f_z:
        full.step(f, 0.0, 0.0, dt)
        if lean.model is None:
            lean.step(f, 0.0, 0.0, dt)
        else:
            lean.track_spectrum(f, 0.0, 0.0)
        if lean.model is not None and (not models or models[-1] is not lean.model):
            models.append(lean.model)
            assert ("P" in vars(lean.model)) == (len(models) == 1)      # solved on first use only
            assert np.array_equal(full.model.omega, lean.model.omega)
            assert np.array_equal(full.model.Q, lean.model.Q)
            assert np.array_equal(full.model.K, lean.model.K)
    assert len(models) == 10                    # at 60 s, then every 15 s to 195 s
    assert np.array_equal(full.buf, lean.buf)


def test_a_state_saved_right_after_a_new_model_restores_the_same_run():
    """The smoother takes a new model at the next Kalman step (``_bind_smoother``); a state
    saved between, right after a spectrum update, restores to a run whose outputs, delayed
    ones included, equal the uninterrupted run's bit for bit."""
    dt, p = 0.05, HeaveObserverParams(model="band", window=60.0, peak_interval=15.0, smoother_lag=2.0)
    t = dt * np.arange(1, int(120 / dt) + 1)
    f_z = -G - 0.5 * np.sin(0.7 * t) - 0.3 * np.sin(1.3 * t + 1.0)
    run = OscillatorBankHeave(p, quiet=True)
    models = []
    for k, f in enumerate(f_z):
        run.step(f, 0.0, 0.0, dt)
        if run.model is not None and (not models or run.model is not models[-1]):
            models.append(run.model)
        if len(models) == 2:                   # the second model, at 75 s, made by this step
            break
    copy = OscillatorBankHeave(p, quiet=True)
    copy.set_state(json.loads(json.dumps(run.get_state())))
    for f in f_z[k + 1:]:
        a, b = run.step(f, 0.0, 0.0, dt), copy.step(f, 0.0, 0.0, dt)
        assert (a.heave, a.delayed_heave, a.delayed_valid) == (b.heave, b.delayed_heave, b.delayed_valid)
    assert k + 1 == int(round(75.0 / dt)) and a.delayed_valid
