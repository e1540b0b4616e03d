"""OSP-IS model descriptions (``<Model>_OspModelDescription.xml``) written next to each FMU.

The Open Simulation Platform interface specification (OSP-IS 1.0) lets a co-simulation tool
(OSP libcosim, the Kopl configurator) connect whole groups of variables at once and check
their units. Every input and output of an FMU is put in exactly one ``Generic`` group named
after its vector: ``imu.acc.x``/``.y``/``.z`` form the group ``imu.acc`` (components ordered
x, y, z; n, e, d; w, x, y, z), a scalar forms a group of its own. Groups never mix inputs and
outputs; units are those of modelDescription.xml, whose UnitDefinitions are copied.

:func:`check` compares a written file with its modelDescription.xml (names, causality, units).
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

NAMESPACE = "https://open-simulation-platform.com/OspModelDescription/1.0.0"
_AXES = ("x", "y", "z", "n", "e", "d", "w")
_ORDER = {a: i for i, a in enumerate(("w", "x", "y", "z", "n", "e", "d"))}


def _group_key(name: str) -> tuple[str, str]:
    stem, _, last = name.rpartition(".")
    return (stem, last) if stem and last in _AXES else (name, "")


def _connectors(md: ET.Element) -> list[tuple[str, str, str]]:
    """(name, causality, unit) of every input and output of a modelDescription.xml root."""
    out = []
    for sv in md.iter("ScalarVariable"):
        causality = sv.get("causality")
        if causality in ("input", "output"):
            typed = next(iter(sv))
            out.append((sv.get("name"), causality, typed.get("unit", "")))
    return out


def groups(md: ET.Element) -> dict[str, tuple[str, list[tuple[str, str]]]]:
    """Group name -> (causality, [(variable, unit), ...]) for a modelDescription.xml root."""
    found: dict[tuple[str, str], list[tuple[str, str, str]]] = {}
    for name, causality, unit in _connectors(md):
        key, axis = _group_key(name)
        found.setdefault((key, causality), []).append((axis, name, unit))
    keys = [k for k, _ in found]
    result = {}
    for (key, causality), members in found.items():
        label = key if keys.count(key) == 1 else f"{key}.{causality}"
        members.sort(key=lambda m: _ORDER.get(m[0], -1))
        result[label] = (causality, [(name, unit) for _, name, unit in members])
    return result


def write(md_xml: bytes, dest: Path) -> Path:
    """Write ``dest`` (``<Model>_OspModelDescription.xml``) for the model description ``md_xml``."""
    md = ET.fromstring(md_xml)
    ET.register_namespace("", NAMESPACE)
    root = ET.Element(f"{{{NAMESPACE}}}OspModelDescription", version="1.0")
    units = md.find("UnitDefinitions")
    if units is not None:
        target = ET.SubElement(root, f"{{{NAMESPACE}}}UnitDefinitions")
        for unit in units:
            u = ET.SubElement(target, f"{{{NAMESPACE}}}Unit", name=unit.get("name"))
            for base in unit:
                ET.SubElement(u, f"{{{NAMESPACE}}}BaseUnit", dict(base.attrib))
    variable_groups = ET.SubElement(root, f"{{{NAMESPACE}}}VariableGroups")
    for label, (_, members) in groups(md).items():
        g = ET.SubElement(variable_groups, f"{{{NAMESPACE}}}Generic", name=label)
        for name, unit in members:
            ET.SubElement(g, f"{{{NAMESPACE}}}Variable", {"ref": name, **({"unit": unit} if unit else {})})
    ET.indent(root)
    dest.write_bytes(ET.tostring(root, encoding="utf-8", xml_declaration=True))
    return dest


def check(md_xml: bytes, osp_xml: bytes) -> list[str]:
    """Disagreements between an OspModelDescription and its modelDescription.xml: unknown or
    repeated references, parameters in groups, groups mixing inputs and outputs, units that
    differ or are undefined, and inputs or outputs in no group. Empty when they agree."""
    md = ET.fromstring(md_xml)
    osp = ET.fromstring(osp_xml)
    ns = {"o": NAMESPACE}
    variables = {sv.get("name"): (sv.get("causality"), next(iter(sv)).get("unit", "")) for sv in md.iter("ScalarVariable")}
    defined = {u.get("name") for u in osp.findall("o:UnitDefinitions/o:Unit", ns)}
    problems, seen = [], set()
    if osp.tag != f"{{{NAMESPACE}}}OspModelDescription":
        return [f"root element {osp.tag} is not OspModelDescription 1.0.0"]
    for group in osp.findall("o:VariableGroups/*", ns):
        label = group.get("name")
        causalities = set()
        for var in group.findall("o:Variable", ns):
            ref, unit = var.get("ref"), var.get("unit", "")
            if ref not in variables:
                problems.append(f"{label}: {ref} is not in modelDescription.xml")
                continue
            causality, md_unit = variables[ref]
            causalities.add(causality)
            if causality not in ("input", "output"):
                problems.append(f"{label}: {ref} has causality {causality}")
            if unit != md_unit:
                problems.append(f"{label}: {ref} has unit {unit!r}, modelDescription.xml {md_unit!r}")
            if unit and unit not in defined:
                problems.append(f"{label}: unit {unit!r} of {ref} is not in UnitDefinitions")
            if ref in seen:
                problems.append(f"{label}: {ref} is in more than one group")
            seen.add(ref)
        if len(causalities) > 1:
            problems.append(f"{label}: mixes {' and '.join(sorted(causalities))}")
    missing = [n for n, (c, _) in variables.items() if c in ("input", "output") and n not in seen]
    problems += [f"{n} ({variables[n][0]}) is in no group" for n in missing]
    return problems


SYSTEM_NAMESPACE = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"
_VALUE_TAG = {bool: "Boolean", int: "Integer", float: "Real", str: "String"}


def write_system_structure(dest: Path, step: float, simulators: dict[str, tuple[Path, dict]],
                           group_connections: list[tuple[tuple[str, str], tuple[str, str]]],
                           variable_connections: list[tuple[tuple[str, str], tuple[str, str]]] = (),
                           step_sizes: dict[str, float] | None = None) -> Path:
    """Write an ``OspSystemStructure.xml`` (OSP-IS 1.0) that libcosim loads directly.

    Parameters
    ----------
    dest : Path
        File to write.
    step : float
        Base step size [s].
    simulators : dict
        Instance name -> (FMU path, initial values {variable: bool/int/float/str}). Each FMU's
        ``_OspModelDescription.xml`` must lie next to it.
    group_connections : list
        ((simulator, output group), (simulator, input group)) pairs, connected variable by
        variable in group order.
    variable_connections : list
        ((simulator, output variable), (simulator, input variable)) pairs.
    step_sizes : dict, optional
        Simulator name -> its own step [s] (a multiple of ``step``); others step at ``step``.
    """
    ET.register_namespace("", SYSTEM_NAMESPACE)

    def sub(parent: ET.Element, tag: str, attrib: dict | None = None, text: str | None = None) -> ET.Element:
        e = ET.SubElement(parent, f"{{{SYSTEM_NAMESPACE}}}{tag}", attrib or {})
        e.text = text
        return e

    root = ET.Element(f"{{{SYSTEM_NAMESPACE}}}OspSystemStructure", version="0.1")
    sub(root, "StartTime", text="0.0")
    sub(root, "BaseStepSize", text=repr(float(step)))
    sub(root, "Algorithm", text="fixedStep")
    sims = sub(root, "Simulators")
    for name, (fmu, values) in simulators.items():
        attrib = {"name": name, "source": Path(fmu).resolve().as_uri()}
        if step_sizes and name in step_sizes:
            attrib["stepSize"] = repr(float(step_sizes[name]))
        sim = sub(sims, "Simulator", attrib)
        initial = sub(sim, "InitialValues")
        for variable, value in values.items():
            v = sub(initial, "InitialValue", {"variable": variable})
            text = str(value).lower() if isinstance(value, bool) else str(value)
            sub(v, _VALUE_TAG[type(value)], {"value": text})
    connections = sub(root, "Connections")
    for (sim_a, group_a), (sim_b, group_b) in group_connections:
        c = sub(connections, "VariableGroupConnection")
        sub(c, "VariableGroup", {"simulator": sim_a, "name": group_a})
        sub(c, "VariableGroup", {"simulator": sim_b, "name": group_b})
    for (sim_a, var_a), (sim_b, var_b) in variable_connections:
        c = sub(connections, "VariableConnection")
        sub(c, "Variable", {"simulator": sim_a, "name": var_a})
        sub(c, "Variable", {"simulator": sim_b, "name": var_b})
    ET.indent(root)
    dest.write_bytes(ET.tostring(root, encoding="utf-8", xml_declaration=True))
    return dest
