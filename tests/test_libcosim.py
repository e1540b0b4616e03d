"""VesselMotion.fmu under OSP libcosim (libcosimpy) equals the in-process model."""
import numpy as np
import pytest

from marinefmu.sea.motion_model import REAL_OUTPUTS, VesselMotionModel, VesselMotionParams

pytestmark = [pytest.mark.fmu, pytest.mark.libcosim]
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

    m = VesselMotionModel(VesselMotionParams.from_flat({**params, "sea.components": 120, "vessel.preset": "semisub"}))
    for k in range(steps):
        ref = m.step(k * 0.01 + 0.01, 0.01)
    # libcosim keeps time in integer nanoseconds; the converted doubles differ from k·0.01 by ~1 ulp
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-9)
    assert abs(got[REAL_OUTPUTS.index(next(v for v in REAL_OUTPUTS if v.name == "truth.cog.d"))]) > 1e-3
