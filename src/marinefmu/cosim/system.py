"""Fixed-step co-simulation master: FMUs through FMPy, or the same slaves in-process.

The master instantiates every component, applies its parameters, and steps on a base step h:
at base step k (t = t0 + k·h) every component with rate multiplier m and k mod m = 0 first
receives its inputs from the outputs all components held at t, then all of them step by m·h
(Jacobi coupling, as OSP libcosim's fixed-step algorithm does). Chosen variables are recorded
at every base step into a structured numpy array whose fields are ``component.variable``, in
memory or streamed to a ``.npy`` file in chunks (``out_file``) for long runs.
After each base step every wired or recorded output is read once, and the row and the next
step's inputs are taken from that read (:mod:`~.exchange`).

Two engines run the same system the same way:

- ``engine="fmpy"`` (default): every FMU through FMPy's ``FMU2Slave`` (the FMI 2.0 C API).
- ``engine="python"``: the slave class of each FMU (the pythonfmu script in its
  ``resources/``) instantiated directly in this interpreter and called without FMI: no
  ctypes, no C++ loader. Same code, same results (bit for bit, tested); the bench compares the
  two to measure what FMI costs.

FMU logging is switched on and every message is collected (:attr:`SystemRunner.messages`) and
forwarded to the Python logger ``marinefmu.fmu``; a failing FMI call raises
:class:`~marinefmu.errors.SystemError_` naming the component, the time and its last
messages, and every instance is freed whatever happens. The system is checked against the
FMUs' model descriptions before anything is instantiated
(:func:`~marinefmu.cosim.system_check.check_system`).
"""
from __future__ import annotations

import importlib.util
import itertools
import logging
import math
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from ctypes import byref
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import SystemError_
from .exchange import PY_TYPES, STATUS, Exchange, ExchangeError, Port, fmpy_channel, slave_channel
from .ssp import SystemDescription
from .system_check import check_system, lookup

log = logging.getLogger("marinefmu.fmu")
ENGINES = ("fmpy", "python")
#: Rows of a result kept in memory before they are written out (``out_file``).
CHUNK_ROWS = 8192
#: Steps between two checks of a run's wall-time limit (``SystemRunner.run(timeout=…)``).
TIMEOUT_CHECK = 100


@dataclass(frozen=True)
class FmuMessage:
    """One message an FMU logged."""

    instance: str
    status: str
    category: str
    text: str


def _fmi_type(kind: str) -> str:
    return "Integer" if kind == "Enumeration" else kind


class _FmpyComponent:
    """One component as an FMU through FMPy's ``FMU2Slave``; messages arrive by callback."""

    def __init__(self, name: str, md: Any, unzip_dir: Path, callbacks: Any) -> None:
        from fmpy.fmi2 import FMU2Slave

        self.name, self.md = name, md
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=str(unzip_dir),
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.fmu.instantiate(loggingOn=True, callbacks=callbacks)
        self.fmu.setDebugLogging(True, [])

    def accessor(self, op: str, kind: str) -> Callable:
        """``getReal``/``setBoolean``/… of the FMU for a variable type."""
        return getattr(self.fmu, f"{op}{_fmi_type(kind)}")

    def channel(self, op: str, kind: str, vrs: Sequence[int]):
        """Buffer and call of the run's exchange (:func:`~.exchange.fmpy_channel`)."""
        return fmpy_channel(self.fmu, op, kind, vrs)

    def setup(self, t0: float) -> None:
        self.fmu.setupExperiment(startTime=t0)

    def initialise(self) -> None:
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()

    def do_step(self, t: float, h: float) -> None:
        self.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)

    def terminate(self) -> None:
        self.fmu.terminate()

    def free(self) -> None:
        self.fmu.freeInstance()


class _PythonComponent:
    """One component as its pythonfmu slave class, run in this interpreter without FMI.

    The slave script is the one packed in the FMU (``resources/<model>.py``), imported under a
    module name unique to the instance; its messages are taken from the slave's log queue after
    every call, as pythonfmu's C++ side does."""

    _count = itertools.count()

    def __init__(self, name: str, md: Any, unzip_dir: Path, messages: list[FmuMessage]) -> None:
        self.name, self.md, self.messages = name, md, messages
        model = md.coSimulation.modelIdentifier
        resources = Path(unzip_dir) / "resources"
        spec = importlib.util.spec_from_file_location(f"_marinefmu_in_process_{model}_{next(self._count)}",
                                                      resources / f"{model}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        self.slave = getattr(module, model)(instance_name=name, resources=str(resources), visible=False)

    def _drain(self) -> None:
        queue = self.slave.log_queue
        for m in queue:
            msg = FmuMessage(self.name, m.status.name.upper(), m.category or "", m.msg)
            self.messages.append(msg)
            level = logging.ERROR if msg.status in ("ERROR", "FATAL") else logging.WARNING if msg.status == "WARNING" else logging.DEBUG
            log.log(level, "[%s] %s: %s", msg.status, msg.instance, msg.text)
        queue.clear()

    def accessor(self, op: str, kind: str) -> Callable:
        """``get_real``/``set_boolean``/… of the slave for a variable type."""
        return getattr(self.slave, f"{op}_{_fmi_type(kind).lower()}")

    def channel(self, op: str, kind: str, vrs: Sequence[int]):
        """Buffer and call of the run's exchange (:func:`~.exchange.slave_channel`)."""
        return slave_channel(self.slave, op, kind, vrs)

    def setup(self, t0: float) -> None:
        self.slave.setup_experiment(t0, None, None)

    def initialise(self) -> None:
        self.slave.enter_initialization_mode()
        self.slave.exit_initialization_mode()
        self._drain()

    def do_step(self, t: float, h: float) -> None:
        ok = self.slave.do_step(t, h)
        if self.slave.log_queue:
            self._drain()
        if not ok:
            raise RuntimeError("doStep returned fmi2Discard")

    def terminate(self) -> None:
        self.slave.terminate()
        self._drain()

    def free(self) -> None:
        self.slave = None


class _Recorder:
    """Rows of a result, filled as plain floats (fast) and handed out as a structured array:
    in memory, or written to a ``.npy`` file in chunks of :data:`CHUNK_ROWS` rows, so memory
    stays flat however long the run."""

    def __init__(self, dtype: np.dtype, rows: int, out_file: str | Path | None) -> None:
        self.dtype, self.rows = dtype, rows
        self.path = None if out_file is None else Path(out_file)
        self.buf = np.zeros((rows if self.path is None else min(rows, CHUNK_ROWS), len(dtype.names)))
        if self.path is not None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.fh = open(self.path, "wb")
            np.lib.format.write_array_header_1_0(self.fh, {"descr": np.lib.format.dtype_to_descr(dtype),
                                                           "fortran_order": False, "shape": (rows,)})
        self.filled = 0   # rows of buf in use

    def column(self, name: str) -> int:
        """Index of a field in the rows handed out by :meth:`row`."""
        return self.dtype.names.index(name)

    def row(self) -> np.ndarray:
        """The next row to fill (a float view, one column per field)."""
        if self.filled == len(self.buf):
            self._flush()
        self.filled += 1
        return self.buf[self.filled - 1]

    def _structured(self) -> np.ndarray:
        out = np.empty(self.filled, dtype=self.dtype)
        for j, name in enumerate(self.dtype.names):
            out[name] = self.buf[:self.filled, j]
        return out

    def _flush(self) -> None:
        self.fh.write(self._structured().tobytes())
        self.filled = 0

    def finish(self) -> np.ndarray:
        """The result: the array, or the file opened read-only as a memory map."""
        if self.path is None:
            return self._structured()
        self._flush()
        self.fh.close()
        return np.load(self.path, mmap_mode="r")

    def close(self) -> None:
        if self.path is not None and not self.fh.closed:
            self.fh.close()


def _forget_paths(root: str) -> None:
    """Drop the ``sys.path`` entries (and their importer cache) under ``root``: pythonfmu's loader
    puts each instance's resources folder on ``sys.path`` and never takes it off, so a process
    running system after system (a campaign worker) would gain six entries a run, each a folder
    already deleted, and every later import would search them all."""
    inside = root.rstrip(os.sep) + os.sep
    sys.path[:] = [p for p in sys.path if not p.startswith(inside)]
    for key in [k for k in sys.path_importer_cache if k.startswith(inside)]:
        del sys.path_importer_cache[key]


class SystemRunner:
    """Run a :class:`~marinefmu.cosim.ssp.SystemDescription` with FMPy or in-process.

    Parameters
    ----------
    system : SystemDescription
        Components, connections, base step.
    base_dir : str or Path
        Folder that relative component sources are resolved against.
    engine : {"fmpy", "python"}
        FMUs through FMI with FMPy, or their slave classes in this interpreter (module
        docstring).
    unpacked : mapping of Path to Path, optional
        FMU file → folder it is already extracted in (``fmpy.extract``), used as it is and
        kept; other FMUs are extracted into a temporary folder for each run. A process that
        runs many systems (a campaign worker) extracts each FMU once.

    Examples
    --------
    >>> runner = SystemRunner(system, "fmus")                       # doctest: +SKIP
    >>> result = runner.run(60.0, record=["vessel.truth.cog.d"])    # doctest: +SKIP
    >>> result["vessel.truth.cog.d"]                                # doctest: +SKIP
    """

    def __init__(self, system: SystemDescription, base_dir: str | Path = ".", engine: str = "fmpy",
                 unpacked: Mapping[Path, Path] | None = None) -> None:
        if engine not in ENGINES:
            raise SystemError_(f"engine = {engine!r} is not allowed: must be one of {', '.join(map(repr, ENGINES))}")
        self.system = system
        self.base_dir = Path(base_dir)
        self.engine = engine
        self.messages: list[FmuMessage] = []
        self.descriptions = check_system(system, self.base_dir)
        #: FMU file (resolved) → folder it is already extracted in: used as it is and kept.
        self.unpacked = {Path(k).resolve(): Path(v) for k, v in (unpacked or {}).items()}
        #: Wall time [s] each component spent in its steps during the last run.
        self.step_seconds: dict[str, float] = {}

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

    def _instantiate(self, comp: Any, unzip_dir: Path, callbacks: Any):
        md = self.descriptions[comp.name]
        if self.engine == "python":
            return _PythonComponent(comp.name, md, unzip_dir, self.messages)
        return _FmpyComponent(comp.name, md, unzip_dir, callbacks)

    def run(self, stop_time: float | None = None, record: Sequence[str] | None = None,
            progress: bool | None = None, out_file: str | Path | None = None,
            timeout: float | None = None) -> np.ndarray:
        """Simulate from the system's start time to ``stop_time`` [s].

        Parameters
        ----------
        stop_time : float, optional
            End time [s]; default the system's stop time.
        record : sequence of str, optional
            ``component.variable`` names to record; default every real and boolean output.
        progress : bool, optional
            Show a progress bar (default: when the run has more than 2,000 base steps).
        out_file : str or Path, optional
            Stream the rows to this ``.npy`` file as the run goes (:data:`CHUNK_ROWS` at a
            time) instead of keeping them in memory; the result is then the file opened as a
            read-only memory map (``numpy.load(out_file, mmap_mode="r")`` reads it later).
        timeout : float, optional
            Wall-time limit of the stepping [s]: past it the run stops with
            :class:`~marinefmu.errors.SystemError_` (checked every :data:`TIMEOUT_CHECK` steps).

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
        callbacks = self._callbacks() if self.engine == "fmpy" else None
        tmp = Path(tempfile.mkdtemp(prefix="marinefmu_"))
        instances: dict[str, Any] = {}
        recorder = None
        t = t0
        try:
            unzipped: dict[Path, Path] = dict(self.unpacked)
            for comp in sysd.components:
                src = comp.path(self.base_dir).resolve()
                if src not in unzipped:
                    unzipped[src] = Path(extract(str(src), unzipdir=str(tmp / f"{len(unzipped)}_{src.stem}")))
                instances[comp.name] = inst = self._instantiate(comp, unzipped[src], callbacks)
                inst.setup(t0)
                for name, value in comp.parameters.items():
                    v = lookup(inst.md, comp.name, name)   # type-checked by check_system
                    cast = PY_TYPES.get(_fmi_type(v.type), str)
                    inst.accessor("set", v.type)([v.valueReference], [cast(value)])
            for name, inst in instances.items():
                logged = len(self.messages)
                try:
                    inst.initialise()
                except Exception as exc:  # FMPy raises FMICallException
                    raise self._fail(name, "initialisation", t0, exc) from None
                # marinefmu slaves refuse a parameter by logging an error (they never raise:
                # see marinefmu.fmu.slave), so an error logged here is a refusal
                refused = [m for m in self.messages[logged:] if m.instance == name and m.status in ("ERROR", "FATAL")]
                if refused:
                    raise self._fail(name, "initialisation", t0, RuntimeError(refused[0].text))
            dtype = np.dtype([("time", "f8")] + [(f, "?" if k == "Boolean" else "f8") for f, (_, k, _) in fields.items()])
            recorder = _Recorder(dtype, n_steps + 1, out_file)
            exchange = Exchange(lambda comp, *how: instances[comp].channel(*how), self._wires(),
                                [Port(comp, _fmi_type(kind), vr) for comp, kind, vr in fields.values()])
            rates = {c.name: c.rate for c in sysd.components}

            def due_at(k: int) -> list[str]:
                return [n for n, m in rates.items() if k % m == 0]

            self._exchange(exchange, recorder.row(), t0, due_at(0))
            bar = tqdm(total=n_steps, unit="step", disable=not (progress if progress is not None else n_steps > 2000),
                       desc=sysd.name, mininterval=0.5)
            spent = self.step_seconds = dict.fromkeys(instances, 0.0)
            clock = time.perf_counter
            deadline = math.inf if timeout is None else clock() + timeout
            try:
                for k in range(n_steps):
                    if k % TIMEOUT_CHECK == 0 and clock() > deadline:
                        raise SystemError_(f"{sysd.name}: wall-time limit of {timeout:g} s reached at t = {t0 + k * sysd.step:.6g} s "
                                           f"of {stop:g} s")
                    t = t0 + k * sysd.step
                    for name in due_at(k):
                        start = clock()
                        try:
                            instances[name].do_step(t, rates[name] * sysd.step)
                        except Exception as exc:
                            raise self._fail(name, "doStep", t, exc) from None
                        spent[name] += clock() - start
                    # the inputs of the next step are set now: nothing changes the outputs
                    # between this step's end and the next one's start
                    self._exchange(exchange, recorder.row(), t0 + (k + 1) * sysd.step,
                                   due_at(k + 1) if k + 1 < n_steps else ())
                    bar.update(1)
            finally:
                bar.close()
            for inst in instances.values():
                inst.terminate()
            return recorder.finish()
        finally:
            if recorder is not None:
                recorder.close()
            for inst in instances.values():
                try:
                    inst.free()
                except Exception:  # noqa: BLE001 - freeing must go on for the others
                    log.exception("freeing %s failed", inst.name)
            shutil.rmtree(tmp, ignore_errors=True)
            _forget_paths(str(tmp))

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

    def _wires(self) -> list[tuple[Port, Port]]:
        """The connections (checked by check_system) as (source, destination) ports."""
        out = []
        for con in self.system.connections:
            a = lookup(self.descriptions[con.start], con.start, con.start_var)
            b = lookup(self.descriptions[con.end], con.end, con.end_var)
            out.append((Port(con.start, _fmi_type(a.type), a.valueReference),
                        Port(con.end, _fmi_type(b.type), b.valueReference)))
        return out

    def _exchange(self, exchange: Exchange, row: np.ndarray, t: float, due: Sequence[str]) -> None:
        """Read the outputs held at ``t`` [s], record them in ``row`` and set the inputs of
        the components ``due`` to step from ``t`` (:mod:`~.exchange`)."""
        try:
            exchange.read()
            exchange.record(row, t)
            exchange.write(due)
        except ExchangeError as exc:
            raise self._fail(exc.component or "?", "exchange", t, exc) from None


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
