"""Memory of each FMU under FMPy over a long run and over many instantiate/free cycles.

Part of ``marinefmu bench`` (project goal: memory stays flat within 10 MB over 10⁶ steps and
over 1,000 instantiate/free cycles). Each measurement runs in a fresh process::

    python -m marinefmu.bench.memory steps  FMU_PATH STEPS
    python -m marinefmu.bench.memory cycles FMU_PATH CYCLES

and prints one JSON line. The resident set size (``VmRSS`` of ``/proc/self/status``) is read
after a warm-up (10⁴ steps, or 10 cycles: caches, lazily imported modules and the spectrum
windows are full by then) and then at ten checkpoints; ``growth_mb`` is the last reading minus
the warm-up one. Estimators are fed a 10-minute VesselMotion record (20 Hz, Hs 2.5 m) played in
a loop, so every code path of a real run (fixes, windows, refits) is exercised.
"""
from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

DT = 0.05
WARM_STEPS = 10_000
WARM_CYCLES = 10
RECORD_S = 600.0
VESSEL = {"sea.hs": 2.5, "sea.tp": 8.0, "gnss.rate": 5.0, "imu.x": 5.0, "imu.z": -3.0}
ESTIMATOR_PARAMS = {"GnssAccFusion": {"acc_lever_arm.x": 5.0, "acc_lever_arm.z": -3.0},
                    "DisplacementReconstructor": {"window": 70.0, "hop": 5.0}, "HeaveObserver": {"window": 60.0}}


def rss_mb() -> float:
    """Resident set size of this process [MB]."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmRSS in /proc/self/status (Linux only)")


class _Fmu:
    def __init__(self, path: Path, unzip: str, name: str = "mem") -> None:
        from fmpy import read_model_description
        from fmpy.fmi2 import FMU2Slave

        self.md = read_model_description(str(path))
        self.vr = {v.name: v for v in self.md.modelVariables}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzip, modelIdentifier=self.md.coSimulation.modelIdentifier,
                             instanceName=name)
        self.fmu.instantiate()
        self.fmu.setupExperiment(startTime=0.0)
        for key, value in (VESSEL if self.md.modelName == "VesselMotion" else ESTIMATOR_PARAMS.get(self.md.modelName, {})).items():
            self.fmu.setReal([self.vr[key].valueReference], [value])
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def close(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


def _feed(fmu: _Fmu):
    """(real refs, bool refs, real rows, bool rows) of the looped record for the FMU's inputs."""
    from ..sea.motion_model import VesselMotionParams, simulate_record

    inputs = [v for v in fmu.md.modelVariables if v.causality == "input"]
    if not inputs:
        return None
    rec = simulate_record(VesselMotionParams.from_flat(VESSEL), RECORD_S, DT)

    def source(name: str) -> np.ndarray:
        for cand in (f"imu.{name}", f"truth.{name}", name):
            if cand in rec:
                return rec[cand]
        raise KeyError(name)

    reals = [v for v in inputs if v.type == "Real"]
    bools = [v for v in inputs if v.type == "Boolean"]
    real_rows = np.column_stack([source(v.name) for v in reals]).tolist()
    bool_rows = (np.column_stack([source(v.name) for v in bools]) > 0.5).tolist() if bools else None
    return [v.valueReference for v in reals], [v.valueReference for v in bools], real_rows, bool_rows


def measure_steps(path: Path, steps: int) -> dict:
    """RSS over ``steps`` steps of one instance."""
    with tempfile.TemporaryDirectory() as tmp:
        from fmpy import extract

        fmu = _Fmu(path, extract(str(path), unzipdir=tmp))
        feed = _feed(fmu)
        readings, every = [], max(1, (steps - WARM_STEPS) // 10)
        for k in range(steps):
            if feed is not None:
                real_refs, bool_refs, real_rows, bool_rows = feed
                row = k % len(real_rows)
                fmu.fmu.setReal(real_refs, real_rows[row])
                if bool_rows is not None:
                    fmu.fmu.setBoolean(bool_refs, bool_rows[row])
            fmu.fmu.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
            if k + 1 == WARM_STEPS or (k + 1 > WARM_STEPS and (k + 1 - WARM_STEPS) % every == 0):
                readings.append(rss_mb())
        fmu.close()
    return {"steps": steps, "warm_mb": readings[0], "readings_mb": readings, "growth_mb": readings[-1] - readings[0]}


def measure_cycles(path: Path, cycles: int) -> dict:
    """RSS over ``cycles`` instantiate / initialise / 10 steps / terminate / free cycles."""
    from fmpy import extract

    with tempfile.TemporaryDirectory() as tmp:
        unzip = extract(str(path), unzipdir=tmp)
        readings, every = [], max(1, (cycles - WARM_CYCLES) // 10)
        for c in range(cycles):
            fmu = _Fmu(path, unzip, f"cycle{c}")
            for k in range(10):
                fmu.fmu.doStep(currentCommunicationPoint=k * DT, communicationStepSize=DT)
            fmu.close()
            if c + 1 == WARM_CYCLES or (c + 1 > WARM_CYCLES and (c + 1 - WARM_CYCLES) % every == 0):
                readings.append(rss_mb())
    return {"cycles": cycles, "warm_mb": readings[0], "readings_mb": readings, "growth_mb": readings[-1] - readings[0]}


def run_isolated(mode: str, path: Path, count: int, timeout: float = 7200.0) -> dict:
    """One measurement in a fresh interpreter (see the module docstring)."""
    import subprocess

    done = subprocess.run([sys.executable, "-m", "marinefmu.bench.memory", mode, str(path), str(count)],
                          capture_output=True, text=True, timeout=timeout)
    if done.returncode != 0 or not done.stdout.strip():
        return {"error": f"exit code {done.returncode}: {done.stderr[-500:]}"}
    return json.loads(done.stdout.strip().splitlines()[-1])


if __name__ == "__main__":
    mode, fmu_path, count = sys.argv[1], Path(sys.argv[2]), int(sys.argv[3])
    result = (measure_steps if mode == "steps" else measure_cycles)(fmu_path, count)
    print(json.dumps(result))
