"""One campaign run, as a Dask task in a worker process: the FMUs, the simulation, the metrics.

The FMUs travel with the campaign (scattered once to every worker as bytes), so a worker needs
marinefmu and its dependencies installed but no shared file system: each worker process writes
them once to a temporary folder of its own and extracts them there (:func:`fmu_folder`). A run
instantiates the scenario's FMUs in the worker process (:class:`~marinefmu.cosim.system.SystemRunner`),
simulates, scores the estimators against the vessel's truth (:func:`marinefmu.analysis.scoring.score`)
and returns a small record; the time series only when the campaign keeps them. Any error of a
run (an FMU refusing a combination of values, a failed step, the wall-time limit) becomes a
record with ``status = "failed"`` and the error, so the campaign goes on.
"""
from __future__ import annotations

import atexit
import functools
import hashlib
import math
import os
import shutil
import socket
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..cosim.ssp import SystemDescription
from .spec import CampaignSpec, Run

#: This process's FMU folders and their extracted FMUs, by the hash of their contents.
_FOLDERS: dict[str, tuple[Path, dict[Path, Path]]] = {}


@dataclass(frozen=True)
class Job:
    """What every run of a campaign shares (sent to each worker once, as the FMUs are: a task
    then carries only its :class:`~.spec.Run`; Dask's worker keeps its recent tasks' arguments in
    a log of 1,000 events, which would hold a whole system per task and grow the worker's memory
    with every run).

    Attributes
    ----------
    system : SystemDescription
        The scenario's system before a run's overrides, its components naming their FMUs by
        file name (:func:`~.engine.portable`).
    spec : CampaignSpec
        The campaign: duration, settling time, time limit, engine, vessel, metrics, what to
        record and whether to keep the series.
    """

    system: SystemDescription
    spec: CampaignSpec


def fmu_folder(fmus: dict[str, bytes]) -> tuple[Path, dict[Path, Path]]:
    """A folder of this process holding ``fmus`` (file name → content) and each FMU extracted
    (FMU file → its folder, :class:`~marinefmu.cosim.system.SystemRunner`'s ``unpacked``),
    written once per content: runs after the first neither unzip nor load new copies of the
    FMUs' binaries."""
    from fmpy import extract

    h = hashlib.sha1()
    for name in sorted(fmus):
        h.update(name.encode())
        h.update(hashlib.sha1(fmus[name]).digest())
    key = h.hexdigest()
    if key not in _FOLDERS:
        folder = Path(tempfile.mkdtemp(prefix="marinefmu_campaign_"))
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
        unpacked = {}
        for i, (name, data) in enumerate(fmus.items()):
            path = folder / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
            unpacked[path.resolve()] = Path(extract(str(path), unzipdir=str(folder / f"unpacked_{i}")))
        _FOLDERS[key] = folder, unpacked
    return _FOLDERS[key]


def prepare(local: bool = False) -> int:
    """Import what every run needs (scipy, filterpy, python-control, the estimators: seconds),
    once per worker process before the first run; the process id. ``local``: the worker belongs
    to the campaign's own local cluster, so a Ctrl-C at the terminal (which reaches every
    process of the terminal's group) is left to the campaign, which cancels the runs and closes
    the cluster, instead of breaking each worker with a traceback of its own."""
    import signal
    import threading

    if local and threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, signal.SIG_IGN)
    import marinefmu.fmu.tables  # noqa: F401
    import marinefmu.cosim.system  # noqa: F401
    import marinefmu.estimators.heave.observer  # noqa: F401
    import marinefmu.analysis.scoring  # noqa: F401

    return os.getpid()


def run_one(run: Run, task: Job, fmus: dict[str, bytes]) -> dict[str, Any]:
    """Simulate and score ``run`` of the campaign ``task`` (module docstring); never raises for
    a failed run.

    Returns
    -------
    dict
        ``id``, ``values``, ``status`` ("ok" or "failed"), ``error``, ``metrics``
        (``component.metric`` → value; NaN for a kept metric the run did not give),
        ``run_s`` (wall time of the simulation) and ``wall_s`` (of the whole task) [s],
        ``worker`` (host:pid), ``rss_mb`` (the worker's resident memory after the run), and
        ``series`` (structured array) when the task keeps it.
    """
    from ..bench.system import rss_mb
    from ..cosim.system import SystemRunner
    from ..analysis.scoring import score

    start = time.perf_counter()
    out: dict[str, Any] = {"id": run.id, "values": run.values, "status": "ok", "error": "",
                           "metrics": {}, "run_s": math.nan, "worker": f"{socket.gethostname()}:{os.getpid()}"}
    try:
        system = task.system.with_parameters(run.overrides)
        folder, unpacked = fmu_folder(fmus)
        spec = task.spec
        runner = SystemRunner(system, folder, engine=spec.engine, unpacked=unpacked)
        t0 = time.perf_counter()
        result = runner.run(spec.duration, record=spec.scenario.record, progress=False, timeout=spec.timeout)
        out["run_s"] = time.perf_counter() - t0
        scores = score(result, system, spec.vessel, spec.settle)
        metrics = {f"{comp}.{name}": float(v) for comp, row in scores.items() for name, v in row.items()}
        out["metrics"] = metrics if spec.metrics is None else {m: metrics.get(m, math.nan) for m in spec.metrics}
        if spec.keep_series:
            out["series"] = result
    except Exception as exc:  # noqa: BLE001 - a failed run is a record; the campaign goes on
        out.update(status="failed", error=f"{type(exc).__name__}: {exc}")
    out["wall_s"] = time.perf_counter() - start
    _give_back_freed_memory()
    out["rss_mb"] = rss_mb()
    return out


def _give_back_freed_memory() -> None:
    """Return the heap's free pages to the system after a run (glibc's ``malloc_trim``; nothing
    elsewhere). Without it a worker's resident set creeps up run after run, pages freed by one
    run but kept by the allocator in the task thread's arena (``marinefmu bench``, part
    ``campaign``, measures a worker's memory over its runs)."""
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


@functools.cache
def _malloc_trim() -> Callable[[int], int] | None:
    """glibc's ``malloc_trim``, looked up once per process (``find_library`` runs ``ldconfig``);
    None where there is none (macOS, Windows, musl)."""
    import ctypes
    import ctypes.util

    try:
        return ctypes.CDLL(ctypes.util.find_library("c")).malloc_trim
    except (OSError, AttributeError, TypeError):
        return None
