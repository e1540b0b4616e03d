"""VesselMotion.fmu under OSP libcosim (libcosimpy) equals the in-process model. Each test runs
in its own subprocess (marker ``isolated``): a native crash fails that test, not the run."""
import numpy as np
import pytest

from marinefmu.sea.motion_model import REAL_OUTPUTS, VesselMotion, VesselMotionParams

pytestmark = [pytest.mark.fmu, pytest.mark.libcosim, pytest.mark.isolated]
libcosim = pytest.importorskip("libcosimpy")


def test_vessel_motion_runs_in_libcosim_and_matches_in_process(fmu_dir):
    from fmpy import read_model_description
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    path = fmu_dir / "VesselMotion.fmu"
    vr = {v.name: v.valueReference for v in read_model_description(str(path)).modelVariables}
    params = {"sea.hs": 4.0, "sea.tp": 10.0, "sea.heading": 2.5, "imu.x": 10.0, "imu.z": -5.0}
    dt_ns, steps = 10_000_000, 1000  # 0.01 s, 10 s
    ex = CosimExecution.from_step_size(step_size=dt_ns)
    idx = ex.add_local_slave(CosimLocalSlave(fmu_path=str(path), instance_name="vessel"))
    for k, v in params.items():
        assert ex.real_initial_value(idx, vr[k], v)
    assert ex.integer_initial_value(idx, vr["sea.components"], 120)
    assert ex.string_initial_value(idx, vr["vessel.preset"], "semisub")
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    assert ex.simulate_until(steps * dt_ns)
    got = np.array(obs.last_real_values(idx, [vr[v.name] for v in REAL_OUTPUTS]))

    m = VesselMotion(VesselMotionParams.from_flat({**params, "sea.components": 120, "vessel.preset": "semisub"}))
    for k in range(steps):
        ref = m.step(k * 0.01 + 0.01, 0.01)
    # libcosim keeps time in integer nanoseconds; the converted doubles differ from k·0.01 by ~1 ulp
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-9)
    assert abs(got[REAL_OUTPUTS.index(next(v for v in REAL_OUTPUTS if v.name == "truth.cog.d"))]) > 1e-3


def test_centre_of_rotation_fed_by_vessel_motion_in_libcosim(fmu_dir):
    """VesselMotion (independent-rotation mode) wired to CentreOfRotation in libcosim equals the
    in-process pair; libcosim passes each output on at the next communication point, so the
    estimator sees the vessel's sample of the previous step (its initial values at step 0)."""
    from fmpy import read_model_description
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    from marinefmu.estimators.centre_of_rotation.filter import CentreOfRotation, CentreOfRotationParams
    from marinefmu.sea.motion_model import REAL_INDEX

    log_output_level(CosimLogLevel.ERROR)
    vpath, cpath = fmu_dir / "VesselMotion.fmu", fmu_dir / "CentreOfRotation.fmu"
    vvr = {v.name: v.valueReference for v in read_model_description(str(vpath)).modelVariables}
    cvr = {v.name: v.valueReference for v in read_model_description(str(cpath)).modelVariables}
    params = {"vessel.mode": 1, "vessel.cr.x": 3.0, "vessel.cr.z": -1.5, "imu.x": 8.0, "imu.y": 2.0, "imu.z": -4.0}
    dt_ns, steps = 10_000_000, 1500
    ex = CosimExecution.from_step_size(step_size=dt_ns)
    v = ex.add_local_slave(CosimLocalSlave(fmu_path=str(vpath), instance_name="vessel"))
    c = ex.add_local_slave(CosimLocalSlave(fmu_path=str(cpath), instance_name="cr"))
    for k, val in params.items():
        assert (ex.integer_initial_value if k == "vessel.mode" else ex.real_initial_value)(v, vvr[k], val)
    assert ex.string_initial_value(v, vvr["vessel.preset"], "research36")
    wires = [(f"imu.{s}.{a}", f"{s}.{a}") for s in ("acc", "gyro") for a in "xyz"]
    for src, dst in wires:
        assert ex.connect_real_variables(v, vvr[src], c, cvr[dst]) == 0  # a libcosim status code: 0 is success
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    assert ex.simulate_until(steps * dt_ns)
    outs = ["offset.x", "offset.y", "offset.z", "acc_cr.z"]
    got = np.array(obs.last_real_values(c, [cvr[n] for n in outs]))

    m = VesselMotion(VesselMotionParams.from_flat({**params, "vessel.preset": "research36"}))
    est = CentreOfRotation(CentreOfRotationParams())
    y = m.peek(0.0)
    for k in range(steps):
        r = est.step([y[REAL_INDEX[f"imu.acc.{a}"]] for a in "xyz"], [y[REAL_INDEX[f"imu.gyro.{a}"]] for a in "xyz"], 0.01)
        y = m.step(k * 0.01 + 0.01, 0.01)
    np.testing.assert_allclose(got, [*r.offset, r.acc_cr[2]], rtol=1e-7, atol=1e-9)
    assert r.valid and np.all(np.abs(r.offset) > 0.0)


def test_heave_observer_fed_by_vessel_motion_in_libcosim(fmu_dir):
    """VesselMotion wired to HeaveObserver (specific force and truth roll/pitch) in libcosim
    equals the in-process pair to 1e-9 (one-step wire delay as above), and is valid with a
    heave of the right size once the 60 s spectrum window is full."""
    from fmpy import read_model_description
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    from marinefmu.estimators.heave.common import HeaveObserverParams
    from marinefmu.estimators.heave.observer import build_heave_model
    from marinefmu.sea.motion_model import REAL_INDEX

    log_output_level(CosimLogLevel.ERROR)
    vpath, hpath = fmu_dir / "VesselMotion.fmu", fmu_dir / "HeaveObserver.fmu"
    vvr = {v.name: v.valueReference for v in read_model_description(str(vpath)).modelVariables}
    hvr = {v.name: v.valueReference for v in read_model_description(str(hpath)).modelVariables}
    vparams = {"sea.hs": 2.0, "sea.tp": 8.0, "imu.x": -5.0, "imu.z": -3.0}
    hparams = {"window": 60.0, "point.x": 40.0}
    dt, steps = 0.05, 1400                                  # 70 s at 20 Hz
    ex = CosimExecution.from_step_size(step_size=50_000_000)
    v = ex.add_local_slave(CosimLocalSlave(fmu_path=str(vpath), instance_name="vessel"))
    h = ex.add_local_slave(CosimLocalSlave(fmu_path=str(hpath), instance_name="heave"))
    for k, val in vparams.items():
        assert ex.real_initial_value(v, vvr[k], val)
    for k, val in hparams.items():
        assert ex.real_initial_value(h, hvr[k], val)
    wires = [(f"imu.acc.{a}", f"acc.{a}") for a in "xyz"] + [("truth.roll", "roll"), ("truth.pitch", "pitch")]
    for src, dst in wires:
        assert ex.connect_real_variables(v, vvr[src], h, hvr[dst]) == 0
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    assert ex.simulate_until(steps * 50_000_000)
    outs = ["heave", "heave_rate", "point.heave", "offset"]
    got = np.array(obs.last_real_values(h, [hvr[n] for n in outs]))
    valid = obs.last_boolean_values(h, [hvr["valid"]])[0]

    m = VesselMotion(VesselMotionParams.from_flat(vparams))
    est = build_heave_model(HeaveObserverParams(window=60.0, point=(40.0, 0.0, 0.0)))     # the default model
    y = m.peek(0.0)
    for k in range(steps):
        r = est.step([y[REAL_INDEX[f"imu.acc.{a}"]] for a in "xyz"], y[REAL_INDEX["truth.roll"]],
                     y[REAL_INDEX["truth.pitch"]], dt)
        y = m.step(k * dt + dt, dt)
    np.testing.assert_allclose(got, [r.heave, r.heave_rate, r.point_heave, r.offset], rtol=1e-7, atol=1e-9)
    assert valid and r.valid and 0.01 < abs(r.heave) < 3.0


def _affinities() -> dict[int, set[int]]:
    """The CPUs each thread of this process may run on, by native thread id (a thread that ends
    while they are read is left out)."""
    import os

    out = {}
    for t in os.listdir("/proc/self/task"):
        try:
            out[int(t)] = os.sched_getaffinity(int(t))
        except OSError:
            pass
    return out


@pytest.mark.skipif(not hasattr(__import__("os"), "sched_setaffinity"), reason="no CPU affinity on this OS")
def test_one_worker_gives_the_same_outputs_with_fewer_threads_and_pins_none(fmu_dir, tmp_path):
    """``one_worker`` (VesselMotion wired to HeaveObserver, 5 s at 100 Hz): the outputs equal the
    default pool's bit for bit (the same Jacobi steps), the execution starts no more threads
    than the default one, and afterwards every thread of the process may run on every CPU it
    could before: nothing is left pinned to the CPU the pool was made on."""
    import os

    from fmpy import read_model_description
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver

    from marinefmu.cosim.libcosim import one_worker, write_osp_system
    from marinefmu.cosim.ssp import Component, Connection, SystemDescription

    system = SystemDescription("pair", (Component("vessel", "VesselMotion.fmu", {"sea.hs": 3.0}),
                                        Component("heave", "HeaveObserver.fmu", {"window": 60.0})),
                               tuple(Connection("vessel", f"imu.acc.{a}", "heave", f"acc.{a}") for a in "xyz")
                               + (Connection("vessel", "truth.roll", "heave", "roll"),
                                  Connection("vessel", "truth.pitch", "heave", "pitch")), step=0.01, stop_time=5.0)
    path = str(write_osp_system(system, fmu_dir, tmp_path / "OspSystemStructure.xml"))
    vr = {m: {v.name: v.valueReference for v in read_model_description(str(fmu_dir / f"{m}.fmu")).modelVariables}
          for m in ("VesselMotion", "HeaveObserver")}
    vessel_out = [vr["VesselMotion"][n] for n in ("truth.cog.d", "imu.acc.z", "truth.roll")]
    heave_out = [vr["HeaveObserver"][n] for n in ("heave", "heave_rate", "offset")]
    cpus = os.sched_getaffinity(0)
    runs = {}
    for how, make in (("default", lambda f: f()), ("one worker", one_worker)):
        threads = set(_affinities())
        ex = make(lambda: CosimExecution.from_osp_config_file(path))
        started = set(_affinities()) - threads
        obs = CosimObserver.create_last_value()
        ex.add_observer(obs)
        vessel, heave = ex.slave_index_from_instance_name("vessel"), ex.slave_index_from_instance_name("heave")
        assert ex.simulate_until(500 * 10_000_000)
        runs[how] = (len(started), obs.last_real_values(vessel, vessel_out), obs.last_real_values(heave, heave_out))
        assert all(a == cpus for a in _affinities().values()), (how, _affinities(), cpus)
    assert runs["one worker"][0] <= runs["default"][0]
    assert runs["one worker"][1:] == runs["default"][1:]
    assert any(v != 0.0 for v in runs["default"][1])          # the vessel moved: the comparison is not of zeros
