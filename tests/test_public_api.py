"""The public face: ``from marinefmu import <FMU name>`` gives the in-process model of that FMU,
with its parameters beside it; every model follows the estimator pattern
(:class:`marinefmu.Estimator`); ``HeaveObserver`` runs what the HeaveObserver FMU runs for each
observer model; and ``import marinefmu`` stays free of the FMI libraries."""
import dataclasses
import importlib.util
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

import marinefmu
from marinefmu import (
    AhcController, AhcControllerParams, AhcWinch, AhcWinchParams, AttitudeEstimator, AttitudeEstimatorParams,
    CentreOfRotation, CentreOfRotationParams, DisplacementReconstructor, DisplacementReconstructorParams, Estimator,
    GnssAccFusion, GnssAccFusionParams, HeaveObserver, HeaveObserverParams, VesselMotion, VesselMotionParams,
)
from marinefmu.estimators.heave.bank import OscillatorBankHeave
from marinefmu.sea.recording.player import SensorRecording, SensorRecordingParams
from marinefmu.estimators.heave.highpass import HighpassHeave
from marinefmu.estimators.heave.observer import build_heave_model
from marinefmu.estimators.heave.wiener import WienerHeave
from marinefmu import MotionReferenceUnit, MotionReferenceUnitParams

ROOT = Path(__file__).resolve().parents[1]

# FMU name -> (in-process model, its parameters)
MODELS = {
    "VesselMotion": (VesselMotion, VesselMotionParams),
    "AttitudeEstimator": (AttitudeEstimator, AttitudeEstimatorParams),
    "DisplacementReconstructor": (DisplacementReconstructor, DisplacementReconstructorParams),
    "GnssAccFusion": (GnssAccFusion, GnssAccFusionParams),
    "CentreOfRotation": (CentreOfRotation, CentreOfRotationParams),
    "HeaveObserver": (HeaveObserver, HeaveObserverParams),
    "AhcWinch": (AhcWinch, AhcWinchParams),
    "AhcController": (AhcController, AhcControllerParams),
    "SensorRecording": (SensorRecording, SensorRecordingParams),
    "MotionReferenceUnit": (MotionReferenceUnit, MotionReferenceUnitParams),
}
# Defaults that cannot play (a recording needs its file and mapping): the example MRU export
EXAMPLE_PARAMS = {"SensorRecording": {"file": str(ROOT / "examples/recordings/generic_mru_sample.csv"),
                                      "mapping": str(ROOT / "examples/recordings/generic_mru.toml")}}

# HeaveObserverParams.model -> the class that does the work (estimators.heave.observer's table)
HEAVE_MODELS = {"wiener": WienerHeave, "band": OscillatorBankHeave, "peaks": OscillatorBankHeave,
                "highpass": HighpassHeave}


@pytest.mark.parametrize("name", marinefmu.__all__)
def test_every_public_name_imports(name):
    assert getattr(marinefmu, name) is not None
    assert name in dir(marinefmu)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'HeaveEstimator'"):
        marinefmu.HeaveEstimator


def test_every_fmu_has_a_model_of_its_name_with_params_beside_it():
    fmus = sorted(p.stem for p in (ROOT / "models").glob("*.py"))
    assert sorted(MODELS) == fmus
    for name, (model, params) in MODELS.items():
        assert model.__name__ == name and params.__name__ == f"{name}Params"
        assert {name, f"{name}Params"} <= set(marinefmu.__all__)


@pytest.mark.parametrize("name", MODELS)
def test_each_model_built_from_its_default_params_is_an_estimator(name):
    model, params = MODELS[name]
    given = EXAMPLE_PARAMS.get(name, {})
    m = model(params(**given))
    assert isinstance(m, Estimator)
    for method in ("reset", "step", "get_state", "set_state"):
        assert callable(getattr(m, method)), method
    assert m.params == params(**given)
    assert dataclasses.is_dataclass(m.params) and type(m.params).__dataclass_params__.frozen
    json.dumps(m.get_state())   # what the FMU's state carries


def test_a_class_without_the_pattern_is_not_an_estimator():
    class StepOnly:
        params = None

        def step(self, dt):
            return dt

    assert not isinstance(StepOnly(), Estimator)


def heave_slave_class():
    """models/HeaveObserver.py loaded in-process (no build)."""
    spec = importlib.util.spec_from_file_location("_test_heave_observer_slave", ROOT / "models" / "HeaveObserver.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod.HeaveObserver


@pytest.mark.parametrize("model", HEAVE_MODELS)
def test_heave_observer_runs_what_the_fmu_runs_for_each_model(model):
    params = HeaveObserverParams(model=model)
    ours = HeaveObserver(params)
    assert type(ours.estimator) is HEAVE_MODELS[model]
    assert type(build_heave_model(params)) is HEAVE_MODELS[model]

    slave = heave_slave_class()(instance_name="heave")
    refs = {v.name: v.value_reference for v in slave.vars.values()}
    slave.set_string([refs["model"]], [model])
    slave.setup_experiment(0.0, None, None)
    slave.exit_initialization_mode()
    assert type(slave.model) is HeaveObserver
    assert type(slave.model.estimator) is HEAVE_MODELS[model]
    assert slave.model.params == params   # the FMU's parameter defaults are the dataclass's


def specific_force(t):
    """A level IMU heaving 1 m at 8 s: f_d = a_d − g [m/s², body z down]."""
    w = 2.0 * math.pi / 8.0
    return (0.0, 0.0, -w * w * math.cos(w * t) - 9.80665)


def test_a_state_round_trip_through_json_reproduces_the_next_steps_exactly():
    params = HeaveObserverParams(model="wiener", window=60.0, peak_interval=5.0)
    dt, n = 0.1, 900
    obs = HeaveObserver(params)
    for k in range(n):
        r = obs.step(specific_force(k * dt), 0.0, 0.0, dt)
    assert r.valid   # past the first spectrum: the state holds a designed filter
    restored = HeaveObserver(params)
    restored.set_state(json.loads(json.dumps(obs.get_state())))
    for k in range(n, n + 50):
        a = obs.step(specific_force(k * dt), 0.0, 0.0, dt)
        b = restored.step(specific_force(k * dt), 0.0, 0.0, dt)
        assert dataclasses.astuple(a) == dataclasses.astuple(b)


def test_reset_starts_over():
    params = HeaveObserverParams(model="wiener", window=60.0, peak_interval=5.0)
    dt = 0.1
    fresh = HeaveObserver(params)
    first = [dataclasses.astuple(fresh.step(specific_force(k * dt), 0.0, 0.0, dt)) for k in range(20)]
    used = HeaveObserver(params)
    for k in range(700):
        used.step(specific_force(k * dt), 0.0, 0.0, dt)
    used.reset()
    assert [dataclasses.astuple(used.step(specific_force(k * dt), 0.0, 0.0, dt)) for k in range(20)] == first


def test_import_marinefmu_and_its_models_leaves_the_fmi_libraries_unloaded():
    """The models run without pythonfmu or FMPy (design page: nothing in sea/ or estimators/
    imports them); the system runner loads FMPy when it runs a system, not on import."""
    code = ("import sys\nimport marinefmu\nassert not {'fmpy', 'pythonfmu'} & set(sys.modules), 'import'\n"
            f"from marinefmu import {', '.join(n for pair in MODELS.values() for n in (pair[0].__name__, pair[1].__name__))}\n"
            "from marinefmu import reconstruct_displacement, score, load_scenario\n"
            "loaded = sorted({'fmpy', 'pythonfmu'} & set(sys.modules))\nassert not loaded, loaded\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
