"""Shared fixtures: the built FMUs (built once per session if missing or stale)."""
from __future__ import annotations

from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def fmu_dir() -> Path:
    """fmus/ of the checkout, with every model built and validated."""
    from marinefmu.cosim.build import build_all

    build_all(verbose=False)
    return ROOT / "fmus"


@pytest.fixture(scope="session")
def relay_fmu(tmp_path_factory) -> Path:
    """A test-only FMU with inputs (tests/models/MfTestRelay.py), to exercise wiring and rates."""
    from marinefmu.cosim.build import build_all

    dest = tmp_path_factory.mktemp("relay")
    build_all(models=ROOT / "tests" / "models", dest=dest, verbose=False)
    return dest / "MfTestRelay.fmu"


DT = 0.01


class Driver:
    """One FMU instance driven step by step through FMPy's FMU2Slave (DT = 0.01 s)."""

    def __init__(self, path, tmp, name):
        self.md = read_model_description(str(path))
        self.vr = {v.name: v for v in self.md.modelVariables}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp / name)),
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate()

    def init(self, params):
        self.fmu.setupExperiment(startTime=0.0)
        for k, v in params.items():
            setter = {"Real": self.fmu.setReal, "Integer": self.fmu.setInteger, "String": self.fmu.setString}
            setter[self.vr[k].type]([self.vr[k].valueReference], [v])
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def step(self, k, inputs, outputs, booleans=("valid",)):
        self.fmu.setReal([self.vr[n].valueReference for n in inputs], list(inputs.values()))
        status = self.fmu.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
        reals = self.fmu.getReal([self.vr[n].valueReference for n in outputs])
        return status, reals, self.fmu.getBoolean([self.vr[n].valueReference for n in booleans])

    def close(self):
        self.fmu.terminate()
        self.fmu.freeInstance()
