"""Variable tables: the names, types, units and descriptions that an FMU exposes.

Plain metadata with no FMI import, so that ``sea/`` and ``estimators/`` can declare their
interface and ``cosim/`` can register it with pythonfmu and write units into the FMU.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

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
