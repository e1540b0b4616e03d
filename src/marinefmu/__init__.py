"""marinefmu: FMI 2.0 co-simulation FMUs for marine motion estimation.

Each FMU's in-process model is importable under the FMU's name, with its parameters beside it::

    from marinefmu import HeaveObserver, HeaveObserverParams
    obs = HeaveObserver(HeaveObserverParams(point=(40.0, 0.0, -5.0)))
    r = obs.step(acc, roll, pitch, dt)        # what the HeaveObserver FMU computes per step

Names are loaded on first use, so that ``import marinefmu`` (which every FMU does) stays cheap:
the systems runner pulls in FMPy only when ``SystemRunner`` is asked for.

Packages: :mod:`marinefmu.sea` (waves, vessel response, sensors: the truth side),
:mod:`marinefmu.estimators` (one package per estimator), :mod:`marinefmu.ahc` (heave
compensation), :mod:`marinefmu.fmu` (making FMUs), :mod:`marinefmu.cosim` (running systems),
:mod:`marinefmu.analysis` (scoring and reports), :mod:`marinefmu.campaign`,
:mod:`marinefmu.bench`, :mod:`marinefmu.papers`. The design page of the documentation says which
may import which.
"""
from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.3.0"

# public name -> module that defines it
_PUBLIC: dict[str, str] = {
    "VesselMotion": "marinefmu.sea.motion_model",
    "VesselMotionParams": "marinefmu.sea.motion_model",
    "AttitudeEstimator": "marinefmu.estimators.attitude.estimator",
    "AttitudeEstimatorParams": "marinefmu.estimators.attitude.estimator",
    "DisplacementReconstructor": "marinefmu.estimators.reconstruction.sliding",
    "DisplacementReconstructorParams": "marinefmu.estimators.reconstruction.sliding",
    "reconstruct_displacement": "marinefmu.estimators.reconstruction.decomposition",
    "GnssAccFusion": "marinefmu.estimators.gnss_fusion.filter",
    "GnssAccFusionParams": "marinefmu.estimators.gnss_fusion.filter",
    "CentreOfRotation": "marinefmu.estimators.centre_of_rotation.filter",
    "CentreOfRotationParams": "marinefmu.estimators.centre_of_rotation.filter",
    "HeaveObserver": "marinefmu.estimators.heave.observer",
    "HeaveObserverParams": "marinefmu.estimators.heave.common",
    "MotionReferenceUnit": "marinefmu.estimators.mru.unit",
    "MotionReferenceUnitParams": "marinefmu.estimators.mru.params",
    "AhcWinch": "marinefmu.ahc.winch",
    "AhcWinchParams": "marinefmu.ahc.winch",
    "AhcController": "marinefmu.ahc.controller",
    "AhcControllerParams": "marinefmu.ahc.controller",
    "SensorRecording": "marinefmu.sea.recording.player",
    "SensorRecordingParams": "marinefmu.sea.recording.player",
    "Estimator": "marinefmu.estimators.protocol",
    "SystemRunner": "marinefmu.cosim.system",
    "load_scenario": "marinefmu.cosim.scenarios",
    "score": "marinefmu.analysis.scoring",
    "SeaState": "marinefmu.sea.waves",
    "jonswap": "marinefmu.sea.waves",
    "pierson_moskowitz": "marinefmu.sea.waves",
    "realise": "marinefmu.sea.waves",
    "load_rao_csv": "marinefmu.sea.vessel",
    "preset_raos": "marinefmu.sea.vessel",
    "save_rao_csv": "marinefmu.sea.vessel",
}

from .errors import (  # noqa: E402  (light: the error classes are always loaded)
    MarineFmuError, ParameterError, ParameterTypeError, RaoFileError, ScenarioError, ShapeError, SystemError_,
)

__all__ = sorted([*_PUBLIC, "MarineFmuError", "ParameterError", "ParameterTypeError", "RaoFileError",
                  "ScenarioError", "ShapeError", "SystemError_", "__version__"])


def __getattr__(name: str) -> Any:
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'marinefmu' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return __all__


if TYPE_CHECKING:  # the same names for type checkers and IDEs
    from .ahc.controller import AhcController, AhcControllerParams
    from .ahc.winch import AhcWinch, AhcWinchParams
    from .analysis.scoring import score
    from .cosim.scenarios import load_scenario
    from .cosim.system import SystemRunner
    from .estimators.attitude.estimator import AttitudeEstimator, AttitudeEstimatorParams
    from .estimators.centre_of_rotation.filter import CentreOfRotation, CentreOfRotationParams
    from .estimators.gnss_fusion.filter import GnssAccFusion, GnssAccFusionParams
    from .estimators.heave.common import HeaveObserverParams
    from .estimators.heave.observer import HeaveObserver
    from .estimators.mru.params import MotionReferenceUnitParams
    from .estimators.mru.unit import MotionReferenceUnit
    from .estimators.protocol import Estimator
    from .estimators.reconstruction.decomposition import reconstruct_displacement
    from .estimators.reconstruction.sliding import DisplacementReconstructor, DisplacementReconstructorParams
    from .sea.motion_model import VesselMotion, VesselMotionParams
    from .sea.vessel import load_rao_csv, preset_raos, save_rao_csv
    from .sea.waves import SeaState, jonswap, pierson_moskowitz, realise
