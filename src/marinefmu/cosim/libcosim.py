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
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..errors import SystemError_
from ..fmu import osp
from .ssp import SystemDescription
from .system_check import check_system, lookup

NS = 1_000_000_000  # libcosim time unit: ns


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
    ex = CosimExecution.from_osp_config_file(str(path))
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
