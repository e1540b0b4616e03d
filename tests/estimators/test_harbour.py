"""Every estimator in harbour: constant input with no motion (specific force (0, 0, −g) FRD,
zero rates, level, GNSS antennas fixed at their lever arms), exact and with the default MEMS
grade's white noise (seeded; GNSS the sensors' default RTK noise). Each must keep every output
finite at every step and every variance it holds positive, and either stay valid with an
estimate that is right (attitude, GNSS fusion, displacement, and heave once the noise gives the
Wiener filter a spectrum) or say once in the log why it is not valid (heave with no spectrum,
centre of rotation with no rotation).

Durations: an hour would take minutes (0.1-0.4 ms a step at 100 Hz, and the Wiener heave's
designs 0.2 s each), so each run lasts as long as its behaviour takes to show, with the
run's end shown to be steady or each refit or design starting afresh, so that a longer run
adds nothing: attitude 120 s (levelling, the auto sizing's 40 s start, its 120 s memory
corrected for the start), displacement 230 s (the 200 s window and four refits), GNSS fusion
190 s (past the wave coast's first spectrum at 180 s, where an axis with no waves gets no
band), centre of rotation 40 s (its judgement of the rotation takes 2.5 s), heave 20 minutes of
exact input (73 designs, the window grown to its 20-minute ``window_max``) and 200 s with noise
(its first spectrum at 120 s and five more designs).
"""
from __future__ import annotations

import logging
import math
from dataclasses import astuple

import numpy as np
import pytest

from marinefmu.estimators.attitude import estimator as att
from marinefmu.estimators.attitude.estimator import AttitudeEstimator
from marinefmu.estimators.centre_of_rotation import filter as cor
from marinefmu.estimators.centre_of_rotation.filter import CentreOfRotation
from marinefmu.estimators.gnss_fusion.antenna_attitude import DEFAULT_ANTENNAS
from marinefmu.estimators.gnss_fusion.filter import GnssAccFusion
from marinefmu.estimators.heave.common import HeaveObserverParams
from marinefmu.estimators.heave.observer import HeaveObserver
from marinefmu.estimators.reconstruction.sliding import DisplacementReconstructor
from marinefmu.frames import G
from marinefmu.papers import paper003
from marinefmu.sea.sensors import IMU_GRADES, GnssParams

DT = 0.01
HEAVE_DT = paper003.DT           # the heave tests' rate, 20 Hz
MEMS = IMU_GRADES["mems"]
VARIANTS = ["exact", "noisy"]


def imu(seconds: float, dt: float, variant: str, seed: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) specific force [m/s², FRD] and angular rate [rad/s] of a sensor at rest, level,
    with the MEMS grade's white noise (per-sample σ = N/√Δt) for ``"noisy"``."""
    n = int(round(seconds / dt))
    acc = np.tile([0.0, 0.0, -G], (n, 1))
    gyro = np.zeros((n, 3))
    if variant == "noisy":
        rng = np.random.default_rng(seed)
        acc += MEMS.acc_noise / math.sqrt(dt) * rng.standard_normal((n, 3))
        gyro += MEMS.gyro_noise / math.sqrt(dt) * rng.standard_normal((n, 3))
    return acc, gyro


def numbers(result) -> list[float]:
    """Every number of a result (nested tuples flattened; booleans and strings left out)."""
    def flat(v):
        if isinstance(v, (tuple, list)):
            return [x for e in v for x in flat(e)]
        return [] if isinstance(v, (bool, np.bool_, str)) or v is None else [float(v)]
    return flat(astuple(result))


def finite(results: list) -> bool:
    """Every number of every result finite (no NaN, no Inf)."""
    return all(math.isfinite(x) for r in results for x in numbers(r))


def warnings_of(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno >= logging.WARNING and r.name.startswith("marinefmu")]


def positive_diagonal(p: np.ndarray) -> bool:
    d = np.diag(p)
    return bool(np.all(np.isfinite(p)) and np.all(d > 0.0))


# ---- attitude: valid, the auto sizing at its floor -------------------------------------------
@pytest.mark.parametrize("variant", VARIANTS)
def test_attitude_stays_valid_and_level_with_its_aiding_at_the_floor(variant, caplog):
    """After levelling (10 s) valid throughout, roll and pitch within 1 mrad (exactly 0 without
    noise); the auto-sized σ_v at :data:`~.attitude.estimator.SIGMA_V_MIN` per axis (noise and
    the filter's own tilt leave up to 2.5 times that), σ_p = POS_RATIO σ_v, and the filter's
    covariance positive; with noise steady over the last 20 s within a factor 2. Without noise
    the sized gyro noise is :data:`~.attitude.estimator.GYRO_NOISE_MIN` and the covariance
    shrinks towards its steady state, still shrinking at 120 s (measured over an hour: steady
    from 12 minutes on, smallest eigenvalue 7.9e-15, valid and exactly level throughout)."""
    acc, gyro = imu(120.0, DT, variant)
    est = AttitudeEstimator()
    out, sigmas, pdiag = [], [], []
    with caplog.at_level(logging.WARNING):
        for k in range(len(acc)):
            out.append(est.step(gyro[k], acc[k], DT))
            if k % 100 == 99:
                assert positive_diagonal(est.kf.P) and positive_diagonal(est.kf.R), k
                sigmas.append(np.sqrt(np.diag(est.kf.R)))
                pdiag.append(np.diag(est.kf.P))
    assert finite(out)
    level = int(round(est.params.level_time / DT))
    assert not any(r.valid for r in out[:level - 1]) and all(r.valid for r in out[level:])
    tilt = np.array([(r.roll, r.pitch) for r in out])
    assert np.max(np.abs(tilt)) < (1e-3 if variant == "noisy" else 1e-15), np.max(np.abs(tilt))
    sigma_v = sigmas[-1][2:4]
    assert np.all(sigma_v >= att.SIGMA_V_MIN)
    assert np.all(sigma_v <= (2.5 if variant == "noisy" else 1.0) * att.SIGMA_V_MIN), sigma_v
    np.testing.assert_allclose(sigmas[-1][0:2], att.POS_RATIO * sigma_v, rtol=1e-12)
    if variant == "exact":      # shrinking towards its steady state, never below zero
        assert np.all(pdiag[-1] <= pdiag[-20] * (1.0 + 1e-12)) and est.gyro_noise_used == att.GYRO_NOISE_MIN
    else:                       # the sizing follows the noise, and the covariance the sizing
        assert np.all(pdiag[-1] < 2.0 * pdiag[-20]) and np.all(pdiag[-1] > 0.5 * pdiag[-20])
    assert warnings_of(caplog) == []


# ---- displacement: valid, nothing (or noise) to reconstruct -----------------------------------
@pytest.mark.parametrize("variant", VARIANTS)
def test_displacement_is_zero_and_valid_once_the_window_is_full(variant, caplog):
    """With no motion there is nothing above the screening frequency, and the reconstruction
    says so: zero displacement exactly (no component fitted) without noise, millimetres of
    fitted noise with it, valid from the first full window on. Each refit starts afresh on its
    window, so four refits show what an hour would."""
    acc, _ = imu(230.0, DT, variant)
    est = DisplacementReconstructor()
    with caplog.at_level(logging.WARNING):
        out = [est.step(acc[k], np.zeros(3), DT) for k in range(len(acc))]
    assert finite(out)
    full = est.n_win - 1
    assert not any(r.valid for r in out[:full]) and all(r.valid for r in out[full:])
    disp = np.array([r.disp + r.vel for r in out])
    if variant == "exact":
        assert np.all(disp == 0.0) and all(len(lam) == 0 for lam, _, _ in est.models)
    else:
        assert np.max(np.abs(disp)) < 0.01, np.max(np.abs(disp))
    assert warnings_of(caplog) == []


# ---- GNSS fusion: valid, the position at the origin --------------------------------------------
@pytest.mark.parametrize("variant", VARIANTS)
def test_gnss_fusion_stays_valid_at_the_origin(variant, caplog):
    """1 Hz fixes of the four antennas at their lever arms: every fix accepted, valid at every
    step, the position within 5 cm (0 without noise), ``pos_std`` and the Kalman and coast
    covariances positive, through the wave coast's first spectrum of a sea with no waves."""
    acc, gyro = imu(190.0, DT, variant)
    arms = np.array(DEFAULT_ANTENNAS)
    gnss = GnssParams()
    rng = np.random.default_rng(2)
    est = GnssAccFusion()
    out = []
    with caplog.at_level(logging.WARNING):
        for k in range(len(acc)):
            fix = None
            if k % 100 == 0:
                fix = arms + (rng.standard_normal((4, 3)) * [gnss.sigma_h, gnss.sigma_h, gnss.sigma_v]
                              if variant == "noisy" else 0.0)
            out.append(est.step(acc[k], fix, DT, gyro[k]))
            if k % 100 == 50:
                assert positive_diagonal(est.kf.P), k
    assert finite(out)
    assert all(r.valid for r in out)
    assert all(r.fix == "accepted" for r in out[::100])
    assert np.all(np.array([r.pos_std for r in out]) > 0.0)
    pos = np.array([r.pos for r in out])
    assert np.max(np.abs(pos)) < (0.05 if variant == "noisy" else 1e-12), np.max(np.abs(pos))
    assert est.coaster.ready
    coast_std = est.coaster.position_std()
    assert np.all(np.isfinite(coast_std)) and np.all(coast_std > 0.0), coast_std
    for band in est.coaster.bands:
        assert positive_diagonal(band.P)
    assert warnings_of(caplog) == []


# ---- centre of rotation: not observable, said once --------------------------------------------
@pytest.mark.parametrize("variant", VARIANTS)
def test_centre_of_rotation_says_once_that_without_rotation_it_cannot_estimate(variant, caplog):
    """No rotation, no offset: once the angular acceleration has been judged (1 s after the
    1.5 s window filled) valid is false for the rest of the run, one warning says why, the
    offset is held and its standard deviation (positive, finite) does not shrink, as the
    gyro's noise would make it (to 1.1 m in 300 s without the check) if it were taken for
    rotation. The CR's own acceleration is still estimated: 0 (with noise, within 5 cm/s²: its
    random walk follows the accelerometer's noise of 7 mm/s² per sample)."""
    acc, gyro = imu(40.0, DT, variant)
    est = CentreOfRotation()
    out = []
    with caplog.at_level(logging.WARNING):
        for k in range(len(acc)):
            out.append(est.step(acc[k], gyro[k], DT))
            if k % 100 == 50:
                assert positive_diagonal(est.kf.P), k
    assert finite(out)
    judged = int(round((est.params.diff_window + cor.EXCITATION_MIN) / DT)) + 1
    assert not any(r.valid for r in out[judged:])
    assert est.unobservable
    logged = warnings_of(caplog)
    assert len(logged) == 1 and "no rotation to observe the offset" in logged[0], logged
    std = np.array([r.offset_std for r in out[judged:]])
    offset = np.array([r.offset for r in out[judged:]])
    assert np.all(std > 1.0) and np.all(np.diff(std, axis=0) >= 0.0), std
    assert np.all(offset == offset[0])
    assert np.max(np.abs([r.acc_cr_n for r in out[judged:]])) < (0.05 if variant == "noisy" else 1e-12)


def test_centre_of_rotation_estimates_again_when_the_rotation_returns(caplog):
    """After 30 s in harbour the vessel starts to roll from rest (0.05 (1 − cos ωt) rad, ω
    0.8 rad/s, about a CR 3 m below the sensor): valid again, and the offset, held until then,
    within 0.25 m of the CR after 30 s (measured 0.08 m; its standard deviation 0.43 m)."""
    acc, gyro = imu(30.0, DT, "exact")
    est = CentreOfRotation()
    for k in range(len(acc)):
        est.step(acc[k], gyro[k], DT)
    assert est.unobservable
    w, amp, depth = 0.8, 0.05, 3.0
    with caplog.at_level(logging.INFO):
        for k in range(3000):
            t = (k + 1) * DT
            roll, rate, ang_acc = amp * (1.0 - math.cos(w * t)), amp * w * math.sin(w * t), amp * w * w * math.cos(w * t)
            # rigid body about a CR at (0, 0, depth) from the sensor: f_b = R^T(−g_n) − α × o − ω × (ω × o)
            f = np.array([0.0, -G * math.sin(roll) + ang_acc * depth, -G * math.cos(roll) + rate * rate * depth])
            r = est.step(f, [rate, 0.0, 0.0], DT)
    assert r.valid and not est.unobservable
    assert abs(r.offset[1]) < 0.05 and abs(r.offset[2] - depth) < 0.25, r.offset
    assert any("rotation again" in m.getMessage() for m in caplog.records)


# ---- heave: no spectrum, said once; with noise, valid and near zero ---------------------------
def test_heave_without_noise_says_once_that_there_is_no_sea(caplog):
    """20 minutes of exact input at 20 Hz: 73 designs find nothing above the noise; valid stays
    false, all outputs zero, and the reason is logged once, not at every design."""
    acc, _ = imu(1200.0, HEAVE_DT, "exact")
    est = HeaveObserver()
    with caplog.at_level(logging.WARNING):
        out = [est.step(acc[k], 0.0, 0.0, HEAVE_DT) for k in range(len(acc))]
    assert finite(out) and not any(r.valid for r in out)
    assert all(numbers(r)[:7] == [0.0] * 7 for r in out)     # heave, rates, point and delayed heave
    logged = warnings_of(caplog)
    assert len(logged) == 1 and "no sea above the accelerometer noise" in logged[0] and "valid = false" in logged[0]


def test_heave_with_sensor_noise_is_valid_and_sub_millimetre(caplog):
    """With the MEMS noise the spectrum's scatter above the noise model gives the Wiener filter
    a tiny sea: valid from the first window (120 s), the heave right to the noise (RMS under
    1 mm; measured 0.3 mm over an hour), the taps finite, no warning."""
    acc, _ = imu(200.0, HEAVE_DT, "noisy")
    est = HeaveObserver()
    with caplog.at_level(logging.WARNING):
        out = [est.step(acc[k], 0.0, 0.0, HEAVE_DT) for k in range(len(acc))]
    assert finite(out)
    first = int(round(est.params.window / HEAVE_DT)) - 1
    assert not any(r.valid for r in out[:first]) and all(r.valid for r in out[first:])
    assert np.all(np.isfinite(est.estimator.taps))
    heave = np.array([r.heave for r in out[first:]])
    assert math.sqrt(np.mean(heave ** 2)) < 1e-3 and np.max(np.abs(heave)) < 5e-3
    assert warnings_of(caplog) == []


@pytest.mark.parametrize("model", ["band", "peaks"])
def test_the_observer_models_say_once_that_there_is_no_peak(model, caplog):
    """The paper's observer models on five minutes of exact input: no spectral peak at any of
    the 13 detections, valid false, the reason logged once."""
    acc, _ = imu(300.0, HEAVE_DT, "exact")
    est = HeaveObserver(HeaveObserverParams(model=model))
    with caplog.at_level(logging.WARNING):
        out = [est.step(acc[k], 0.0, 0.0, HEAVE_DT) for k in range(len(acc))]
    assert finite(out) and not any(r.valid for r in out)
    logged = warnings_of(caplog)
    assert len(logged) == 1 and "no spectral peak" in logged[0] and "valid = false" in logged[0], logged
