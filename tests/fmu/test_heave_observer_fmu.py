"""The HeaveObserver FMU run by FMPy equals the in-process observer bit for bit (with a NaN
sample), and saves/restores its state."""
import math

import numpy as np
import pytest
from tests.conftest import DT, Driver

from marinefmu.fmu.tables import heave_params
from marinefmu.estimators.heave.bank import OscillatorBankHeave
from marinefmu.estimators.heave.wiener import WienerHeave

OUTS = ["heave", "heave_rate", "point.heave", "point.heave_rate", "delayed.heave", "delayed.point.heave",
        "delayed.delay", "offset", "peak_period"]
PARAMS = {"model": "band", "window": 40.0, "omega_min": 0.35, "smoother_lag": 2.0, "point.x": 40.0, "point.z": -5.0}


def _inputs(k):
    t = (k + 1) * DT
    return {"acc.x": 0.1 * math.sin(0.9 * t), "acc.y": 0.0, "acc.z": -9.80665 - 0.4 * math.cos(0.8 * t) - 0.1 * math.cos(1.7 * t),
            "roll": 0.02 * math.sin(0.7 * t), "pitch": 0.03 * math.cos(0.8 * t)}


def _run_beside(f, est, steps, nan_at):
    """Step the FMU and the in-process estimator alike (a NaN acc.z at ``nan_at``): equal outputs
    and flags at every step, valid false and finite outputs at the NaN; the last outputs, flags."""
    for k in range(steps):
        inputs = _inputs(k)
        if k == nan_at:
            inputs["acc.z"] = math.nan
        status, reals, flags = f.step(k, inputs, OUTS, ("valid", "delayed.valid"))
        r = est.step((inputs["acc.x"], inputs["acc.y"], inputs["acc.z"]), inputs["roll"], inputs["pitch"], DT)
        assert status in (0, None)
        assert reals == [r.heave, r.heave_rate, r.point_heave, r.point_heave_rate, r.delayed_heave,
                         r.delayed_point_heave, r.delay, r.offset, r.peak_period], k
        assert flags == [r.valid, r.delayed_valid]
        if k == nan_at:
            assert not flags[0] and all(np.isfinite(reals))
    return reals, flags


@pytest.mark.fmu
def test_heave_fmu_equals_in_process(fmu_dir, tmp_path):
    f = Driver(fmu_dir / "HeaveObserver.fmu", tmp_path, "heave")
    f.init(PARAMS)
    obs = OscillatorBankHeave(heave_params(PARAMS))
    flags = _run_beside(f, obs, 5500, 5000)[1]
    assert f.fmu.getInteger([f.vr["modes"].valueReference]) == [obs._result.modes] and obs._result.modes >= 2
    assert all(flags)
    f.close()


@pytest.mark.fmu
def test_heave_fmu_state_restore_repeats_the_run(fmu_dir, tmp_path):
    f = Driver(fmu_dir / "HeaveObserver.fmu", tmp_path, "heave_state")
    f.init(PARAMS)
    for k in range(4200):
        f.step(k, _inputs(k), OUTS)
    state = f.fmu.getFMUstate()
    first = [f.step(k, _inputs(k), OUTS)[1] for k in range(4200, 4300)]
    f.fmu.setFMUstate(state)
    again = [f.step(k, _inputs(k), OUTS)[1] for k in range(4200, 4300)]
    assert again == first
    f.fmu.freeFMUstate(state)
    f.close()


@pytest.mark.fmu
def test_wiener_heave_fmu_equals_in_process(fmu_dir, tmp_path):
    """model = "wiener" (the Wiener filter from the spectrum) through the FMU, with a NaN sample."""
    params = {**PARAMS, "model": "wiener"}
    f = Driver(fmu_dir / "HeaveObserver.fmu", tmp_path, "heave_wiener")
    f.init(params)
    est = WienerHeave(heave_params(params))
    reals, flags = _run_beside(f, est, 5000, 4500)
    assert all(flags) and reals[0] != 0.0
    f.close()
