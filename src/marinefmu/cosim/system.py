"""Fixed-step co-simulation master on FMPy's ``FMU2Slave``.

The master instantiates every component, applies its parameters, and steps on a base step h:
at base step k (t = t0 + k·h) every component with rate multiplier m and k mod m = 0 first
receives its inputs from the outputs all components held at t, then all of them step by m·h
(Jacobi coupling, as OSP libcosim's fixed-step algorithm does). Chosen variables are recorded
at every base step into a structured numpy array whose fields are ``component.variable``.

FMU logging is switched on and every message is collected (:attr:`SystemRunner.messages`) and
forwarded to the Python logger ``marinefmu.fmu``; a failing FMI call raises
:class:`~marinefmu.errors.SystemError_` naming the component, the time and its last
messages, and every instance is freed whatever happens.
"""
from __future__ import annotations

import logging
import math
import shutil
import tempfile
from collections.abc import Sequence
from ctypes import byref
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SystemError_
from .ssp import SystemDescription
from .system_check import check_system, lookup

log = logging.getLogger("marinefmu.fmu")
STATUS = ["OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"]


@dataclass(frozen=True)
class FmuMessage:
    """One message an FMU logged."""

    instance: str
    status: str
    category: str
    text: str


class _Instance:
    """One instantiated component: FMU2Slave plus name → (type, value reference) lookup."""

    def __init__(self, name: str, md: Any, unzip_dir: Path, callbacks: Any) -> None:
        from fmpy.fmi2 import FMU2Slave

        self.name = name
        self.md = md
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=str(unzip_dir),
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(loggingOn=True, callbacks=callbacks)
        self.instantiated = True
        self.fmu.setDebugLogging(True, [])

    def variable(self, var: str, causality: Sequence[str] | None = None):
        return lookup(self.md, self.name, var, None if causality is None else tuple(causality))

    def set_value(self, var: str, value: Any) -> None:
        """Set a parameter (already type-checked by :func:`check_system`)."""
        v = self.variable(var, ("parameter", "input"))
        kind = "Integer" if v.type == "Enumeration" else v.type
        cast = {"Real": float, "Integer": int, "Boolean": bool}.get(kind, str)
        _accessor(self.fmu, "set", kind)([v.valueReference], [cast(value)])


class SystemRunner:
    """Run a :class:`~marinefmu.cosim.ssp.SystemDescription` with FMPy.

    Parameters
    ----------
    system : SystemDescription
        Components, connections, base step.
    base_dir : str or Path
        Folder that relative component sources are resolved against.

    Examples
    --------
    >>> runner = SystemRunner(system, "fmus")                       # doctest: +SKIP
    >>> result = runner.run(60.0, record=["vessel.truth.cog.d"])    # doctest: +SKIP
    >>> result["vessel.truth.cog.d"]                                # doctest: +SKIP
    """

    def __init__(self, system: SystemDescription, base_dir: str | Path = ".") -> None:
        self.system = system
        self.base_dir = Path(base_dir)
        self.messages: list[FmuMessage] = []
        self.descriptions = check_system(system, self.base_dir)

    def _callbacks(self):
        from fmpy.fmi2 import (
            calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
            fmi2CallbackLoggerTYPE, free,
        )
        from fmpy.logging import addLoggerProxy

        def logger(component, instance, status, category, message):
            msg = FmuMessage(
                instance=instance.decode(errors="replace") if instance else "?",
                status=STATUS[status] if 0 <= status < len(STATUS) else str(status),
                category=category.decode(errors="replace") if category else "",
                text=message.decode(errors="replace") if message else "",
            )
            self.messages.append(msg)
            level = logging.ERROR if status >= 3 else logging.WARNING if status == 1 else logging.DEBUG
            log.log(level, "[%s] %s: %s", msg.status, msg.instance, msg.text)

        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(logger)
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        addLoggerProxy(byref(cb))
        return cb

    def _fail(self, inst: str, what: str, t: float, exc: Exception) -> SystemError_:
        recent = [m for m in self.messages if m.instance == inst][-5:]
        details = "".join(f"\n  [{m.status}] {m.text}" for m in recent)
        return SystemError_(f"{inst}: {what} failed at t = {t:.6g} s: {exc}{details}")

    def run(self, stop_time: float | None = None, record: Sequence[str] | None = None,
            progress: bool | None = None) -> np.ndarray:
        """Simulate from the system's start time to ``stop_time`` [s].

        Parameters
        ----------
        stop_time : float, optional
            End time [s]; default the system's stop time.
        record : sequence of str, optional
            ``component.variable`` names to record; default every real and boolean output.
        progress : bool, optional
            Show a progress bar (default: when the run has more than 2,000 base steps).

        Returns
        -------
        numpy.ndarray
            Structured array with a ``time`` field [s] and one field per recorded variable,
            one row per base step including the start.
        """
        from fmpy import extract
        from tqdm import tqdm

        sysd = self.system
        t0 = sysd.start_time
        stop = sysd.stop_time if stop_time is None else stop_time
        n_steps = int(math.floor((stop - t0) / sysd.step + 1e-9))
        if n_steps < 1:
            raise SystemError_(f"stop time {stop} s leaves no step of {sysd.step} s after start {t0} s")
        fields = self._record_fields(self.descriptions, record)  # refused before anything is instantiated
        callbacks = self._callbacks()
        tmp = Path(tempfile.mkdtemp(prefix="marinefmu_"))
        instances: dict[str, _Instance] = {}
        t = t0
        try:
            unzipped: dict[Path, Path] = {}
            for comp in sysd.components:
                src = comp.path(self.base_dir).resolve()
                if src not in unzipped:
                    unzipped[src] = Path(extract(str(src), unzipdir=str(tmp / f"{len(unzipped)}_{src.stem}")))
                instances[comp.name] = inst = _Instance(comp.name, self.descriptions[comp.name], unzipped[src], callbacks)
                inst.fmu.setupExperiment(startTime=t0)
                for name, value in comp.parameters.items():
                    inst.set_value(name, value)
            # wiring (checked by check_system before anything was instantiated)
            wires = []  # (end component, getter, source vr, setter, destination vr), resolved once
            for con in sysd.connections:
                a = instances[con.start].variable(con.start_var)
                b = instances[con.end].variable(con.end_var)
                wires.append((con.end, _accessor(instances[con.start].fmu, "get", a.type), [a.valueReference],
                              _accessor(instances[con.end].fmu, "set", b.type), [b.valueReference]))
            for name, inst in instances.items():
                logged = len(self.messages)
                try:
                    inst.fmu.enterInitializationMode()
                    inst.fmu.exitInitializationMode()
                except Exception as exc:  # FMPy raises FMICallException
                    raise self._fail(name, "initialisation", t0, exc) from None
                # marinefmu slaves refuse a parameter by logging an error (they never raise:
                # see marinefmu.cosim.slave), so an error logged here is a refusal
                refused = [m for m in self.messages[logged:] if m.instance == name and m.status in ("ERROR", "FATAL")]
                if refused:
                    raise self._fail(name, "initialisation", t0, RuntimeError(refused[0].text))
            out = np.zeros(n_steps + 1, dtype=[("time", "f8")] + [(f, "?" if k == "Boolean" else "f8") for f, (_, k, _) in fields.items()])
            getters = self._getters(instances, fields)
            rates = {c.name: c.rate for c in sysd.components}
            self._transfer(wires, set(instances))
            self._sample(out, 0, t0, getters)
            bar = tqdm(total=n_steps, unit="step", disable=not (progress if progress is not None else n_steps > 2000),
                       desc=sysd.name, mininterval=0.5)
            try:
                for k in range(n_steps):
                    t = t0 + k * sysd.step
                    due = {n for n, m in rates.items() if k % m == 0}
                    self._transfer(wires, due)
                    for name in due:
                        try:
                            instances[name].fmu.doStep(currentCommunicationPoint=t, communicationStepSize=rates[name] * sysd.step)
                        except Exception as exc:
                            raise self._fail(name, "doStep", t, exc) from None
                    self._sample(out, k + 1, t0 + (k + 1) * sysd.step, getters)
                    bar.update(1)
            finally:
                bar.close()
            for inst in instances.values():
                inst.fmu.terminate()
            return out
        finally:
            for inst in instances.values():
                try:
                    inst.fmu.freeInstance()
                except Exception:  # noqa: BLE001 - freeing must go on for the others
                    log.exception("freeing %s failed", inst.name)
            shutil.rmtree(tmp, ignore_errors=True)

    @staticmethod
    def _record_fields(mds: dict[str, Any], record: Sequence[str] | None) -> dict[str, tuple[str, str, int]]:
        fields: dict[str, tuple[str, str, int]] = {}
        if record is None:
            for name, md in mds.items():
                for v in md.modelVariables:
                    if v.causality == "output" and v.type in ("Real", "Boolean"):
                        fields[f"{name}.{v.name}"] = (name, v.type, v.valueReference)
            return fields
        for full in record:
            comp, _, var = full.partition(".")
            if comp not in mds:
                raise SystemError_(f"record {full!r}: unknown component {comp!r} (known: {', '.join(mds)})")
            v = lookup(mds[comp], comp, var)
            if v.type not in ("Real", "Boolean", "Integer"):
                raise SystemError_(f"record {full!r}: only Real, Integer and Boolean variables can be recorded")
            fields[full] = (comp, v.type, v.valueReference)
        return fields

    @staticmethod
    def _getters(instances, fields):
        groups: dict[tuple[str, str], tuple[list[int], list[str]]] = {}
        for f, (comp, kind, vr) in fields.items():
            vrs, names = groups.setdefault((comp, kind), ([], []))
            vrs.append(vr)
            names.append(f)
        result = []
        for (comp, kind), (vrs, names) in groups.items():
            result.append((_accessor(instances[comp].fmu, "get", kind), vrs, names))
        return result

    @staticmethod
    def _sample(out: np.ndarray, row: int, t: float, getters) -> None:
        out["time"][row] = t
        for get, vrs, names in getters:
            for name, value in zip(names, get(vrs)):
                out[name][row] = value

    @staticmethod
    def _transfer(wires, due: set[str]) -> None:
        # read every due input's source first, then set: all inputs see the outputs held at t
        values = [(set_, dst_vr, get(src_vr)) for end, get, src_vr, set_, dst_vr in wires if end in due]
        for set_, dst_vr, value in values:
            set_(dst_vr, value)


def _accessor(fmu: Any, op: str, kind: str):
    """The FMU2Slave method ``getReal``/``setBoolean``/… for a variable type."""
    return getattr(fmu, f"{op}{'Integer' if kind == 'Enumeration' else kind}")


def save_csv(result: np.ndarray, path: str | Path) -> Path:
    """Write a recorded result as CSV with a header of field names; return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    names = result.dtype.names
    cols = np.column_stack([result[n].astype(float) for n in names])
    np.savetxt(path, cols, delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    return path


def load_csv(path: str | Path) -> np.ndarray:
    """Read a CSV written by :func:`save_csv` back into a structured array."""
    return np.genfromtxt(path, delimiter=",", names=True, deletechars="", dtype=float)
