"""Every FMU runs in a Python made from nothing but the FMUs' own ``resources/requirements.txt``
and the two host tools, FMPy and libcosimpy (which are not the FMUs' requirements).

A fresh virtual environment (``python -m venv``: no path into the test environment, no
marinefmu) gets ``pip install -r`` of every FMU's requirements.txt extracted from the FMU (pip's
cache makes the second run quick), plus fmpy and libcosimpy. In it, in two processes at once:

- **FMPy** runs VesselMotion, then each other FMU fed with VesselMotion's signals
  (``fmu_worker``'s inputs and parameters) until its warm-up is over, all in one process as a
  host with several FMUs would: the specific force is g-level, every estimator is valid,
  outputs are finite and nothing is logged as an error;
- **libcosim** runs each FMU alone, inputs at their start values, for 10 s: outputs are finite
  and VesselMotion's vertical specific force is g-level.

Every ``marinefmu`` module in those processes comes from an extracted FMU. A slave whose
default parameters are refused (SensorRecording: no file to play back) is only instantiated
and initialised under FMPy, and loaded by libcosim.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from fmu_worker import FMUS, WARM_UP  # noqa: E402

pytestmark = [pytest.mark.fmu, pytest.mark.libcosim]
HOST_TOOLS = ["fmpy", "libcosimpy"]
PIP_TIMEOUT = 900.0     # s; from pip's cache about a minute on the 2-core CI machine
RUN_TIMEOUT = 600.0     # s; each worker takes well under a minute
G = 9.80665
#: pip's words when no package index can be reached: the test is skipped, not failed.
OFFLINE = ("NewConnectionError", "Failed to establish a new connection", "Temporary failure in name resolution",
           "Network is unreachable", "ConnectTimeoutError", "ReadTimeoutError")

WORKER = r'''
import importlib.util, json, math, sys
from pathlib import Path

mode, conformance, fmu_dir, work = sys.argv[1], sys.argv[2], Path(sys.argv[3]), Path(sys.argv[4])
names = sys.argv[5].split(",")
out = {"marinefmu_importable": importlib.util.find_spec("marinefmu") is not None, "python": sys.executable}
sys.path.insert(0, conformance)
import numpy as np
import fmu_worker as w


def ours():
    return {n: getattr(m, "__file__", None) for n, m in list(sys.modules.items())
            if n == "marinefmu" or n.startswith("marinefmu.")}


if mode == "fmpy":
    w.RECORD_STEPS = max(w.WARM_UP.values()) + 100
    out["record"] = w.case_record("VesselMotion", fmu_dir, work)
    data = np.load(work / "record.npz")
    rec, cols = data["values"], list(data["names"])
    out["acc_z_mean"] = float(rec[:, cols.index("imu.acc.z")].mean())
    out["acc_norm_mean"] = float(np.linalg.norm(rec[:, [cols.index(f"imu.acc.{a}") for a in "xyz"]], axis=1).mean())
    for name in names:
        if name == "VesselMotion":
            continue
        if name not in w.PARAMS:   # no known good parameters: instantiate, initialise, free
            inst = w.Instance(fmu_dir, name, work)
            inst.init({})
            inst.close()
            out[name] = {"initialised": True, "errors": [m for s, m in inst.messages if s >= 3]}
            continue
        inst, feed = w.start(name, fmu_dir, work)
        rows = np.array(w.advance(inst, feed, 0, w.WARM_UP[name] + 50))
        n = len(rows)
        # outputs with a truth of the same name: largest error over the last 50 steps, and the truth's range
        # (an output "<x>_used", the angle an estimator applied, against truth.<x>)
        truth = {}
        for i, o in enumerate(inst.output_names):
            key = o.removesuffix("_used")
            if f"truth.{key}" in cols:
                t = rec[n - 50:n, cols.index(f"truth.{key}")]
                truth[key] = (float(np.abs(rows[-50:, i] - t).max()), float(np.ptp(t)))
        out[name] = {"finite": bool(np.all(np.isfinite(rows))), "valid": inst.valid(), "steps": n,
                     "first_output": inst.output_names[0], "first_output_moves": bool(np.ptp(rows[-50:, 0]) > 0),
                     "truth": truth, "errors": [m for s, m in inst.messages if s >= 3]}
        inst.close()
else:
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave
    from fmpy import read_model_description

    log_output_level(CosimLogLevel.ERROR)
    # a libcosim execution deletes the folders it extracted its FMUs to when it is destroyed, and the
    # marinefmu every FMU in this process imports lies in the first one's: keep them all alive
    executions = []
    for name in names:
        path = str(fmu_dir / f"{name}.fmu")
        if name not in w.PARAMS:   # no known good parameters: loaded (instantiated) only
            ex = CosimExecution.from_step_size(step_size=round(w.DT * 1e9))
            executions.append(ex)
            out[name] = {"loaded": ex.add_local_slave(CosimLocalSlave(fmu_path=path, instance_name=name)) >= 0}
            continue
        md = read_model_description(path)
        reals = {v.name: v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == "Real"}
        ex = CosimExecution.from_step_size(step_size=round(w.DT * 1e9))
        executions.append(ex)
        index = ex.add_local_slave(CosimLocalSlave(fmu_path=path, instance_name=name))
        obs = CosimObserver.create_last_value()
        ex.add_observer(obs)
        ok = ex.simulate_until(round(200 * w.DT * 1e9))
        values = dict(zip(reals, obs.last_real_values(index, list(reals.values()))))
        out[name] = {"simulated": bool(ok), "finite": all(math.isfinite(x) for x in values.values()),
                     "outputs": len(values), "acc_z": values.get("imu.acc.z")}
out["unzipped"] = str(work)
out["marinefmu"] = ours()
print(json.dumps(out))
'''


def _requirements(fmu_dir: Path, dest: Path) -> list[Path]:
    """Each FMU's resources/requirements.txt, extracted to ``dest/<Model>.txt``."""
    files = []
    for fmu in sorted(fmu_dir.glob("*.fmu")):
        with zipfile.ZipFile(fmu) as z:
            (dest / f"{fmu.stem}.txt").write_bytes(z.read("resources/requirements.txt"))
        files.append(dest / f"{fmu.stem}.txt")
    return files


def _clean_env() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "PYTHONSTARTUP")}


@pytest.fixture(scope="module")
def requirements_venv(fmu_dir, tmp_path_factory) -> tuple[str, dict]:
    """A fresh virtual environment with the FMUs' requirements and the host tools; its python
    and the process environment to run it with."""
    where = tmp_path_factory.mktemp("requirements-venv")
    env = _clean_env()
    subprocess.run([sys.executable, "-m", "venv", str(where / "venv")], check=True, capture_output=True, env=env)
    python = str(where / "venv" / "bin" / "python")
    reqs = [a for f in _requirements(fmu_dir, where) for a in ("-r", str(f))]
    done = subprocess.run([python, "-m", "pip", "install", "--disable-pip-version-check", "--progress-bar", "off",
                           *reqs, *HOST_TOOLS], capture_output=True, text=True, env=env, timeout=PIP_TIMEOUT)
    if done.returncode != 0:
        if any(word in done.stdout + done.stderr for word in OFFLINE):
            pytest.skip(f"no package index reachable to install the FMUs' requirements:\n{done.stderr[-1500:]}")
        pytest.fail(f"pip install -r of the FMUs' requirements.txt failed:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}",
                    pytrace=False)
    return python, env


def _run(mode: str, python: str, env: dict, fmu_dir: Path, work: Path, names: list[str]) -> dict:
    work.mkdir()
    done = subprocess.run([python, "-c", WORKER, mode, str(HERE), str(fmu_dir), str(work), ",".join(names)],
                          capture_output=True, text=True, env=env, cwd=work, timeout=RUN_TIMEOUT)
    assert done.returncode == 0, f"{mode} worker: exit code {done.returncode}\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def runs(requirements_venv, fmu_dir, tmp_path_factory) -> dict[str, dict]:
    """The FMPy and the libcosim worker's results, run at once."""
    python, env = requirements_venv
    names = sorted(f.stem for f in fmu_dir.glob("*.fmu"))
    work = tmp_path_factory.mktemp("requirements-runs")
    with ThreadPoolExecutor(max_workers=2) as pool:
        futures = {mode: pool.submit(_run, mode, python, env, fmu_dir, work / mode, names) for mode in ("fmpy", "libcosim")}
        return {mode: f.result() for mode, f in futures.items()}


def test_the_environment_has_the_requirements_and_no_marinefmu(requirements_venv, fmu_dir):
    python, env = requirements_venv
    code = ("import importlib.metadata as m, importlib.util as u, json\n"
            "print(json.dumps({'marinefmu': u.find_spec('marinefmu') is not None,"
            " 'dists': sorted(d.metadata['Name'].lower() for d in m.distributions())}))")
    found = json.loads(subprocess.run([python, "-c", code], capture_output=True, text=True, env=env, check=True).stdout)
    assert not found["marinefmu"]
    assert {"numpy", "scipy", "filterpy", "control", "threadpoolctl", "fmpy", "libcosimpy"} <= set(found["dists"])
    assert "pythonfmu" not in found["dists"] and "marinefmu" not in found["dists"]


@pytest.mark.parametrize("engine", ["fmpy", "libcosim"])
def test_only_the_fmus_own_code_runs(runs, engine):
    r = runs[engine]
    assert not r["marinefmu_importable"] and "requirements-venv" in r["python"]
    files = list(r["marinefmu"].values())
    assert files and all(f and "/resources/marinefmu/" in f for f in files), r["marinefmu"]
    if engine == "fmpy":   # extracted by fmu_worker into the run's folder
        assert all(f.startswith(r["unzipped"]) for f in files), r["marinefmu"]


def test_vessel_motion_gives_g_level_specific_force_under_fmpy(runs):
    r = runs["fmpy"]
    assert r["record"]["finite"] and r["record"]["steps"] == max(WARM_UP.values()) + 100
    assert abs(r["acc_z_mean"] + G) < 0.05 * G, r["acc_z_mean"]      # a level sensor at rest reads -g
    assert abs(r["acc_norm_mean"] - G) < 0.05 * G, r["acc_norm_mean"]


@pytest.mark.parametrize("name", [n for n in FMUS if n != "VesselMotion"])
def test_each_estimator_fed_by_vessel_motion_is_valid_after_its_warm_up_under_fmpy(runs, name):
    r = runs["fmpy"][name]
    assert r["finite"] and r["valid"] and r["errors"] == [], r
    assert r["first_output_moves"], r     # its best estimate follows the sea


def test_an_fmu_without_known_parameters_is_instantiated_and_initialised(runs, fmu_dir):
    for name in sorted(f.stem for f in fmu_dir.glob("*.fmu") if f.stem not in FMUS):
        assert runs["fmpy"][name]["initialised"] and runs["libcosim"][name]["loaded"], (runs["fmpy"][name],
                                                                                      runs["libcosim"][name])


def test_every_fmu_runs_alone_under_libcosim(runs):
    r = runs["libcosim"]
    for name in FMUS:
        assert r[name]["simulated"] and r[name]["finite"] and r[name]["outputs"] >= 2, (name, r[name])
    assert abs(r["VesselMotion"]["acc_z"] + G) < 0.3 * G, r["VesselMotion"]   # one sample: g plus the wave's part


@pytest.mark.parametrize("name", ["AttitudeEstimator", "GnssAccFusion"])
def test_attitude_estimates_follow_the_truth_under_fmpy(runs, name):
    """Roll, pitch and yaw within 0.01 rad of VesselMotion's truth over the last 2.5 s (the sea
    pitches the vessel by some 0.015-0.03 rad peak to peak in that time)."""
    truth = runs["fmpy"][name]["truth"]
    for angle in ("roll", "pitch", "yaw"):
        assert truth[angle][0] < 0.01, (angle, truth)
