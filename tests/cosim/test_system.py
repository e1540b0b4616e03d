"""SSP system files and the FMPy system runner: wiring, rates, recording, errors."""
import numpy as np
import pytest

from marinefmu.cosim.ssp import Component, Connection, SystemDescription, read_ssd, write_ssd
from marinefmu.cosim.system import SystemRunner, load_csv, save_csv
from marinefmu.errors import ParameterError, SystemError_
from marinefmu.sea.motion_model import VesselMotion, VesselMotionParams

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
    m = VesselMotion(VesselMotionParams.from_flat({"sea.hs": 3.0}))
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


def _relays(tmp_path, fmu_dir, relay_fmu):
    import shutil

    shutil.copy(fmu_dir / "VesselMotion.fmu", tmp_path)
    shutil.copy(relay_fmu, tmp_path)
    return (Component("v", "VesselMotion.fmu"), Component("a", "MfTestRelay.fmu"), Component("b", "MfTestRelay.fmu"))


@pytest.mark.parametrize(
    "wiring,match",
    [
        ([("v.truth.cog.q", "a.u")], r"v \(VesselMotion\) has no variable 'truth\.cog\.q' \(did you mean 'truth\.cog\.n', 'truth\.cog\.e', 'truth\.cog\.d'"),
        ([("v.truth.cog.d", "a.gain")], r"a\.gain has causality 'parameter', expected input"),
        ([("a.u", "b.u")], r"a\.u has causality 'input', expected output"),
        ([("v.gnss.valid", "a.u")], r"connection v\.gnss\.valid -> a\.u: Boolean output cannot feed Real input"),
        ([("v.truth.roll", "a.u")], r"connection v\.truth\.roll -> a\.u: unit 'rad' cannot feed an input in 'm'"),
        ([("v.truth.cog.d", "a.u"), ("v.truth.cog.n", "a.u")], r"input a\.u is already fed by v\.truth\.cog\.d"),
        ([("a.y", "b.u"), ("b.y", "a.u")], r"connection cycle without a delay: a -> b -> a"),
    ],
)
def test_bad_wiring_is_refused_before_any_fmu_is_instantiated(fmu_dir, relay_fmu, tmp_path, monkeypatch, wiring, match):
    from fmpy.fmi2 import FMU2Slave

    comps = _relays(tmp_path, fmu_dir, relay_fmu)
    sysd = SystemDescription("bad", comps, tuple(Connection.parse(a, b) for a, b in wiring), 0.01, 0.1)

    def no_instantiate(*args, **kwargs):
        raise AssertionError("an FMU was instantiated")

    monkeypatch.setattr(FMU2Slave, "instantiate", no_instantiate)
    with pytest.raises(SystemError_, match=match):
        SystemRunner(sysd, tmp_path)
    from marinefmu.cosim.libcosim import write_osp_system
    from marinefmu.cosim.ssp import write_ssp

    with pytest.raises(SystemError_, match=match):
        write_ssp(sysd, tmp_path, tmp_path / "bad.ssp")
    with pytest.raises(SystemError_, match=match):
        write_osp_system(sysd, tmp_path, tmp_path / "OspSystemStructure.xml")
    assert not (tmp_path / "bad.ssp").exists() and not (tmp_path / "OspSystemStructure.xml").exists()


def test_a_loop_marked_delay_runs_with_one_step_of_delay(fmu_dir, relay_fmu, tmp_path):
    comps = _relays(tmp_path, fmu_dir, relay_fmu)
    comps = (comps[0], Component("a", "MfTestRelay.fmu", {"gain": 1.0}), Component("b", "MfTestRelay.fmu", {"gain": 0.5}))
    loop = (Connection.parse("a.y", "b.u"), Connection.parse("b.y", "a.u", delay=True))
    sysd = SystemDescription("loop", comps, loop, 0.01, 0.05)
    assert read_ssd(write_ssd(sysd, tmp_path / "SystemStructure.ssd")) == sysd   # the flag survives the SSD
    r = SystemRunner(sysd, tmp_path).run(record=["a.y", "b.y"], progress=False)
    # a.y(k+1) = b.y(k), b.y(k+1) = 0.5 a.y(k): from zero the loop stays at zero, exactly
    assert np.all(r["a.y"] == 0.0) and np.all(r["b.y"] == 0.0)


def test_a_packaged_system_naming_a_missing_variable_is_refused_on_reading(fmu_dir, relay_fmu, tmp_path):
    import zipfile

    from marinefmu.cosim.ssp import read_ssp, write_ssp

    comps = _relays(tmp_path, fmu_dir, relay_fmu)
    good = SystemDescription("s", comps[:2], (Connection.parse("v.truth.cog.d", "a.u"),), 0.01, 0.1)
    ssp = write_ssp(good, tmp_path, tmp_path / "s.ssp")
    with zipfile.ZipFile(ssp) as z:
        files = {n: z.read(n) for n in z.namelist()}
    files["SystemStructure.ssd"] = files["SystemStructure.ssd"].replace(b'endConnector="u"', b'endConnector="uu"')
    with zipfile.ZipFile(tmp_path / "t.ssp", "w") as z:
        for n, data in files.items():
            z.writestr(n, data)
    with pytest.raises(SystemError_, match=r"a \(MfTestRelay\) has no variable 'uu' \(did you mean 'u'"):
        read_ssp(tmp_path / "t.ssp", tmp_path / "unpacked")
    del files["resources/MfTestRelay.fmu"]
    with zipfile.ZipFile(tmp_path / "m.ssp", "w") as z:
        for n, data in files.items():
            z.writestr(n, data)
    with pytest.raises(SystemError_, match=r"component a: FMU .*MfTestRelay\.fmu not found"):
        read_ssp(tmp_path / "m.ssp", tmp_path / "unpacked2")


def test_build_skips_unchanged_models_and_rebuilds_a_changed_one(tmp_path):
    import shutil
    from pathlib import Path

    from marinefmu.fmu.build import build_all

    models = tmp_path / "models"
    models.mkdir()
    shutil.copy(Path(__file__).resolve().parents[1] / "models" / "MfTestRelay.py", models)
    dest = tmp_path / "fmus"
    assert [r.rebuilt for r in build_all(models, dest, verbose=False)] == [True]
    stamp = (dest / "MfTestRelay.fmu").stat().st_mtime_ns
    assert [r.rebuilt for r in build_all(models, dest, verbose=False)] == [False]
    assert (dest / "MfTestRelay.fmu").stat().st_mtime_ns == stamp
    (models / "MfTestRelay.py").write_text((models / "MfTestRelay.py").read_text() + "\n# changed\n")
    assert [r.rebuilt for r in build_all(models, dest, verbose=False)] == [True]


def _quick_system():
    """The ``system`` scenario with the heave observer's and the reconstructor's windows cut
    to 26 and 30 s, so every estimator works within 40 s."""
    from dataclasses import replace

    from marinefmu.cosim.scenarios import load_scenario

    sysd = load_scenario("system").system
    short = {"heave": {"window": 26.0, "peak_interval": 5.0, "omega_min": 0.5}, "recon": {"window": 30.0, "hop": 5.0, "cutoff": 0.1}}
    comps = tuple(replace(c, parameters={**c.parameters, **short.get(c.name, {})}) for c in sysd.components)
    return replace(sysd, components=comps)


def test_in_process_engine_equals_fmpy_bit_for_bit(fmu_dir):
    """engine="python" runs each FMU's own slave script without FMI: the same numbers."""
    sysd = _quick_system()
    runners = {e: SystemRunner(sysd, fmu_dir, engine=e) for e in ("python", "fmpy")}
    runs = {e: r.run(40.0, progress=False) for e, r in runners.items()}
    a, b = runs["python"], runs["fmpy"]
    for r in runners.values():   # the time each component spent stepping
        assert set(r.step_seconds) == {c.name for c in sysd.components} and all(v > 0 for v in r.step_seconds.values())
    assert a.dtype == b.dtype and len(a) == 4001
    for name in a.dtype.names:
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    assert a["heave.valid"][-1] and a["recon.valid"][-1] and a["fusion.valid"][-1]   # every estimator worked
    with pytest.raises(SystemError_, match=r"engine = 'java' is not allowed: must be one of 'fmpy', 'python'"):
        SystemRunner(sysd, fmu_dir, engine="java")


def test_streamed_result_equals_the_in_memory_one(fmu_dir, tmp_path, monkeypatch):
    """out_file: rows go to a .npy file chunk by chunk (chunks of 7 rows here, to cross many
    boundaries) and come back as a memory map equal to the in-memory result."""
    import marinefmu.cosim.system as system_module

    sysd = SystemDescription("one", (Component("vessel", "VesselMotion.fmu"),), (), 0.05, 2.0)
    record = ["vessel.truth.cog.d", "vessel.gnss.valid", "vessel.imu.acc.z"]
    mem = SystemRunner(sysd, fmu_dir).run(record=record, progress=False)
    monkeypatch.setattr(system_module, "CHUNK_ROWS", 7)
    streamed = SystemRunner(sysd, fmu_dir).run(record=record, progress=False, out_file=tmp_path / "r.npy")
    assert isinstance(streamed, np.memmap) and streamed.dtype == mem.dtype and len(streamed) == 41
    np.testing.assert_array_equal(streamed, mem)
    np.testing.assert_array_equal(np.load(tmp_path / "r.npy"), mem)
    assert mem["vessel.gnss.valid"].dtype == bool and mem["vessel.gnss.valid"].any()


def test_two_builders_of_one_folder_take_turns(tmp_path):
    """make test's two workers (or two shells) may build at once: the folder's lock makes one
    build while the other waits and then finds the FMU up to date, never half written."""
    import shutil
    import subprocess
    import sys
    from pathlib import Path

    models = tmp_path / "models"
    models.mkdir()
    shutil.copy(Path(__file__).resolve().parents[1] / "models" / "MfTestRelay.py", models)
    dest = tmp_path / "fmus"
    code = ("import sys\nfrom pathlib import Path\nfrom marinefmu.fmu.build import build_all\n"
            f"print([r.rebuilt for r in build_all(Path({str(models)!r}), Path({str(dest)!r}), verbose=False)])\n")
    procs = [subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for _ in range(2)]
    outs = [p.communicate(timeout=300) for p in procs]
    assert [p.returncode for p in procs] == [0, 0], [err[-2000:] for _, err in outs]
    assert sorted(out.strip() for out, _ in outs) == ["[False]", "[True]"]


def test_runs_leave_sys_path_as_they_found_it(fmu_dir):
    """pythonfmu puts each instance's resources folder on sys.path; a run takes its own temporary
    folders off again, so a process running system after system (a campaign worker) does not
    gain six entries a run (it did: 6 → 36 entries after five runs of the system scenario)."""
    import sys

    from marinefmu.cosim.system import SystemRunner
    from marinefmu.cosim.scenarios import load_scenario

    sc = load_scenario("system")
    SystemRunner(sc.system, fmu_dir).run(0.05, record=sc.record, progress=False)   # first-run imports
    before = list(sys.path)
    for _ in range(2):
        SystemRunner(sc.system, fmu_dir).run(0.05, record=sc.record, progress=False)
    assert sys.path == before
    assert not [k for k in sys.path_importer_cache if "marinefmu_" in k and k.startswith(("/tmp", "/var"))]
