"""Systems of FMUs as SSP 1.0 System Structure Descriptions (``.ssd``).

A system is a set of :class:`Component` (an FMU with parameter values and an integer rate
multiplier), :class:`Connection` (output → input by variable name) and a base step. The SSD
holds components as ``ssd:Component`` with inline ``ssv:ParameterSet`` bindings, connections
as ``ssd:Connection``, and the stop time in ``ssd:DefaultExperiment``. SSP has no field for a
fixed base step or per-component rates, so those are stored as annotations of type
``org.marinefmu.stepping`` (other tools ignore annotations they do not know).
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import ParameterError

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
    "mf": "https://github.com/marinefmu/marinefmu/ssp-annotations",
}
ANNOTATION = "org.marinefmu.stepping"
for _prefix, _uri in NS.items():
    ET.register_namespace(_prefix, _uri)

Value = float | int | bool | str


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


@dataclass(frozen=True)
class Component:
    """One FMU instance in a system.

    Attributes
    ----------
    name : str
        Instance name (unique in the system).
    source : str
        Path of the FMU, relative to the SSD's folder or absolute.
    parameters : dict
        Parameter name → value (float, int, bool or str).
    rate : int
        Steps every ``rate`` base steps with step size ``rate × step``.
    """

    name: str
    source: str
    parameters: dict[str, Value] = field(default_factory=dict)
    rate: int = 1

    def path(self, base: str | Path) -> Path:
        """The FMU file: ``source`` itself if absolute, else relative to ``base``."""
        p = Path(self.source)
        return p if p.is_absolute() else Path(base) / p

    @property
    def kind(self) -> str:
        """The FMU's model name, from the source's file name (``VesselMotion`` for
        ``fmus/VesselMotion.fmu``)."""
        return self.source.replace("\\", "/").rsplit("/", 1)[-1].removesuffix(".fmu")

    def __post_init__(self) -> None:
        if not self.name or "." in self.name:
            raise ParameterError(f"component name {self.name!r} must be non-empty and contain no '.'")
        if isinstance(self.rate, bool) or not isinstance(self.rate, int) or self.rate < 1:
            raise ParameterError(f"components.{self.name}.rate = {self.rate!r} is out of range: must be an integer >= 1")


@dataclass(frozen=True)
class Connection:
    """Output ``start.start_var`` feeds input ``end.end_var``.

    ``delay`` marks a connection that closes a feedback loop on purpose: it carries the output
    one macro step late (as every connection does under Jacobi coupling), and a loop without
    one such connection is refused (:mod:`marinefmu.cosim.system_check`).
    """

    start: str
    start_var: str
    end: str
    end_var: str
    delay: bool = False

    @classmethod
    def parse(cls, src: str, dst: str, delay: bool = False) -> "Connection":
        """From ``"vessel.imu.acc.x"``, ``"att.acc.x"`` (component name before the first dot)."""
        for s in (src, dst):
            if "." not in s:
                raise ParameterError(f"connection end {s!r} must be '<component>.<variable>'")
        a, av = src.split(".", 1)
        b, bv = dst.split(".", 1)
        return cls(a, av, b, bv, delay)

    def __str__(self) -> str:
        return f"{self.start}.{self.start_var} -> {self.end}.{self.end_var}{' (delay)' if self.delay else ''}"


@dataclass(frozen=True)
class SystemDescription:
    """A system of FMUs with a fixed base step.

    Attributes
    ----------
    name : str
        System name.
    components : tuple of Component
        Instances, stepped in this order.
    connections : tuple of Connection
        Output → input couplings.
    step : float
        Base communication step [s].
    stop_time : float
        Default stop time [s].
    start_time : float
        Start time [s].
    """

    name: str
    components: tuple[Component, ...]
    connections: tuple[Connection, ...] = ()
    step: float = 0.01
    stop_time: float = 600.0
    start_time: float = 0.0

    def __post_init__(self) -> None:
        names = [c.name for c in self.components]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise ParameterError(f"duplicate component name(s): {', '.join(sorted(dup))}")
        for c in self.connections:
            for end in (c.start, c.end):
                if end not in names:
                    raise ParameterError(f"connection {c}: unknown component {end!r} (known: {', '.join(names)})")
        if not (self.step > 0):
            raise ParameterError(f"step = {self.step!r} is out of range: must be > 0 [s]")

    def component(self, name: str) -> Component:
        """The component called ``name``."""
        for c in self.components:
            if c.name == name:
                return c
        raise KeyError(name)

    def with_parameters(self, overrides: Mapping[str, Mapping[str, Value]]) -> SystemDescription:
        """This system with parameter ``overrides`` (component name → parameter name → value)
        set over each component's own; components not named keep theirs."""
        unknown = sorted(set(overrides) - {c.name for c in self.components})
        if unknown:
            raise ParameterError(f"unknown component(s) {', '.join(unknown)} (known: {', '.join(c.name for c in self.components)})")
        comps = tuple(replace(c, parameters={**c.parameters, **overrides[c.name]}) if c.name in overrides else c
                      for c in self.components)
        return replace(self, components=comps)


def _typed(value: Value) -> tuple[str, str]:
    if isinstance(value, bool):
        return "Boolean", "true" if value else "false"
    if isinstance(value, int):
        return "Integer", str(value)
    if isinstance(value, float):
        return "Real", repr(value)
    return "String", str(value)


def write_ssd(system: SystemDescription, path: str | Path, types: Mapping[tuple[str, str], str] | None = None) -> Path:
    """Write ``system`` as an SSP 1.0 ``SystemStructure.ssd`` file; return its path.

    ``types`` maps (component, connector) to its FMI type (``Real``, ``Integer``, ``Boolean``,
    ``String``); connectors not in it are written as ``Real``.
    """
    types = types or {}
    root = ET.Element(_q("ssd", "SystemStructureDescription"), {"version": "1.0", "name": system.name})
    sys_el = ET.SubElement(root, _q("ssd", "System"), {"name": system.name})
    connected: dict[str, dict[str, str]] = {c.name: {} for c in system.components}
    for con in system.connections:
        connected[con.start][con.start_var] = "output"
        connected[con.end][con.end_var] = "input"
    elements = ET.SubElement(sys_el, _q("ssd", "Elements"))
    for comp in system.components:
        ce = ET.SubElement(elements, _q("ssd", "Component"),
                           {"name": comp.name, "source": comp.source, "type": "application/x-fmu-sharedlibrary"})
        if connected[comp.name]:
            conns = ET.SubElement(ce, _q("ssd", "Connectors"))
            for var, kind in connected[comp.name].items():
                c = ET.SubElement(conns, _q("ssd", "Connector"), {"name": var, "kind": kind})
                ET.SubElement(c, _q("ssc", types.get((comp.name, var), "Real")))
        if comp.parameters:
            binding = ET.SubElement(ET.SubElement(ce, _q("ssd", "ParameterBindings")), _q("ssd", "ParameterBinding"))
            pset = ET.SubElement(ET.SubElement(binding, _q("ssd", "ParameterValues")), _q("ssv", "ParameterSet"),
                                 {"version": "1.0", "name": f"{comp.name}_parameters"})
            params = ET.SubElement(pset, _q("ssv", "Parameters"))
            for name, value in comp.parameters.items():
                kind, text = _typed(value)
                ET.SubElement(ET.SubElement(params, _q("ssv", "Parameter"), {"name": name}), _q("ssv", kind), {"value": text})
        ann = ET.SubElement(ET.SubElement(ce, _q("ssd", "Annotations")), _q("ssc", "Annotation"), {"type": ANNOTATION})
        ET.SubElement(ann, _q("mf", "Rate"), {"multiplier": str(comp.rate)})
    cons = ET.SubElement(sys_el, _q("ssd", "Connections"))
    for con in system.connections:
        ce = ET.SubElement(cons, _q("ssd", "Connection"), {"startElement": con.start, "startConnector": con.start_var,
                                                           "endElement": con.end, "endConnector": con.end_var})
        if con.delay:
            ann = ET.SubElement(ET.SubElement(ce, _q("ssd", "Annotations")), _q("ssc", "Annotation"), {"type": ANNOTATION})
            ET.SubElement(ann, _q("mf", "Delay"), {"steps": "1"})
    exp = ET.SubElement(root, _q("ssd", "DefaultExperiment"),
                        {"startTime": repr(system.start_time), "stopTime": repr(system.stop_time)})
    ann = ET.SubElement(ET.SubElement(exp, _q("ssd", "Annotations")), _q("ssc", "Annotation"), {"type": ANNOTATION})
    ET.SubElement(ann, _q("mf", "BaseStep"), {"size": repr(system.step)})
    ET.indent(root)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ET.ElementTree(root).write(path, encoding="UTF-8", xml_declaration=True)
    return path


def _parse_value(el: ET.Element, where: str) -> Value:
    tag = el.tag.split("}")[1]
    text = el.get("value")
    try:
        if tag == "Real":
            return float(text)
        if tag == "Integer":
            return int(text)
        if tag == "Boolean":
            if text not in ("true", "false"):
                raise ValueError(text)
            return text == "true"
        if tag == "String":
            return "" if text is None else text
    except (TypeError, ValueError):
        raise ParameterError(f"{where}: value {text!r} is not a valid {tag}") from None
    raise ParameterError(f"{where}: unsupported parameter type {tag}")


def read_ssd(path: str | Path) -> SystemDescription:
    """Read a ``.ssd`` written by :func:`write_ssd` (or any SSD with inline parameter sets).

    Component ``source`` paths are returned as written (relative to the SSD's folder).
    """
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise ParameterError(f"{path}: cannot read the SSD: {exc}") from exc
    sys_el = root.find("ssd:System", NS)
    if sys_el is None:
        raise ParameterError(f"{path}: no ssd:System element")
    components = []
    for ce in sys_el.findall("ssd:Elements/ssd:Component", NS):
        name = ce.get("name")
        params: dict[str, Value] = {}
        for p in ce.findall("ssd:ParameterBindings/ssd:ParameterBinding/ssd:ParameterValues/ssv:ParameterSet/ssv:Parameters/ssv:Parameter", NS):
            (val,) = list(p)
            params[p.get("name")] = _parse_value(val, f"{path}: component {name}, parameter {p.get('name')}")
        rate_el = ce.find(f"ssd:Annotations/ssc:Annotation[@type='{ANNOTATION}']/mf:Rate", NS)
        components.append(Component(name, ce.get("source"), params, int(rate_el.get("multiplier")) if rate_el is not None else 1))
    connections = tuple(
        Connection(c.get("startElement"), c.get("startConnector"), c.get("endElement"), c.get("endConnector"),
                   c.find(f"ssd:Annotations/ssc:Annotation[@type='{ANNOTATION}']/mf:Delay", NS) is not None)
        for c in sys_el.findall("ssd:Connections/ssd:Connection", NS)
    )
    exp = root.find("ssd:DefaultExperiment", NS)
    step_el = root.find(f"ssd:DefaultExperiment/ssd:Annotations/ssc:Annotation[@type='{ANNOTATION}']/mf:BaseStep", NS)
    return SystemDescription(
        name=root.get("name", path.stem), components=tuple(components), connections=connections,
        step=float(step_el.get("size")) if step_el is not None else 0.01,
        stop_time=float(exp.get("stopTime", 600.0)) if exp is not None else 600.0,
        start_time=float(exp.get("startTime", 0.0)) if exp is not None else 0.0,
    )


def write_ssp(system: SystemDescription, fmu_dir: str | Path, dest: str | Path) -> Path:
    """Write an SSP 1.0 package: ``SystemStructure.ssd`` plus every FMU under ``resources/``.

    Component sources are resolved against ``fmu_dir`` (unless absolute) and become
    ``resources/<file>.fmu`` in the package; connector types are read from the FMUs'
    model descriptions (FMPy), so Boolean connections are typed Boolean.
    """
    import tempfile
    import zipfile

    from .system_check import check_system

    fmu_dir, dest = Path(fmu_dir), Path(dest)
    mds = check_system(system, fmu_dir)
    files: dict[str, Path] = {}
    comps = []
    for c in system.components:
        src = c.path(fmu_dir)
        files[f"resources/{src.name}"] = src
        comps.append(Component(c.name, f"resources/{src.name}", c.parameters, c.rate))
    variables = {c: {v.name: v.type for v in md.modelVariables} for c, md in mds.items()}
    types = {(name, var): variables[name][var] for con in system.connections
             for name, var in ((con.start, con.start_var), (con.end, con.end_var))}
    packaged = SystemDescription(system.name, tuple(comps), system.connections, system.step, system.stop_time,
                                 system.start_time)
    dest.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        ssd = write_ssd(packaged, Path(tmp) / "SystemStructure.ssd", types)
        with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as z:
            z.write(ssd, "SystemStructure.ssd")
            for arcname, src in files.items():
                z.write(src, arcname)
    return dest


def read_ssp(path: str | Path, into: str | Path) -> SystemDescription:
    """Unpack an ``.ssp`` into the folder ``into`` and read its ``SystemStructure.ssd``; the
    component sources are returned as absolute paths into that folder. The system is checked
    against its FMUs (:func:`~marinefmu.cosim.system_check.check_system`) before it is returned,
    so a package naming a missing FMU or variable is refused before anything is instantiated."""
    import zipfile

    path, into = Path(path), Path(into)
    try:
        with zipfile.ZipFile(path) as z:
            z.extractall(into)
    except (OSError, zipfile.BadZipFile) as exc:
        raise ParameterError(f"{path}: not a readable SSP package: {exc}") from exc
    from .system_check import check_system

    system = read_ssd(into / "SystemStructure.ssd")
    comps = tuple(Component(c.name, str((into / c.source).resolve()), c.parameters, c.rate) for c in system.components)
    system = SystemDescription(system.name, comps, system.connections, system.step, system.stop_time, system.start_time)
    check_system(system, into)
    return system
