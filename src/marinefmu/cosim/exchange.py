"""The master's data exchange of one base step: read every needed output once, record, wire.

:class:`~.system.SystemRunner` runs it: after the components have stepped to t, every
(component, type) that has a wired or a recorded output is read **once**, into a buffer
allocated before the run; the recorded columns are copied from those buffers, and the inputs of
the components due at t are gathered from them and set, one set call per (component, type).
Reading each destination's sources separately (a source feeding five estimators read five times
at every step) and the recorded outputs again after the step, each read through FMPy's
``getReal``, which builds two ctypes arrays and a list per call, costs about as much as
everything else the master does per base step.

It is a Jacobi exchange: every input sees the outputs held at t, and all reads happen before
any set, so the results are bit for bit those of reading each source per destination (every
output of every component of the ``system`` and ``ahc`` scenarios compared under both
engines); the runner's wiring and rate tests check it.

Through FMPy the calls go to the FMU's C functions directly (``fmi2GetReal`` … of
``FMU2Slave.dll``, with the argument types FMPy declared), on arrays made once; a status
above fmi2Warning raises :class:`ExchangeError`, as FMPy's wrappers would. In-process
(``engine="python"``) the slave's ``get_real`` … are called.
"""
from __future__ import annotations

import ctypes
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

#: ctypes type of the values of each FMI 2.0 variable type (fmi2Real, fmi2Integer, fmi2Boolean).
CTYPES = {"Real": ctypes.c_double, "Integer": ctypes.c_int, "Boolean": ctypes.c_int}
#: Python conversion of a value handed to a slave in-process, per FMI type (pythonfmu's C++
#: side passes these types).
PY_TYPES: dict[str, Callable] = {"Real": float, "Integer": int, "Boolean": bool}
#: FMI 2.0 status names by value (fmi2OK = 0 … fmi2Pending = 5).
STATUS = ["OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING"]


class ExchangeError(RuntimeError):
    """A get or set call failed (status above fmi2Warning); ``component`` names the component
    once the exchange knows it."""

    component: str | None = None


@dataclass(frozen=True)
class Port:
    """One variable of one component: ``kind`` is its FMI type (Real, Integer, Boolean)."""

    component: str
    kind: str
    vr: int


def fmpy_channel(fmu, op: str, kind: str, vrs: Sequence[int]) -> tuple[np.ndarray, Callable[[], None]]:
    """A buffer and a call that reads the variables ``vrs`` into it (``op="get"``) or sets
    them from it (``op="set"``), through the FMU's C function (module docstring).

    Parameters
    ----------
    fmu : fmpy.fmi2.FMU2Slave
        Instantiated FMU.
    op : {"get", "set"}
    kind : {"Real", "Integer", "Boolean"}
    vrs : sequence of int
        Value references.

    Returns
    -------
    (numpy.ndarray, callable)
        The buffer (a numpy view of the ctypes array the call uses) and the call.
    """
    name = f"fmi2{op.capitalize()}{kind}"
    func = getattr(fmu.dll, name)        # FMPy declared its argument types when it loaded the FMU
    n = len(vrs)
    refs = (ctypes.c_uint * n)(*vrs)
    values = (CTYPES[kind] * n)()
    component = fmu.component

    def call() -> None:
        status = func(component, refs, n, values)
        if status > 1:
            raise ExchangeError(f"{name} returned {STATUS[status] if status < len(STATUS) else status}")

    return np.ctypeslib.as_array(values), call


def slave_channel(slave, op: str, kind: str, vrs: Sequence[int]) -> tuple[np.ndarray, Callable[[], None]]:
    """:func:`fmpy_channel` for a pythonfmu slave called in-process (its ``get_real`` …)."""
    vrs = list(vrs)
    buf = np.zeros(len(vrs), dtype=np.float64 if kind == "Real" else np.int32)
    method = getattr(slave, f"{op}_{kind.lower()}")
    if op == "get":
        def call() -> None:
            buf[:] = method(vrs)
    else:
        cast = PY_TYPES[kind]

        def call() -> None:
            method(vrs, [cast(v) for v in buf.tolist()])
    return buf, call


class Exchange:
    """Reads, recording and wiring of a run (module docstring).

    Parameters
    ----------
    channel : callable
        ``channel(component, op, kind, vrs)`` → (buffer, call), :func:`fmpy_channel` or
        :func:`slave_channel` bound to the component's instance.
    wires : iterable of (Port, Port)
        Connections, source → destination (types checked beforehand).
    recorded : sequence of Port
        Variables recorded, in the order of the row's columns 1, 2, … (column 0 is time).
    """

    def __init__(self, channel: Callable, wires: Iterable[tuple[Port, Port]], recorded: Sequence[Port]) -> None:
        wires = list(wires)
        # every (component, type) read, with its value references in a fixed order
        needed: dict[tuple[str, str], dict[int, int]] = {}
        for port in [a for a, _ in wires] + list(recorded):
            slots = needed.setdefault((port.component, port.kind), {})
            slots.setdefault(port.vr, len(slots))
        self.reads: list[Callable[[], None]] = []
        buffers: dict[tuple[str, str], np.ndarray] = {}
        self.read_components: list[str] = []     # the component of each read, for error messages
        for (comp, kind), slots in needed.items():
            buffers[comp, kind], call = channel(comp, "get", kind, list(slots))
            self.reads.append(call)
            self.read_components.append(comp)
        # recording: per read buffer, positions in it → columns of the row
        rec: dict[tuple[str, str], tuple[list[int], list[int]]] = {}
        for col, port in enumerate(recorded, start=1):
            idx, cols = rec.setdefault((port.component, port.kind), ([], []))
            idx.append(needed[port.component, port.kind][port.vr])
            cols.append(col)
        self.record_plan = [(buffers[key], np.array(idx), np.array(cols)) for key, (idx, cols) in rec.items()]
        # wiring: per destination, per type, one buffer set in one call, gathered per source
        into: dict[str, dict[str, list[tuple[Port, Port]]]] = {}
        for a, b in wires:
            into.setdefault(b.component, {}).setdefault(b.kind, []).append((a, b))
        self.writes: dict[str, list] = {}
        for dest, by_kind in into.items():
            plans = []
            for kind, pairs in by_kind.items():
                buf, call = channel(dest, "set", kind, [b.vr for _, b in pairs])
                gathers: dict[tuple[str, str], tuple[list[int], list[int]]] = {}
                for pos, (a, _) in enumerate(pairs):
                    src, dst = gathers.setdefault((a.component, a.kind), ([], []))
                    src.append(needed[a.component, a.kind][a.vr])
                    dst.append(pos)
                plans.append((buf, call, [(buffers[key], np.array(s), np.array(d)) for key, (s, d) in gathers.items()]))
            self.writes[dest] = plans

    def read(self) -> None:
        """Read every needed output now (after the step, before any set)."""
        for i, call in enumerate(self.reads):
            try:
                call()
            except ExchangeError as exc:
                exc.component = self.read_components[i]
                raise

    def record(self, row: np.ndarray, t: float) -> None:
        """Fill ``row`` (time [s] in column 0) from the last :meth:`read`."""
        row[0] = t
        for buf, idx, cols in self.record_plan:
            row[cols] = buf[idx]

    def write(self, due: Iterable[str]) -> None:
        """Set the inputs of the components in ``due`` from the last :meth:`read`."""
        for dest in due:
            for buf, call, gathers in self.writes.get(dest, ()):
                for src, s, d in gathers:
                    buf[d] = src[s]
                try:
                    call()
                except ExchangeError as exc:
                    exc.component = dest
                    raise

