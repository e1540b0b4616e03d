"""One conformance case of one FMU, run in a fresh process (see ``test_conformance.py``).

Usage::

    python fmu_worker.py CASE FMU_NAME FMU_DIR WORK_DIR

(the ``exit_*`` cases take several names, comma-separated, as FMU_NAME)

prints one JSON object (the case's measurements) as the last line of stdout. The module needs
only FMPy, numpy and (for the libcosim cases) libcosimpy: it never imports ``marinefmu``, so the
same cases run from a virtual environment in which the source tree is not importable. Inputs
for the estimator FMUs come from a VesselMotion.fmu record made once by the ``record`` case.

Every estimator input ``X`` is fed from the VesselMotion output ``imu.X``, ``truth.X`` or ``X``
(the first that exists), so ``acc.x`` <- ``imu.acc.x``, ``roll`` <- ``truth.roll``,
``gnss.ant1.n`` <- ``gnss.ant1.n``.
"""
from __future__ import annotations

import json
import math
import re
import sys
import tempfile
from ctypes import byref
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy

DT = 0.05                  # s, communication step of every case (20 Hz)
RECORD_STEPS = 10600       # 530 s of VesselMotion output: 190 s warm-up + a 5-minute GNSS dropout + recovery
OK, WARNING, DISCARD, ERROR, FATAL = range(5)
FMUS = ("VesselMotion", "AttitudeEstimator", "DisplacementReconstructor", "GnssAccFusion", "CentreOfRotation",
        "HeaveObserver", "AhcWinch", "AhcController", "MotionReferenceUnit")
#: Inputs with no VesselMotion output of their name: (source output, offset added)
ALIASES = {"tip.n": ("truth.point.n", 0.0), "tip.e": ("truth.point.e", 0.0), "tip.d": ("truth.point.d", 0.0),
           "tip_vel.d": ("truth.point_vel.d", 0.0), "command": ("truth.point_vel.d", 0.0),
           "heave": ("truth.point.d", 10.0), "heave_rate": ("truth.point_vel.d", 0.0), "length": ("truth.point.d", 30.0),
           "heave_valid": ("gnss.valid", 0.0),   # a boolean input (true through the record)
           "heading": ("truth.yaw", 0.3), "heading.valid": ("gnss.valid", 0.0)}
VESSEL = {"sea.hs": 2.5, "sea.tp": 8.0, "gnss.rate": 5.0, "imu.x": 5.0, "imu.z": -3.0}
#: Parameters of each FMU for these cases: short windows so every estimator is valid within 70 s.
PARAMS = {
    "VesselMotion": VESSEL,
    "AttitudeEstimator": {"level_time": 2.0},
    "DisplacementReconstructor": {"window": 70.0, "hop": 5.0},
    "GnssAccFusion": {"acc_lever_arm.x": 5.0, "acc_lever_arm.z": -3.0},
    "CentreOfRotation": {},
    "HeaveObserver": {"window": 60.0},
    "AhcWinch": {},
    "AhcController": {},
    "MotionReferenceUnit": {"window": 45.0, "omega_min": 0.3, "mp1.enabled": True, "mp1.x": 20.0, "mp1.z": -5.0},
}
#: Steps until each FMU's outputs are valid with PARAMS (checked by the ``state`` case).
WARM_UP = {"VesselMotion": 1, "AttitudeEstimator": 100, "DisplacementReconstructor": 1500, "GnssAccFusion": 200,
           "CentreOfRotation": 200, "HeaveObserver": 1300, "AhcWinch": 1,
           "AhcController": 201,   # the feedforward fades in over engage_time = 10 s before valid
           "MotionReferenceUnit": 1320}  # levelling 10 s, the 45 s window, the third axis 10 s later
#: A refused parameter per FMU (logging-off case).
BAD_PARAMETER = {"VesselMotion": ("sea.hs", -1.0), "AttitudeEstimator": ("vel_sigma", -1.0),
                 "DisplacementReconstructor": ("window", 10.0), "GnssAccFusion": ("gate", 0.0),
                 "CentreOfRotation": ("hp_cutoff", 0.0), "HeaveObserver": ("max_modes", 0),
                 "AhcWinch": ("stiffness", 0.0), "AhcController": ("k_p", -1.0),
                 "MotionReferenceUnit": ("mp1.x", 250.0)}


_UNZIPPED: dict[str, Path] = {}


def _status(exc: FMICallException) -> int:
    found = re.search(r"status (\d+)", str(exc))
    return int(found.group(1)) if found else -1


class Instance:
    """One FMU instance under FMPy, with its log messages collected in :attr:`messages`."""

    def __init__(self, fmu_dir: Path, name: str, work: Path, instance: str = "a", logging: bool = True) -> None:
        path = Path(fmu_dir) / f"{name}.fmu"
        self.name = name
        self.md = read_model_description(str(path))
        self.var = {v.name: v for v in self.md.modelVariables}
        if name not in _UNZIPPED:  # once per process: the instances of an FMU share it, as in a tool
            _UNZIPPED[name] = Path(tempfile.mkdtemp(prefix=f"{name}-", dir=work))
            extract(str(path), unzipdir=str(_UNZIPPED[name]))
        unzip = _UNZIPPED[name]
        self.messages: list[tuple[int, str]] = []
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        addLoggerProxy(byref(self._callbacks))
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=str(unzip),
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance)
        self.fmu.instantiate(loggingOn=logging, callbacks=self._callbacks)
        if logging:
            self.fmu.setDebugLogging(True, [])
        variables = self.md.modelVariables
        self.real_inputs = [v for v in variables if v.causality == "input" and v.type == "Real"]
        self.bool_inputs = [v for v in variables if v.causality == "input" and v.type == "Boolean"]
        self.real_outputs = [v for v in variables if v.causality == "output" and v.type == "Real"]
        self.int_outputs = [v for v in variables if v.causality == "output" and v.type == "Integer"]
        self.bool_outputs = [v for v in variables if v.causality == "output" and v.type == "Boolean"]
        self.output_names = [v.name for v in (*self.real_outputs, *self.int_outputs, *self.bool_outputs)]

    def _log(self, env, instance, status, category, message) -> None:
        self.messages.append((int(status), message.decode(errors="replace") if message else ""))

    def init(self, params: dict) -> None:
        self.fmu.setupExperiment(startTime=0.0)
        for key, value in params.items():
            v = self.var[key]
            setter = {"Real": self.fmu.setReal, "Integer": self.fmu.setInteger, "Boolean": self.fmu.setBoolean,
                      "String": self.fmu.setString}[v.type]
            setter([v.valueReference], [value])
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def set_inputs(self, reals: dict[str, float], booleans: dict[str, bool] | None = None) -> None:
        if reals:
            self.fmu.setReal([self.var[n].valueReference for n in reals], list(reals.values()))
        if booleans:
            self.fmu.setBoolean([self.var[n].valueReference for n in booleans], list(booleans.values()))

    def step(self, t: float, h: float) -> int:
        """doStep; the FMI status (0 OK ... 4 Fatal)."""
        try:
            self.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        except FMICallException as exc:
            return _status(exc)
        return OK

    def outputs(self) -> list[float]:
        """Every output (real, integer, boolean as 0/1), in :attr:`output_names` order."""
        vals = list(self.fmu.getReal([v.valueReference for v in self.real_outputs])) if self.real_outputs else []
        if self.int_outputs:
            vals += [float(x) for x in self.fmu.getInteger([v.valueReference for v in self.int_outputs])]
        if self.bool_outputs:
            vals += [float(bool(x)) for x in self.fmu.getBoolean([v.valueReference for v in self.bool_outputs])]
        return vals

    def valid(self) -> bool:
        return bool(self.fmu.getBoolean([self.var["valid"].valueReference])[0]) if "valid" in self.var else True

    def close(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


class Feed:
    """Inputs of an FMU at step k from the VesselMotion record."""

    def __init__(self, inst: Instance, work: Path) -> None:
        data = np.load(Path(work) / "record.npz")
        names = list(data["names"])
        rec = data["values"]

        def source(n: str) -> np.ndarray:
            if n in ALIASES:
                out, offset = ALIASES[n]
                return rec[:, names.index(out)] + offset
            for cand in (f"imu.{n}", f"truth.{n}", n):
                if cand in names:
                    return rec[:, names.index(cand)]
            raise KeyError(f"{inst.name}: no VesselMotion output for input {n}")

        self.real = {v.name: source(v.name) for v in inst.real_inputs}
        self.bool = {v.name: source(v.name) > 0.5 for v in inst.bool_inputs}
        self.truth_cog = rec[:, [names.index(f"truth.cog.{a}") for a in "ned"]]

    def at(self, k: int) -> tuple[dict[str, float], dict[str, bool]]:
        return ({n: float(x[k]) for n, x in self.real.items()}, {n: bool(x[k]) for n, x in self.bool.items()})


def start(name: str, fmu_dir: Path, work: Path, instance: str = "a", params: dict | None = None,
          logging: bool = True) -> tuple[Instance, Feed | None]:
    inst = Instance(fmu_dir, name, work, instance, logging)
    inst.init(PARAMS[name] if params is None else params)
    return inst, (Feed(inst, work) if inst.real_inputs or inst.bool_inputs else None)


def advance(inst: Instance, feed: Feed | None, k0: int, k1: int, shift: int = 0) -> list[list[float]]:
    """Steps k0..k1-1 fed from the record (shifted by ``shift`` steps); the outputs of each."""
    out = []
    for k in range(k0, k1):
        if feed is not None:
            inst.set_inputs(*feed.at(k + shift))
        status = inst.step(k * DT, DT)
        if status != OK:
            raise RuntimeError(f"{inst.name}: doStep at step {k} returned status {status}: {inst.messages[-3:]}")
        out.append(inst.outputs())
    return out


def same(a, b) -> bool:
    """Bit-identical, NaN equal to NaN."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a.shape == b.shape and bool(np.all((a == b) | (np.isnan(a) & np.isnan(b))))


# --- cases ------------------------------------------------------------------------------------

def case_record(name: str, fmu_dir: Path, work: Path) -> dict:
    """Run VesselMotion.fmu and save every output (the inputs of the other cases)."""
    inst, _ = start("VesselMotion", fmu_dir, work)
    values = np.array(advance(inst, None, 0, RECORD_STEPS))
    inst.close()
    np.savez(Path(work) / "record.npz", names=np.array(inst.output_names), values=values)
    return {"steps": len(values), "finite": bool(np.all(np.isfinite(values)))}


def case_two_instances(name: str, fmu_dir: Path, work: Path) -> dict:
    """Outputs of one instance alone vs. the same instance stepped alongside a second one that
    has different inputs (or, for VesselMotion, a different sea), past the warm-up."""
    n = WARM_UP[name] + 100
    alone_inst, feed = start(name, fmu_dir, work, "alone")
    alone = advance(alone_inst, feed, 0, n)
    alone_inst.close()
    a, feed = start(name, fmu_dir, work, "a")
    other = {**PARAMS[name], "sea.seed": 7, "sea.hs": 4.0} if name == "VesselMotion" else PARAMS[name]
    b, _ = start(name, fmu_dir, work, "b", params=other)
    paired, b_out = [], []
    for k in range(n):
        paired += advance(a, feed, k, k + 1)
        b_out += advance(b, feed, k, k + 1, shift=1000)
    a.close()
    b.close()
    return {"identical": same(alone, paired), "other_differs": not same(alone, b_out), "steps": n}


def case_reset(name: str, fmu_dir: Path, work: Path) -> dict:
    """Run, reset and rerun; then free, instantiate again and rerun."""
    n = 300
    inst, feed = start(name, fmu_dir, work)
    first = advance(inst, feed, 0, n)
    inst.fmu.reset()
    inst.init(PARAMS[name])
    after_reset = advance(inst, feed, 0, n)
    inst.close()
    again, feed = start(name, fmu_dir, work)
    after_new = advance(again, feed, 0, n)
    again.close()
    return {"reset_identical": same(first, after_reset), "reinstantiate_identical": same(first, after_new), "steps": n}


def case_state(name: str, fmu_dir: Path, work: Path) -> dict:
    """Save at k1 (after the outputs are valid), run to k2, restore, rerun: identical outputs;
    the serialized state restored into a fresh instance gives the same outputs again."""
    k1 = WARM_UP[name] + 20
    k2 = k1 + 200
    inst, feed = start(name, fmu_dir, work)
    advance(inst, feed, 0, k1)
    valid_at_save = inst.valid()
    state = inst.fmu.getFMUstate()
    blob = inst.fmu.serializeFMUstate(state)
    first = advance(inst, feed, k1, k2)
    inst.fmu.setFMUstate(state)
    inst.fmu.freeFMUstate(state)
    rerun = advance(inst, feed, k1, k2)
    inst.close()
    fresh, feed = start(name, fmu_dir, work, "fresh")
    restored = fresh.fmu.deSerializeFMUstate(blob)
    fresh.fmu.setFMUstate(restored)
    fresh.fmu.freeFMUstate(restored)
    from_blob = advance(fresh, feed, k1, k2)
    fresh.close()
    cs = inst.md.coSimulation
    return {"can_get_set": bool(cs.canGetAndSetFMUstate), "can_serialize": bool(cs.canSerializeFMUstate),
            "valid_at_save": valid_at_save, "restore_identical": same(first, rerun),
            "deserialize_identical": same(first, from_blob), "state_bytes": len(blob),
            # outputs that moved between k1 and k2: a restore of outputs alone could not repeat them
            "outputs_moving": int(np.sum(np.ptp(np.asarray(first), axis=0) > 0)), "real_outputs": len(inst.real_outputs)}


#: Settings under which the faults case tries an FMU, each with the inputs it leaves unread
#: (default: PARAMS, every input read). CentreOfRotation ignores its angle inputs unless angles =
#: input; GnssAccFusion reads them only with attitude = input, and then antenna 1 alone: it is
#: tried both ways.
FAULT_RUNS = {"CentreOfRotation": [({"angles": "input"}, ())],
              "GnssAccFusion": [({}, ("roll", "pitch", "yaw")),
                                ({"attitude": "input", "attitude_lag": DT}, ("gnss.ant2.", "gnss.ant3.", "gnss.ant4."))]}
BAD_VALUES = {"nan": math.nan, "inf": math.inf, "-inf": -math.inf, "1e12": 1e12}
INJECT_EVERY = 40  # steps between two bad samples (2 s)


def case_faults(name: str, fmu_dir: Path, work: Path) -> dict:
    """For each bad value: after warm-up, one bad sample on each real input in turn, 2 s apart.
    Per injection: the step status, ``valid`` on that step, whether a warning was logged, and
    whether the output recovered (valid again) before the next injection."""
    report: dict[str, dict] = {label: {"finite": True, "rows": []} for label in BAD_VALUES}
    for run, (extra, unread) in enumerate(FAULT_RUNS.get(name, [({}, ())])):
        for label, bad in BAD_VALUES.items():
            _faults(name, fmu_dir, work, f"f{run}{label}", {**PARAMS[name], **extra}, unread, bad, report[label])
    return report


def _faults(name: str, fmu_dir: Path, work: Path, instance: str, params: dict, unread: tuple, bad: float,
            report: dict) -> None:
    """:func:`case_faults` for one setting and one bad value: its rows added to ``report``."""
    inst, feed = start(name, fmu_dir, work, instance, params)
    k = WARM_UP[name]
    advance(inst, feed, 0, k)
    for v in inst.real_inputs:
        if unread and v.name.startswith(unread):
            continue
        if v.name.startswith("gnss."):  # antenna positions are a sample only on a new epoch
            while not feed.bool["gnss.new"][k]:
                advance(inst, feed, k, k + 1)
                k += 1
        reals, bools = feed.at(k)
        reals[v.name] = bad
        inst.set_inputs(reals, bools)
        seen = len(inst.messages)
        status = inst.step(k * DT, DT)
        out = inst.outputs()
        warned = any(s == WARNING for s, _ in inst.messages[seen:])
        row = {"input": v.name, "status": status, "valid": inst.valid(), "warned": warned}
        report["finite"] &= bool(np.all(np.isfinite(out)))
        after = advance(inst, feed, k + 1, k + INJECT_EVERY)
        report["finite"] &= bool(np.all(np.isfinite(after)))
        row["recovered"] = inst.valid()
        report["rows"].append(row)
        k += INJECT_EVERY
    inst.close()


def case_zero_hour(name: str, fmu_dir: Path, work: Path) -> dict:
    """An hour of constant zero on every input (0.5 s steps)."""
    inst, _ = start(name, fmu_dir, work)
    h, n = 0.5, 7200
    statuses, finite = set(), True
    zeros = {v.name: 0.0 for v in inst.real_inputs}
    falses = {v.name: False for v in inst.bool_inputs}
    for k in range(n):
        inst.set_inputs(zeros, falses)
        statuses.add(inst.step(k * h, h))
        finite &= bool(np.all(np.isfinite(inst.outputs())))
    inst.close()
    return {"statuses": sorted(statuses), "finite": finite, "seconds": n * h,
            "warnings": sum(s == WARNING for s, _ in inst.messages)}


def _gnss_disturbance(name: str, fmu_dir: Path, work: Path, start_k: int, steps: int, jump_n: float) -> dict:
    """Fusion fed from the record, with GNSS invalid (jump_n = 0) or moved north by jump_n m
    for ``steps`` steps from ``start_k``; position errors against the truth COG."""
    inst, feed = start(name, fmu_dir, work)
    pos = [inst.var[f"pos.{a}"].valueReference for a in "ned"]
    errs, valid, statuses, finite = [], [], set(), True
    for k in range(start_k + steps + 600):
        reals, bools = feed.at(k)
        if start_k <= k < start_k + steps:
            if jump_n:
                for i in range(1, 5):
                    reals[f"gnss.ant{i}.n"] += jump_n
            else:
                bools = {n: False for n in bools}
        inst.set_inputs(reals, bools)
        statuses.add(inst.step(k * DT, DT))
        out = inst.outputs()
        finite &= bool(np.all(np.isfinite(out)))
        errs.append(np.abs(np.array(inst.fmu.getReal(pos)) - feed.truth_cog[k]).max())
        valid.append(inst.valid())
    inst.close()
    errs, valid = np.array(errs), np.array(valid)
    during = slice(start_k, start_k + steps)
    back = np.flatnonzero(valid[start_k + steps:])
    return {"statuses": sorted(statuses), "finite": finite, "max_error_during": float(errs[during].max()),
            "max_error_after_10s": float(errs[start_k + steps + 200:].max()),
            "valid_false_during": bool(not valid[during].all()), "valid_before": bool(valid[start_k - 1]),
            "valid_again_after_s": float(back[0] * DT) if back.size else None,
            "warnings": [m for s, m in inst.messages if s == WARNING][:4]}


def case_gnss_dropout(name: str, fmu_dir: Path, work: Path) -> dict:
    """A 5-minute GNSS dropout (gnss.valid false) 190 s into the run (the wave coast is ready:
    its spectrum window, wave_coast.SPECTRUM_WINDOW, is 180 s)."""
    return _gnss_disturbance(name, fmu_dir, work, 3800, 6000, 0.0)


def case_gnss_jump(name: str, fmu_dir: Path, work: Path) -> dict:
    """A 65 m jump north of every antenna for 20 s, 190 s into the run (the wave coast is
    ready, as for the dropout)."""
    return _gnss_disturbance(name, fmu_dir, work, 3800, 400, 65.0)


def case_step_sizes(name: str, fmu_dir: Path, work: Path) -> dict:
    """Zero and negative steps (refused: Discard, a logged message, nothing changed), then tiny
    (1e-6 s), large (10 s) and varying steps (accepted, finite outputs)."""
    k = 100
    ref, feed = start(name, fmu_dir, work, "ref")
    reference = advance(ref, feed, 0, k + 20)
    ref.close()
    inst, feed = start(name, fmu_dir, work)
    advance(inst, feed, 0, k)
    before = inst.outputs()
    refused = {}
    for label, h in (("zero", 0.0), ("negative", -DT), ("nan", math.nan)):
        seen = len(inst.messages)
        status = inst.step(k * DT, h)
        logged = [m for _, m in inst.messages[seen:]]
        refused[label] = {"status": status, "logged": logged[:1], "unchanged": same(inst.outputs(), before)}
    continued = advance(inst, feed, k, k + 20)
    result = {"refused": refused, "continues_identically": same(continued, reference[k:k + 20])}
    t = (k + 20) * DT
    rng = np.random.default_rng(8)
    checks = {"tiny": [1e-6] * 20, "large": [10.0] * 6, "varying": list(rng.uniform(1e-3, 0.3, 200))}
    for label, steps in checks.items():
        statuses, finite = set(), True
        for j, h in enumerate(steps):
            if feed is not None:
                inst.set_inputs(*feed.at(k + 20 + j))
            statuses.add(inst.step(t, h))
            finite &= bool(np.all(np.isfinite(inst.outputs())))
            t += h
        result[label] = {"statuses": sorted(statuses), "finite": finite}
    inst.close()
    return result


def case_quaternion_norm(name: str, fmu_dir: Path, work: Path) -> dict:
    """10⁶ steps of gyro-only integration (mode 0) of a constant tumble (0.3, -0.2, 0.5 rad/s,
    ~16 000 turns in 10⁴ s): the largest deviation of |q| from 1, read every 10⁵ steps."""
    inst = Instance(fmu_dir, name, work)
    inst.init({"mode": 0, "init": "given"})
    inst.set_inputs({"gyro.x": 0.3, "gyro.y": -0.2, "gyro.z": 0.5, "acc.x": 0.0, "acc.y": 0.0, "acc.z": -9.80665})
    q_refs = [inst.var[f"q.{c}"].valueReference for c in "wxyz"]
    worst, statuses, steps = 0.0, set(), 1_000_000
    for k in range(steps):
        statuses.add(inst.step(k * 0.01, 0.01))
        if (k + 1) % 100_000 == 0:
            worst = max(worst, abs(math.sqrt(sum(c * c for c in inst.fmu.getReal(q_refs))) - 1.0))
    inst.close()
    return {"steps": steps, "statuses": sorted(statuses), "max_norm_error": worst}


def case_many_instances(name: str, fmu_dir: Path, work: Path) -> dict:
    """30 instantiate / initialise / 5 steps / free cycles in one process: every step OK, one
    slave class alive (pythonfmu runs the model script again per instance), no repeated
    ``sys.path`` entries."""
    import gc

    statuses = set()
    for c in range(30):
        inst, feed = start(name, fmu_dir, work, f"m{c}")
        for k in range(5):
            if feed is not None:
                inst.set_inputs(*feed.at(k))
            statuses.add(inst.step(k * DT, DT))
        inst.close()
    gc.collect()
    classes = [o for o in gc.get_objects() if isinstance(o, type) and o.__name__ == name and o.__module__ == name]
    return {"statuses": sorted(statuses), "slave_classes": len(classes),
            "repeated_sys_path": len(sys.path) - len(set(sys.path))}


def case_logging_off(name: str, fmu_dir: Path, work: Path) -> dict:
    """With logging off: a refused parameter and a zero step still return a non-OK status."""
    key, value = BAD_PARAMETER[name]
    bad = Instance(fmu_dir, name, work, "bad", logging=False)
    bad.init({**PARAMS[name], key: value})
    refused_status = bad.step(0.0, DT)
    bad.close()
    good, _ = start(name, fmu_dir, work, logging=False)
    zero_status = good.step(0.0, 0.0)
    good.close()
    return {"refused_parameter_status": refused_status, "zero_step_status": zero_status}


EXIT_STEPS = 100   # steps of each instance in the exit cases, outputs read after each


def _exit_run(names: list[str], fmu_dir: Path, work: Path, instance: str) -> tuple[list[Instance], list[int]]:
    """One instance of each FMU in ``names``, inputs at their start values, EXIT_STEPS steps with
    every output read after each; the instances and the statuses seen."""
    insts = []
    for n in names:
        inst = Instance(fmu_dir, n, work, instance)
        inst.init(PARAMS[n])
        insts.append(inst)
    statuses = set()
    for k in range(EXIT_STEPS):
        for inst in insts:
            statuses.add(inst.step(k * DT, DT))
            inst.outputs()
    return insts, sorted(statuses)


def _exit_state() -> dict:
    """FMU library copies mapped in this process and those whose exit guard is armed
    (``marinefmu.fmu.host_exit`` as bundled in the FMUs; None if no FMU has loaded it)."""
    with open("/proc/self/maps") as maps:
        mapped = {line.split()[-1] for line in maps if "/binaries/linux64/" in line}
    guard = sys.modules.get("marinefmu.fmu.host_exit")
    return {"libraries": len(mapped), "guarded": guard.guarded() if guard is not None else None}


def case_exit_mixed(name: str, fmu_dir: Path, work: Path) -> dict:
    """The FMUs named (comma-separated) each with one instance freed and one left alive, then a
    normal exit: the test asserts exit code 0 (the exit-time clean-up is the case)."""
    names = name.split(",")
    freed, statuses = _exit_run(names, fmu_dir, work, "freed")
    alive, more = _exit_run(names, fmu_dir, work, "alive")
    for inst in freed:
        inst.close()
    return {"statuses": sorted({*statuses, *more}), **_exit_state()}


def case_exit_kept(name: str, fmu_dir: Path, work: Path) -> dict:
    """The FMUs named, none freed, then a normal exit."""
    _, statuses = _exit_run(name.split(","), fmu_dir, work, "kept")
    return {"statuses": statuses, **_exit_state()}


def case_exit_reloaded(name: str, fmu_dir: Path, work: Path) -> dict:
    """The FMUs named, all freed (FMPy unloads every library copy it can), then all instantiated
    again from the same folders and left alive at exit: the reloaded copies are guarded again."""
    names = name.split(",")
    first, statuses = _exit_run(names, fmu_dir, work, "first")
    at_first = _exit_state()
    for inst in first:
        inst.close()
    after_free = _exit_state()
    _, more = _exit_run(names, fmu_dir, work, "again")
    return {"statuses": sorted({*statuses, *more}), "first": at_first, "after_free": after_free, **_exit_state()}


CASES = {n[5:]: f for n, f in globals().items() if n.startswith("case_")}

if __name__ == "__main__":
    case, fmu_name, fmu_dir, work_dir = sys.argv[1:5]
    result = CASES[case](fmu_name, Path(fmu_dir), Path(work_dir))
    sys.stdout.flush()
    print("\n" + json.dumps(result), flush=True)
