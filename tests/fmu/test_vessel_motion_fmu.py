"""The built VesselMotion.fmu under FMPy: validation, units, equality with the in-process model,
several instances, FMU state, reset, and refused parameters."""
import shutil
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from marinefmu.sea.motion_model import BOOLEAN_OUTPUTS, PARAMETERS, REAL_OUTPUTS, VesselMotion, VesselMotionParams

pytestmark = pytest.mark.fmu
DT = 0.01
PARAMS = {"sea.hs": 3.5, "sea.tp": 8.0, "sea.heading": 2.2, "sea.spreading": 4.0, "sea.seed": 9, "sea.components": 150,
          "vessel.preset": "research36", "vessel.speed": 2.0, "imu.x": 6.0, "imu.y": 1.5, "imu.z": -3.0,
          "gnss.dropout.start": 3.0, "gnss.dropout.duration": 1.0}


class Fmu:
    """Minimal FMPy driver used only by these tests (independent of marinefmu's runner)."""

    def __init__(self, path, tmp, name="vm"):
        self.md = read_model_description(str(path))
        self.vr = {v.name: v for v in self.md.modelVariables}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp / name)),
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()
        self.reals = [self.vr[v.name].valueReference for v in REAL_OUTPUTS]
        self.bools = [self.vr[v.name].valueReference for v in BOOLEAN_OUTPUTS]

    def init(self, params):
        self.fmu.setupExperiment(startTime=0.0)
        for k, v in params.items():
            ref = [self.vr[k].valueReference]
            {"Real": self.fmu.setReal, "Integer": self.fmu.setInteger, "String": self.fmu.setString}[self.vr[k].type](ref, [v])
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def step(self, k):
        self.fmu.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
        return self.fmu.getReal(self.reals), self.fmu.getBoolean(self.bools)

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def in_process(params, n):
    m = VesselMotion(VesselMotionParams.from_flat(params))
    # the FMU computes its time as current_time + step_size: do exactly the same
    return [(m.step(k * DT + DT, DT), m.boolean_outputs()) for k in range(n)]


def test_validate_fmu_reports_nothing(fmu_dir):
    assert validate_fmu(str(fmu_dir / "VesselMotion.fmu")) == []


def test_model_description_has_units_descriptions_and_parameters(fmu_dir):
    with zipfile.ZipFile(fmu_dir / "VesselMotion.fmu") as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    units = {u.get("name") for u in root.find("UnitDefinitions")}
    assert {"m", "m/s", "m/s2", "rad", "rad/s", "rad/s2"} <= units
    svs = {sv.get("name"): sv for sv in root.find("ModelVariables")}
    assert svs["imu.acc.x"].find("Real").get("unit") == "m/s2"
    assert svs["truth.cog.d"].find("Real").get("unit") == "m"
    assert svs["gnss.rate"].find("Real").get("unit") == "Hz"
    assert "[m/s2]" in svs["imu.acc.x"].get("description") and "body" in svs["imu.acc.x"].get("description")
    for p in PARAMETERS:
        assert svs[p.name].get("causality") == "parameter" and svs[p.name].get("variability") == "fixed"
    outputs = [i + 1 for i, sv in enumerate(root.find("ModelVariables")) if sv.get("causality") == "output"]
    assert [int(u.get("index")) for u in root.find("ModelStructure/InitialUnknowns")] == outputs


def test_fmpy_run_equals_the_in_process_model(fmu_dir, tmp_path):
    n = 1000
    fmu = Fmu(fmu_dir / "VesselMotion.fmu", tmp_path)
    fmu.init(PARAMS)
    got = [fmu.step(k) for k in range(n)]
    fmu.close()
    ref = in_process(PARAMS, n)
    np.testing.assert_allclose(np.array([g[0] for g in got]), np.array([r[0] for r in ref]), rtol=0, atol=1e-12)
    assert [g[1] for g in got] == [r[1] for r in ref]
    # the run covered the dropout: valid went false and came back
    valid = [g[1][0] for g in got]
    assert not all(valid) and valid[-1]


def test_several_instances_in_one_process_are_independent(fmu_dir, tmp_path):
    a, b = Fmu(fmu_dir / "VesselMotion.fmu", tmp_path, "a"), Fmu(fmu_dir / "VesselMotion.fmu", tmp_path, "b")
    pb = {**PARAMS, "sea.hs": 1.0, "vessel.preset": "semisub", "sea.seed": 2}
    a.init(PARAMS)
    b.init(pb)
    ya = [a.step(k)[0] for k in range(200)]
    yb = [b.step(k)[0] for k in range(200)]
    a.close()
    b.close()
    np.testing.assert_allclose(ya, [r[0] for r in in_process(PARAMS, 200)], atol=1e-12)
    np.testing.assert_allclose(yb, [r[0] for r in in_process(pb, 200)], atol=1e-12)


def test_get_and_set_fmu_state_replays_identically(fmu_dir, tmp_path):
    fmu = Fmu(fmu_dir / "VesselMotion.fmu", tmp_path)
    fmu.init(PARAMS)
    for k in range(100):
        fmu.step(k)
    state = fmu.fmu.getFMUstate()
    first = [fmu.step(k) for k in range(100, 150)]
    fmu.fmu.setFMUstate(state)
    again = [fmu.step(k) for k in range(100, 150)]
    fmu.fmu.freeFMUstate(state)
    fmu.close()
    assert first == again  # noise, bias and GNSS hold restored exactly


def test_serialized_fmu_state_round_trips(fmu_dir, tmp_path):
    fmu = Fmu(fmu_dir / "VesselMotion.fmu", tmp_path)
    fmu.init(PARAMS)
    for k in range(50):
        fmu.step(k)
    state = fmu.fmu.getFMUstate()
    blob = fmu.fmu.serializeFMUstate(state)
    fmu.fmu.freeFMUstate(state)
    first = [fmu.step(k) for k in range(50, 80)]
    restored = fmu.fmu.deSerializeFMUstate(blob)
    fmu.fmu.setFMUstate(restored)
    assert [fmu.step(k) for k in range(50, 80)] == first
    fmu.fmu.freeFMUstate(restored)
    fmu.close()


def test_reset_starts_over(fmu_dir, tmp_path):
    fmu = Fmu(fmu_dir / "VesselMotion.fmu", tmp_path)
    fmu.init(PARAMS)
    first = [fmu.step(k) for k in range(30)]
    fmu.fmu.reset()
    fmu.init(PARAMS)
    assert [fmu.step(k) for k in range(30)] == first
    fmu.close()


@pytest.mark.parametrize(
    "name,value,match",
    [
        ("sea.hs", -1.0, r"sea\.hs = -1\.0 is out of range: must be in \(0\.0, 30\.0\] \[m\]"),
        ("sea.tp", 0.0, r"sea\.tp = 0\.0 is out of range"),
        ("imu.acc_noise", -0.1, r"imu\.acc_noise = -0\.1 is out of range"),
        ("vessel.preset", "tanker", r"vessel\.preset = 'tanker' is not allowed: must be one of 'semisub', 'polar_supply', 'research36'"),
        ("vessel.rao_file", "/nonexistent/raos.csv", r"vessel\.rao_file = '/nonexistent/raos\.csv' cannot be read"),
        ("sea.hs", float("nan"), r"sea\.hs = nan is not finite"),
        ("sea.components", 3, r"sea\.components = 3 is out of range"),
        ("vessel.mode", 5, r"vessel\.mode = 5 is out of range"),
    ],
)
def test_bad_parameter_fails_initialisation_with_a_message_naming_it(fmu_dir, name, value, match):
    from marinefmu.cosim.ssp import Component, SystemDescription
    from marinefmu.cosim.system import SystemRunner
    from marinefmu.errors import SystemError_

    system = SystemDescription("bad", (Component("vessel", "VesselMotion.fmu", {name: value}),), (), 0.01, 1.0)
    with pytest.raises(SystemError_, match=r"vessel: initialisation failed at t = 0 s(.|\n)*" + match):
        SystemRunner(system, fmu_dir).run(progress=False)


def test_fmu_runs_from_a_copy_without_the_source_tree(fmu_dir, tmp_path):
    """The FMU bundles marinefmu in its resources."""
    with zipfile.ZipFile(fmu_dir / "VesselMotion.fmu") as z:
        names = z.namelist()
    assert "resources/marinefmu/sea/motion_model.py" in names
    assert "resources/VesselMotion.py" in names
    assert not any("__pycache__" in n for n in names)
    copy = tmp_path / "elsewhere" / "VesselMotion.fmu"
    copy.parent.mkdir()
    shutil.copy(fmu_dir / "VesselMotion.fmu", copy)
    fmu = Fmu(copy, tmp_path)
    fmu.init({})
    y, b = fmu.step(0)
    fmu.close()
    assert np.all(np.isfinite(y))


def test_refused_fmu_discards_its_steps_and_never_crashes_the_process(fmu_dir, tmp_path):
    """pythonfmu 0.7.0 crashes the process after ~3 slave exceptions; marinefmu slaves never raise."""
    from fmpy.fmi1 import FMICallException

    for i in range(6):
        fmu = Fmu(fmu_dir / "VesselMotion.fmu", tmp_path, f"bad{i}")
        fmu.init({"sea.hs": -1.0})  # initialisation itself returns OK; the refusal is logged
        with pytest.raises(FMICallException, match="status 2"):  # fmi2Discard
            fmu.step(0)
        fmu.close()
    good = Fmu(fmu_dir / "VesselMotion.fmu", tmp_path, "good")
    good.init(PARAMS)
    assert good.step(0)[0] == pytest.approx(in_process(PARAMS, 1)[0][0], abs=1e-12)
    good.close()
