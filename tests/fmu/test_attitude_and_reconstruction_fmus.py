"""AttitudeEstimator and DisplacementReconstructor FMUs (and GnssAccFusion's validation and
parameter refusal) run by FMPy equal the in-process
estimators bit for bit, refuse bad parameters by name, and coast over a NaN input."""
import numpy as np
import pytest
from tests.conftest import Driver
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from marinefmu.fmu.tables import attitude_params, sliding_params
from marinefmu.estimators.attitude.estimator import AttitudeEstimator
from marinefmu.estimators.reconstruction.sliding import DisplacementReconstructor
from marinefmu.papers import paper000_semisub

DT = 0.01


@pytest.fixture(scope="module")
def record():
    return paper000_semisub.simulate(80.0, noise=True)


@pytest.mark.fmu
@pytest.mark.parametrize("name", ["AttitudeEstimator", "DisplacementReconstructor", "GnssAccFusion", "CentreOfRotation", "HeaveObserver"])
def test_validate(fmu_dir, name):
    assert validate_fmu(str(fmu_dir / f"{name}.fmu")) == []


@pytest.mark.fmu
def test_attitude_fmu_equals_in_process(fmu_dir, tmp_path, record):
    params = {"level_time": 2.0}
    f = Driver(fmu_dir / "AttitudeEstimator.fmu", tmp_path, "att")
    f.init(params)
    est = AttitudeEstimator(attitude_params(params))
    outs = ["roll", "pitch", "yaw", "q.w", "q.x", "q.y", "q.z"]
    for k in range(3000):
        g, a = record["gyro"][k], record["acc"][k]
        inputs = {"gyro.x": g[0], "gyro.y": g[1], "gyro.z": g[2], "acc.x": a[0], "acc.y": a[1], "acc.z": a[2]}
        if k == 2500:
            inputs["gyro.y"] = float("nan")
        status, reals, valid = f.step(k, inputs, outs)
        r = est.step([inputs["gyro.x"], inputs["gyro.y"], inputs["gyro.z"]], a, DT)
        assert status in (0, None) and reals == [r.roll, r.pitch, r.yaw, *r.q] and valid == [r.valid]
        if k == 2500:
            assert valid == [False] and all(np.isfinite(reals))
    f.close()


@pytest.mark.fmu
def test_reconstructor_fmu_equals_in_process(fmu_dir, tmp_path, record):
    params = {"window": 70.0, "hop": 5.0, "cutoff": 0.04, "lever_arm.x": 41.0, "lever_arm.y": 35.0, "lever_arm.z": -35.0}
    f = Driver(fmu_dir / "DisplacementReconstructor.fmu", tmp_path, "rec")
    f.init(params)
    est = DisplacementReconstructor(sliding_params(params))
    outs = ["disp.n", "disp.e", "disp.d", "vel.n", "vel.e", "vel.d", "delay"]
    for k in range(7600):
        a, e = record["acc"][k], record["euler"][k]
        inputs = {"acc.x": a[0], "acc.y": a[1], "acc.z": a[2], "roll": e[0], "pitch": e[1], "yaw": e[2]}
        status, reals, valid = f.step(k, inputs, outs)
        r = est.step(a, e, DT)
        assert status in (0, None) and reals == [*r.disp, *r.vel, r.delay] and valid == [r.valid]
    assert valid == [True]
    f.close()


@pytest.mark.fmu
@pytest.mark.parametrize("name,params,message", [
    ("AttitudeEstimator", {"vel_sigma": -1.0}, "vel_sigma = -1.0 is out of range"),
    ("DisplacementReconstructor", {"window": 10.0}, "window = 10.0 is out of range"),
    ("DisplacementReconstructor", {"max_components": 0}, "max_components = 0 is out of range"),
    ("GnssAccFusion", {"gate": 0.0}, "gate = 0.0 is out of range"),
    ("GnssAccFusion", {"q": -1.0}, "q = -1.0 is out of range"),
    ("GnssAccFusion", {"r": 0.0}, "r = 0.0 is out of range"),
    ("CentreOfRotation", {"hp_cutoff": 0.0}, "hp_cutoff = 0.0 is out of range"),
    ("CentreOfRotation", {"acc_sigma": -1.0}, "acc_sigma = -1.0 is out of range"),
    ("HeaveObserver", {"window": 20.0}, "window = 20.0 is out of range"),
    ("HeaveObserver", {"max_modes": 0}, "max_modes = 0 is out of range"),
])
def test_bad_parameters_are_logged_and_steps_discarded(fmu_dir, tmp_path, name, params, message):
    from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

    logged = []

    def logger(env, instance, status, category, text):
        logged.append(text.decode())

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(logger)
    md = read_model_description(str(fmu_dir / f"{name}.fmu"))
    vr = {v.name: v for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu_dir / f"{name}.fmu"), unzipdir=str(tmp_path / "u")),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bad")
    fmu.instantiate(loggingOn=True, callbacks=cb)
    fmu.setDebugLogging(True, [])
    fmu.setupExperiment(startTime=0.0)
    for k, v in params.items():
        {"Real": fmu.setReal, "Integer": fmu.setInteger}[vr[k].type]([vr[k].valueReference], [v])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    assert any(message in m for m in logged), logged
    with pytest.raises(Exception):  # fmi2Discard is raised by FMPy as an FMICallException
        fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=DT)
    fmu.terminate()
    fmu.freeInstance()
