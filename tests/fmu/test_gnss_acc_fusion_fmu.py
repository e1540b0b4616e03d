"""GnssAccFusion FMU run by FMPy equals the in-process estimator bit for bit, including a NaN
accelerometer sample, NaN antenna coordinates and new-fix detection without gnss.new."""
import numpy as np
import pytest
from tests.conftest import DT, Driver

from marinefmu.fmu.tables import fusion_params
from marinefmu.estimators.gnss_fusion.filter import GnssAccFusion
from marinefmu.papers import paper001

ANT_IN = [f"gnss.ant{i}.{a}" for i in range(1, 5) for a in "ned"]


@pytest.mark.fmu
@pytest.mark.parametrize("connect_new", [True, False])
def test_fusion_fmu_equals_in_process(fmu_dir, tmp_path, connect_new):
    rec = paper001.simulate(30.0, {"gnss.rate": 2.0})
    params = {f"ant{i + 1}.{a}": v for i, arm in enumerate(paper001.ANT) for a, v in zip("xyz", arm)}
    params.update({f"acc_lever_arm.{a}": v for a, v in zip("xyz", paper001.IMU)})
    f = Driver(fmu_dir / "GnssAccFusion.fmu", tmp_path, f"fus{connect_new}")
    f.init(params)
    est = GnssAccFusion(fusion_params(params))
    outs = ["pos.n", "pos.e", "pos.d", "vel.n", "roll", "acc_n.d", "gnss.residual"]
    accepted = 0
    for k in range(len(rec["acc"])):
        acc, gyro, ant = rec["acc"][k].tolist(), rec["gyro"][k].tolist(), rec["gnss"][k].tolist()
        if k == 1500:
            acc[0] = float("nan")
        if 2049 <= k < 2099:  # an epoch (2 Hz) with NaN antenna coordinates, held by the receiver
            ant[4] = float("nan")
        inputs = {"acc.x": acc[0], "acc.y": acc[1], "acc.z": acc[2], "gyro.x": gyro[0], "gyro.y": gyro[1],
                  "gyro.z": gyro[2], **dict(zip(ANT_IN, ant))}
        new = bool(rec["gnss_new"][k])
        f.fmu.setBoolean([f.vr["gnss.valid"].valueReference], [bool(rec["gnss_valid"][k])])
        if connect_new:
            f.fmu.setBoolean([f.vr["gnss.new"].valueReference], [new])
        status, reals, flags = f.step(k, inputs, outs, ("valid", "gnss.accepted"))
        r = est.step(acc, np.array(ant) if new else None, DT, gyro)
        accepted += r.fix == "accepted"
        assert status in (0, None)
        assert reals == [*r.pos, r.vel[0], r.euler[0], r.acc_n[2], r.residual], k
        assert flags == [r.valid, r.fix == "accepted"]
        if k in (1500, 2049):
            assert all(np.isfinite(reals))
            assert (not r.valid) if k == 1500 else r.fix == "skipped"
    assert accepted == 60  # 61 epochs (t = 0, 0.5, …, 30 s) at 2 Hz, one skipped
    f.close()
