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
