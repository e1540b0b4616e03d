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
