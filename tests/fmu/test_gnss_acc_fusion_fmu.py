"""GnssAccFusion FMU run by FMPy equals the in-process estimator bit for bit, including a NaN
accelerometer sample, NaN antenna coordinates and new-fix detection without gnss.new; and so
with attitude = input (one receiver, the angles from the inputs), a NaN angle included."""
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
    outs = ["pos.n", "pos.e", "pos.d", "vel.n", "roll_used", "acc_n.d", "gnss.residual"]
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


@pytest.mark.fmu
def test_fusion_fmu_with_input_attitude_equals_in_process(fmu_dir, tmp_path):
    """One receiver on gnss.ant1 (antenna 1 of the record), the true angles on roll, pitch, yaw,
    one step late and turned forward (attitude_lag), gnss.new unconnected, a NaN roll at one
    step; antennas 2-4 unconnected (zeros)."""
    rec = paper001.simulate(20.0, {"gnss.rate": 2.0})
    params = {"attitude": "input", "attitude_lag": DT, **{f"ant1.{a}": v for a, v in zip("xyz", paper001.ANT[0])},
              **{f"acc_lever_arm.{a}": v for a, v in zip("xyz", paper001.IMU)}}
    f = Driver(fmu_dir / "GnssAccFusion.fmu", tmp_path, "fus_input")
    f.init(params)
    est = GnssAccFusion(fusion_params(params))
    outs = ["pos.n", "pos.e", "pos.d", "vel.e", "pos_std.n", "roll_used", "pitch_used", "yaw_used", "acc_n.n"]
    late = np.r_[rec["euler"][:1], rec["euler"][:-1]]
    bad = 0
    for k in range(len(rec["acc"])):
        acc, gyro, ant, euler = (rec[key][k].tolist() for key in ("acc", "gyro", "gnss", "euler"))
        euler[:2] = late[k, :2].tolist()
        if k == 700:
            euler[0] = float("nan")
        inputs = {"acc.x": acc[0], "acc.y": acc[1], "acc.z": acc[2], "gyro.x": gyro[0], "gyro.y": gyro[1],
                  "gyro.z": gyro[2], **dict(zip(ANT_IN[:3], ant[:3])), "roll": euler[0], "pitch": euler[1], "yaw": euler[2]}
        f.fmu.setBoolean([f.vr["gnss.valid"].valueReference], [bool(rec["gnss_valid"][k])])
        status, reals, flags = f.step(k, inputs, outs, ("valid", "gnss.accepted"))
        r = est.step(acc, np.array(ant[:3]) if rec["gnss_new"][k] else None, DT, gyro, euler)
        assert status in (0, None)
        assert reals == [*r.pos, r.vel[1], r.pos_std[0], *r.euler, r.acc_n[0]], k
        assert flags == [r.valid, r.fix == "accepted"], k
        bad += not r.valid and k > 0
    assert bad == 1 and r.valid     # the NaN roll, and valid from the first fix on
    f.close()
