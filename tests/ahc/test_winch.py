"""The AHC winch and load model against analytic responses."""
import math

import numpy as np
import pytest

from marinefmu.ahc.winch import G, AhcWinch, AhcWinchParams
from marinefmu.errors import ParameterError


def test_load_rings_as_the_damped_mass_on_a_spring():
    """Winch held, tip still, load released 5 cm above its rest point: z(t) − z_eq is the
    damped oscillation of m z̈ + c ż + k z = 0 (ω = √(k/m) = 10 rad/s, ζ = c/(2√(km)) = 0.05)."""
    p = AhcWinchParams()
    m = AhcWinch(p)
    z_eq = m.x[3]
    m.x[3] -= 0.05
    w, zeta = math.sqrt(p.stiffness / p.mass), p.damping / (2.0 * math.sqrt(p.stiffness * p.mass))
    wd = w * math.sqrt(1.0 - zeta ** 2)
    dt, err = 0.01, 0.0
    for k in range(1, 301):
        s = m.step(0.0, 0.0, 0.0, dt)
        t = k * dt
        exact = -0.05 * math.exp(-zeta * w * t) * (math.cos(wd * t) + zeta * w / wd * math.sin(wd * t))
        err = max(err, abs(s.load - z_eq - exact))
        assert not s.slack and s.length == p.length0
    assert err < 1e-12, err    # the exact linear step (RK4 alone: ~1e-9)


@pytest.mark.parametrize("order", [1, 2])
def test_exact_linear_step_agrees_with_rk4_and_yields_to_it_near_a_limit(order):
    """A minute of a heaving tip and a following command, once with the exact linear step and
    once with RK4 on every step: the same motion to 1e-8 m (measured 5e-10 for order 1, 2e-9 for
    order 2: RK4's own error at 2 ms substeps), the same flags. A command past the speed limit
    with a tight acceleration limit takes RK4 (the limit acts) and flags it."""
    p = AhcWinchParams(order=order, zeta=0.5)
    exact, rk4 = AhcWinch(p), AhcWinch(p)
    rk4._in_linear_regime = lambda *args: False
    used = []
    original = exact._linear_step
    exact._linear_step = lambda dt: used.append(dt) or original(dt)
    for k in range(6000):
        t = k * 0.01
        args = (0.3 * math.cos(0.7 * t + 0.2), 0.5 * math.sin(0.7 * t), 0.35 * math.cos(0.7 * t), 0.01)
        a, b = exact.step(*args), rk4.step(*args)
        for f in ("length", "speed", "load", "load_vel"):
            assert getattr(a, f) == pytest.approx(getattr(b, f), abs=1e-8), (k, f)
        assert a.tension == pytest.approx(b.tension, abs=1e-2)
        assert (a.acc_limited, a.slack, a.stroke_limited) == (b.acc_limited, b.slack, b.stroke_limited)
    assert 5980 <= len(used) < 6000      # all but the first steps, where the command's jump meets the acceleration limit
    limited = AhcWinch(AhcWinchParams(order=order, max_acc=0.5))
    used.clear()
    limited._linear_step = lambda dt: used.append(dt) or original(dt)
    for _ in range(50):
        s = limited.step(3.0, 0.0, 0.0, 0.01)
        assert s.speed_limited and s.acc_limited and s.acc == pytest.approx(0.5)
    assert len(used) <= 1                # order 2 tries the first step (a = 0), and its end fails the check


def test_first_order_motor_follows_a_speed_step():
    """v(t) = u (1 − e^{−t/τ}), L(t) = L₀ + u (t − τ (1 − e^{−t/τ})) below the limits."""
    p = AhcWinchParams(tau=0.2, max_acc=10.0)
    m = AhcWinch(p)
    for k in range(1, 101):
        s = m.step(0.5, 0.0, 0.0, 0.01)
        t = k * 0.01
        assert s.speed == pytest.approx(0.5 * (1.0 - math.exp(-t / 0.2)), abs=1e-9)
        assert s.length == pytest.approx(p.length0 + 0.5 * (t - 0.2 * (1.0 - math.exp(-t / 0.2))), abs=1e-9)
        assert not (s.speed_limited or s.acc_limited or s.stroke_limited)


def test_second_order_motor_step_settles_with_its_overshoot():
    p = AhcWinchParams(order=2, omega_n=10.0, zeta=0.5, max_acc=100.0)
    m = AhcWinch(p)
    v = [m.step(1.0, 0.0, 0.0, 0.01).speed for _ in range(300)]
    overshoot = max(v) - 1.0
    assert overshoot == pytest.approx(math.exp(-math.pi * 0.5 / math.sqrt(1 - 0.25)), rel=1e-3)   # 16.3 %
    assert v[-1] == pytest.approx(1.0, abs=1e-4)


def test_limits_act_and_are_flagged():
    p = AhcWinchParams(max_speed=1.0, max_acc=0.5, max_length=20.5)
    m = AhcWinch(p)
    s = m.step(3.0, 0.0, 0.0, 0.1)
    assert s.speed_limited and s.acc_limited
    assert s.speed == pytest.approx(0.05, abs=1e-9)          # 0.5 m/s² for 0.1 s
    for _ in range(40):
        s = m.step(1.0, 0.0, 0.0, 0.1)
    assert s.stroke_limited and s.length == 20.5 and s.speed == 0.0


def test_a_tip_dropping_faster_than_the_load_can_fall_slackens_the_wire():
    """The tip drops at 4 m/s from rest: the load cannot follow faster than free fall, the
    wire goes slack (tension 0, flagged, never negative) and takes the load again."""
    m = AhcWinch(AhcWinchParams())
    slack, tensions = [], []
    for k in range(100):
        s = m.step(0.0, 4.0 * (k + 1) * 0.01, 4.0, 0.01)
        slack.append(s.slack)
        tensions.append(s.tension)
    assert any(slack[:20]) and min(tensions) == 0.0 and not slack[-1] and tensions[-1] > 0.0


def test_at_rest_the_wire_carries_the_load():
    m = AhcWinch(AhcWinchParams(), tip=-12.0)
    s = m.step(0.0, -12.0, 0.0, 1.0)
    assert s.tension == pytest.approx(1.0e4 * G) and s.load == pytest.approx(-12.0 + 20.0 + 1.0e4 * G / 1.0e6)


@pytest.mark.parametrize("kwargs,match", [
    ({"stiffness": 0.0}, r"stiffness = 0\.0 is out of range"),
    ({"max_speed": -1.0}, r"max_speed = -1\.0 is out of range"),
    ({"max_acc": 0.0}, r"max_acc = 0\.0 is out of range"),
    ({"min_length": 10.0, "max_length": 5.0}, r"max_length = 5\.0 is out of range"),
    ({"order": 3}, r"order = 3 is out of range"),
])
def test_bad_parameters_name_the_cause(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        AhcWinchParams(**kwargs)


def test_a_bad_input_is_held_flagged_and_never_passed_on():
    good = AhcWinch(AhcWinchParams())
    bad = AhcWinch(AhcWinchParams())
    for k in range(50):
        tip = 0.1 * math.sin(0.5 * k * 0.01)
        a = good.step(0.2, tip, 0.0, 0.01)
        corrupt = k == 20
        b = bad.step(math.nan if corrupt else 0.2, math.inf if corrupt else tip, 0.0, 0.01)
        assert b.valid is (not corrupt) and (b.warning is not None) is corrupt
        assert all(math.isfinite(v) for v in (b.length, b.load, b.load_vel, b.tension))
    assert abs(a.load - b.load) < 1e-3          # one held step changes little
    state = bad.get_state()
    again = AhcWinch(AhcWinchParams())
    again.set_state(state)
    assert again.step(0.2, 0.0, 0.0, 0.01) == bad.step(0.2, 0.0, 0.0, 0.01)


@pytest.mark.fmu
def test_fmu_equals_the_in_process_model_under_vessel_motion(fmu_dir):
    """AhcWinch.fmu hanging off VesselMotion's bow point (FMPy runner, no command): the same
    numbers as AhcWinch fed the recorded tip motion (Jacobi: the inputs of step k are
    the vessel's outputs at row k)."""
    from marinefmu.cosim.ssp import Component, Connection, SystemDescription
    from marinefmu.cosim.system import SystemRunner

    sysd = SystemDescription("winch", (Component("vessel", "VesselMotion.fmu", {"sea.hs": 3.0}),
                                       Component("winch", "AhcWinch.fmu", {"mass": 5.0e3})),
                             (Connection.parse("vessel.truth.point.d", "winch.tip.d"),
                              Connection.parse("vessel.truth.point_vel.d", "winch.tip_vel.d")), 0.01, 20.0)
    r = SystemRunner(sysd, fmu_dir).run(record=["vessel.truth.point.d", "vessel.truth.point_vel.d", "winch.load.d",
                                                "winch.tension", "winch.length", "winch.valid", "winch.slack"],
                                        progress=False)
    m = AhcWinch(AhcWinchParams(mass=5.0e3), tip=float(r["vessel.truth.point.d"][0]))
    load = [m.step(0.0, float(r["vessel.truth.point.d"][k]), float(r["vessel.truth.point_vel.d"][k]), 0.01).load
            for k in range(len(r) - 1)]
    np.testing.assert_array_equal(r["winch.load.d"][1:], load)
    assert r["winch.valid"][1:].all() and not r["winch.slack"].any() and (r["winch.length"][1:] == 20.0).all()
    # uncompensated, the load follows the tip: the wire only stretches by the dynamic load
    tip = r["vessel.truth.point.d"][1:]
    assert np.std(r["winch.load.d"][1:] - tip) < 0.05 * np.std(tip)
