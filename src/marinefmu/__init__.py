"""marinefmu: FMI 2.0 co-simulation FMUs for marine motion estimation.

The truth side lives in :mod:`marinefmu.sea` (waves, vessel response, sensors), the
estimators from the literature in :mod:`marinefmu.estimators`, the FMI side in
:mod:`marinefmu.cosim`.
"""
from __future__ import annotations

__version__ = "0.1.0"

from .errors import MarineFmuError, ParameterError, RaoFileError, ScenarioError  # noqa: E402
from .sea.motion_model import VesselMotionModel, VesselMotionParams  # noqa: E402
from .sea.vessel import load_rao_csv, preset_raos, save_rao_csv  # noqa: E402
from .sea.waves import SeaState, jonswap, pierson_moskowitz, realise  # noqa: E402

__all__ = [
    "MarineFmuError", "ParameterError", "RaoFileError", "ScenarioError",
    "VesselMotionModel", "VesselMotionParams", "SeaState", "jonswap", "pierson_moskowitz", "realise",
    "load_rao_csv", "preset_raos", "save_rao_csv",
]
