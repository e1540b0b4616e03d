"""Displacement reconstruction (paper 000 sections 3.2-4): closed forms, the SDOF example,
the semisub 6-DOF goals, the sliding-window estimator and bad input."""
import json
import math

import numpy as np
import pytest
from scipy import linalg

from marinefmu.errors import ParameterError
from marinefmu.estimators.reconstruction.decomposition import (_complex_least_squares, _least_squares_amplitudes, _lstsq, decompose,
                                                 exp_grid, reconstruct_displacement, tilt_correct)
from marinefmu.estimators.reconstruction.sliding import DisplacementReconstructorParams, DisplacementReconstructor
from marinefmu.papers import paper000_sdof, paper000_semisub

LAM = -0.05 + 2j * math.pi * 0.2
GAM = 0.75 * np.exp(0.3j)


def damped_plus_offset(t):
    return 2.0 + 2 * np.real(GAM * np.exp(LAM * t))


def test_closed_form_damped_sinusoid_and_offset_recovered_to_1e_8():
    dt = 0.1
    t = np.arange(600) * dt
    d = decompose(damped_plus_offset(t), dt, max_components=2, sc_tol=1e-12)
    assert d.order == 3
    pair = d.lam[d.lam.imag > 0]
    assert abs(pair[0] - LAM) < 1e-8
    assert abs(d.gamma[d.lam.imag > 0][0] - GAM) < 1e-8
    real = np.abs(d.lam.imag) < 1e-12
    assert abs(d.lam[real][0]) < 1e-8 and abs(d.gamma[real][0] - 2.0) < 1e-8
    rec = reconstruct_displacement(damped_plus_offset(t), dt, 0.05, max_components=2, sc_tol=1e-12, fmax=2.0)
    exact = 2 * np.real(GAM / LAM ** 2 * np.exp(LAM * t))  # offset screened out, eq. 30
    np.testing.assert_allclose(rec.displacement, exact, atol=1e-8)
    np.testing.assert_allclose(rec.velocity, 2 * np.real(GAM / LAM * np.exp(LAM * t)), atol=1e-8)
    assert list(rec.components["kept"]) == [False, True]


def test_exp_grid_matches_numpy_exp_to_a_few_ulp():
    lam = np.array([-0.05 + 2j * math.pi * 0.2, -0.05 - 2j * math.pi * 0.2, 0.0, -0.3, 0.001 + 3j])
    n, dt = 1000, 0.2
    ref = np.exp(np.multiply.outer(np.arange(n) * dt, lam))
    np.testing.assert_allclose(exp_grid(lam, dt, n), ref, rtol=1e-12, atol=0)


def test_real_least_squares_equals_the_complex_solve():
    rng = np.random.default_rng(5)
    lam = np.array([-0.02 + 1.2j, -0.02 - 1.2j, -0.1 + 0.4j, -0.1 - 0.4j, 0.0, -0.5])
    x = rng.normal(size=400)
    g_real, fit_real = _least_squares_amplitudes(x, lam, 0.2, with_fit=True)
    g_cplx, fit_cplx = _complex_least_squares(x, lam, 0.2, with_fit=True)
    np.testing.assert_allclose(g_real, g_cplx, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(fit_real, fit_cplx, atol=1e-10)
    np.testing.assert_allclose(g_real[0], np.conj(g_real[1]), rtol=0, atol=0)  # exact pairs


def test_least_squares_solver_equals_the_svd_solve():
    """The amplitudes' solver (normal equations refined once, QR or SVD fallbacks) equals the
    SVD-based minimum-norm solve to rounding on a well-conditioned basis, a near-degenerate one
    (two poles 1e-7 rad/s apart: the fallback) and a complex one."""
    rng = np.random.default_rng(7)
    t = np.arange(1000) * 0.2
    for gap in (0.3, 1e-7):
        w = np.array([0.5, 0.5 + gap, 1.1, 2.0])
        v = np.column_stack([np.cos(w * tt) for tt in t]).T
        v = np.column_stack((v, np.sin(np.outer(t, w)), np.exp(-0.01 * t)))
        v /= np.linalg.norm(v, axis=0)
        x = v @ rng.normal(size=v.shape[1]) + 1e-3 * rng.normal(size=len(t))
        ref, *_ = linalg.lstsq(v, x, lapack_driver="gelsd")
        np.testing.assert_allclose(_lstsq(v, x) @ v.T, ref @ v.T, rtol=0, atol=1e-12)  # the fits
        if gap > 1e-3:
            np.testing.assert_allclose(_lstsq(v, x), ref, rtol=1e-12, atol=1e-13)
    vc = np.exp(np.outer(t, [-0.01 + 1j, -0.02 + 0.4j]))
    vc /= np.linalg.norm(vc, axis=0)
    xc = (vc @ np.array([1.0 + 2j, -0.5j])).astype(complex)
    np.testing.assert_allclose(_lstsq(vc, xc), linalg.lstsq(vc, xc)[0], rtol=1e-12)


def test_sdof_example_of_section_4():
    r = paper000_sdof.run()
    c = r["components"]
    # forced response (undamped) and the offset
    for f in (0.2, 0.3, 0.8):
        row = c[np.argmin(np.abs(c["frequency"] - f))]
        assert abs(row["frequency"] - f) < 1e-4 and abs(row["damping"]) < 1e-4 and row["kept"]
    zero = c[c["frequency"] < 1e-6]
    assert len(zero) == 1 and not zero["kept"][0] and abs(zero["amplitude"][0] - paper000_sdof.OFFSET) < 1e-3
    # the model's own transient poles (m_a = 0): 0.3225 Hz ξ 0.581 and 0.4148 Hz ξ 0.208
    for pole in paper000_sdof.transient_poles()[::2]:
        f, xi = abs(pole.imag) / (2 * math.pi), -pole.real / abs(pole)
        row = c[np.argmin(np.abs(c["frequency"] - f))]
        assert abs(row["frequency"] - f) < 2e-3 * f and abs(row["damping"] - xi) < 2e-3
    assert len(c) == 6  # the paper's extraction value
    assert r["max_error_pct"] <= 0.5  # goal; measured 0.0022 %


def test_sdof_against_a_coarse_newmark_reference_shows_the_schemes_own_error():
    """With the integration step equal to the 0.1 s sample step, Newmark's period error
    (≈ (ωΔt)²/12, 2 % at 0.8 Hz) makes the reference itself disagree with its acceleration:
    the same reconstruction then scores ~0.9 %, close to the paper's 0.81 %."""
    coarse = paper000_sdof.run(substeps=1)["max_error_pct"]
    assert 0.5 < coarse < 1.2


def test_paper_stopping_criterion_stops_early_on_the_sdof():
    sim = paper000_sdof.simulate(substeps=20)
    keep = sim["time"] >= 3.0 - 1e-9
    a = sim["a"][keep] + 2.0
    paper = decompose(a, 0.1, max_components=6, stop="sc_sw", sc_tol=1e-3)
    ours = decompose(a, 0.1, max_components=6)
    assert paper.order < ours.order == 11


@pytest.mark.parametrize("noise,bounds", [(False, (1.0, 1.0, 1.0)), (True, (3.0, 3.0, 3.0))])
def test_semisub_6dof_goals(noise, bounds):
    r = paper000_semisub.run(duration=1200.0, noise=noise)
    assert np.all(r["cog_rms_pct"] <= bounds), r["cog_rms_pct"]
    if not noise:
        assert np.all(r["attitude_rms_deg"][:2] < 0.001)  # gyro-only, noise-free: paper's setting
    else:  # the project's goal, aided filter + post-processed refinement (measured 0.0061/0.0070)
        assert np.all(r["attitude_rms_deg"][:2] <= 0.02), r["attitude_rms_deg"]


def test_tilt_correction_small_angle_matches_exact_to_second_order():
    rng = np.random.default_rng(2)
    euler = rng.normal(size=(50, 3)) * [0.01, 0.01, 0.0]
    f = np.array([0.1, -0.2, -9.7]) + rng.normal(size=(50, 3)) * 0.05
    exact = tilt_correct(f, euler)
    small = tilt_correct(f, euler, "small_angle")
    assert np.max(np.abs(exact - small)) < 9.81 * 0.05 ** 2 + 0.3 * 0.05  # O(φ²g) + O(φ·a_dyn)


@pytest.mark.parametrize("kwargs,match", [
    ({"cutoff": 0.0}, r"cutoff = 0.0 is out of range: must be in \(0.0, 50.0\)"),
    ({"cutoff": 50.0}, r"cutoff = 50.0 is out of range"),
    ({"max_components": 0}, r"max_components = 0 is out of range"),
    ({"segment": 10.0}, r"segment = 10.0 is out of range: must be >= 66.6"),
])
def test_invalid_settings_are_refused_by_name(kwargs, match):
    args = {"cutoff": 0.03, **kwargs}
    with pytest.raises(ParameterError, match=match):
        reconstruct_displacement(np.zeros(1000), 0.01, **args)


def test_degenerate_signals_give_finite_zeros():
    for x in (np.zeros(5000), np.full(5000, 3.0), np.zeros(3), np.ones(4)):
        r = reconstruct_displacement(x, 0.01, 0.03)
        assert np.all(np.isfinite(r.displacement)) and np.allclose(r.displacement, 0.0, atol=1e-9)


def test_nan_in_batch_input_is_refused():
    x = np.zeros(1000)
    x[10] = np.nan
    with pytest.raises(ParameterError, match="NaN or Inf"):
        reconstruct_displacement(x, 0.01, 0.03)


def sliding_record(seconds=330.0):
    rec = paper000_semisub.simulate(seconds, noise=False)
    return rec["acc"], rec["euler"], rec["cog"]


def test_sliding_window_centred_estimate_and_validity():
    acc, euler, cog = sliding_record()
    sr = DisplacementReconstructor(DisplacementReconstructorParams(window=200.0, hop=20.0, lever_arm=paper000_semisub.LEVER_ARM))
    assert sr.estimate_at(0.0) is None  # nothing fitted yet
    out = [sr.step(acc[k], euler[k], 0.01) for k in range(len(acc))]
    first = next(k for k, r in enumerate(out) if r.valid)
    assert first == 19999  # the sample at t = 200 s fills the window
    assert out[-1].delay == 100.0
    # the output is the model at the window centre, delay s before the latest sample
    d, v = sr.estimate_at(out[-1].delay)
    np.testing.assert_allclose(d, out[-1].disp, rtol=0, atol=1e-12)
    np.testing.assert_allclose(v, out[-1].vel, rtol=0, atol=1e-12)
    with pytest.raises(ValueError, match="lag must be in"):
        sr.estimate_at(200.0)
    centred = np.array([r.disp for r in out[20000:]])
    truth = cog[20000 - 10000:len(cog) - 10000]
    err = centred - (truth - truth.mean(axis=0))
    rel = np.sqrt(np.mean(err ** 2, axis=0)) / truth.std(axis=0)
    # the deck-edge sensor (41, 35, -35) m from the COG, noise-free: 130 s scored here, measured
    # 0.15 / 0.17 / 0.12 % with R_nb l high-passed at the screen; a straight-line transfer
    # (which subtracts R_nb l's slow part, which the screen has removed from the IMU's motion)
    # errs 0.54 / 0.81 / 0.16 %, and fails this
    assert np.all(rel < 0.003), rel


def test_sliding_bad_samples_hold_invalidate_and_state_round_trips():
    acc, euler, _ = sliding_record(95.0)
    p = DisplacementReconstructorParams(window=70.0, hop=10.0, cutoff=0.04)
    sr = DisplacementReconstructor(p, dt=0.01)
    for k in range(7500):
        sr.step(acc[k], euler[k], 0.01)
    r = sr.step([np.nan, 0.0, 0.0], euler[7500], 0.01)
    assert not r.valid and r.warning and all(map(math.isfinite, r.disp + r.vel))
    saved = json.loads(json.dumps(sr.get_state()))
    a = [sr.step(acc[k], euler[k], 0.01) for k in range(7501, 9100)]
    sr2 = DisplacementReconstructor(p)
    sr2.set_state(saved)
    b = [sr2.step(acc[k], euler[k], 0.01) for k in range(7501, 9100)]
    assert [x.disp for x in a] == [x.disp for x in b]
    assert a[-1].valid  # one replaced sample in 7000 is below max_bad_fraction


def test_sliding_block_of_centre_values_equals_the_per_step_model():
    """Each step's output (read from a block of model values computed ahead) equals the model
    evaluated at the window centre that step (estimate_at), to rounding, across refits, block
    edges, a hop longer than half the window (where the centre leaves the fitted window and the
    lever arm is extrapolated) and a restored state."""
    acc, euler, _ = sliding_record(120.0)
    p = DisplacementReconstructorParams(window=70.0, hop=40.0, cutoff=0.04, lever_arm=(20.0, -5.0, -8.0))
    sr = DisplacementReconstructor(p, dt=0.01)
    worst = 0.0
    for k in range(len(acc)):
        r = sr.step(acc[k], euler[k], 0.01)
        if k == 9037:  # mid-block
            sr2 = DisplacementReconstructor(p)
            sr2.set_state(json.loads(json.dumps(sr.get_state())))
            sr = sr2
        if sr.models is not None:
            d, v = sr.estimate_at(r.delay)
            worst = max(worst, float(np.max(np.abs(np.concatenate((d - r.disp, v - r.vel))))))
    assert sr.models is not None and worst < 1e-12, worst


@pytest.mark.parametrize("kwargs,match", [
    ({"window": 10.0}, r"window = 10.0 is out of range: must be in \[66.6"),
    ({"hop": 0.0}, r"hop = 0.0 is out of range"),
    ({"tilt": "exakt"}, r"tilt = 'exakt' is not allowed"),
])
def test_sliding_parameters_refused_by_name(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        DisplacementReconstructorParams(**kwargs).validate(0.01)
