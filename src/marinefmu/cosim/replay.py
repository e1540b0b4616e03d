"""``marinefmu replay``: a recording run through the estimator FMUs.

The system is the built-in scenario ``system`` with its VesselMotion replaced by a
SensorRecording component (``rec``) playing the record: the chosen estimators keep that
scenario's parameters and wiring (the AttitudeEstimator's roll, pitch and yaw feed the
estimators that need angles, so choosing one of those brings the AttitudeEstimator along), and
their lever arms are the record's: the IMU's (``--imu`` or the mapping's ``[imu] lever_arm``),
the antennas' (the mapping's), and the monitoring point's (``--point`` or the mapping's
``[ref] point.lever_arm``), all relative to the COG in the body frame.

The fusion (GnssAccFusion) runs on four antennas as in that scenario. On a record with fewer
(one receiver) it takes ``attitude = "input"``: the AttitudeEstimator's roll and pitch (brought
along if not chosen) and the record's compass ``heading`` as the yaw rotate the specific force,
and it reads ``gnss.ant1`` only, at the mapping's ``gnss.ant1`` lever arm or, without one, at
the IMU. The yaw is the compass, a sensor as the vessel would have it, not ``ref.yaw``, which is
the reference the report scores against; a one-receiver record without a ``[heading]`` is
refused before the run.

The base step is the record's mean sample interval (rounded to 9 significant digits) unless
given, and the run lasts the record (less ``start``) unless given; a run longer than the record
is reported before it starts (and the FMU logs the end of the record when it comes).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from ..errors import MarineFmuError
from ..sea.recording.mapping import Mapping, load_mapping
from ..sea.recording.reader import Record, Summary
from ..sea.recording.schema import BOOLEAN_OUTPUTS, REAL_OUTPUTS
from .scenarios import load_scenario
from .ssp import Component, Connection, SystemDescription

#: ``--estimators`` names → (component name in the system scenario, FMU).
ESTIMATORS: dict[str, tuple[str, str]] = {
    "attitude": ("att", "AttitudeEstimator"), "reconstruction": ("recon", "DisplacementReconstructor"),
    "fusion": ("fusion", "GnssAccFusion"), "cr": ("cr", "CentreOfRotation"), "heave": ("heave", "HeaveObserver"),
}
#: The recording component's name in the system.
REC = "rec"


@dataclass(frozen=True)
class ReplayPlan:
    """A replay system and what it was built from.

    Attributes
    ----------
    system : SystemDescription
        ``rec`` and the estimators, wired.
    record : Record
        The scanned record (its :attr:`~marinefmu.sea.recording.reader.Record.summary`).
    mapping : Mapping
        The sidecar.
    estimators : tuple of str
        Component names of the estimators.
    duration : float
        Simulated time [s].
    notes : list of str
        What the plan decided (an estimator brought along, a run longer than the record, …).
    imu, point : tuple of float or None
        Lever arms used, FRD [m] relative to the COG.
    """

    system: SystemDescription
    record: Record
    mapping: Mapping
    estimators: tuple[str, ...]
    duration: float
    notes: list[str] = field(default_factory=list)
    imu: tuple[float, float, float] | None = None
    point: tuple[float, float, float] | None = None

    @property
    def summary(self) -> Summary:
        return self.record.summary


def _vector(text: str | None, what: str) -> tuple[float, float, float] | None:
    if text is None:
        return None
    try:
        v = tuple(float(x) for x in text.split(","))
    except ValueError:
        v = ()
    if len(v) != 3 or not all(math.isfinite(x) for x in v):
        raise MarineFmuError(f"{what} = {text!r} must be three numbers x,y,z [m]")
    return v  # type: ignore[return-value]


def plan_replay(record: str | Path, mapping: str | Path, estimators: str | list[str] = "attitude,heave",
                imu: str | tuple | None = None, point: str | tuple | None = None, step: float | None = None,
                duration: float | None = None, start: float = 0.0,
                parameters: dict[str, Any] | None = None, fmu: str = "SensorRecording.fmu") -> ReplayPlan:
    """Build the replay system (module docstring).

    Parameters
    ----------
    record, mapping : str or Path
        The record and its sidecar.
    estimators : str or list of str
        Names from :data:`ESTIMATORS`, comma-separated or a list.
    imu, point : str or tuple, optional
        Lever arms ``x,y,z`` [m] (FRD, relative to the COG) overriding the mapping's.
    step, duration : float, optional
        Base step and simulated time [s] (defaults: module docstring).
    start : float
        Offset into the record [s].
    parameters : dict, optional
        ``"component.parameter"`` → value, overriding the scenario's (e.g. ``"att.acc_noise"``).
    fmu : str
        The recording FMU's source (relative to the FMU folder, or absolute).

    Raises
    ------
    MarineFmuError
        An unknown estimator, a bad lever arm, an estimator the record cannot feed; the record's
        own refusals (:class:`~marinefmu.sea.recording.mapping.RecordingError`).
    """
    names = [e.strip() for e in (estimators.split(",") if isinstance(estimators, str) else estimators) if e.strip()]
    unknown = [e for e in names if e not in ESTIMATORS]
    if unknown or not names:
        raise MarineFmuError(f"--estimators: unknown {', '.join(map(repr, unknown)) or 'none given'}; choose from "
                             f"{', '.join(ESTIMATORS)}")
    m = load_mapping(mapping)
    rec = Record(record, m)
    notes: list[str] = []
    s = rec.summary
    imu_arm = _vector(imu, "--imu") if isinstance(imu, (str, type(None))) else tuple(map(float, imu))
    point_arm = _vector(point, "--point") if isinstance(point, (str, type(None))) else tuple(map(float, point))
    imu_arm = imu_arm or m.lever_arms.get("imu")
    point_arm = point_arm or m.lever_arms.get("ref.point")
    comps = [ESTIMATORS[e][0] for e in names]
    antennas = m.antennas()
    # fewer than four antennas: one receiver, the attitude from the AttitudeEstimator and the compass
    one_receiver = "fusion" in comps and 0 < len(antennas) < 4
    if (one_receiver or any(c in comps for c in ("recon", "cr", "heave"))) and "att" not in comps:
        comps.insert(0, "att")
        notes.append("the AttitudeEstimator was added: it gives the roll and pitch the other estimators need")
    if one_receiver and 1 not in antennas:
        raise MarineFmuError(f"--estimators fusion: with fewer than four antennas GnssAccFusion reads gnss.ant1 (one "
                             f"receiver); the mapping {m.source} maps {', '.join(f'ant{k}' for k in antennas)}")
    if one_receiver and "heading" not in m.channels:
        raise MarineFmuError(f"--estimators fusion: GnssAccFusion needs four GNSS antennas, or one receiver and a compass "
                             f"heading for its yaw; the mapping {m.source} has {len(antennas)} antenna(s) and no [heading]")
    if one_receiver and len(antennas) > 1:
        notes.append(f"fusion: {len(antennas)} antennas, not four: one receiver, gnss.ant1, is used")
    if "fusion" in comps and not one_receiver and any(f"gnss.ant{k}" not in m.lever_arms for k in antennas):
        raise MarineFmuError(f"--estimators fusion: the mapping {m.source} must state every antenna's lever_arm")
    needs = {"att": ("imu.acc", "imu.gyro"), "recon": ("imu.acc",), "fusion": ("imu.acc", "gnss"),
             "cr": ("imu.acc", "imu.gyro"), "heave": ("imu.acc",)}
    for c in comps:
        missing = [g for g in needs[c] if g not in m.channels]
        if missing:
            raise MarineFmuError(f"{c}: needs {', '.join(missing)} in the record; the mapping {m.source} has none")
    if step is None:
        step = float(f"{s.duration / max(1, s.rows - 1):.9g}")
    sc = load_scenario("system")
    by_name = {c.name: c for c in sc.system.components}
    arm = lambda prefix, v: {f"{prefix}.{a}": float(x) for a, x in zip("xyz", v)}  # noqa: E731
    components = [Component(REC, fmu, {"file": str(Path(record).resolve()), "mapping": str(Path(mapping).resolve()),
                                       "start": float(start)})]
    for c in comps:
        p = dict(by_name[c].parameters)
        if imu_arm is not None:
            p.update({"recon": arm("lever_arm", imu_arm), "fusion": arm("acc_lever_arm", imu_arm),
                      "cr": arm("sensor", imu_arm)}.get(c, {}))
        elif c in ("recon", "fusion", "cr"):
            p.update({"recon": arm("lever_arm", (0, 0, 0)), "fusion": arm("acc_lever_arm", (0, 0, 0)),
                      "cr": arm("sensor", (0, 0, 0))}[c])
            notes.append(f"{c}: no IMU lever arm in the mapping or --imu: the IMU is taken at the COG")
        if c == "fusion" and one_receiver:
            # the AttitudeEstimator's roll and pitch arrive one step late (Jacobi coupling)
            p.update({"attitude": "input", "attitude_lag": float(step)})
            receiver = m.lever_arms.get("gnss.ant1")
            if receiver is None:
                notes.append("fusion: no lever arm for gnss.ant1 in the mapping: the receiver is taken at the IMU")
            p.update(arm("ant1", receiver or imu_arm or (0.0, 0.0, 0.0)))
        elif c == "fusion":
            for k in antennas:
                p.update(arm(f"ant{k}", m.lever_arms[f"gnss.ant{k}"]))
        if c == "heave":
            if point_arm is not None:
                rel = [pp - ii for pp, ii in zip(point_arm, imu_arm or (0.0, 0.0, 0.0))]
                p.update(arm("point", rel))
            else:
                p.update(arm("point", (0.0, 0.0, 0.0)))
                notes.append("heave: no monitoring point (--point or [ref] point.lever_arm): point.heave is at the IMU")
        components.append(Component(c, by_name[c].source, p, 1))
    for key, value in (parameters or {}).items():
        comp, _, var = key.partition(".")
        idx = [i for i, c in enumerate(components) if c.name == comp]
        if not idx or not var:
            raise MarineFmuError(f"--set {key}: unknown component {comp!r} (the system has {', '.join(c.name for c in components)})")
        c = components[idx[0]]
        components[idx[0]] = replace(c, parameters={**c.parameters, var: value})
    names_set = set(comps) | {REC}
    connections = []
    for con in sc.system.connections:
        start_c = REC if con.start == "vessel" else con.start
        unused = one_receiver and con.end == "fusion" and con.end_var.startswith(("gnss.ant2", "gnss.ant3", "gnss.ant4"))
        if start_c in names_set and con.end in names_set and not unused:
            connections.append(Connection(start_c, con.start_var, con.end, con.end_var, con.delay))
    if one_receiver:
        connections += [Connection("att", "roll", "fusion", "roll"), Connection("att", "pitch", "fusion", "pitch"),
                        Connection(REC, "heading", "fusion", "yaw")]
    available = s.duration - start
    if duration is None:
        duration = available
        n = math.floor(duration / step + 1e-9)
        duration = n * step
    elif duration > available + 1e-9:
        notes.append(f"the run ({duration:g} s) is longer than the record from start = {start:g} s ({available:g} s): "
                     "after the record's end every output holds and every valid is false")
    if not duration >= step:
        raise MarineFmuError(f"the record ({s.duration:g} s) leaves no step of {step:g} s after start = {start:g} s")
    system = SystemDescription(f"replay of {Path(record).name}", tuple(components), tuple(connections), float(step),
                               float(duration))
    return ReplayPlan(system, rec, m, tuple(comps), float(duration), notes, imu_arm, point_arm)


def recording_outputs() -> list[str]:
    """Names of the recording FMU's outputs (real then boolean)."""
    return [v.name for v in REAL_OUTPUTS] + [v.name for v in BOOLEAN_OUTPUTS]


def run_replay(plan: ReplayPlan, fmu_dir: str | Path, out_dir: str | Path | None = None, engine: str = "fmpy",
               progress: bool | None = None):
    """Run the plan; return (result, runner). Streams to ``out_dir/results.npy`` when given."""
    from .system import SystemRunner

    runner = SystemRunner(plan.system, fmu_dir, engine=engine)
    out_file = None if out_dir is None else Path(out_dir) / "results.npy"
    result = runner.run(plan.system.start_time + plan.duration, record=None, progress=progress, out_file=out_file)
    return result, runner
