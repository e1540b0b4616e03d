"""Streaming benchmark of the SensorRecording model and FMU: a 24-hour record at 100 Hz.

:func:`write_day_record` writes the record (8.64 million rows: IMU, a 5 Hz GNSS antenna held
between epochs with its ``new`` flag, and three reference signals) with numpy in chunks;
:func:`recording_bench` then plays it whole in-process, in a fresh process of its own so that
the resident-memory peak (``VmHWM``, :func:`marinefmu.bench.system.peak_rss_mb`) is the player's, and through FMPy for a stretch of it
(the FMI per-step overhead), and reports the opening scan's time, the steps per second and the
peak resident memory of each. The goal of issue 51: ≤ 500 MB resident and ≥ 20,000 steps/s.

The bound behind the FMPy figure, :func:`fmi_floor`: the same loop (``doStep``, nine reals and
three booleans read per step) on an FMU with the recording's variables whose ``doStep`` does
nothing. No player inside pythonfmu's slave can stream faster than that through FMPy.
"""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

#: The record's mapping (its columns as written by :func:`write_day_record`).
MAPPING = """[time]
column = "t"
unit = "s"
[imu]
acc = { x = "ax", y = "ay", z = "az" }
gyro = { x = "gx", y = "gy", z = "gz" }
[gnss]
new = "new"
ant1 = { n = "n", e = "e", d = "d" }
[ref]
roll = "roll"
pitch = "pitch"
heave = "heave"
"""
GOAL_MB = 500.0
GOAL_STEPS_S = 20_000.0


def write_day_record(path: str | Path, hours: float = 24.0, rate: float = 100.0, chunk: int = 200_000) -> Path:
    """Write a synthetic record of ``hours`` at ``rate`` [Hz] (and its mapping beside it, ``.toml``)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    n = int(round(hours * 3600.0 * rate))
    rng = np.random.default_rng(1)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("t,ax,ay,az,gx,gy,gz,n,e,d,new,roll,pitch,heave\n")
        for k0 in range(0, n, chunk):
            k = np.arange(k0, min(n, k0 + chunk))
            t = k / rate
            w = 2 * np.pi / 9.0
            roll, pitch, heave = 0.05 * np.sin(w * t), 0.03 * np.cos(w * t), 1.2 * np.sin(w * t + 0.3)
            acc = np.column_stack([9.81 * pitch, -9.81 * roll, -9.81 + 1.2 * w * w * np.sin(w * t + 0.3)])
            acc += 1e-3 * rng.normal(size=acc.shape)
            gyro = np.column_stack([0.05 * w * np.cos(w * t), -0.03 * w * np.sin(w * t), 0 * t]) + 1e-4 * rng.normal(size=acc.shape)
            epoch = (k % int(round(rate / 5.0))) == 0
            fix = np.floor(k / (rate / 5.0)) * (rate / 5.0) / rate     # the held epoch's time
            gnss = np.column_stack([0.1 * np.sin(w * fix), 0.1 * np.cos(w * fix), 1.2 * np.sin(w * fix + 0.3)])
            data = np.column_stack([t, acc, gyro, gnss, epoch, roll, pitch, heave])
            np.savetxt(fh, data, delimiter=",", fmt=["%.2f"] + ["%.6f"] * 9 + ["%d"] + ["%.6f"] * 3)
    path.with_suffix(".toml").write_text(MAPPING, encoding="utf-8")
    return path


_PLAYER = """
import json, sys, time
from marinefmu.bench.system import peak_rss_mb
from marinefmu.sea.recording import SensorRecording, SensorRecordingParams
path, mapping, steps, dt = sys.argv[1], sys.argv[2], int(sys.argv[3]), float(sys.argv[4])
t0 = time.perf_counter()
p = SensorRecording(SensorRecordingParams(path, mapping))
scan = time.perf_counter() - t0
n = min(steps, int(p.duration / dt)) if steps else int(p.duration / dt)
t0 = time.perf_counter()
for k in range(n):
    p.step(k * dt + dt, dt)
play = time.perf_counter() - t0
print(json.dumps({"rows": p.record.summary.rows, "steps": n, "scan_s": scan, "play_s": play, "steps_per_s": n / play,
                  "max_rss_mb": peak_rss_mb(),
                  "ended": p.ended, "imu_invalid_steps": p.invalid_steps.get("imu.valid", 0)}))
"""

_FMPY = """
import json, sys, time
from fmpy import extract, read_model_description
def peak_rss_mb():   # VmHWM as marinefmu.bench.system.peak_rss_mb, without importing marinefmu here
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024.0
from fmpy.fmi2 import FMU2Slave
fmu, path, mapping, steps, dt = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4]), float(sys.argv[5])
md = read_model_description(fmu)
vr = {v.name: v.valueReference for v in md.modelVariables}
s = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu), modelIdentifier=md.coSimulation.modelIdentifier, instanceName="rec")
s.instantiate()
s.setupExperiment(startTime=0.0)
s.setString([vr["file"], vr["mapping"]], [path, mapping])
t0 = time.perf_counter()
s.enterInitializationMode(); s.exitInitializationMode()
scan = time.perf_counter() - t0
reals = [vr[n] for n in ("imu.acc.x", "imu.acc.y", "imu.acc.z", "imu.gyro.x", "imu.gyro.y", "imu.gyro.z",
                         "gnss.ant1.n", "gnss.ant1.e", "gnss.ant1.d")]
bools = [vr["imu.valid"], vr["gnss.valid"], vr["gnss.new"]]
t0 = time.perf_counter()
for k in range(steps):
    s.doStep(currentCommunicationPoint=k * dt, communicationStepSize=dt)
    s.getReal(reals); s.getBoolean(bools)
play = time.perf_counter() - t0
s.terminate(); s.freeInstance()
print(json.dumps({"steps": steps, "scan_s": scan, "play_s": play, "steps_per_s": steps / play,
                  "max_rss_mb": peak_rss_mb()}))
"""


def _run(code: str, *args: str) -> dict:
    done = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"recording benchmark failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def fmi_floor(fmu_dir: str | Path, work: str | Path, path: Path, steps: int, dt: float = 0.01) -> dict:
    """Steps per second of the FMPy loop of :func:`recording_bench` on an idle copy of the
    SensorRecording FMU (:func:`marinefmu.bench.system.idle_fmus`): the FMI call chain alone."""
    from marinefmu.bench.system import idle_fmus

    idle = idle_fmus(Path(fmu_dir), Path(work) / "idle_fmus", ("SensorRecording",))
    return _run(_FMPY, str(idle / "SensorRecording.fmu"), str(path), str(path.with_suffix(".toml")), str(steps), repr(dt))


def recording_bench(fmu_dir: str | Path, work: str | Path, hours: float = 24.0, fmpy_steps: int = 500_000,
                    record: str | Path | None = None) -> dict:
    """Write (or reuse ``record``) and play the day-long record (module docstring)."""
    work = Path(work)
    t0 = time.perf_counter()
    path = Path(record) if record else write_day_record(work / "day_100hz.csv", hours)
    written = time.perf_counter() - t0
    mapping = path.with_suffix(".toml")
    dt = 0.01
    player = _run(_PLAYER, str(path), str(mapping), "0", repr(dt))
    fmpy = _run(_FMPY, str(Path(fmu_dir) / "SensorRecording.fmu"), str(path), str(mapping), str(fmpy_steps), repr(dt))
    floor = fmi_floor(fmu_dir, work, path, fmpy_steps, dt)
    fmpy["share_of_floor"] = fmpy["steps_per_s"] / floor["steps_per_s"]
    out = {"record": {"hours": hours, "rows": player["rows"], "mb": path.stat().st_size / 1e6, "write_s": written},
           "in_process": player, "fmpy": fmpy, "fmi_floor": floor,
           "goal": {"max_rss_mb": GOAL_MB, "steps_per_s": GOAL_STEPS_S}}
    print(f"recording: {player['rows']:,} rows ({out['record']['mb']:.0f} MB CSV): opening scan {player['scan_s']:.0f} s; "
          f"in-process {player['steps_per_s']:,.0f} steps/s over {player['steps']:,} steps, peak RSS "
          f"{player['max_rss_mb']:.0f} MB; FMPy {fmpy['steps_per_s']:,.0f} steps/s over {fmpy['steps']:,} steps, peak RSS "
          f"{fmpy['max_rss_mb']:.0f} MB; an FMU that does nothing, same loop: {floor['steps_per_s']:,.0f} steps/s "
          f"(goal <= {GOAL_MB:.0f} MB, >= {GOAL_STEPS_S:,.0f} steps/s)", flush=True)
    return out
