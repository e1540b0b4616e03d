"""The same system in OSP libcosim: a scenario's :class:`~.ssp.SystemDescription` written as an
``OspSystemStructure.xml`` and run with libcosimpy.

:func:`write_osp_system` turns the components, their parameters, rate multipliers and the
variable connections of a system into OSP-IS 1.0 (each FMU's ``<Model>_OspModelDescription.xml``
must lie next to it, as ``marinefmu build`` writes it). :func:`run_libcosim` loads that file with
``CosimExecution.from_osp_config_file`` (libcosim's fixed-step algorithm: every simulator
receives the outputs all held at t, then all step, as :class:`~.system.SystemRunner` does) and
samples chosen variables with a last-value observer every ``sample_every`` s. Its result has the
runner's layout (a ``time`` field and one ``component.variable`` field each), so the two engines
compare field by field.

:func:`one_worker` makes a libcosimpy execution whose fixed-step algorithm steps the simulators
on one worker thread (the reason is in its docstring); :func:`run_libcosim` uses it, and a user
who builds an execution with libcosimpy directly can too.
"""
from __future__ import annotations

import math
import os
import threading
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

import numpy as np

from ..errors import SystemError_
from ..fmu import osp
from .ssp import SystemDescription
from .system_check import check_system, lookup

NS = 1_000_000_000  # libcosim time unit: ns

T = TypeVar("T")


def _threads() -> set[int]:
    """The native ids of this process's threads (Linux: ``/proc/self/task``); only the calling
    thread's where that folder does not exist."""
    try:
        return {int(t) for t in os.listdir("/proc/self/task")}
    except OSError:
        return {threading.get_native_id()}


def one_worker(create: Callable[[], T]) -> T:
    """``create()``, a libcosimpy execution constructor (``CosimExecution.from_osp_config_file``,
    ``from_step_size`` …), with libcosim's worker pool sized for one CPU.

    libcosim's fixed-step algorithm hands each simulator's step to a pool of worker threads sized
    from the CPUs the creating thread may run on, and waits for them. pythonfmu FMUs in one
    process share one Python interpreter and its global interpreter lock, so those workers cannot
    step two of them at once: what the pool adds is a hand-over between threads for every FMU at
    every step, and on a busy machine each hand-over waits for the scheduler. Made for one CPU,
    the pool steps the simulators one after the other without it, as the FMPy runner does; the
    results are the same (the algorithm stays Jacobi: each simulator reads the outputs held at
    t). What it saves is measured in ``docs/decisions/system-libcosim-one-worker.md``.

    How: the calling thread is held to one of its CPUs while ``create`` runs, so that the pool is
    made for one; then the calling thread and every thread ``create`` started get the calling
    thread's former CPUs back, so nothing stays pinned. Where the operating system has no
    ``sched_setaffinity`` (Windows, macOS), or refuses it, ``create()`` is called as it is.

    Parameters
    ----------
    create : callable
        Makes and returns the execution, e.g.
        ``lambda: CosimExecution.from_osp_config_file(path)``.

    Returns
    -------
    object
        What ``create`` returned.
    """
    if not hasattr(os, "sched_setaffinity"):
        return create()
    cpus = os.sched_getaffinity(0)
    before = _threads()
    try:
        os.sched_setaffinity(0, {min(cpus)})
    except OSError:                  # a sandbox that refuses it: the default pool, as libcosim makes it
        return create()
    try:
        return create()
    finally:
        os.sched_setaffinity(0, cpus)
        for tid in _threads() - before:
            try:
                os.sched_setaffinity(tid, cpus)
            except OSError:          # a thread that ended meanwhile
                pass


def write_osp_system(system: SystemDescription, fmu_dir: str | Path, dest: str | Path) -> Path:
    """Write ``system`` as an ``OspSystemStructure.xml`` at ``dest``.

    Parameters
    ----------
    system : SystemDescription
        Components (sources relative to ``fmu_dir`` unless absolute), parameters, connections.
    fmu_dir : str or Path
        Folder of the FMUs and their OSP model descriptions.
    dest : str or Path
        File to write.
    """
    fmu_dir = Path(fmu_dir)
    check_system(system, fmu_dir)
    simulators, step_sizes = {}, {}
    for c in system.components:
        simulators[c.name] = (c.path(fmu_dir), dict(c.parameters))
        if c.rate != 1:
            step_sizes[c.name] = c.rate * system.step
    connections = [((k.start, k.start_var), (k.end, k.end_var)) for k in system.connections]
    return osp.write_system_structure(Path(dest), system.step, simulators, [], connections, step_sizes)


def run_libcosim(system: SystemDescription, fmu_dir: str | Path, work: str | Path, stop_time: float,
                 record: Sequence[str], sample_every: float) -> np.ndarray:
    """Simulate ``system`` in libcosim to ``stop_time`` [s], sampling ``record`` every
    ``sample_every`` s (a multiple of the base step).

    Returns
    -------
    numpy.ndarray
        Structured array: ``time`` [s] and one field per ``component.variable`` (Real as f8,
        Boolean as bool), one row per sample from the first ``sample_every`` on.
    """
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.ERROR)   # libcosim logs every FMI call at its default level

    ratio = sample_every / system.step
    if ratio < 1 or abs(ratio - round(ratio)) > 1e-9:
        raise SystemError_(f"sample_every = {sample_every} s must be a multiple of the base step {system.step} s")
    mds = check_system(system, fmu_dir)
    wanted = []  # (field, component, variable)
    for full in record:
        comp, _, var = full.partition(".")
        if comp not in mds:
            raise SystemError_(f"record {full!r}: unknown component {comp!r} (known: {', '.join(mds)})")
        v = lookup(mds[comp], comp, var)
        if v.type not in ("Real", "Boolean"):
            raise SystemError_(f"record {full!r}: only Real and Boolean variables can be sampled here, not {v.type}")
        wanted.append((full, comp, v))
    path = write_osp_system(system, fmu_dir, Path(work) / "OspSystemStructure.xml")
    ex = one_worker(lambda: CosimExecution.from_osp_config_file(str(path)))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    fields = [(full, ex.slave_index_from_instance_name(comp), v.type, v.valueReference) for full, comp, v in wanted]
    n = int(math.floor(stop_time / sample_every + 1e-9))
    out = np.zeros(n, dtype=[("time", "f8")] + [(f, "?" if k == "Boolean" else "f8") for f, _, k, _ in fields])
    for row in range(n):
        t = round((row + 1) * sample_every * NS)
        if not ex.simulate_until(t):
            raise SystemError_(f"libcosim stopped before t = {t / NS} s")
        out["time"][row] = t / NS
        for f, index, kind, vr in fields:
            get = obs.last_boolean_values if kind == "Boolean" else obs.last_real_values
            out[f][row] = get(index, [vr])[0]
    return out
