"""The AHC controller: its law, bad inputs, anti-windup, and the loop closed around
the winch in co-simulation with the true crane-tip motion (the ideal the observer-fed loop is
to be compared with)."""
import math

import numpy as np
import pytest

from marinefmu.ahc.controller import AhcController, AhcControllerParams
from marinefmu.errors import ParameterError


def test_the_law_is_feedforward_plus_pi_on_the_length():
    c = AhcController(AhcControllerParams(length0=20.0, k_ff=1.0, k_p=2.0, k_i=0.5, heave_ref=-10.0, engage_time=0.0))
    out = c.step(heave=-9.5, heave_rate=0.3, length=19.0, dt=0.1)
    ref = 20.0 - (-9.5 + 10.0)                       # 19.5 m
    assert out.length_ref == pytest.approx(ref)
    assert out.command == pytest.approx(-0.3 + 2.0 * (ref - 19.0) + 0.5 * (ref - 19.0) * 0.1)
    assert out.valid and out.warning is None


def test_bad_inputs_are_held_and_the_integrator_is_clamped():
    c = AhcController(AhcControllerParams(k_i=1.0, max_integral=0.5, max_command=100.0, engage_time=0.0))
    a = c.step(0.1, 0.2, 19.0, 0.1)
    b = c.step(math.nan, 0.2, 19.0, 0.1)
    assert not b.valid and "bad heave nan" in b.warning and math.isfinite(b.command)
    for _ in range(100):                             # a length error the winch never closes
        c.step(0.0, 0.0, 10.0, 0.1)
    assert c.integral == 0.5
    assert a.valid


def test_the_feedforward_fades_in_while_the_estimate_is_valid_and_out_while_not():
    c = AhcController(AhcControllerParams(length0=20.0, k_ff=1.0, k_p=0.0, k_i=0.0, engage_time=2.0))
    off = c.step(1.0, 0.5, 20.0, 0.1, heave_valid=False)
    assert off.engagement == 0.0 and off.length_ref == 20.0 and off.command == 0.0 and not off.valid
    ramp = [c.step(1.0, 0.5, 20.0, 0.1) for _ in range(20)]
    assert [r.engagement for r in ramp[:3]] == pytest.approx([0.05, 0.1, 0.15])
    assert ramp[4].length_ref == pytest.approx(20.0 - 0.25) and ramp[4].command == pytest.approx(-0.5 * 0.25)
    assert not ramp[-2].valid and ramp[-1].valid and ramp[-1].engagement == 1.0
    down = c.step(1.0, 0.5, 20.0, 0.1, heave_valid=False)     # one rejected estimate: 5 % off, not all
    assert down.engagement == pytest.approx(0.95) and not down.valid
    with pytest.raises(ParameterError, match=r"engage_time = -1\.0 is out of range"):
        AhcControllerParams(engage_time=-1.0)


@pytest.mark.parametrize("kwargs,match", [
    ({"k_p": -1.0}, r"k_p = -1\.0 is out of range"),
    ({"k_ff": 3.0}, r"k_ff = 3\.0 is out of range"),
    ({"max_integral": 0.0}, r"max_integral = 0\.0 is out of range"),
])
def test_bad_parameters_name_the_cause(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        AhcControllerParams(**kwargs)


@pytest.mark.fmu
def test_truth_fed_loop_holds_the_load_still_in_co_simulation(fmu_dir):
    """VesselMotion (Hs 3 m, Tp 9 s, crane tip 50 m forward, 15 m up) → AhcController fed the
    true tip motion → AhcWinch at that tip, FMPy runner, 120 s: the load's vertical motion
    falls from 100 % of the tip's (no compensation, k_ff = 0) to 2.0 % (k_p = 3 /s, measured
    after 30 s; 5.0 % with the default k_p = 1 /s). The loop needs its length feedback
    marked ``delay``."""
    from marinefmu.cosim.ssp import Component, Connection, SystemDescription
    from marinefmu.cosim.system import SystemRunner

    vessel = Component("vessel", "VesselMotion.fmu", {"sea.hs": 3.0, "sea.tp": 9.0, "point.x": 50.0, "point.z": -15.0})
    ratios = {}
    for k_ff in (0.0, 1.0):
        sysd = SystemDescription("ahc", (
            vessel, Component("ctrl", "AhcController.fmu", {"heave_ref": -15.0, "k_ff": k_ff, "k_p": 3.0, "k_i": 0.1}),
            Component("winch", "AhcWinch.fmu")), tuple(Connection.parse(a, b, delay=a == "winch.length") for a, b in (
                ("vessel.truth.point.d", "ctrl.heave"), ("vessel.truth.point_vel.d", "ctrl.heave_rate"),
                ("winch.length", "ctrl.length"), ("ctrl.command", "winch.command"),
                ("vessel.truth.point.d", "winch.tip.d"), ("vessel.truth.point_vel.d", "winch.tip_vel.d"))), 0.01, 120.0)
        r = SystemRunner(sysd, fmu_dir).run(record=["vessel.truth.point.d", "winch.load.d", "winch.stroke_limited"],
                                            progress=False)
        tip, load = r["vessel.truth.point.d"][3000:], r["winch.load.d"][3000:]
        ratios[k_ff] = float(np.std(load) / np.std(tip))
        assert not r["winch.stroke_limited"].any()
    assert ratios[0.0] > 0.95 and ratios[1.0] < 0.03, ratios


def test_a_clipped_command_stops_the_integration_into_the_clip():
    c = AhcController(AhcControllerParams(length0=20.0, k_ff=0.0, k_p=1.0, k_i=1.0, max_command=2.0, engage_time=0.0))
    out = c.step(0.0, 0.0, 15.0, 0.1)                    # 5 m short: 5 m/s asked, 2 m/s given
    assert out.command == 2.0 and out.command_limited and c.integral == 0.0
    small = c.step(0.0, 0.0, 19.5, 0.1)                   # inside the clip: integrates again
    assert not small.command_limited and c.integral == pytest.approx(0.05)
    back = c.step(0.0, 0.0, 26.0, 0.1)                    # clipped the other way: held again
    assert back.command == -2.0 and back.command_limited and c.integral == pytest.approx(0.05)
