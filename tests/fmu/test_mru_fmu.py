"""The MotionReferenceUnit FMU run by FMPy equals the in-process unit bit for bit, with its
monitoring points mapped to their own outputs (a point left off stays zero)."""
import math

import numpy as np
import pytest
from tests.conftest import DT, Driver

from marinefmu import ParameterError
from marinefmu.bench.cases import case_record
from marinefmu.estimators.mru.unit import MotionReferenceUnit
from marinefmu.fmu.tables import mru_params
from marinefmu.sea.motion_model import stack

PARAMS = {"window": 45.0, "omega_min": 0.3, "delayed_lag": 5.0, "mp2.x": 20.0, "mp2.z": -5.0}
LOCATION = ("surge", "sway", "heave", "surge_rate", "sway_rate", "heave_rate", "heave_acc", "delayed.surge",
            "delayed.sway", "delayed.heave")
OUTS = ["roll", "pitch", "yaw", *LOCATION, *(f"mp2.{n}" for n in LOCATION), "mp1.heave", "delayed.delay",
        "wave_period"]
FLAGS = ("valid", "motion.valid", "delayed.valid", "heading.used", "motion.joint")


@pytest.mark.fmu
def test_mru_fmu_equals_in_process(fmu_dir, tmp_path):
    rec = case_record("polar_supply", 3.0, 10.0, "cog", duration=80.0)
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    f = Driver(fmu_dir / "MotionReferenceUnit.fmu", tmp_path, "mru")
    f.fmu.setBoolean([f.vr["mp2.enabled"].valueReference], [True])
    f.init(PARAMS)
    model = MotionReferenceUnit(mru_params({**PARAMS, "mp2.enabled": True}))
    assert model.params.points == ((20.0, 0.0, -5.0),)
    nan_at = 7000
    for k in range(len(acc)):
        a = acc[k].copy()
        if k == nan_at:
            a[2] = math.nan
        inputs = {**{f"gyro.{x}": float(v) for x, v in zip("xyz", gyro[k])},
                  **{f"acc.{x}": float(v) for x, v in zip("xyz", a)}}
        status, reals, flags = f.step(k, inputs, OUTS, FLAGS)
        r = model.step(gyro[k], a, DT)
        assert status in (0, None)
        expected = [r.roll, r.pitch, r.yaw,
                    *r.position[0], *r.velocity[0], r.heave_acc[0], *r.delayed_position[0],
                    *r.position[1], *r.velocity[1], r.heave_acc[1], *r.delayed_position[1],
                    0.0, r.delay, r.wave_period]
        assert reals == expected, k
        assert flags == [r.valid, r.motion_valid, r.delayed_valid, r.heading_used, r.joint], k
        if k == nan_at:
            assert not flags[0] and not flags[1] and all(np.isfinite(reals))
    assert flags[:3] == [True, True, True]
    assert abs(reals[OUTS.index("mp2.heave")] - reals[OUTS.index("heave")]) > 1e-3   # the point is not the IMU
    f.close()


@pytest.mark.fmu
def test_the_taught_joint_filter_runs_in_the_fmu_as_in_process(fmu_dir, tmp_path):
    """At 10 Hz with a 10 s joint memory the joint filter is taught within 500 s (its first fit
    at the refit after 352 s of taught rows); from then on the FMU's outputs are the in-process unit's, bit for bit, and ``motion.joint`` says so."""
    dt, every = 0.1, 10
    rec = case_record("polar_supply", 3.0, 10.0, "cog", duration=600.0)
    gyro, acc = stack(rec, "imu.gyro")[::every], stack(rec, "imu.acc")[::every]
    params = {"window": 45.0, "omega_min": 0.3, "delayed_lag": 5.0, "joint_memory": 10.0}
    f = Driver(fmu_dir / "MotionReferenceUnit.fmu", tmp_path, "mru_joint")
    f.init(params)
    model = MotionReferenceUnit(mru_params(params))
    outs = ["surge", "sway", "heave", "surge_rate", "sway_rate", "heave_rate"]
    joint_steps = 0
    for k in range(len(acc)):
        inputs = {**{f"gyro.{x}": float(v) for x, v in zip("xyz", gyro[k])},
                  **{f"acc.{x}": float(v) for x, v in zip("xyz", acc[k])}}
        _, reals, flags = f.step(k, inputs, outs, ("motion.joint",), dt=dt)
        r = model.step(gyro[k], acc[k], dt)
        assert reals == [*r.position[0], *r.velocity[0]] and flags == [r.joint], k
        joint_steps += r.joint
    assert joint_steps >= 1000
    f.close()


def test_the_fmu_parameters_reach_the_unit():
    """``mru_params`` passes the FMU's own names to the unit's parameters (the FMU test above
    builds both sides from it, so a parameter it dropped would go unseen there)."""
    p = mru_params({"tilt_tau": 0.0, "aid_reference": False, "joint_memory": 90.0, "motion_model": "axis"})
    assert (p.tilt_tau, p.aid_reference, p.joint_memory, p.motion_model) == (0.0, False, 90.0, "axis")
    assert mru_params({"tilt_tau": 50.0}).tilt_tau == 50.0


@pytest.mark.parametrize("values, message", [
    ({"mp3.enabled": True, "mp3.x": 300.0}, "mp3 must lie within 200 m"),
    ({"mp2.enabled": True, "mp4.enabled": True, "mp4.z": math.nan}, "mp4[2] = nan is not finite"),
    ({"delayed_lag": -1.0}, "delayed_lag = -1.0 is out of range"),
])
def test_a_refusal_names_the_fmus_own_parameter(values, message):
    """A point is named by its own number, not by its place among the enabled ones (the unit
    numbers those 1, 2, …), and the delay by the FMU's name for it, not the heave filter's."""
    with pytest.raises(ParameterError) as refused:
        mru_params(values)
    assert str(refused.value).startswith(message)
