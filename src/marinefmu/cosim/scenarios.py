"""Scenario files (TOML): a system of FMUs, its parameters and what to record.

Format::

    [scenario]
    name = "default"
    description = "…"
    duration = 600.0        # [s], > 0
    step = 0.01             # base step [s], 1e-4 … 10

    [components.vessel]
    fmu = "VesselMotion"    # fmus/VesselMotion.fmu (or a path ending in .fmu)
    rate = 1                # steps every `rate` base steps
    [components.vessel.parameters]
    sea = { hs = 2.5, tp = 9.0 }    # nested tables are flattened to "sea.hs", "sea.tp"
    "vessel.preset" = "polar_supply"

    [[connections]]
    from = "vessel.imu.acc.x"
    to = "att.acc.x"
    # delay = true          # this connection closes a feedback loop on purpose (see cosim.system_check)

    [record]
    variables = ["vessel.truth.cog.d"]   # optional; default every output

Validation names the offending key (``scenario.duration``, ``components.vessel.rate``, …) and
refuses unknown keys rather than ignoring a typo.
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from .ssp import Component, Connection, SystemDescription
from ..errors import ParameterError, ScenarioError

_TOP = {"scenario", "components", "connections", "record"}
_SCENARIO = {"name", "description", "duration", "step"}
_COMPONENT = {"fmu", "rate", "parameters"}


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.

    Attributes
    ----------
    name, description : str
        Identification.
    duration, step : float
        Simulated time and base step [s].
    system : SystemDescription
        Components (sources relative to the FMU folder) and connections.
    record : tuple of str or None
        ``component.variable`` names to record; None = every output.
    source : str
        Where the scenario was read from.
    """

    name: str
    description: str
    duration: float
    step: float
    system: SystemDescription
    record: tuple[str, ...] | None
    source: str


def builtin_scenarios() -> list[str]:
    """Names of the scenarios shipped with the package."""
    return sorted(p.name[:-5] for p in resources.files("marinefmu").joinpath("data/scenarios").iterdir() if p.name.endswith(".toml"))


def load_scenario(spec: str | Path) -> Scenario:
    """Load a scenario from a TOML file path, or by the name of a built-in scenario."""
    path = Path(spec)
    if path.suffix != ".toml" and not path.exists():
        if str(spec) not in builtin_scenarios():
            raise ScenarioError(f"scenario {str(spec)!r} is neither a file nor a built-in scenario ({', '.join(builtin_scenarios())})")
        text = resources.files("marinefmu").joinpath(f"data/scenarios/{spec}.toml").read_text()
        return parse_scenario(text, f"<built-in {spec}>")
    try:
        text = path.read_text()
    except OSError as exc:
        raise ScenarioError(f"scenario file {path} cannot be read: {exc.strerror}") from exc
    return parse_scenario(text, str(path))


def flatten(d: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested tables as one level of dotted keys: ``{"sea": {"hs": 2}}`` → ``{"sea.hs": 2}``."""
    out: dict[str, Any] = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(flatten(v, key + "."))
        else:
            out[key] = v
    return out


def _unknown(where: str, got: dict, allowed: set[str]) -> None:
    extra = sorted(set(got) - allowed)
    if extra:
        raise ScenarioError(f"{where}: unknown key(s) {', '.join(extra)}; allowed: {', '.join(sorted(allowed))}")


def _number(src: str, key: str, value: Any, lo: float, hi: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(f"{src}: {key} must be a number, got {value!r}")
    if not (lo < value <= hi):
        raise ScenarioError(f"{src}: {key} = {value!r} is out of range: must be in ({lo}, {hi}]")
    return float(value)


def parse_scenario(text: str, source: str = "<string>") -> Scenario:
    """Parse and validate scenario TOML ``text``; ``source`` names it in messages."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{source}: not valid TOML: {exc}") from None
    _unknown(source, doc, _TOP)
    sc = doc.get("scenario")
    if not isinstance(sc, dict):
        raise ScenarioError(f"{source}: missing [scenario] table")
    _unknown(f"{source}: [scenario]", sc, _SCENARIO)
    name = sc.get("name", Path(source).stem)
    if not isinstance(name, str) or not name:
        raise ScenarioError(f"{source}: scenario.name must be a non-empty string")
    duration = _number(source, "scenario.duration", sc.get("duration", 600.0), 0.0, 1e7)
    step = _number(source, "scenario.step", sc.get("step", 0.01), 0.0, 10.0)
    comps = doc.get("components")
    if not isinstance(comps, dict) or not comps:
        raise ScenarioError(f"{source}: needs at least one [components.<name>] table")
    components = []
    for cname, c in comps.items():
        where = f"components.{cname}"
        if not isinstance(c, dict):
            raise ScenarioError(f"{source}: {where} must be a table")
        _unknown(f"{source}: [{where}]", c, _COMPONENT)
        fmu = c.get("fmu")
        if not isinstance(fmu, str) or not fmu:
            raise ScenarioError(f"{source}: {where}.fmu must name an FMU (e.g. \"VesselMotion\")")
        rate = c.get("rate", 1)
        if isinstance(rate, bool) or not isinstance(rate, int) or rate < 1:
            raise ScenarioError(f"{source}: {where}.rate = {rate!r} is out of range: must be an integer >= 1")
        params = c.get("parameters", {})
        if not isinstance(params, dict):
            raise ScenarioError(f"{source}: {where}.parameters must be a table")
        flat = flatten(params)
        for k, v in flat.items():
            if not isinstance(v, (bool, int, float, str)):
                raise ScenarioError(f"{source}: {where}.parameters.{k} must be a number, boolean or string, got {v!r}")
        try:
            components.append(Component(cname, fmu if fmu.endswith(".fmu") else f"{fmu}.fmu", flat, rate))
        except ParameterError as exc:
            raise ScenarioError(f"{source}: {exc}") from None
    connections = []
    for i, con in enumerate(doc.get("connections", [])):
        where = f"connections[{i}]"
        if not isinstance(con, dict):
            raise ScenarioError(f"{source}: {where} must be a table with 'from' and 'to'")
        _unknown(f"{source}: {where}", con, {"from", "to", "delay"})
        delay = con.get("delay", False)
        if not isinstance(delay, bool):
            raise ScenarioError(f"{source}: {where}.delay = {delay!r} must be true or false")
        try:
            connections.append(Connection.parse(con["from"], con["to"], delay))
        except (KeyError, TypeError, AttributeError):
            raise ScenarioError(f"{source}: {where} needs string keys 'from' and 'to'") from None
        except ParameterError as exc:
            raise ScenarioError(f"{source}: {where}: {exc}") from None
    rec = doc.get("record", {})
    _unknown(f"{source}: [record]", rec, {"variables"})
    variables = rec.get("variables")
    if variables is not None and (not isinstance(variables, list) or not all(isinstance(v, str) for v in variables)):
        raise ScenarioError(f"{source}: record.variables must be a list of 'component.variable' strings")
    try:
        system = SystemDescription(name, tuple(components), tuple(connections), step, duration)
    except ParameterError as exc:
        raise ScenarioError(f"{source}: {exc}") from None
    return Scenario(name, sc.get("description", ""), duration, step, system,
                    tuple(variables) if variables is not None else None, source)
