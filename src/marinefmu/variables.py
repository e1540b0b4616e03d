"""Variable tables: the names, types, units and descriptions that an FMU exposes.

Plain metadata with no FMI import, so that ``sea/`` and ``estimators/`` can declare their
interface and ``fmu/`` can register it with pythonfmu and write units into the FMU.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass
from typing import Any, Literal

Kind = Literal["real", "integer", "boolean", "string"]


@dataclass(frozen=True)
class Variable:
    """One FMU variable.

    Attributes
    ----------
    name : str
        Dotted FMI structured name, e.g. ``"imu.acc.x"``.
    kind : str
        ``"real"``, ``"integer"``, ``"boolean"`` or ``"string"``.
    default : float | int | bool | str
        Start value (parameters and inputs).
    unit : str
        FMI unit name (``"m"``, ``"m/s2"``, ``"rad/s"``, …) or ``""`` for dimensionless.
    description : str
        Human description including the frame.
    """

    name: str
    kind: Kind
    default: float | int | bool | str
    unit: str
    description: str


def real(name: str, default: float, unit: str, description: str) -> Variable:
    """Shorthand for a real variable."""
    return Variable(name, "real", float(default), unit, description)


def vec(prefix: str, axes: str | tuple[str, ...], default, unit: str, description: str) -> list[Variable]:
    """Real variables ``prefix.<axis>`` for each axis (``"xyz"``, ``"ned"``, or a tuple of names)."""
    names = tuple(axes)
    defaults = default if isinstance(default, (tuple, list)) else (default,) * len(names)
    return [real(f"{prefix}.{a}", d, unit, f"{description}, {a}") for a, d in zip(names, defaults)]


def resolve(table: list[Variable], values: dict[str, Any], what: str) -> dict[str, Any]:
    """Every parameter of ``table`` with its value from ``values`` or its default.

    Raises
    ------
    ParameterError
        For an unknown name, with the closest known name as a hint.
    """
    from .errors import ParameterError

    known = {v.name: v for v in table}
    unknown = [k for k in values if k not in known]
    if unknown:
        hints = {k: difflib.get_close_matches(k, known, n=1) for k in unknown}
        msg = "; ".join(f"{k!r}" + (f" (did you mean {h[0]!r}?)" if h else "") for k, h in hints.items())
        raise ParameterError(f"unknown {what} parameter(s): {msg}")
    return {name: values.get(name, var.default) for name, var in known.items()}
