"""SSP system files and the FMPy system runner: wiring, rates, recording, errors."""
import numpy as np
import pytest

from marinefmu.cosim.ssp import Component, Connection, SystemDescription, read_ssd, write_ssd
from marinefmu.cosim.system import SystemRunner, load_csv, save_csv
from marinefmu.errors import ParameterError, SystemError_
from marinefmu.sea.motion_model import VesselMotionModel, VesselMotionParams

pytestmark = pytest.mark.fmu


def test_ssd_round_trip_keeps_every_value_type(tmp_path):
    sysd = SystemDescription(
        "s", (Component("v", "VesselMotion.fmu", {"sea.hs": 2.0, "sea.seed": 3, "vessel.preset": "semisub", "flag": True}),
              Component("r", "MfTestRelay.fmu", {"gain": 0.5}, rate=4)),
        (Connection.parse("v.truth.cog.d", "r.u"),), 0.02, 30.0)
    path = write_ssd(sysd, tmp_path / "SystemStructure.ssd")
    assert read_ssd(path) == sysd
    text = path.read_text()
    assert "http://ssp-standard.org/SSP1/SystemStructureDescription" in text and 'startConnector="truth.cog.d"' in text


def test_ssd_refuses_bad_wiring():
    with pytest.raises(ParameterError, match="unknown component 'x'"):
        SystemDescription("s", (Component("v", "V.fmu"),), (Connection.parse("x.y", "v.u"),))
    with pytest.raises(ParameterError, match="duplicate component name"):
        SystemDescription("s", (Component("v", "V.fmu"), Component("v", "W.fmu")))
    with pytest.raises(ParameterError, match=r"components\.v\.rate = 0 is out of range"):
        Component("v", "V.fmu", rate=0)


def test_runner_wires_outputs_to_inputs_with_rates(fmu_dir, relay_fmu, tmp_path):
    import shutil

    shutil.copy(fmu_dir / "VesselMotion.fmu", tmp_path)
    shutil.copy(relay_fmu, tmp_path)
    sysd = SystemDescription(
        "wired",
        (Component("vessel", "VesselMotion.fmu", {"sea.hs": 3.0}),
         Component("fast", "MfTestRelay.fmu", {"gain": -2.0}),
         Component("slow", "MfTestRelay.fmu", {"gain": 1.0}, rate=5)),
        (Connection.parse("vessel.truth.cog.d", "fast.u"), Connection.parse("vessel.truth.cog.d", "slow.u")),
        0.01, 2.0)
    r = SystemRunner(sysd, tmp_path).run(record=["vessel.truth.cog.d", "fast.y", "fast.steps", "slow.y", "slow.steps", "slow.time"])
    assert r.size == 201 and r["time"][-1] == pytest.approx(2.0)
    # Jacobi coupling: the relay steps from t with the input the vessel held at t
    np.testing.assert_allclose(r["fast.y"][1:], -2.0 * r["vessel.truth.cog.d"][:-1], atol=1e-15)
    assert r["fast.steps"][-1] == 200 and r["slow.steps"][-1] == 40
    # the slow relay steps every 5 base steps with a 0.05 s step and holds its output between
    k = np.arange(201)
    np.testing.assert_allclose(r["slow.time"][k % 5 == 0][1:], r["time"][k % 5 == 0][1:], atol=1e-12)
    np.testing.assert_allclose(r["slow.y"][5::5], r["vessel.truth.cog.d"][0:-5:5], atol=1e-15)
    # the vessel through the runner equals the in-process model
    m = VesselMotionModel(VesselMotionParams.from_flat({"sea.hs": 3.0}))
    ref = [m.step(k * 0.01 + 0.01, 0.01) for k in range(200)]
    from marinefmu.sea.motion_model import REAL_INDEX

    np.testing.assert_allclose(r["vessel.truth.cog.d"][1:], [y[REAL_INDEX["truth.cog.d"]] for y in ref], atol=1e-12)


def test_runner_records_every_output_by_default_and_csv_round_trips(fmu_dir, tmp_path):
    sysd = SystemDescription("one", (Component("vessel", "VesselMotion.fmu"),), (), 0.05, 1.0)
    r = SystemRunner(sysd, fmu_dir).run(progress=False)
    assert "vessel.imu.acc.z" in r.dtype.names and "vessel.gnss.valid" in r.dtype.names
    back = load_csv(save_csv(r, tmp_path / "r.csv"))
    np.testing.assert_allclose(back["vessel.imu.acc.z"], r["vessel.imu.acc.z"], rtol=1e-9)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"parameters": {"sea.hz": 1.0}}, r"vessel \(VesselMotion\) has no variable 'sea.hz' \(did you mean 'sea.hs'"),
        ({"parameters": {"sea.hs": "big"}}, r"vessel\.sea\.hs is Real; cannot set it to 'big'"),
        ({"parameters": {"truth.cog.d": 1.0}}, r"vessel\.truth\.cog\.d has causality 'output', expected parameter or input"),
        ({"record": ["vessel.imu.acc.q"]}, r"has no variable 'imu\.acc\.q' \(did you mean"),
        ({"record": ["ship.imu.acc.x"]}, r"record 'ship.imu.acc.x': unknown component 'ship'"),
    ],
)
def test_runner_errors_name_what_is_wrong(fmu_dir, kwargs, match):
    sysd = SystemDescription("bad", (Component("vessel", "VesselMotion.fmu", kwargs.get("parameters", {})),), (), 0.01, 0.1)
    with pytest.raises(SystemError_, match=match):
        SystemRunner(sysd, fmu_dir).run(record=kwargs.get("record"), progress=False)
    # everything was freed: the same process runs a good system afterwards
    ok = SystemDescription("ok", (Component("vessel", "VesselMotion.fmu"),), (), 0.01, 0.1)
    assert SystemRunner(ok, fmu_dir).run(progress=False).size == 11


def test_runner_refuses_a_missing_fmu(tmp_path):
    with pytest.raises(SystemError_, match="FMU .*Nope.fmu not found"):
        SystemRunner(SystemDescription("x", (Component("v", "Nope.fmu"),)), tmp_path)


def test_a_step_failure_is_reported_with_component_time_and_messages(fmu_dir, relay_fmu, tmp_path):
    import shutil

    shutil.copy(fmu_dir / "VesselMotion.fmu", tmp_path)
    shutil.copy(relay_fmu, tmp_path)
    # wiring a Real output into a Real parameter is refused before anything steps
    sysd = SystemDescription("x", (Component("v", "VesselMotion.fmu"), Component("r", "MfTestRelay.fmu")),
                             (Connection.parse("v.truth.cog.d", "r.gain"),), 0.01, 0.1)
    with pytest.raises(SystemError_, match=r"r\.gain has causality 'parameter', expected input"):
        SystemRunner(sysd, tmp_path).run(progress=False)


def test_build_skips_unchanged_models_and_rebuilds_a_changed_one(tmp_path):
    import shutil
    from pathlib import Path

    from marinefmu.cosim.build import build_all

    models = tmp_path / "models"
    models.mkdir()
    shutil.copy(Path(__file__).parent / "models" / "MfTestRelay.py", models)
    dest = tmp_path / "fmus"
    assert [r.rebuilt for r in build_all(models, dest, verbose=False)] == [True]
    stamp = (dest / "MfTestRelay.fmu").stat().st_mtime_ns
    assert [r.rebuilt for r in build_all(models, dest, verbose=False)] == [False]
    assert (dest / "MfTestRelay.fmu").stat().st_mtime_ns == stamp
    (models / "MfTestRelay.py").write_text((models / "MfTestRelay.py").read_text() + "\n# changed\n")
    assert [r.rebuilt for r in build_all(models, dest, verbose=False)] == [True]
