"""VesselMotion's per-step path (buffers, Python floats) against the straightforward composition
of its public pieces: rigid_body(), RigidBodyState.points(), specific_force() and the IMU's
equations evaluated on numpy arrays. They must agree bit for bit: VesselMotion is the truth."""
import math

import numpy as np
import pytest

from marinefmu.frames import specific_force
from marinefmu.sea.motion_model import REAL_OUTPUTS, VesselMotion, VesselMotionParams
from marinefmu.sea.sensors import Imu, ImuParams

CASES = [
    {},
    {"sea.heading": 2.6179938779914944, "imu.x": 5.0, "imu.y": 1.0, "imu.z": -3.0, "point.x": 62.0, "point.z": -12.0,
     "imu.acc_bias.x": 0.01, "imu.gyro_bias.z": -1e-3},
    {"vessel.mode": 1, "vessel.cr.x": 3.0, "vessel.cr.z": -2.0, "sea.components": 60, "gnss.jump.start": 0.5,
     "gnss.jump.duration": 0.5, "gnss.jump.n": 4.0, "gnss.dropout.start": 1.2, "gnss.dropout.duration": 0.4},
]


def reference_imu(imu: Imu, f_true, w_true, dt):
    """The IMU model on numpy arrays, term by term as in its docstring."""
    phi = math.exp(-dt / imu.params.bias_tau)
    w = imu._rng.standard_normal(12)
    gm = phi * imu.gm_bias + imu._sigma_b * math.sqrt(1.0 - phi * phi) * w[:6]
    imu.gm_bias = gm
    return np.concatenate((f_true, w_true)) + imu._const + gm + imu._density / math.sqrt(dt) * w[6:]


def reference_outputs(m: VesselMotion, t: float, dt: float | None) -> list[float]:
    p = m.params
    cr = np.array(p.cr if p.mode == 1 else (0.0, 0.0, 0.0))
    s = m.rigid_body(t)
    pts = s.points(np.array([[0.0, 0.0, 0.0], p.imu.lever_arm, p.point]) - cr)
    f_imu = specific_force(s.rot, pts[1, 6:9])
    if dt is None:
        meas = np.concatenate((f_imu, s.rate)) + m.imu.bias
    else:
        meas = reference_imu(m.imu, f_imu, s.rate, dt)
        k = m.gnss.epoch_due(t)
        m.gnss_new = k is not None
        if k is not None:
            m.gnss.measure(k, m.antenna_positions(k / p.gnss.rate))
    return np.concatenate((meas, m.gnss.positions, pts[0], s.euler, s.rate, s.ang_acc, pts[1], f_imu, pts[2],
                           cr, m.imu.bias, (s.wave,))).tolist()


@pytest.mark.parametrize("flat", CASES)
def test_step_equals_the_composition_of_the_public_pieces_bit_for_bit(flat):
    fast, ref = (VesselMotion(VesselMotionParams.from_flat(flat)) for _ in range(2))
    assert fast.peek(0.0) == reference_outputs(ref, 0.0, None)
    dts = [0.01] * 150 + [0.02] * 20 + [0.005] * 40  # a changed step size renews the IMU's factors
    t = 0.0
    for dt in dts:
        t += dt
        got, want = fast.step(t, dt), reference_outputs(ref, t, dt)
        assert len(got) == len(REAL_OUTPUTS)
        assert got == want, [v.name for v, a, b in zip(REAL_OUTPUTS, got, want) if a != b]
        assert fast.boolean_outputs() == [ref.gnss.valid, ref.gnss_new, ref.params.mode == 1]
    assert fast.peek(t) == reference_outputs(ref, t, None)


def test_state_restore_renews_the_held_gnss_fix_and_the_imu_bias():
    m = VesselMotion(VesselMotionParams.from_flat({"gnss.rate": 10.0}))
    for k in range(30):
        m.step(0.01 * (k + 1), 0.01)
    state = m.get_state()
    ahead = [m.step(0.01 * (k + 31), 0.01) for k in range(25)]
    m.reset()
    m.set_state(state)
    assert [m.step(0.01 * (k + 31), 0.01) for k in range(25)] == ahead


def test_imu_measure_values_equal_the_array_equations():
    p = ImuParams.from_grade("tactical", acc_bias=(0.1, -0.2, 0.3), gyro_bias=(1e-3, 0.0, -2e-3))
    a, b = Imu(p, np.random.default_rng(3)), Imu(p, np.random.default_rng(3))
    rng = np.random.default_rng(4)
    for dt in [0.01] * 5 + [0.1] * 5 + [0.01] * 5:
        f, w = rng.standard_normal(3), rng.standard_normal(3)
        assert a.measure_values(f.tolist(), w.tolist(), dt) == reference_imu(b, f, w, dt).tolist()
        assert a.bias.tolist() == (b._const + b.gm_bias).tolist()
    assert isinstance(a.measure(f, w, 0.01), np.ndarray)
