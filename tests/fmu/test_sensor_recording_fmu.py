"""The built SensorRecording.fmu: validation, the round trip VesselMotion → record → replay
through the estimator FMUs (FMPy and libcosim), reset, FMU state, several instances, NaN, gaps
and the end of the record, refusals, and a self-contained FMU (build-recording)."""
from dataclasses import replace

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from marinefmu.sea.recording.schema import BOOLEAN_OUTPUTS, REAL_OUTPUTS

pytestmark = pytest.mark.fmu
DT = 0.01
ESTIMATORS = ("att", "heave", "fusion")


class Rec:
    """One SensorRecording instance through FMPy, with its log."""

    def __init__(self, path, tmp, name="rec"):
        from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2CallbackAllocateMemoryTYPE, \
            fmi2CallbackFreeMemoryTYPE, calloc, free

        self.md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.log = []

        def logger(c, inst, status, cat, msg):
            self.log.append((status, msg.decode()))

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self._cb = cb
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp / name)),
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(loggingOn=True, callbacks=cb)
        self.reals = [self.vr[v.name] for v in REAL_OUTPUTS]
        self.bools = [self.vr[v.name] for v in BOOLEAN_OUTPUTS]

    def init(self, file="", mapping="", start=0.0):
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.setString([self.vr["file"], self.vr["mapping"]], [str(file), str(mapping)])
        self.fmu.setReal([self.vr["start"]], [start])
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def step(self, k, dt=DT):
        status = self.fmu.doStep(currentCommunicationPoint=k * dt, communicationStepSize=dt)
        return status, self.fmu.getReal(self.reals), self.fmu.getBoolean(self.bools)

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """20 s of the system scenario recorded at its 0.01 s step."""
    from marinefmu.cosim.record import record

    out = tmp_path_factory.mktemp("recorded") / "system.csv"
    return record("system", out, duration=20.0)


@pytest.fixture
def small(tmp_path):
    """A 2 s IMU + GNSS record with a NaN at 0.5 s and a gap 1.0-1.3 s."""
    rows = []
    for k in range(201):
        t = k * 0.01
        if 1.0 < t < 1.3:
            continue
        ax = "nan" if k == 50 else repr(float(np.sin(t)))
        g = f"{t!r},{2 * t!r},{-t!r}" if k % 20 == 0 else ",,"
        rows.append(f"{t!r},{ax},0.1,-9.8,0.01,0.02,0.03,{g}")
    csv = tmp_path / "small.csv"
    csv.write_text("time,ax,ay,az,gx,gy,gz,n,e,d\n" + "\n".join(rows) + "\n")
    toml = tmp_path / "small.toml"
    toml.write_text('[time]\ncolumn = "time"\n[imu]\nmax_gap = 0.05\nacc = { x = "ax", y = "ay", z = "az" }\n'
                    'gyro = { x = "gx", y = "gy", z = "gz" }\n[gnss]\nmax_gap = 0.5\nant1 = { n = "n", e = "e", d = "d" }\n')
    return csv, toml


def test_validates_and_describes_units(fmu_dir):
    assert validate_fmu(str(fmu_dir / "SensorRecording.fmu")) == []
    md = read_model_description(str(fmu_dir / "SensorRecording.fmu"))
    v = {x.name: x for x in md.modelVariables}
    assert v["imu.acc.x"].unit == "m/s2" and v["gnss.ant1.n"].unit == "m" and v["ref.roll"].unit == "rad"
    assert v["gnss.new"].type == "Boolean" and v["file"].type == "String" and v["start"].unit == "s"


def _live_system():
    from marinefmu.cosim.scenarios import load_scenario

    sc = load_scenario("system")
    keep = {"vessel", *ESTIMATORS}
    return replace(sc.system, components=tuple(c for c in sc.system.components if c.name in keep),
                   connections=tuple(c for c in sc.system.connections if c.start in keep and c.end in keep))


def test_round_trip_replay_gives_the_live_run_through_the_estimator_fmus(fmu_dir, recorded):
    from marinefmu.cosim.replay import plan_replay, run_replay
    from marinefmu.cosim.system import SystemRunner

    live = SystemRunner(_live_system(), fmu_dir).run(20.0)
    plan = plan_replay(recorded.csv, recorded.mapping, "attitude,heave,fusion")
    assert plan.system.step == DT and plan.duration == pytest.approx(20.0)
    replayed, _ = run_replay(plan, fmu_dir)
    assert len(replayed) == len(live) == 2001
    compared = 0
    for name in live.dtype.names:
        if name.split(".")[0] in ESTIMATORS:
            a, b = live[name].astype(float), replayed[name].astype(float)
            np.testing.assert_allclose(b, a, rtol=1e-9, atol=1e-300, err_msg=name)
            compared += 1
        elif name.startswith("vessel.") and f"rec.{name[7:]}" in replayed.dtype.names:
            np.testing.assert_array_equal(replayed[f"rec.{name[7:]}"], live[name], err_msg=name)
    assert compared > 40


def test_reset_state_and_two_instances(fmu_dir, small, tmp_path):
    csv, toml = small
    a = Rec(fmu_dir / "SensorRecording.fmu", tmp_path, "a")
    b = Rec(fmu_dir / "SensorRecording.fmu", tmp_path, "b")
    a.init(csv, toml)
    b.init(csv, toml, start=0.5)
    first = [a.step(k) for k in range(60)]
    state = a.fmu.getFMUstate()
    blob = a.fmu.serializeFMUstate(state)
    rest = [a.step(k) for k in range(60, 190)]
    b_out = [b.step(k) for k in range(40)]
    a.fmu.setFMUstate(state)
    assert [a.step(k) for k in range(60, 190)] == rest
    a.fmu.setFMUstate(a.fmu.deSerializeFMUstate(blob))
    assert [a.step(k) for k in range(60, 190)] == rest
    a.fmu.reset()
    a.init(csv, toml)
    assert [a.step(k) for k in range(60)] == first
    alone = Rec(fmu_dir / "SensorRecording.fmu", tmp_path, "c")
    alone.init(csv, toml, start=0.5)
    assert [alone.step(k) for k in range(40)] == b_out      # the other instance changed nothing
    for r in (a, b, alone):
        r.close()


def test_nan_gap_and_end_of_record_through_the_fmu(fmu_dir, small, tmp_path):
    csv, toml = small
    r = Rec(fmu_dir / "SensorRecording.fmu", tmp_path)
    r.init(csv, toml)
    iv, gv, new, active = (BOOLEAN_OUTPUTS.index(next(v for v in BOOLEAN_OUTPUTS if v.name == n))
                           for n in ("imu.valid", "gnss.valid", "gnss.new", "record.active"))
    out = {k: r.step(k, 0.01) for k in range(260)}
    assert all(s is None for s, _, _ in out.values())   # FMPy raises on anything but OK
    assert all(np.isfinite(y).all() for _, y, _ in out.values())
    valid = {k: f[iv] for k, (_, _, f) in out.items()}
    assert valid[48] and not valid[49] and valid[50]           # t = 0.50 s (step 49 ends there) is the NaN
    assert not any(valid[k] for k in range(100, 129)) and valid[130]
    assert [k for k, (_, _, f) in out.items() if f[new]][:3] == [19, 39, 59]
    assert out[199][2][active] and not out[200][2][active] and not any(out[250][2])
    texts = [m for _, m in r.log]
    assert sum("end of the record" in m for m in texts) == 1
    assert any("bad sample" in m for m in texts) and any("max_gap = 0.05" in m for m in texts)
    r.close()


def test_a_bad_record_is_refused_at_initialisation_and_every_step_discarded(fmu_dir, small, tmp_path):
    csv, toml = small
    bad = tmp_path / "bad.csv"
    bad.write_text(csv.read_text().replace("0.1,-9.8", "0.1,x9.8", 1))
    r = Rec(fmu_dir / "SensorRecording.fmu", tmp_path)
    r.init(bad, toml)
    assert any(s == 3 and "bad.csv, line 2, column 'az': 'x9.8' is not a number" in m for s, m in r.log)
    from fmpy.fmi1 import FMICallException

    for k in range(2):
        with pytest.raises(FMICallException, match="discard"):
            r.step(k)
    r.close()


def test_build_recording_bundles_the_record_and_runs_without_the_original(fmu_dir, recorded, tmp_path):
    from marinefmu.fmu.recording_build import build_recording

    csv = tmp_path / "copy.csv"
    toml = tmp_path / "copy.toml"
    csv.write_bytes(recorded.csv.read_bytes())
    toml.write_text(recorded.mapping.read_text())
    fmu = build_recording(csv, toml, tmp_path / "out" / "Mailed.fmu")
    assert validate_fmu(str(fmu)) == [] and (tmp_path / "out" / "Mailed_OspModelDescription.xml").exists()
    ref = Rec(fmu_dir / "SensorRecording.fmu", tmp_path, "ref")
    ref.init(recorded.csv, recorded.mapping)
    expected = [ref.step(k) for k in range(300)]
    ref.close()
    csv.unlink()
    toml.unlink()
    r = Rec(fmu, tmp_path, "mailed")
    r.init()                     # empty file and mapping: the bundled ones
    assert [r.step(k) for k in range(300)] == expected
    r.close()


@pytest.mark.libcosim
@pytest.mark.isolated
def test_replay_runs_in_libcosim_as_in_fmpy(fmu_dir, recorded, tmp_path):
    pytest.importorskip("libcosimpy")
    from marinefmu.cosim.libcosim import run_libcosim
    from marinefmu.cosim.replay import plan_replay, run_replay

    plan = plan_replay(recorded.csv, recorded.mapping, "attitude", duration=5.0)
    names = ["rec.imu.acc.z", "rec.gnss.ant1.n", "rec.gnss.valid", "rec.ref.roll", "att.roll", "att.pitch"]
    lc = run_libcosim(plan.system, fmu_dir, tmp_path, 5.0, names, 0.01)
    fp, _ = run_replay(plan, fmu_dir)
    for n in names:
        # libcosim keeps time in integer nanoseconds, up to 0.5 ns off the record's stamps: the
        # recording snaps such a point to the sample (player.SNAP), so the runs agree exactly
        np.testing.assert_array_equal(lc[n], fp[n][1:], err_msg=n)
