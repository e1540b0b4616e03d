"""Scoring of estimator components against a vessel's truth, on a synthetic result with known
errors (no FMU needed)."""
import math

import numpy as np
import pytest

from marinefmu.cosim.ssp import Component, Connection, SystemDescription
from marinefmu.analysis.scoring import score


def _result(n=2001, dt=0.1):
    fields = ["vessel.truth.roll", "vessel.truth.pitch", "vessel.truth.imu.d", "vessel.truth.point.d",
              "vessel.truth.cog.n", "vessel.truth.cog.e", "vessel.truth.cog.d",
              "att.roll", "att.pitch", "att.valid", "heave.heave", "heave.point.heave", "heave.valid",
              "fusion.pos.n", "fusion.pos.e", "fusion.pos.d", "fusion.valid"]
    r = np.zeros(n, dtype=[("time", "f8")] + [(f, "?" if f.endswith("valid") else "f8") for f in fields])
    t = np.arange(n) * dt
    r["time"] = t
    wave = np.sin(0.7 * t)
    r["vessel.truth.roll"], r["vessel.truth.pitch"] = 0.05 * wave, 0.02 * wave
    r["vessel.truth.imu.d"], r["vessel.truth.point.d"] = 3.0 + wave, -7.0 + 2.0 * wave     # means the observer has not
    for a in "ned":
        r[f"vessel.truth.cog.{a}"] = wave
    return r, t


def test_scores_are_the_rms_errors_over_the_valid_settled_span():
    r, t = _result()
    start = 50.0                                        # valid from 50 s; settle 60 s: scored from 110 s
    for c in ("att", "heave", "fusion"):
        r[f"{c}.valid"] = t >= start
    r["att.roll"] = r["vessel.truth.roll"] + math.radians(0.1) * np.sign(np.sin(3.0 * t))   # 0.1 deg RMS
    r["att.pitch"] = r["vessel.truth.pitch"] + np.where(t < 110.0, 1.0, 0.0)             # wrong only before scoring
    r["heave.heave"] = np.sin(0.7 * t) + 0.02 * np.cos(2.0 * t)                           # 2/√2 cm RMS
    r["heave.point.heave"] = 2.0 * np.sin(0.7 * t)
    for i, a in enumerate("ned"):
        r[f"fusion.pos.{a}"] = r[f"vessel.truth.cog.{a}"] + 0.01 * (i + 1)                # 1, 2, 3 cm
    system = SystemDescription("s", tuple(Component(n, f"{k}.fmu") for n, k in (
        ("vessel", "VesselMotion"), ("att", "AttitudeEstimator"), ("heave", "HeaveObserver"), ("fusion", "GnssAccFusion"))),
        (Connection("vessel", "imu.acc.x", "att", "acc.x"),), 0.1, 200.0)
    s = score(r, system, "vessel", delay=0)
    assert set(s) == {"att", "heave", "fusion"}
    assert s["att"]["roll_deg"] == pytest.approx(0.1, rel=1e-6)
    assert s["att"]["pitch_deg"] == pytest.approx(0.0, abs=1e-12)
    assert s["att"]["scored_s"] == pytest.approx(200.0 - 110.0 + 0.1, abs=1e-9)
    assert s["att"]["valid_fraction"] == pytest.approx(1501 / 2001)   # 50.0 s … 200.0 s
    # the truth's mean over the span is removed; the sinusoid's own mean over 90 s is not zero
    span = t >= 110.0
    truth = r["vessel.truth.imu.d"][span]
    expected = np.sqrt(np.mean((r["heave.heave"][span] - (truth - truth.mean())) ** 2))
    assert s["heave"]["heave_cm"] == pytest.approx(100 * expected, rel=1e-12) and 1.0 < s["heave"]["heave_cm"] < 2.5
    assert s["heave"]["heave_std_cm"] == pytest.approx(100 * np.std(truth))
    assert [s["fusion"][f"pos_{a}_cm"] for a in "ned"] == pytest.approx([1.0, 2.0, 3.0])


def test_an_estimator_never_valid_has_no_error_metrics():
    r, _ = _result()
    system = SystemDescription("s", (Component("vessel", "VesselMotion.fmu"), Component("att", "AttitudeEstimator.fmu")),
                               (), 0.1, 200.0)
    s = score(r, system, "vessel")
    assert s["att"]["valid_fraction"] == 0.0 and s["att"]["scored_s"] == 0.0 and math.isnan(s["att"]["roll_deg"])


def test_estimates_are_compared_with_the_truth_one_communication_step_earlier():
    """Jacobi coupling: the estimate recorded at t_{k+1} was computed from the vessel's
    outputs at t_k; with delay = 1 an estimator that echoes the truth one row late scores 0."""
    r, t = _result()
    r["att.valid"] = np.ones_like(t, dtype=bool)
    r["att.roll"] = np.r_[0.0, r["vessel.truth.roll"][:-1]]
    r["att.pitch"] = np.r_[0.0, r["vessel.truth.pitch"][:-1]]
    system = SystemDescription("s", (Component("vessel", "VesselMotion.fmu"), Component("att", "AttitudeEstimator.fmu")),
                               (), 0.1, 200.0)
    assert score(r, system, "vessel")["att"]["roll_deg"] == 0.0
    assert score(r, system, "vessel", delay=0)["att"]["roll_deg"] > 0.01


def _mru_system(mp1=(5.0, 2.0, -1.0)):
    vessel = Component("vessel", "VesselMotion.fmu", {"imu.x": 1.0, "imu.y": 0.0, "imu.z": -2.0,
                                                       "point.x": 6.0, "point.y": 2.0, "point.z": -3.0})
    mru = Component("mru", "MotionReferenceUnit.fmu", {"mp1.enabled": True, "mp1.x": mp1[0], "mp1.y": mp1[1],
                                                        "mp1.z": mp1[2]})
    return SystemDescription("s", (vessel, mru), (), 0.1, 200.0)


def test_a_motion_reference_unit_is_scored_at_its_imu_and_at_the_vessels_point_with_its_delay():
    """Known errors: 1, 2, 3 cm square waves at the IMU; at the point (mp1 = the vessel's point
    minus its IMU) 2 cm on each axis, so 2√3 cm in 3-D; the delayed outputs are the truth
    ``delay`` s late, so score 0; roll and pitch from ``valid``, the motion from ``motion.valid``."""
    from marinefmu.analysis.scoring import mru_point

    n, dt, lag = 2001, 0.1, 50
    t = np.arange(n) * dt
    wave, square = np.sin(0.7 * t), np.sign(np.sin(3.0 * t + 0.1))
    locs = [("imu", ""), ("point", "mp1.")]
    fields = ["vessel.truth.roll", "vessel.truth.pitch", "mru.roll", "mru.pitch", "mru.valid", "mru.motion.valid",
              "mru.delayed.delay"] + [f"vessel.truth.{w}.{a}" for w, _ in locs for a in "ned"] + [
              f"mru.{p}{d}{x}" for _, p in locs for d in ("", "delayed.") for x in ("surge", "sway", "heave")]
    r = np.zeros(n, dtype=[("time", "f8")] + [(f, "?" if f.endswith("valid") else "f8") for f in fields])
    r["time"] = t
    r["mru.valid"], r["mru.motion.valid"] = t >= 10.0, t >= 50.0   # scored from 70 s and 110 s
    r["vessel.truth.roll"] = 0.05 * wave
    r["mru.roll"] = r["vessel.truth.roll"] + math.radians(0.01) * square
    r["mru.delayed.delay"] = lag * dt
    for (w, p), errors in zip(locs, ((0.01, 0.02, 0.03), (0.02, 0.02, 0.02))):
        for i, ((x, a), e) in enumerate(zip((("surge", "n"), ("sway", "e"), ("heave", "d")), errors)):
            truth = 4.0 + (1.0 + i) * wave                                              # a mean the unit has not
            r[f"vessel.truth.{w}.{a}"] = truth
            r[f"mru.{p}{x}"] = truth - 4.0 + e * square
            r[f"mru.{p}delayed.{x}"] = np.r_[np.zeros(lag), truth[:-lag]]
    system = _mru_system()
    assert mru_point(system, "mru", "vessel") == "mp1."
    s = score(r, system, "vessel", delay=0)["mru"]
    assert s["roll_deg"] == pytest.approx(0.01, rel=1e-3) and s["pitch_deg"] == 0.0
    assert s["scored_s"] == pytest.approx(200.0 - 70.0 + 0.1, abs=1e-9)
    span = t >= 110.0
    sq = square[span] - square[span].mean()                     # the error about its mean over the span
    for p, errors in (("", (1.0, 2.0, 3.0)), ("point_", (2.0, 2.0, 2.0))):
        for x, e in zip(("surge", "sway", "heave"), errors):
            assert s[f"{p}{x}_cm"] == pytest.approx(e * np.sqrt(np.mean(sq ** 2)), rel=1e-9)
            assert s[f"{p}delayed_{x}_cm"] == pytest.approx(0.0, abs=1e-9)
    assert s["point_heave_std_cm"] == pytest.approx(100 * 3.0 * np.std(wave[span]), rel=1e-9)
    assert s["point_3d_cm"] == pytest.approx(2.0 * np.sqrt(3.0) * np.sqrt(np.mean(sq ** 2)), rel=1e-9)
    assert s["point_distance_m"] == pytest.approx(np.sqrt(30.0))
    # a monitoring point elsewhere than the vessel's point is not scored against it
    other = score(r, _mru_system((5.0, 2.0, -1.5)), "vessel", delay=0)["mru"]
    assert mru_point(_mru_system((5.0, 2.0, -1.5)), "mru", "vessel") is None
    assert "point_heave_cm" not in other and other["heave_cm"] == s["heave_cm"]
