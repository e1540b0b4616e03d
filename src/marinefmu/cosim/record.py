"""``marinefmu record``: a VesselMotion run written as a recording plus its mapping sidecar.

The scenario's VesselMotion component is run in-process (the same code its FMU runs, stepped as
:class:`~marinefmu.cosim.system.SystemRunner` steps it: end times t0 + k·h + h, the first row at
t0 the values the FMU shows after initialisation), and every row written with 17 significant
digits, so that a replay at the co-simulation step gives the live run's values bit for bit. The
sensors keep VesselMotion's names (``imu.acc.x``, ``gnss.ant1.n``, ``gnss.valid``, ``gnss.new``);
the truth is written as ``ref.*`` (``ref.roll``, ``ref.heave`` = ``truth.imu.d``, ``ref.cog.n``,
…). The sidecar, beside the CSV with the suffix ``.toml``, maps every column and states the
lever arms of the IMU, the antennas and the monitoring point.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import MarineFmuError
from ..sea.motion_model import BOOLEAN_OUTPUTS, PARAMETERS, REAL_INDEX, VesselMotion, VesselMotionParams
from ..sea.sensors import ANTENNAS
from .scenarios import Scenario, load_scenario

#: Rows written at once.
CHUNK = 8192
#: Record column ← VesselMotion output, for the truth written as ref.*.
REF_COLUMNS: dict[str, str] = {
    "ref.roll": "truth.roll", "ref.pitch": "truth.pitch", "ref.yaw": "truth.yaw", "ref.heave": "truth.imu.d",
    **{f"ref.{g}.{a}": f"truth.{g}.{a}" for g in ("imu", "imu_vel", "cog", "point") for a in "ned"},
    **{f"ref.rate.{a}": f"truth.rate.{a}" for a in "xyz"}, **{f"ref.imu_f.{a}": f"truth.imu_f.{a}" for a in "xyz"},
}
SENSOR_COLUMNS: list[str] = [*(f"imu.acc.{a}" for a in "xyz"), *(f"imu.gyro.{a}" for a in "xyz"),
                             *(f"gnss.ant{k}.{a}" for k in range(1, ANTENNAS + 1) for a in "ned")]
COLUMNS: list[str] = ["time", *SENSOR_COLUMNS, "gnss.valid", "gnss.new", *REF_COLUMNS]


@dataclass(frozen=True)
class RecordResult:
    """What :func:`record` wrote."""

    csv: Path
    mapping: Path
    rows: int
    step: float
    component: str


def vessel_params(scenario: Scenario, component: str | None = None) -> tuple[str, VesselMotionParams, int]:
    """The scenario's VesselMotion component (the first, or ``component``): its name, its
    parameters as the FMU gets them (each value cast to its variable's type) and its rate."""
    comps = [c for c in scenario.system.components if c.kind == "VesselMotion" and (component is None or c.name == component)]
    if not comps:
        raise MarineFmuError(f"scenario {scenario.name}: no VesselMotion component"
                             + (f" named {component!r}" if component else "") + " to record")
    comp = comps[0]
    kinds = {v.name: v.kind for v in PARAMETERS}
    cast = {"real": float, "integer": int, "string": str, "boolean": bool}
    values = {k: cast[kinds[k]](v) if k in kinds else v for k, v in comp.parameters.items()}
    return comp.name, VesselMotionParams.from_flat(values), comp.rate


def _sidecar(p: VesselMotionParams, csv_name: str, dt: float) -> str:
    arm = lambda v: "[" + ", ".join(repr(float(x)) for x in v) + "]"  # noqa: E731
    vec = lambda prefix, axes: "{ " + ", ".join(f'{a} = "{prefix}.{a}"' for a in axes) + " }"  # noqa: E731
    ants = "\n".join(f'ant{k} = {{ n = "gnss.ant{k}.n", e = "gnss.ant{k}.e", d = "gnss.ant{k}.d", '
                     f'lever_arm = {arm(p.gnss.antennas[k - 1])} }}' for k in range(1, ANTENNAS + 1))
    gnss_gap = max(2.0, 2.5 / p.gnss.rate)
    return f"""# Mapping of {csv_name}, written by `marinefmu record` (a VesselMotion run; SI units, NED/FRD).
[time]
column = "time"
unit = "s"

[frames]
body = "frd"
world = "ned"
acc = "specific_force"
heave = "down"

[imu]
max_gap = {max(0.5, 2.5 * dt)!r}
lever_arm = {arm(p.imu.lever_arm)}    # [m] IMU relative to the COG, body frame
acc = {vec("imu.acc", "xyz")}
gyro = {vec("imu.gyro", "xyz")}

[gnss]
max_gap = {gnss_gap!r}
new = "gnss.new"
valid = "gnss.valid"
{ants}

[ref]
max_gap = {max(0.5, 2.5 * dt)!r}
roll = "ref.roll"
pitch = "ref.pitch"
yaw = "ref.yaw"
heave = "ref.heave"          # at the IMU, positive down
imu = {vec("ref.imu", "ned")}
imu_vel = {vec("ref.imu_vel", "ned")}
cog = {vec("ref.cog", "ned")}
point = {{ n = "ref.point.n", e = "ref.point.e", d = "ref.point.d", lever_arm = {arm(p.point)} }}
rate = {vec("ref.rate", "xyz")}
imu_f = {vec("ref.imu_f", "xyz")}
"""


def record(scenario: str | Path | Scenario, out: str | Path, duration: float | None = None,
           component: str | None = None, progress: bool = False) -> RecordResult:
    """Write the scenario's VesselMotion run as ``out`` (CSV) and ``out`` with ``.toml``.

    Parameters
    ----------
    scenario : str, Path or Scenario
        Scenario file, built-in name, or a loaded scenario.
    out : str or Path
        The CSV to write.
    duration : float, optional
        Simulated time [s]; default the scenario's.
    component : str, optional
        The VesselMotion component to record (default the first).
    progress : bool
        Show a progress bar.

    Returns
    -------
    RecordResult
        The files, the number of rows (the start and one per step) and the step [s].
    """
    from tqdm import tqdm

    sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
    name, params, rate = vessel_params(sc, component)
    duration = sc.duration if duration is None else float(duration)
    if not duration > 0:
        raise MarineFmuError(f"--duration = {duration} is out of range: must be > 0 [s]")
    h = sc.step
    dt = rate * h
    t0 = sc.system.start_time
    n = int(np.floor(duration / h + 1e-9)) // rate
    if n < 1:
        raise MarineFmuError(f"duration {duration} s leaves no step of {dt} s")
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    model = VesselMotion(params)
    sensor_idx = [REAL_INDEX[c] for c in SENSOR_COLUMNS]
    ref_idx = [REAL_INDEX[c] for c in REF_COLUMNS.values()]
    flag_idx = [[v.name for v in BOOLEAN_OUTPUTS].index(f) for f in ("gnss.valid", "gnss.new")]
    buf = np.empty((min(n + 1, CHUNK), len(COLUMNS)))
    filled = 0
    with open(out, "w", encoding="utf-8") as fh, tqdm(total=n, unit="step", disable=not progress, desc="record") as bar:
        fh.write(",".join(COLUMNS) + "\n")
        for k in range(n + 1):
            if k == 0:
                t, y = t0, model.peek(t0)
            else:
                t = (t0 + (k - 1) * rate * h) + dt     # as SlaveIO.step: current_time + step_size
                y = model.step(t, dt)
                bar.update(1)
            flags = model.boolean_outputs()
            row = buf[filled]
            row[0] = t
            row[1:1 + len(sensor_idx)] = [y[i] for i in sensor_idx]
            row[1 + len(sensor_idx)] = flags[flag_idx[0]]
            row[2 + len(sensor_idx)] = flags[flag_idx[1]]
            row[3 + len(sensor_idx):] = [y[i] for i in ref_idx]
            filled += 1
            if filled == len(buf) or k == n:
                np.savetxt(fh, buf[:filled], delimiter=",", fmt="%.17g")
                filled = 0
    mapping = out.with_suffix(".toml")
    mapping.write_text(_sidecar(params, out.name, dt), encoding="utf-8")
    return RecordResult(out, mapping, n + 1, dt, name)
