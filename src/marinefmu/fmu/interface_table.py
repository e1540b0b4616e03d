"""An FMU's interface as table rows, read from the modelDescription.xml inside the built FMU.

The documentation's FMU pages show these rows (the ``fmu-interface`` directive of the docs),
so that the interface table printed for a user is the one the FMU declares and cannot drift
from it. Only the standard library is used: no FMI tool is needed to read the table.

The allowed range of a variable comes from the ``min``/``max`` attributes of its type element
when the XML has them. The FMUs of this package state the range in the description instead
(``variables.Variable`` has no bounds; the models check them at initialisation), in one of
these forms, which are returned as written:

- an interval: ``(0, 10]``, ``[0, 1)``, ``(cutoff, Nyquist]``;
- a span: ``0..20``, ``0.1..1e6``;
- a bound or a chain of bounds: ``> 0``, ``>= 2/cutoff, <= 3600``, ``0 < Hs <= 30``;
- a choice: ``one of jonswap, pierson-moskowitz``.
"""
from __future__ import annotations

import re
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

#: The keys of each row, in the order of the table's columns.
COLUMNS: tuple[str, ...] = (
    "name", "causality", "variability", "type", "unit", "start", "range", "description",
)

_TYPES = ("Real", "Integer", "Boolean", "String", "Enumeration")

_INTERVAL = re.compile(r"[(\[]\s*[^,()\[\]]+,\s*[^,()\[\]]+[)\]]")
_SPAN = re.compile(r"[-+\w.]+\s*\.\.\s*[-+\w.]+")
_BOUND = re.compile(r"(<=|>=|<|>|≤|≥)\s*\S.*")
_CHAIN = re.compile(r"\S+\s*(<=|<|≤)\s*\S+\s*(<=|<|≤)\s*\S+")
_ONE_OF = re.compile(r"\bone of ([\w.+-]+(?:,\s*[\w.+-]+)*)")
_REMARK = re.compile(r"\s*\([^()]*\)$")  # a trailing explanation, "(1: full compensation)"


def interface_rows(fmu_path: str | Path) -> list[dict[str, str]]:
    """Every ScalarVariable of an FMU's modelDescription.xml, as one row each.

    Parameters
    ----------
    fmu_path : str or pathlib.Path
        The ``.fmu`` file (a zip archive with ``modelDescription.xml`` at its root).

    Returns
    -------
    list of dict
        One dict per ScalarVariable, in the order of the XML, with the keys of :data:`COLUMNS`,
        every value a string (``""`` where the XML has nothing): ``name``, ``causality``
        (FMI 2.0's default ``local`` when absent), ``variability`` (default ``continuous``),
        ``type`` (``Real``, ``Integer``, ``Boolean``, ``String`` or ``Enumeration``), ``unit``
        (the variable's own or its declared type's), ``start``, ``range`` (see
        :func:`allowed_range`) and ``description``.

    Raises
    ------
    FileNotFoundError
        If ``fmu_path`` does not exist.
    ValueError
        If the archive has no ``modelDescription.xml`` or a ScalarVariable has no type element.
    """
    path = Path(fmu_path)
    if not path.is_file():
        raise FileNotFoundError(f"no FMU at {path}")
    with zipfile.ZipFile(path) as archive:
        try:
            xml = archive.read("modelDescription.xml")
        except KeyError:
            raise ValueError(f"{path} has no modelDescription.xml") from None
    root = ET.fromstring(xml)

    declared: dict[str, dict[str, str]] = {}  # TypeDefinitions: declaredType -> its attributes
    for simple in root.iter("SimpleType"):
        element = next((c for c in simple if c.tag in _TYPES), None)
        if element is not None:
            declared[simple.get("name", "")] = dict(element.attrib)

    rows = []
    for var in root.iter("ScalarVariable"):
        element = next((c for c in var if c.tag in _TYPES), None)
        if element is None:
            raise ValueError(f"{path}: variable {var.get('name')!r} has no type element")
        attrs = {**declared.get(element.get("declaredType", ""), {}), **element.attrib}
        description = var.get("description", "")
        rows.append({
            "name": var.get("name", ""),
            "causality": var.get("causality", "local"),
            "variability": var.get("variability", "continuous"),
            "type": element.tag,
            "unit": attrs.get("unit", ""),
            "start": attrs.get("start", ""),
            "range": allowed_range(description, attrs.get("min"), attrs.get("max"), attrs.get("unit", "")),
            "description": description,
        })
    return rows


def allowed_range(description: str, minimum: str | None = None, maximum: str | None = None,
                  unit: str = "") -> str:
    """The allowed range of a variable: from its ``min``/``max``, else as its description states it.

    Parameters
    ----------
    description : str
        The variable's description, e.g. ``"Significant wave height Hs, 0 < Hs <= 30 [m]"``.
    minimum, maximum : str or None
        The ``min`` and ``max`` attributes of the variable's type element, if any.
    unit : str
        The variable's unit; a trailing ``[unit]`` of the description is not part of a range.

    Returns
    -------
    str
        ``"[min, max]"``, ``">= min"`` or ``"<= max"`` from the attributes; otherwise the range
        clauses of the description as written (``"0 < Hs <= 30"``, ``"(0, 10]"``, ``"0..20"``,
        ``">= 2/cutoff, <= 3600"``, ``"one of band, peaks"``); ``""`` if it states none.

    Examples
    --------
    >>> allowed_range("Significant wave height Hs, 0 < Hs <= 30 [m]", unit="m")
    '0 < Hs <= 30'
    >>> allowed_range("Wave spectrum: one of jonswap, pierson-moskowitz")
    'one of jonswap, pierson-moskowitz'
    >>> allowed_range("Gain", "0", "2")
    '[0, 2]'
    """
    if minimum is not None and maximum is not None:
        return f"[{minimum}, {maximum}]"
    if minimum is not None:
        return f">= {minimum}"
    if maximum is not None:
        return f"<= {maximum}"

    text = description.strip()
    if unit and text.endswith(f"[{unit}]"):
        text = text[: -len(unit) - 2].rstrip()
    choice = _ONE_OF.search(text)
    if choice:
        return f"one of {choice.group(1)}"

    found: list[str] = []
    clauses = _clauses(text)
    for i, clause in enumerate(clauses[1:], start=1):  # the first clause names the quantity
        body = clause[len("else "):] if clause.startswith("else ") else clause
        matched = _range_clause(body)
        if matched is None:
            continue
        if body is not clause:  # "0 = long-crested, else 1..100": the alternative belongs to it
            if clauses[i - 1] not in found:
                found.append(clauses[i - 1])
            found.append(clause)
        else:
            found.append(matched)
    return ", ".join(found)


def _clauses(text: str) -> list[str]:
    """``text`` split at the commas and semicolons outside brackets and parentheses."""
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth = max(depth - 1, 0)
        elif ch in ",;" and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    parts.append(text[start:].strip())
    return [p for p in parts if p]


def _range_clause(clause: str) -> str | None:
    """The clause as written if it is a range, without a trailing remark; ``None`` if it is not."""
    if _BOUND.fullmatch(clause):  # a bound keeps its wording: ">= two periods of omega_min (...)"
        return clause
    for candidate in (clause, _REMARK.sub("", clause)):
        if _INTERVAL.fullmatch(candidate) or _SPAN.fullmatch(candidate) or _CHAIN.fullmatch(candidate):
            return candidate
    return None
