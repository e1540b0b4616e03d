"""Post-processing of a pythonfmu ``modelDescription.xml``: units and initial unknowns.

pythonfmu writes neither FMI ``unit`` attributes nor ``UnitDefinitions``, and it omits
``ModelStructure/InitialUnknowns`` (which FMI 2.0 requires for outputs whose ``initial`` is
``calculated``: ``fmpy.validation`` reports it). :func:`postprocess_model_description` adds
both, leaving everything else untouched.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET

#: SI base-unit exponents of every unit used by marinefmu (FMI 2.0 BaseUnit attributes).
#: Units with non-integer exponents (noise densities per √Hz) are declared without a BaseUnit.
UNITS: dict[str, dict[str, int]] = {
    "m": {"m": 1},
    "m/s": {"m": 1, "s": -1},
    "m/s2": {"m": 1, "s": -2},
    "rad": {"rad": 1},
    "rad/s": {"rad": 1, "s": -1},
    "rad/s2": {"rad": 1, "s": -2},
    "s": {"s": 1},
    "Hz": {"s": -1},
    "m/s2/sqrt(Hz)": {},
    "rad/s/sqrt(Hz)": {},
    "m2": {"m": 2},
    "rad2": {"rad": 2},
    "m2/s3": {"m": 2, "s": -3},
    "m2/s2": {"m": 2, "s": -2},
    "m2*s": {"m": 2, "s": 1},
    "m/s2/sqrt(s)": {},
    "m/sqrt(s)": {},
    "kg": {"kg": 1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N/m": {"kg": 1, "s": -2},
    "N*s/m": {"kg": 1, "s": -1},
    "1/s": {"s": -1},
    "1/s2": {"s": -2},
    "m*s": {"m": 1, "s": 1},
}
_ORDER = ("ModelExchange", "CoSimulation", "UnitDefinitions", "TypeDefinitions", "LogCategories",
          "DefaultExperiment", "VendorAnnotations", "ModelVariables", "ModelStructure")


def postprocess_model_description(xml: bytes, units: dict[str, str]) -> bytes:
    """Return ``xml`` with ``unit`` attributes, ``UnitDefinitions`` and ``InitialUnknowns``.

    Parameters
    ----------
    xml : bytes
        modelDescription.xml as written by pythonfmu.
    units : dict
        Variable name → unit name (``""`` for none). Every unit must be in :data:`UNITS`.

    Raises
    ------
    KeyError
        If a variable uses a unit missing from :data:`UNITS` (a programming error).
    """
    root = ET.fromstring(xml)
    used: set[str] = set()
    variables = root.find("ModelVariables")
    outputs: list[int] = []
    for index, sv in enumerate(variables.findall("ScalarVariable"), start=1):
        unit = units.get(sv.get("name"), "")
        real = sv.find("Real")
        if unit and real is not None:
            if unit not in UNITS:
                raise KeyError(f"unit {unit!r} of {sv.get('name')} is not in marinefmu.fmu.units.UNITS")
            real.set("unit", unit)
            used.add(unit)
        if sv.get("causality") == "output":
            outputs.append(index)
    if used:
        defs = ET.Element("UnitDefinitions")
        for name in sorted(used):
            u = ET.SubElement(defs, "Unit", {"name": name})
            if UNITS[name]:
                ET.SubElement(u, "BaseUnit", {k: str(v) for k, v in UNITS[name].items()})
        _insert_ordered(root, defs)
    structure = root.find("ModelStructure")
    if outputs and structure.find("InitialUnknowns") is None:
        init = ET.SubElement(structure, "InitialUnknowns")
        for index in outputs:
            ET.SubElement(init, "Unknown", {"index": str(index)})
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def _insert_ordered(root: ET.Element, element: ET.Element) -> None:
    """Insert ``element`` where the FMI 2.0 schema's sequence wants it."""
    rank = _ORDER.index(element.tag)
    for i, child in enumerate(list(root)):
        if child.tag in _ORDER and _ORDER.index(child.tag) > rank:
            root.insert(i, element)
            return
    root.append(element)
