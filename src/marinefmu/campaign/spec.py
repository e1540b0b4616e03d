"""Campaign specification (TOML): which system, what to vary, what to keep.

Format::

    [campaign]
    name = "scatter"            # default: the file's stem
    scenario = "system"         # a built-in scenario, a scenario TOML or an .ssp package (relative to this file)
    duration = 600.0            # simulated time per run [s], (0, 1e6]; default the scenario's
    settle = 60.0               # not scored after each estimator's valid goes true [s], [0, duration)
    timeout = 3600.0            # wall-time limit per run [s], (0, 1e6]; a run past it is recorded as failed
    engine = "fmpy"             # "fmpy" (FMI through FMPy) or "python" (the slave code in-process)
    vessel = "vessel"           # the VesselMotion component whose truth scores the others
    metrics = ["heave.heave_cm", "att.roll_deg"]   # component.metric to keep; default every one
    keep_series = false         # also keep each run's recorded time series (series/<id>.npy)

    [grid]                      # component.parameter = values; the runs are the Cartesian product
    "vessel.sea.hs" = [1.0, 2.0, 3.0]
    "vessel.sea.tp" = { start = 6.0, stop = 14.0, step = 2.0 }    # or { start, stop, num }
    "vessel.sea.seed" = [1, 2]

    [sets.placement.bridge]     # a labelled axis of the grid: each label sets several
    "vessel.imu" = { x = 5.0, y = 1.0, z = -3.0 }   # parameters together (nested tables
    "heave.point" = { x = 57.0, y = -1.0, z = -9.0 } # flatten to vessel.imu.x, …)
    [sets.placement.keel]
    "vessel.imu" = { x = 0.0, y = 0.0, z = 5.0 }
    "heave.point" = { x = 62.0, y = 0.0, z = -17.0 }

Everything is checked by :func:`load_spec` before anything runs, and a refusal names the key:
unknown keys, an empty grid, a component or parameter the scenario's FMUs do not have, a value of
the wrong type, a parameter both in ``[grid]`` and in a set, an unknown metric, and a value the
FMU itself refuses (each distinct value is tried alone on the scenario's component, in-process,
as :class:`~marinefmu.cosim.system.SystemRunner` with ``engine = "python"`` initialises it).
Values that are valid alone but not together are found when the run starts; that run is
recorded as failed with the FMU's message and the campaign goes on.
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ParameterError, ScenarioError, SystemError_
from ..cosim.scenarios import Scenario, flatten, load_scenario

_TOP = {"campaign", "grid", "sets"}
_CAMPAIGN = {"name", "scenario", "duration", "settle", "timeout", "engine", "vessel", "metrics", "keep_series"}
#: Most runs a campaign may have (a typo such as a step of 0.001 should not start a million runs).
MAX_RUNS = 100_000
Value = float | int | bool | str


class CampaignSpecError(ScenarioError):
    """A campaign specification is malformed; the message names the offending key."""


@dataclass(frozen=True)
class Run:
    """One run of a campaign.

    Attributes
    ----------
    id : str
        Stable identity (a hash of the system, duration, settle, engine and the run's values):
        a rerun of the campaign skips the runs whose id is already in its table.
    values : dict
        Grid key (``component.parameter``) → value, and set axis → label, as the table's columns.
    overrides : dict
        Component → parameter → value set over the scenario's.
    """

    id: str
    values: dict[str, Value]
    overrides: dict[str, dict[str, Value]]


@dataclass(frozen=True)
class CampaignSpec:
    """A validated campaign (module docstring); :meth:`runs` lists its runs. The scenario's
    components name their FMUs by file name only, in ``fmu_dir`` (the FMU folder given, or
    where an SSP package was unpacked), so run ids do not depend on where the files are."""

    name: str
    scenario: Scenario
    duration: float
    settle: float
    timeout: float
    engine: str
    vessel: str
    metrics: tuple[str, ...] | None
    keep_series: bool
    grid: dict[str, tuple[Value, ...]]
    sets: dict[str, dict[str, dict[str, Value]]]
    fmu_dir: Path = Path("fmus")
    source: str = ""
    text: str = field(default="", repr=False)

    @property
    def axes(self) -> list[str]:
        """The table's parameter columns: the grid keys, then the set axes."""
        return [*self.grid, *self.sets]

    def runs(self) -> list[Run]:
        """Every run: the Cartesian product of the grid's values and the sets' labels."""
        base = json.dumps([repr(self.scenario.system), self.scenario.record, self.duration, self.settle, self.engine,
                           self.vessel], sort_keys=True)
        dims = [[(k, v) for v in vals] for k, vals in self.grid.items()]
        dims += [[(axis, label) for label in labels] for axis, labels in self.sets.items()]
        out = []
        for combo in itertools.product(*dims):
            values = dict(combo)
            overrides: dict[str, dict[str, Value]] = {}
            for key, v in combo:
                if key in self.sets:
                    for p, pv in self.sets[key][v].items():
                        comp, par = p.split(".", 1)
                        overrides.setdefault(comp, {})[par] = pv
                else:
                    comp, par = key.split(".", 1)
                    overrides.setdefault(comp, {})[par] = v
            ident = hashlib.sha1(json.dumps([base, overrides], sort_keys=True).encode()).hexdigest()[:16]
            out.append(Run(ident, values, overrides))
        return out


def _fail(source: str, msg: str) -> CampaignSpecError:
    return CampaignSpecError(f"{source}: {msg}")


def _number(source: str, key: str, value: Any, lo: float, hi: float, lo_closed: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise _fail(source, f"{key} must be a finite number, got {value!r}")
    if not ((lo <= value if lo_closed else lo < value) and value <= hi):
        raise _fail(source, f"{key} = {value!r} is out of range: must be in {'[' if lo_closed else '('}{lo:g}, {hi:g}]")
    return float(value)


def _grid_values(source: str, key: str, spec: Any) -> tuple[Value, ...]:
    """A grid entry: a non-empty list, or a range table {start, stop, step} / {start, stop, num}."""
    where = f"grid.{key!r}"
    if isinstance(spec, list):
        if not spec:
            raise _fail(source, f"{where} is empty: give at least one value")
        for v in spec:
            if not isinstance(v, (bool, int, float, str)):
                raise _fail(source, f"{where}: {v!r} is not a number, boolean or string")
            if isinstance(v, float) and not math.isfinite(v):
                raise _fail(source, f"{where}: {v!r} is not finite")
        if len(set(map(repr, spec))) != len(spec):
            raise _fail(source, f"{where} repeats a value: {spec!r}")
        return tuple(spec)
    if isinstance(spec, dict):
        keys = set(spec)
        if keys not in ({"start", "stop", "step"}, {"start", "stop", "num"}):
            raise _fail(source, f"{where} must be a list or a table {{start, stop, step}} or {{start, stop, num}}, "
                        f"got keys {sorted(keys)}")
        start = _number(source, f"{where}.start", spec["start"], -math.inf, math.inf)
        stop = _number(source, f"{where}.stop", spec["stop"], -math.inf, math.inf)
        if stop < start:
            raise _fail(source, f"{where}: stop = {stop:g} is below start = {start:g}")
        if "num" in spec:
            num = spec["num"]
            if isinstance(num, bool) or not isinstance(num, int) or not 1 <= num <= MAX_RUNS:
                raise _fail(source, f"{where}.num = {num!r} is out of range: must be an integer in [1, {MAX_RUNS}]")
            if num == 1:
                return (start,)
            return tuple(start + (stop - start) * i / (num - 1) for i in range(num))
        step = _number(source, f"{where}.step", spec["step"], 0.0, math.inf)
        n = int(math.floor((stop - start) / step + 1e-9)) + 1
        if n > MAX_RUNS:
            raise _fail(source, f"{where}: {n} values; at most {MAX_RUNS}")
        ints = all(isinstance(spec[k], int) and not isinstance(spec[k], bool) for k in ("start", "step"))
        return tuple(int(spec["start"]) + int(spec["step"]) * i if ints else round(start + step * i, 12) for i in range(n))
    raise _fail(source, f"{where} must be a list of values or a range table, got {spec!r}")


def load_spec(path: str | Path, fmu_dir: str | Path, check_values: bool = True) -> CampaignSpec:
    """Read and validate a campaign file (module docstring).

    Parameters
    ----------
    path : str or Path
        The campaign TOML.
    fmu_dir : str or Path
        Folder of the built FMUs (``fmus/``), to check parameter names, types and values.
    check_values : bool
        Try every distinct value on its FMU, in-process (module docstring); seconds for a
        large grid.

    Raises
    ------
    CampaignSpecError
        Naming the offending key.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise CampaignSpecError(f"campaign file {path} cannot be read: {exc.strerror}") from None
    return parse_spec(text, fmu_dir, str(path), path.parent, check_values)


def parse_spec(text: str, fmu_dir: str | Path, source: str = "<string>", base: Path | None = None,
               check_values: bool = True) -> CampaignSpec:
    """Parse and validate campaign TOML ``text`` (see :func:`load_spec`); ``base`` is the folder
    that a relative scenario path is resolved against."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise _fail(source, f"not valid TOML: {exc}") from None
    extra = sorted(set(doc) - _TOP)
    if extra:
        raise _fail(source, f"unknown key(s) {', '.join(extra)}; allowed: {', '.join(sorted(_TOP))}")
    camp = doc.get("campaign")
    if not isinstance(camp, dict):
        raise _fail(source, "missing [campaign] table")
    extra = sorted(set(camp) - _CAMPAIGN)
    if extra:
        raise _fail(source, f"[campaign]: unknown key(s) {', '.join(extra)}; allowed: {', '.join(sorted(_CAMPAIGN))}")
    sc_name = camp.get("scenario")
    if not isinstance(sc_name, str) or not sc_name:
        raise _fail(source, "campaign.scenario must name a built-in scenario or a scenario TOML file")
    sc_path = Path(sc_name)
    if sc_path.suffix in (".toml", ".ssp") and not sc_path.is_absolute() and base is not None:
        sc_path = base / sc_path
    try:
        scenario, fmu_dir = (_ssp_scenario(sc_path) if sc_path.suffix == ".ssp" else
                             (load_scenario(sc_path if sc_path.suffix == ".toml" else sc_name), Path(fmu_dir)))
    except (ScenarioError, SystemError_, ParameterError) as exc:
        raise _fail(source, f"campaign.scenario: {exc}") from None
    name = camp.get("name", Path(source).stem)
    if not isinstance(name, str) or not name or any(c in name for c in "/\\"):
        raise _fail(source, "campaign.name must be a non-empty string without slashes")
    duration = _number(source, "campaign.duration", camp.get("duration", scenario.duration), 0.0, 1e6)
    settle = _number(source, "campaign.settle", camp.get("settle", 60.0), 0.0, math.inf, lo_closed=True)
    if settle >= duration:
        raise _fail(source, f"campaign.settle = {settle:g} is out of range: must be below campaign.duration = {duration:g} s")
    timeout = _number(source, "campaign.timeout", camp.get("timeout", 3600.0), 0.0, 1e6)
    engine = camp.get("engine", "fmpy")
    if engine not in ("fmpy", "python"):
        raise _fail(source, f"campaign.engine = {engine!r} is not allowed: must be 'fmpy' or 'python'")
    keep = camp.get("keep_series", False)
    if not isinstance(keep, bool):
        raise _fail(source, f"campaign.keep_series = {keep!r} must be true or false")

    from ..cosim.system_check import check_system, lookup, value_fits
    from ..analysis.scoring import COMMON_METRICS, METRICS

    system = scenario.system
    try:
        mds = check_system(system, fmu_dir)
    except SystemError_ as exc:
        raise _fail(source, f"campaign.scenario {sc_name!r}: {exc}") from None
    kinds = {c.name: c.kind for c in system.components}
    vessels = [n for n, k in kinds.items() if k == "VesselMotion"]
    vessel = camp.get("vessel", vessels[0] if len(vessels) == 1 else None)
    if vessel not in vessels:
        raise _fail(source, f"campaign.vessel = {vessel!r} must name the VesselMotion component whose truth scores "
                    f"the others ({', '.join(vessels) or 'the scenario has none'})")

    metrics = camp.get("metrics")
    if metrics is not None:
        if not isinstance(metrics, list) or not metrics or not all(isinstance(m, str) for m in metrics):
            raise _fail(source, "campaign.metrics must be a non-empty list of 'component.metric' strings")
        for m in metrics:
            comp, _, metric = m.partition(".")
            if comp not in kinds or kinds[comp] not in METRICS:
                scored = [n for n, k in kinds.items() if k in METRICS]
                raise _fail(source, f"campaign.metrics: {m!r}: {comp!r} is not a scored component of the scenario "
                            f"({', '.join(scored)})")
            if metric not in METRICS[kinds[comp]] + COMMON_METRICS:
                raise _fail(source, f"campaign.metrics: {m!r}: a {kinds[comp]} has no metric {metric!r} "
                            f"({', '.join(METRICS[kinds[comp]] + COMMON_METRICS)})")
        metrics = tuple(metrics)

    def parameter(where: str, key: str, value: Value) -> None:
        comp, dot, par = key.partition(".")
        if not dot or comp not in kinds:
            raise _fail(source, f"{where}: {key!r} must be 'component.parameter' with a component of the scenario "
                        f"({', '.join(kinds)})")
        try:
            v = lookup(mds[comp], comp, par, ("parameter",))
        except SystemError_ as exc:
            raise _fail(source, f"{where}: {exc}") from None
        if not value_fits(v.type, value):
            raise _fail(source, f"{where}: {key} is {v.type}; cannot set it to {value!r}")

    grid_doc = doc.get("grid", {})
    if not isinstance(grid_doc, dict):
        raise _fail(source, "[grid] must be a table of 'component.parameter' = values")
    grid: dict[str, tuple[Value, ...]] = {}
    for key, spec in grid_doc.items():
        grid[key] = _grid_values(source, key, spec)
        for v in grid[key]:
            parameter(f"grid.{key!r}", key, v)
    sets_doc = doc.get("sets", {})
    if not isinstance(sets_doc, dict):
        raise _fail(source, "[sets] must hold tables [sets.<axis>.<label>]")
    sets: dict[str, dict[str, dict[str, Value]]] = {}
    for axis, labels in sets_doc.items():
        if axis in grid or not isinstance(labels, dict) or not labels:
            raise _fail(source, f"sets.{axis} must hold at least one table [sets.{axis}.<label>] and not be a grid key")
        sets[axis] = {}
        for label, params in labels.items():
            if not isinstance(params, dict) or not params:
                raise _fail(source, f"sets.{axis}.{label} must be a non-empty table of 'component.parameter' = value")
            flat = flatten(params)
            for key, v in flat.items():
                parameter(f"sets.{axis}.{label}", key, v)
                if key in grid:
                    raise _fail(source, f"sets.{axis}.{label}: {key} is also in [grid]; set it in one place")
            sets[axis][label] = flat
        keys = [set(p) for p in sets[axis].values()]
        if any(k != keys[0] for k in keys):
            raise _fail(source, f"sets.{axis}: every label must set the same parameters (got {sorted(map(sorted, keys))})")
    if not grid and not sets:
        raise _fail(source, "the campaign varies nothing: give [grid] values or [sets] labels")
    n_runs = math.prod(len(v) for v in grid.values()) * math.prod(len(v) for v in sets.values())
    if n_runs > MAX_RUNS:
        raise _fail(source, f"{n_runs} runs; at most {MAX_RUNS}")
    spec = CampaignSpec(name, scenario, duration, settle, timeout, engine, vessel, metrics, keep, grid, sets,
                        Path(fmu_dir), source, text)
    if check_values:
        check_values_alone(spec, spec.fmu_dir)
    return spec


def _ssp_scenario(path: Path) -> tuple[Scenario, Path]:
    """An SSP package as a scenario, unpacked into a folder of this process (removed at exit);
    its components name their FMUs by file name in that folder."""
    import atexit
    import shutil
    import tempfile
    from dataclasses import replace

    from ..cosim.ssp import read_ssp

    into = Path(tempfile.mkdtemp(prefix="marinefmu_campaign_ssp_"))
    atexit.register(shutil.rmtree, into, ignore_errors=True)
    system = read_ssp(path, into)
    comps = tuple(replace(c, source=Path(c.source).relative_to(into.resolve()).as_posix()) for c in system.components)
    system = replace(system, components=comps)
    return Scenario(system.name, f"SSP package {path}", system.stop_time - system.start_time, system.step, system,
                    None, str(path)), into


def check_values_alone(spec: CampaignSpec, fmu_dir: str | Path) -> None:
    """Initialise each varied component once per distinct value (alone, over the scenario's own
    parameters), in-process, and refuse the first value its FMU refuses, naming the key."""
    from ..cosim.ssp import SystemDescription
    from ..cosim.system import SystemRunner

    tries: list[tuple[str, str, dict[str, Value]]] = []
    for key, values in spec.grid.items():
        comp, par = key.split(".", 1)
        tries += [(f"grid.{key!r} = {v!r}", comp, {par: v}) for v in values]
    for axis, labels in spec.sets.items():
        for label, params in labels.items():
            by_comp: dict[str, dict[str, Value]] = {}
            for p, v in params.items():
                comp, par = p.split(".", 1)
                by_comp.setdefault(comp, {})[par] = v
            tries += [(f"sets.{axis}.{label}", comp, pars) for comp, pars in by_comp.items()]
    system = spec.scenario.system
    for where, comp, pars in tries:
        alone = SystemDescription(f"check_{comp}", (system.component(comp),), (), system.step, system.step)
        try:
            SystemRunner(alone.with_parameters({comp: pars}), fmu_dir, engine="python").run(record=[], progress=False)
        except SystemError_ as exc:
            raise _fail(spec.source, f"{where}: refused: {exc}") from None
