"""Static check of a system of FMUs, before any FMU is instantiated.

:func:`check_system` reads every component's ``modelDescription.xml`` (FMPy's
``read_model_description``, which only unzips and parses XML: no binary is loaded) and refuses,
with a :class:`~marinefmu.errors.SystemError_` naming the element:

- a component whose FMU file is missing or unreadable;
- a parameter the FMU does not have, or that is not a parameter (or input), or a value of the
  wrong type (a string for a Real, 1.5 for an Integer, …);
- a connection end the FMU does not have (with the closest names suggested), a start that is not
  an output, an end that is not an input, different types on the two ends, or different units
  (when both ends declare one);
- an input fed by more than one connection;
- a cycle of connections in which no connection is marked ``delay``. Both runners (FMPy's
  :class:`~marinefmu.cosim.system.SystemRunner` and libcosim's fixed-step algorithm) couple by
  Jacobi iteration, so every connection in fact carries one macro step of delay; a loop is
  nevertheless only accepted when the user says so on one of its connections
  (``delay = true`` in the scenario), because the FMUs declare direct feedthrough (their
  outputs depend on their inputs within a step) and an undeclared loop is almost always a
  wiring mistake.
"""
from __future__ import annotations

import difflib
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..errors import SystemError_

if TYPE_CHECKING:  # annotations only: ssp imports this module to check what it reads
    from .ssp import Component, SystemDescription


def describe(comp: Component, base_dir: str | Path) -> Any:
    """The FMPy ``ModelDescription`` of ``comp``'s FMU; refuse a missing or unreadable file."""
    from fmpy import read_model_description

    src = comp.path(base_dir)
    if not src.is_file():
        raise SystemError_(f"component {comp.name}: FMU {src} not found (run `marinefmu build`)")
    try:
        return read_model_description(str(src))
    except Exception as exc:  # noqa: BLE001 - FMPy raises many kinds for a bad archive or XML
        raise SystemError_(f"component {comp.name}: cannot read the model description of {src}: {exc}") from None


def lookup(md: Any, comp: str, var: str, causality: tuple[str, ...] | None = None) -> Any:
    """The model variable ``var`` of component ``comp`` (model description ``md``), refusing an
    unknown name (suggesting the closest ones) or a causality not in ``causality``."""
    variables = {v.name: v for v in md.modelVariables}
    v = variables.get(var)
    if v is None:
        close = difflib.get_close_matches(var, variables, n=3)
        hint = f" (did you mean {', '.join(map(repr, close))}?)" if close else ""
        raise SystemError_(f"{comp} ({md.modelName}) has no variable {var!r}{hint}")
    if causality is not None and v.causality not in causality:
        raise SystemError_(f"{comp}.{var} has causality {v.causality!r}, expected {' or '.join(causality)}")
    return v


def value_fits(kind: str, value: Any) -> bool:
    """Whether a scenario value can be given to an FMI variable of type ``kind``."""
    if kind == "Real":
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if kind in ("Integer", "Enumeration"):
        return isinstance(value, (int, float)) and not isinstance(value, bool) and float(value).is_integer()
    if kind == "Boolean":
        return isinstance(value, bool)
    return isinstance(value, str)


def unit_of(v: Any) -> str | None:
    """A variable's unit: its own, else its declared type's."""
    if v.unit:
        return v.unit
    return getattr(v.declaredType, "unit", None) if v.declaredType is not None else None


def find_cycle(system: SystemDescription) -> list[str] | None:
    """A cycle of components joined by connections not marked ``delay`` (names in order, the
    first repeated at the end), or None."""
    edges: dict[str, set[str]] = {c.name: set() for c in system.components}
    for con in system.connections:
        if not con.delay:
            edges[con.start].add(con.end)
    state: dict[str, int] = {}  # 1 on the path, 2 done
    path: list[str] = []

    def visit(n: str) -> list[str] | None:
        state[n] = 1
        path.append(n)
        for m in sorted(edges[n]):
            if state.get(m) == 1:
                return path[path.index(m):] + [m]
            if m not in state:
                found = visit(m)
                if found:
                    return found
        path.pop()
        state[n] = 2
        return None

    for c in system.components:
        if c.name not in state:
            found = visit(c.name)
            if found:
                return found
    return None


def check_system(system: SystemDescription, base_dir: str | Path = ".") -> Mapping[str, Any]:
    """Refuse a system that cannot run, before any FMU is instantiated (see the module
    docstring for the checks); return component name → FMPy ``ModelDescription``."""
    mds = {c.name: describe(c, base_dir) for c in system.components}
    for comp in system.components:
        for name, value in comp.parameters.items():
            v = lookup(mds[comp.name], comp.name, name, ("parameter", "input"))
            if not value_fits(v.type, value):
                raise SystemError_(f"{comp.name}.{name} is {v.type}; cannot set it to {value!r}")
    fed: dict[tuple[str, str], str] = {}
    for con in system.connections:
        a = lookup(mds[con.start], con.start, con.start_var, ("output",))
        b = lookup(mds[con.end], con.end, con.end_var, ("input",))
        if a.type != b.type:
            raise SystemError_(f"connection {con}: {a.type} output cannot feed {b.type} input")
        ua, ub = unit_of(a), unit_of(b)
        if ua and ub and ua != ub:
            raise SystemError_(f"connection {con}: unit {ua!r} cannot feed an input in {ub!r}")
        key = (con.end, con.end_var)
        if key in fed:
            raise SystemError_(f"connection {con}: input {con.end}.{con.end_var} is already fed by {fed[key]}")
        fed[key] = f"{con.start}.{con.start_var}"
    cycle = find_cycle(system)
    if cycle:
        raise SystemError_(f"connection cycle without a delay: {' -> '.join(cycle)}; mark one of its connections "
                           "delay = true (it then carries one macro step of delay) or break the loop")
    return mds
