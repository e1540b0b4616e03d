"""Tier 2: the pythonfmu slave driven in-process, without building an FMU."""
import importlib.util
from pathlib import Path

import numpy as np

from marinefmu.sea.motion_model import REAL_OUTPUTS, VesselMotion, VesselMotionParams

SCRIPT = Path(__file__).resolve().parents[2] / "models" / "VesselMotion.py"


def slave_class():
    spec = importlib.util.spec_from_file_location("_test_vessel_motion_slave", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.VesselMotion


def test_slave_steps_like_the_model_and_exposes_every_variable():
    s = slave_class()(instance_name="v")
    names = {v.name: v.value_reference for v in s.vars.values()}
    s.set_real([names["sea.hs"]], [4.0])
    s.set_string([names["vessel.preset"]], ["semisub"])
    s.setup_experiment(0.0, None, None)
    s.exit_initialization_mode()
    got = []
    for k in range(50):
        assert s.do_step(k * 0.01, 0.01) is True
        got.append(s.get_real([names[v.name] for v in REAL_OUTPUTS]))
    m = VesselMotion(VesselMotionParams.from_flat({"sea.hs": 4.0, "vessel.preset": "semisub"}))
    np.testing.assert_array_equal(got, [m.step(k * 0.01 + 0.01, 0.01) for k in range(50)])


def test_refused_parameter_is_logged_and_steps_are_discarded():
    s = slave_class()(instance_name="v")
    names = {v.name: v.value_reference for v in s.vars.values()}
    s.set_real([names["sea.tp"]], [-2.0])
    s.exit_initialization_mode()
    assert s.do_step(0.0, 0.01) is False
    msgs = [m.msg for m in s.log_queue]
    assert any("invalid parameter: sea.tp = -2.0 is out of range" in m for m in msgs)
    assert s.log_queue[0].status.name == "error"


def test_unexpected_step_error_is_contained():
    s = slave_class()(instance_name="v")
    s.exit_initialization_mode()
    s.model.step = None  # simulate a bug
    assert s.do_step(0.0, 0.01) is False
    first = s.log_queue[-1].msg
    assert "step failed at t = 0.0 s: TypeError" in first and "Traceback (most recent call last)" in first
    assert s.do_step(0.01, 0.01) is False  # and every later step, without the traceback again
    assert s.log_queue[-1].msg.endswith("the FMU cannot step") and "Traceback" not in s.log_queue[-1].msg


def slave_of(script):
    spec = importlib.util.spec_from_file_location(f"_test_{script}_slave", SCRIPT.parent / f"{script}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return getattr(mod, script)


def test_direct_output_reads_and_input_writes_equal_pythonfmus_own():
    """SlaveIO's get_real and set_real (outputs and inputs by index) against Fmi2Slave's."""
    import pytest
    from pythonfmu import Boolean, Real
    from pythonfmu.fmi2slave import Fmi2Slave

    s = slave_of("HeaveObserver")(instance_name="h")
    vr = {v.name: v.value_reference for v in s.vars.values()}
    reals = [r for r, v in s.vars.items() if isinstance(v, Real)]
    boolean = next(r for r, v in s.vars.items() if isinstance(v, Boolean))
    inputs = [vr[n] for n in ("acc.x", "acc.y", "acc.z", "roll", "pitch")]
    s.set_real(inputs, [0.1, -0.2, -9.7, 1, np.float64(0.02)])  # an int and a numpy float: stored as float
    assert [s.io.inputs[n] for n in ("acc.x", "acc.y", "acc.z", "roll", "pitch")] == [0.1, -0.2, -9.7, 1.0, 0.02]
    assert all(type(s.io.inputs[n]) is float for n in ("roll", "pitch"))
    param = next(r for r in reals if s.vars[r].causality.name == "parameter")
    s.set_real([inputs[0], param, inputs[1]], [0.5, s.vars[param].getter(), 0.25])  # a parameter midway
    assert s.io.inputs["acc.x"] == 0.5 and s.io.inputs["acc.y"] == 0.25
    with pytest.raises(TypeError, match="not of type Real"):
        s.set_real([inputs[2], boolean], [1.5, 0.0])
    assert s.io.inputs["acc.z"] == 1.5  # applied up to the bad reference, as pythonfmu does
    s.setup_experiment(0.0, None, None)
    s.exit_initialization_mode()
    for k in range(30):
        s.set_real(inputs, [0.01 * k, 0.0, -9.8, 0.001 * k, 0.0])
        assert s.do_step(0.01 * k, 0.01) is True
        assert s.get_real(reals) == Fmi2Slave.get_real(s, reals)
        outs = [r for r in reals if s.vars[r].causality.name == "output"]
        assert s.get_real(outs) == Fmi2Slave.get_real(s, outs) == [float(x) for x in s.io.real_out]
    with pytest.raises(TypeError, match="not of type Real"):
        s.get_real([outs[0], boolean])
