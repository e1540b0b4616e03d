"""GnssAccFusion's ``noise_sizing``: R sized from the epoch rate and the antenna-fit residual
("auto"), or r/Δt as given ("fixed"). Synthetic platforms run at Δt = 0.05 s to keep the runs
short (R = r/Δt holds for any accelerometer interval)."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from marinefmu.bench.cases import case_record, placements
from marinefmu.bench.defaults_fusion import FUSION_GRID, cog_rms_cm, merit
from marinefmu.errors import ParameterError
from marinefmu.estimators.gnss_fusion.antenna_attitude import DEFAULT_ANTENNAS, antenna_attitude
from marinefmu.estimators.gnss_fusion.filter import (FIX_INTERVAL_REF, NOISE_FACTOR_RANGE, NOISE_MEMORY, SIGMA_REF,
                                                     GnssAccFusion, GnssAccFusionParams, residual_ms)
from marinefmu.frames import G

ARMS = np.array(DEFAULT_ANTENNAS)
DT = 0.05
LEVEL = np.array([0.0, 0.0, -G])


def at_rest(seconds: float, rate: float, sigma: tuple[float, float], seed: int = 1,
            params: GnssAccFusionParams | None = None) -> tuple[GnssAccFusion, list[float]]:
    """The fusion on a level platform at rest at the origin, antennas with white noise of
    ``sigma`` (horizontal, vertical) [m] at ``rate`` [Hz]; the estimator and the fit residual
    of every epoch [m]."""
    rng = np.random.default_rng(seed)
    est = GnssAccFusion(params or GnssAccFusionParams(coast="inertial"))
    every = int(round(1.0 / (rate * DT)))
    residuals = []
    for k in range(int(round(seconds / DT))):
        gnss = None
        if k % every == 0:
            gnss = ARMS + np.array([sigma[0], sigma[0], sigma[1]]) * rng.standard_normal((4, 3))
        r = est.step(LEVEL, gnss, DT, np.zeros(3))
        assert all(math.isfinite(x) for x in (*r.pos, *r.vel, *r.pos_std))
        if gnss is not None:
            residuals.append(r.residual)
    return est, residuals


def running_mean(values: list[float]) -> float:
    """The filter's running mean of the squares (the mean until :data:`NOISE_MEMORY`, then
    exponential), recomputed from the residuals it reported."""
    m = 0.0
    for i, v in enumerate(values):
        m += (v * v - m) / min(i + 1, NOISE_MEMORY)
    return m


def test_residual_ms_is_the_mean_square_fit_residual_of_noisy_antennas():
    # the sum of squares is a weighted chi-square (5 horizontal, 1 vertical degree of freedom for
    # the level rectangle): relative std sqrt(2 (5 + 2.25²)) / 7.25 = 0.62 per fix, 1.6 % over 1500;
    # 5 % is 3 sigma. Tilted by up to 0.1 rad, as a vessel in waves.
    rng = np.random.default_rng(7)
    sig = np.array([0.02, 0.02, 0.03])
    ms = []
    for _ in range(1500):
        rot = Rotation.from_euler("ZYX", rng.uniform(-0.1, 0.1, 3) * (10, 1, 1)).as_matrix()
        ms.append(antenna_attitude(ARMS @ rot.T + sig * rng.standard_normal((4, 3)), ARMS).residual ** 2)
    expected = residual_ms(ARMS, 0.02, 0.03)
    assert expected == pytest.approx((5 * 0.02 ** 2 + 0.03 ** 2) / 4, rel=1e-12)
    assert np.mean(ms) == pytest.approx(expected, rel=0.05)


@pytest.mark.parametrize("rate, scale", [(1.0, 1.0), (5.0, 1.0), (1.0, 3.0)])
def test_auto_r_is_what_the_receiver_rate_and_noise_imply(rate, scale):
    # r = r_default at 1 Hz with the reference noise SIGMA_REF; k times the rate or s times the
    # noise's standard deviation: k or s² times that
    seconds = 120.0 if rate == 1.0 else 40.0
    est, residuals = at_rest(seconds, rate, (scale * SIGMA_REF[0], scale * SIGMA_REF[1]))
    r0 = GnssAccFusionParams().r
    interval = float(np.median(est.intervals))
    assert interval == pytest.approx(1.0 / rate, rel=1e-9)
    factor = running_mean(residuals) / residual_ms(ARMS, *SIGMA_REF)
    assert est.r_used == pytest.approx(r0 * FIX_INTERVAL_REF / interval * factor, rel=1e-12)
    # the running mean over >= 100 fixes: relative std 0.62/sqrt(100) = 6 %; 20 % is 3 sigma
    assert est.r_used == pytest.approx(r0 * rate * scale ** 2, rel=0.2)


def test_fixed_hands_r_over_dt_to_every_gnss_update(monkeypatch):
    est = GnssAccFusion(GnssAccFusionParams(coast="inertial", noise_sizing="fixed"))
    seen = []
    update = est.kf.update
    monkeypatch.setattr(est.kf, "update", lambda z, R=None: (seen.append(np.array(R)), update(z, R=R))[1])
    rng = np.random.default_rng(2)
    for k in range(400):
        est.step(LEVEL, ARMS + 0.03 * rng.standard_normal((4, 3)) if k % 4 == 0 else None, DT, np.zeros(3))
    assert len(seen) == 99          # the first epoch initialises
    for r in seen:
        assert np.array_equal(r, np.eye(3) * (est.params.r / DT))
    assert est.r_used == est.params.r


@pytest.mark.parametrize("sigma", [(0.0, 0.0), SIGMA_REF])
def test_auto_r_stays_positive_and_finite_in_harbour(sigma):
    # exact input (no noise: a zero residual) takes the lower bound of the noise factor
    est, _ = at_rest(30.0, 5.0, sigma)
    assert math.isfinite(est.r_used) and est.r_used > 0.0
    if sigma == (0.0, 0.0):
        assert est.r_used == pytest.approx(GnssAccFusionParams().r * 5.0 * NOISE_FACTOR_RANGE[0], rel=1e-9)
    assert np.all(np.linalg.eigvalsh(est.kf.P) > 0.0)


def test_the_sizing_state_survives_get_and_set_state():
    est, _ = at_rest(10.0, 5.0, SIGMA_REF)
    other = GnssAccFusion(est.params)
    other.set_state(est.get_state())
    rng = np.random.default_rng(4)
    for k in range(40):
        gnss = ARMS + 0.01 * rng.standard_normal((4, 3)) if k % 4 == 0 else None
        a, b = est.step(LEVEL, gnss, DT, np.zeros(3)), other.step(LEVEL, gnss, DT, np.zeros(3))
        assert a == b
    assert other.r_used == est.r_used


def test_an_unknown_noise_sizing_is_refused_with_the_choices():
    with pytest.raises(ParameterError, match=r"noise_sizing = 'adaptive' is not allowed: must be one of 'auto', 'fixed'"):
        GnssAccFusionParams(noise_sizing="adaptive")


def test_defaults_within_the_goal_of_the_best_known_setting_on_a_short_case():
    # 5 Hz RTK (VesselMotion's default) on the polar supply vessel in Hs 3 m, IMU forward: the
    # defaults against the system scenario's setting (the best known at 5 Hz) and paper 001's
    # (1 Hz, the fixed defaults before the sizing), 60 s scored after 40 s; paper 001's is over
    # the goal here, so the case tells
    rec = case_record("polar_supply", 3.0, 10.0, "far", duration=100.0)
    base = GnssAccFusionParams(acc_lever_arm=placements("polar_supply")["far"], coast="inertial")
    default = merit(cog_rms_cm(rec, base, settle=40.0))
    paper, system = (merit(cog_rms_cm(rec, replace(base, noise_sizing="fixed", **g), settle=40.0))
                     for g in FUSION_GRID[:2])
    assert default <= 1.15 * min(paper, system)
    assert paper > 1.15 * system


def test_the_bench_coast_changes_nothing_without_a_gap():
    # defaults_fusion runs coast="inertial": without a GNSS gap the position is the band coast's
    from marinefmu.bench.defaults_fusion import BENCH_COAST
    from marinefmu.estimators.gnss_fusion.runs import fuse
    from marinefmu.sea.motion_model import stack

    rec = case_record("semisub", 1.0, 5.0, "far", duration=30.0)
    acc, gyro = stack(rec, "imu.acc"), stack(rec, "imu.gyro")
    gnss = np.hstack([stack(rec, f"gnss.ant{i}", "ned") for i in range(1, 5)])
    base = GnssAccFusionParams(acc_lever_arm=placements("semisub")["far"])
    pos = [fuse(acc, 0.01, gnss, rec["gnss.new"], gyro, replace(base, coast=c), gnss_valid=rec["gnss.valid"])["pos"]
           for c in ("band", BENCH_COAST)]
    assert np.array_equal(pos[0], pos[1])
