"""An MRU-grade IMU (VesselMotion ``imu.grade = mru``) through the estimators at their defaults:
the datasheet figure of the class (≤ 0.01° roll and pitch, as a Kongsberg MRU 5+ states) and the
heave goal at a point 60 m away."""
from __future__ import annotations

import numpy as np
import pytest

from marinefmu.bench.cases import case_record
from marinefmu.bench.defaults import attitude_rms_deg, point_heave_cm
from marinefmu.estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
from marinefmu.sea.motion_model import stack

DT = 0.01
ARM = (60.0, 0.0, 0.0)  # the monitoring point relative to the IMU, body frame [m]


@pytest.fixture(scope="module")
def mru_record() -> dict[str, np.ndarray]:
    """Polar supply vessel, Hs 3 m / Tp 10 s, IMU at the COG, MRU grade, 450 s; the monitoring
    point 60 m forward of the IMU."""
    return case_record("polar_supply", 3.0, 10.0, "cog", duration=450.0,
                       extra={"imu.grade": "mru", **{f"point.{a}": v for a, v in zip("xyz", ARM)}})


def test_mru_grade_meets_the_datasheet_roll_and_pitch(mru_record):
    """At its defaults the estimator sizes the gyro's noise from the data (``aid_sizing =
    "auto"``) and so trusts an MRU's gyro as much as it deserves: measured 0.0041 / 0.0033°
    against the 0.01° datasheet goal. With ``aid_sizing = "fixed"`` (the MEMS gyro figures and
    the aiding of 1 m/s, 3 m as given) it errs 0.0100 / 0.0079°, and no fixed σ_v of 0.05-1 m/s
    does better. The check holds the goal and that the sizing at least halves the fixed error."""
    roll, pitch = attitude_rms_deg(mru_record, AttitudeEstimatorParams())
    assert roll <= 0.01 and pitch <= 0.01, (roll, pitch)
    fixed = attitude_rms_deg(mru_record, AttitudeEstimatorParams(aid_sizing="fixed"))
    assert 2.0 * max(roll, pitch) <= max(fixed), (roll, pitch, fixed)


def test_heave_at_60_m_fed_by_the_mru_attitude_meets_the_goal(mru_record):
    """The HeaveObserver at its defaults, given the point only, fed by the defaults' angles:
    within max(2 cm, 2.5 % of the point's heave std) from 150 s on."""
    rec = mru_record
    att = estimate_attitude(stack(rec, "imu.gyro"), stack(rec, "imu.acc"), DT)
    err_cm, std_cm = point_heave_cm(rec, att["roll"], att["pitch"], ARM, settle=150.0)
    assert err_cm <= max(2.0, 0.025 * std_cm), (err_cm, std_cm)
