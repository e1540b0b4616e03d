"""Exception hierarchy and parameter checks shared by every marinefmu module.

Every refusal names the offending parameter and the allowed range, so a user who set
``sea.hs = -1`` in an FMI tool reads ``sea.hs = -1 is out of range: must be > 0 [m]``
rather than a traceback from deep inside numpy.
"""
from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

import numpy as np


class MarineFmuError(Exception):
    """Base class of every error raised on purpose by marinefmu."""


class ParameterError(MarineFmuError, ValueError):
    """A parameter is out of its allowed range, non-finite or of an unknown choice."""


class ParameterTypeError(MarineFmuError, TypeError):
    """A parameter has the wrong type."""


class ShapeError(MarineFmuError, ValueError):
    """An array argument has the wrong shape (python-control's ``ControlDimension`` habit)."""


class RaoFileError(ParameterError):
    """An RAO table file is unreadable or malformed."""


class ScenarioError(ParameterError):
    """A scenario file is malformed; the message names the offending key."""


class SystemError_(MarineFmuError, RuntimeError):
    """A co-simulation system could not be built or stepped (FMU error, bad wiring)."""


def check_finite(name: str, value: Any, unit: str = "") -> float:
    """Return ``value`` as float, refusing non-numbers and NaN/Inf.

    Parameters
    ----------
    name : str
        Parameter name used in the message (e.g. ``"sea.hs"``).
    value : Any
        The value to check.
    unit : str
        Unit shown in the message.
    """
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ParameterTypeError(f"{name} must be a real number, got {value!r} ({type(value).__name__})")
    x = float(value)
    if not math.isfinite(x):
        raise ParameterError(f"{name} = {x} is not finite: must be a finite number{_u(unit)}")
    return x


def check_range(
    name: str,
    value: Any,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    hi_open: bool = False,
    unit: str = "",
) -> float:
    """Return ``value`` as float after checking it is finite and in the given range.

    ``lo``/``hi`` are inclusive unless ``lo_open``/``hi_open`` is set. The message states
    the allowed range, e.g. ``sea.hs = 0 is out of range: must be > 0 [m]``.
    """
    x = check_finite(name, value, unit)
    bad_lo = lo is not None and (x <= lo if lo_open else x < lo)
    bad_hi = hi is not None and (x >= hi if hi_open else x > hi)
    if bad_lo or bad_hi:
        raise ParameterError(f"{name} = {value!r} is out of range: must be {_describe(lo, hi, lo_open, hi_open)}{_u(unit)}")
    return x


def check_int(name: str, value: Any, *, lo: int | None = None, hi: int | None = None) -> int:
    """Return ``value`` as int after checking it is an integer in ``[lo, hi]``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        if isinstance(value, (float, np.floating)) and float(value).is_integer():
            value = int(value)
        else:
            raise ParameterTypeError(f"{name} must be an integer, got {value!r}")
    v = int(value)
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise ParameterError(f"{name} = {v} is out of range: must be {_describe(lo, hi, False, False)}")
    return v


def check_choice(name: str, value: Any, choices: Iterable[str]) -> str:
    """Return ``value`` if it is one of ``choices``; never fall back to a default on a typo."""
    options = tuple(choices)
    if not isinstance(value, str) or value not in options:
        raise ParameterError(f"{name} = {value!r} is not allowed: must be one of {', '.join(map(repr, options))}")
    return value


def check_vector(name: str, value: Any, size: int = 3, unit: str = "") -> tuple[float, ...]:
    """Return a finite vector of length ``size`` as a tuple of floats."""
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ParameterTypeError(f"{name} must be {size} real numbers, got {value!r}") from exc
    if arr.shape != (size,):
        raise ShapeError(f"{name} must have shape ({size},), got {arr.shape}")
    for i, x in enumerate(arr):
        check_finite(f"{name}[{i}]", float(x), unit)
    return tuple(float(x) for x in arr)


def _describe(lo, hi, lo_open, hi_open) -> str:
    if lo is not None and hi is not None:
        return f"in {'(' if lo_open else '['}{lo}, {hi}{')' if hi_open else ']'}"
    if lo is not None:
        return f"{'>' if lo_open else '>='} {lo}"
    if hi is not None:
        return f"{'<' if hi_open else '<='} {hi}"
    return "finite"


def _u(unit: str) -> str:
    return f" [{unit}]" if unit else ""
