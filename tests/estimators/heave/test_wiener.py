"""The causal Wiener heave estimator (HeaveObserver model = "wiener", beyond paper 003): its
design against closed forms, the noise subtraction, a bias step, bad samples, state restore and
the model switch. Accuracy against VesselMotion truth is in test_heave.py."""
import math

import numpy as np
import pytest

from marinefmu.errors import ParameterError
from marinefmu.estimators.heave.bank import OscillatorBankHeave
from marinefmu.estimators.heave.common import HeaveObserverParams
from marinefmu.estimators.heave.observer import build_heave_model
from marinefmu.estimators.heave.spectrum import Spectrum
from marinefmu.estimators.heave.wiener import WienerHeave, sea_heave_density, wiener_taps
from marinefmu.frames import G

DT, N, Q = 0.05, 7e-4, 1e-4


def _response(taps, omega, dt=DT):
    """Response of full-rate taps (newest first) to e^{jωt} of acceleration."""
    return taps @ np.exp(-1j * np.outer(np.arange(taps.shape[-1]) * dt, omega))


def test_design_passes_a_strong_sea_with_unit_gain_and_no_gain_at_zero_frequency():
    """A narrow sea (Gaussian heave spectrum at 0.6 rad/s, 1 m²) far above the noise: at its
    peak the four outputs are heave, its rate and both 5 s late to 0.5 % and 0.5°; the taps sum
    to zero, so a constant acceleration (a bias) gives no heave."""
    omega = 2 * math.pi * np.arange(1, 6001) / (12000 * DT)         # a 600 s window's bins
    s_z = np.exp(-0.5 * ((omega - 0.6) / 0.05) ** 2) / (0.05 * math.sqrt(2 * math.pi))
    weights = wiener_taps(omega, s_z, DT, 8, 450, 5.0, N, Q)
    assert weights.shape == (4, 450)
    taps = np.repeat(weights / 8, 8, axis=1)                          # each block mean over its samples
    np.testing.assert_allclose(taps.sum(axis=1), 0.0, atol=1e-9 * np.abs(taps).sum())
    w = np.array([0.55, 0.6, 0.65])
    h = _response(taps, w) * -(w**2)                                  # heave in, estimate out
    want = np.array([np.ones(3), 1j * w, np.exp(-5j * w), 1j * w * np.exp(-5j * w)])
    ratio = h / want
    assert np.all(np.abs(np.abs(ratio) - 1) < 0.005) and np.all(np.abs(np.angle(ratio)) < math.radians(0.5))


def test_acceleration_above_the_band_is_not_amplified():
    """Acceleration measured above omega_max (short waves a buoy follows, vibration) is not heave
    to estimate; passed as ``unwanted`` it enters the design's autocorrelation, and the filter's
    gain on it falls from 1.25 to 0.0022 m per m/s² at 6.3 rad/s (measured), its heave response
    at the sea's peak unchanged (measured 6e-5)."""
    omega = 2 * math.pi * np.arange(1, 6001) / (12000 * DT)
    s_z = np.exp(-0.5 * ((omega - 0.6) / 0.05) ** 2) / (0.05 * math.sqrt(2 * math.pi))
    unwanted = np.where((omega > 6.2) & (omega < 6.6), 0.1, 0.0)            # (m/s²)²/(rad/s)
    w = np.array([0.6, 6.3, 6.5])
    blind, seeing = (_response(np.repeat(wiener_taps(omega, s_z, DT, 8, 450, 5.0, N, Q, u) / 8, 8, axis=1)[0], w)
                     for u in (None, unwanted))
    assert np.all(np.abs(blind[1:]) > 1.0) and np.all(np.abs(seeing[1:]) < 0.01)
    assert abs(seeing[0] * -0.36 - 1.0) < 0.005 and abs(seeing[0] / blind[0] - 1.0) < 1e-3   # heave gain 1 at the peak


def test_sea_density_is_the_spectrum_above_the_noise_in_the_band():
    omega = np.linspace(0.01, 10.0, 1000)
    noise = (N**2 + Q**2 / omega**2) / math.pi
    flat = Spectrum(omega, omega, omega, omega, noise + 1e-3)
    sea = sea_heave_density(flat, N, Q, 0.3, 6.0)
    band = (omega >= 0.3) & (omega <= 6.0)
    np.testing.assert_allclose(sea[band], 1e-3 / omega[band] ** 4, rtol=1e-12)
    assert np.all(sea[~band] == 0.0)
    assert not np.any(sea_heave_density(Spectrum(omega, omega, omega, omega, noise), N, Q, 0.3, 6.0))


def _sea(t):
    """Vertical specific force of a two-component sea [m/s², down] and its heave [m]."""
    z = 0.5 * np.cos(0.7 * t) + 0.3 * np.cos(1.1 * t + 1.0)
    return -0.5 * 0.49 * np.cos(0.7 * t) - 0.3 * 1.21 * np.cos(1.1 * t + 1.0) - G, z


def _run(est, acc, dt=0.1):
    return [est.step(a, 0.01, 0.02, dt) for a in acc]


def test_bias_step_and_bad_samples():
    """+2 m/s² from the first sample: no heave from it once valid (the taps sum to zero) and the
    offset output is its vertical part; a NaN or an absurd sample gives valid false, a warning
    and finite outputs, and the filter goes on; without noise, heave to 1 mm."""
    t = np.arange(1, 3001) * 0.1
    acc, z = _sea(t)
    params = HeaveObserverParams(model="wiener", window=60.0, omega_min=0.3)
    ref = _run(WienerHeave(params), acc)
    biased = _run(WienerHeave(params), acc + 2.0)
    assert not ref[598].valid and ref[600].valid
    assert max(abs(b.heave - r.heave) for b, r in zip(biased[600:], ref[600:])) < 1e-9
    assert biased[-1].offset - ref[-1].offset == pytest.approx(2.0 * math.cos(0.01) * math.cos(0.02), abs=1e-9)
    est = WienerHeave(params)
    bad = acc.copy()
    bad[2000] = math.nan
    out = _run(est, bad)
    assert not out[2000].valid and "non-finite" in out[2000].warning and math.isfinite(out[2000].heave)
    assert all(r.valid for r in out[2001:])
    assert not est.step(-G, 2.0, 0.0, 0.1).valid                  # absurd roll
    assert not est.step([0.0, 0.0, 500.0], 0.0, 0.0, 0.1).valid   # absurd specific force
    # a noise-free two-line sea from 150 s: heave within 1 mm RMS of its 0.41 m std (measured 0.68 mm:
    # the filter's noise model keeps it from trusting the lines fully)
    heave = np.array([r.heave for r in ref])
    assert np.sqrt(np.mean((heave[1500:] - z[1500:]) ** 2)) < 1e-3


def test_response_predicts_the_output():
    """Between designs the filter is linear and time-invariant: on a noise-free two-line sea its
    real-time heave is Re(H(ω) z) summed over the lines, with H from ``response`` (block sums of
    a running sum in the filter, an independent sum of complex exponentials here), to 1e-9 m."""
    t = np.arange(1, 3001) * 0.1
    acc, _ = _sea(t)
    est = WienerHeave(HeaveObserverParams(model="wiener", window=60.0, omega_min=0.3))
    out = _run(est, acc)
    h = est.response(np.array([0.7, 1.1]))
    assert h.shape == (2,) and abs(h[0] - 1) < 0.01 and abs(h[1] - 1) < 0.01
    tilt = math.cos(0.01) * math.cos(0.02)                    # _run's roll and pitch
    since = est.next_detect - 150                             # the last design, 15 s before the next
    lines = 0.5 * h[0] * np.exp(0.7j * t) + 0.3 * h[1] * np.exp(1j * (1.1 * t + 1.0))
    np.testing.assert_allclose([r.heave for r in out[since:]], tilt * lines.real[since:], rtol=0, atol=1e-9)
    assert WienerHeave().response(0.5) is None


def test_state_restore_repeats_the_run():
    t = np.arange(1, 1501) * 0.1
    acc, _ = _sea(t)
    est = WienerHeave(HeaveObserverParams(model="wiener", window=60.0, omega_min=0.3))
    _run(est, acc[:900])
    twin = WienerHeave(est.params)
    twin.set_state(est.get_state())
    assert [r.heave for r in _run(est, acc[900:])] == [r.heave for r in _run(twin, acc[900:])]


def test_model_switch():
    assert isinstance(build_heave_model(HeaveObserverParams(model="wiener")), WienerHeave)
    assert HeaveObserverParams().model == "wiener"                # the default
    assert OscillatorBankHeave().params.model == "band"                # the observer class's own default
    with pytest.raises(ParameterError, match="model = 'wiener' is not an observer model"):
        OscillatorBankHeave(HeaveObserverParams(model="wiener"))
    with pytest.raises(ParameterError, match="model = 'kalman' is not allowed"):
        HeaveObserverParams(model="kalman")


def test_bias_step_search_is_the_least_squares_hinge_fit():
    """The closed-form search (:mod:`marinefmu.estimators.heave.bias_step`) against the hinge fit done
    by numpy's least squares, candidate by candidate: the same size at every candidate (1e-9),
    the same best candidate, found where the step is; no step in the same data without it; a
    step younger than 5 s is not yet reported (a fit limited to older kinks would misplace it)."""
    from marinefmu.estimators.heave.bias_step import MIN_AGE, find_bias_step

    rng = np.random.default_rng(4)
    dt, n = 0.05, 12000                                   # 600 s, 600 blocks of 1 s
    t = np.arange(n) * dt
    sea = 0.4 * np.sin(0.8 * t + 1.0) + 0.2 * np.sin(1.3 * t) + 0.01 * rng.standard_normal(n)
    step = np.where(t >= 450.0, 0.08, 0.0)
    a = sea + step
    blocks = a.reshape(600, 20).mean(axis=1)
    v = np.cumsum(blocks - blocks.mean())
    j = np.arange(600.0)
    sizes, reductions = [], []
    for s in range(60, 598):
        x = np.column_stack([np.ones(600), j, np.maximum(j - s, 0.0)])
        coef, *_ = np.linalg.lstsq(x, v, rcond=None)
        base, *_ = np.linalg.lstsq(x[:, :2], v, rcond=None)
        sizes.append(coef[2])
        reductions.append(np.sum((v - x[:, :2] @ base) ** 2) - np.sum((v - x @ coef) ** 2))
        assert find_bias_step(a, dt, at=(s + 1) * 20).size == pytest.approx(coef[2], abs=1e-9)
    found = find_bias_step(a, dt)
    assert found.index == (60 + int(np.argmax(reductions)) + 1) * 20 == 9000      # t = 450 s
    assert found.size == pytest.approx(0.08, abs=1e-3)
    assert find_bias_step(sea, dt) is None
    t = np.arange(int(620 / dt)) * dt                                 # a longer sea, a step at 600 s
    young = 0.4 * np.sin(0.8 * t + 1.0) + 0.2 * np.sin(1.3 * t) + np.where(t >= 600.0, 0.5, 0.0)
    assert find_bias_step(young[:int(602.5 / dt)], dt) is None                  # 2.5 s old
    old = find_bias_step(young[int(12.5 / dt):int(612.5 / dt)], dt)             # 12.5 s old
    assert old.index * dt + 12.5 == pytest.approx(600.0, abs=1.0) and old.size == pytest.approx(0.5, abs=0.05)


def test_a_group_of_axes_gives_each_axis_own_outputs():
    """WienerGroup's one batched product equals each axis's own push to rounding, through
    designs a quarter interval apart (taps of different lengths, zero-padded), a bias step of 0.5 m/s²
    taken out of one axis's buffers, bad samples, and a state restore (which rebinds)."""
    from marinefmu.estimators.heave.common import SilentLog
    from marinefmu.estimators.heave.wiener import WienerAxis, WienerGroup

    p = HeaveObserverParams(window=120.0, peak_interval=15.0)
    rng = np.random.default_rng(11)
    n, dt = 30000, 0.01
    t = np.arange(n) * dt
    acc = np.stack([np.sin(w * t + ph) * a for w, ph, a in ((0.7, 0.1, 0.8), (0.9, 1.0, 0.5), (1.1, 2.0, 1.0))])
    acc += 0.02 * rng.normal(size=acc.shape)
    acc[2, 20000:] += 0.5                                    # a bias step on the third axis

    def axes():
        made = [WienerAxis(p, SilentLog(), f"axis {i}", reject_below=i < 2, find_steps=i == 2) for i in range(3)]
        for i, axis in enumerate(made):
            axis.start(dt, p.window + p.peak_interval * i / 4.0, interval=4 * p.peak_interval)
        return made

    single, grouped = axes(), axes()
    group = WienerGroup(grouped)
    group.bind()
    seen = 0
    for k in range(n):
        values = [None if k in (16000, 16001) else float(acc[i, k]) for i in range(3)]
        if k == 25000:
            restored = axes()
            for axis, old in zip(restored, grouped):
                axis.set_state(old.get_state())
            group = WienerGroup(restored)
            group.bind()
            grouped = restored
        out = group.push(values)
        own = [axis.push(v) for axis, v in zip(single, values)]
        if any(o is None for o in own):
            assert out is None
            continue
        seen += 1
        np.testing.assert_allclose(out, np.array(own), rtol=0, atol=1e-12)
    assert seen > 15000 and single[2].level != 0.0
