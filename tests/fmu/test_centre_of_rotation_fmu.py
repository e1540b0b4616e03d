"""CentreOfRotation FMU run by FMPy equals the in-process estimator bit for bit, holds over a
NaN sample, and saves/restores its state."""
import math

import numpy as np
import pytest
from tests.conftest import DT, Driver

from marinefmu.fmu.tables import cr_params
from marinefmu.estimators.centre_of_rotation.filter import CentreOfRotation
from marinefmu.papers import paper002

OUTS = ["offset.x", "offset.y", "offset.z", "offset_std.z", "cr.x", "acc_cr.z", "acc_cr_n.d", "roll_used", "delay"]


@pytest.fixture(scope="module")
def rec():
    return paper002.record(paper002.SENSORS["bridge"], duration=20.0)


def _inputs(rec, k):
    return {**{f"acc.{a}": float(rec[f"imu.acc.{a}"][k]) for a in "xyz"},
            **{f"gyro.{a}": float(rec[f"imu.gyro.{a}"][k]) for a in "xyz"},
            **{n: float(rec[f"truth.{n}"][k]) for n in ("roll", "pitch", "yaw")}}


@pytest.mark.fmu
@pytest.mark.parametrize("angles", ["gyro_hp", "input"])
def test_cr_fmu_equals_in_process(fmu_dir, tmp_path, rec, angles):
    params = {"angles": angles, "settle_time": 5.0, "sensor.x": 8.0, "sensor.y": 2.0, "sensor.z": -4.0}
    f = Driver(fmu_dir / "CentreOfRotation.fmu", tmp_path, f"cr_{angles}")
    f.init(params)
    est = CentreOfRotation(cr_params(params))
    for k in range(len(rec["imu.acc.x"])):
        inputs = _inputs(rec, k)
        if k == 1200:
            inputs["acc.y"] = math.nan
        status, reals, flags = f.step(k, inputs, OUTS, ("valid", "settled"))
        r = est.step([inputs[f"acc.{a}"] for a in "xyz"], [inputs[f"gyro.{a}"] for a in "xyz"], DT,
                     [inputs[n] for n in ("roll", "pitch", "yaw")])
        assert status in (0, None)
        assert reals == [*r.offset, r.offset_std[2], r.cr[0], r.acc_cr[2], r.acc_cr_n[2], r.euler[0], r.delay], k
        assert flags == [r.valid, r.settled]
        if k == 1200:
            assert not flags[0] and all(np.isfinite(reals))
    assert all(flags)
    f.close()


@pytest.mark.fmu
def test_cr_fmu_state_restore_repeats_the_run(fmu_dir, tmp_path, rec):
    f = Driver(fmu_dir / "CentreOfRotation.fmu", tmp_path, "cr_state")
    f.init({})
    for k in range(300):
        f.step(k, _inputs(rec, k), OUTS)
    state = f.fmu.getFMUstate()
    first = [f.step(k, _inputs(rec, k), OUTS)[1] for k in range(300, 400)]
    f.fmu.setFMUstate(state)
    again = [f.step(k, _inputs(rec, k), OUTS)[1] for k in range(300, 400)]
    assert again == first
    f.fmu.freeFMUstate(state)
    f.close()


@pytest.mark.fmu
def test_no_rotation_is_said_once_in_the_fmu_log(fmu_dir, tmp_path):
    """A vessel in harbour (constant specific force, zero rate): the estimator's reason for
    valid = false, which it gives through Python's logging, reaches the FMU log once, at the
    step's time, and the step status stays OK."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

    logged = []
    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda env, inst, status, cat, text: logged.append((status, text.decode())))
    path = fmu_dir / "CentreOfRotation.fmu"
    md = read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp_path / "u")),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="harbour")
    fmu.instantiate(loggingOn=True, callbacks=cb)
    fmu.setDebugLogging(True, [])
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.setReal([vr[f"acc.{a}"] for a in "xyz"], [0.0, 0.0, -9.80665])
    fmu.setReal([vr[f"gyro.{a}"] for a in "xyz"], [0.0, 0.0, 0.0])
    for k in range(1000):
        fmu.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
    valid = fmu.getBoolean([vr["valid"]])[0]
    fmu.terminate()
    fmu.freeInstance()
    said = [(s, m) for s, m in logged if "no rotation" in m]
    assert not valid
    assert len(said) == 1 and said[0][0] == 1, logged          # once, as a warning (fmi2Warning = 1)
    assert said[0][1].startswith("harbour: t = ") and "valid = false" in said[0][1], said
