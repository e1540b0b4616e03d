"""What a recording can hold, and the fixed interface of the SensorRecording FMU.

Every signal a mapping sidecar can name is a *channel* of a *group*. A group is one sensor (or
one reference signal) with its own validity: the IMU (specific force and angular rate), the GNSS
antennas, a compass heading, and the reference (truth) signals ``ref.*``. The FMU's outputs are
fixed at build time, so every group is always there: one the record lacks outputs zeros with its
validity false.

Output names are those of VesselMotion (``imu.acc.x``, ``gnss.ant1.n``, ``gnss.valid``, …), so a
system wired to VesselMotion runs on a recording by swapping that one component; truth signals
come out as ``ref.*`` rather than ``truth.*`` because a record's reference is whatever the record
holds (a simulator's truth, an MRU's own attitude), not necessarily the truth.

Conventions (the design page): NED world, FRD body, specific force f_b = R_nbᵀ(a_n − g_n), heave
positive down, SI units, radians. Records in other conventions are converted at the boundary
(:mod:`.mapping`).
"""
from __future__ import annotations

from dataclasses import dataclass

from ...variables import Variable, real, vec

#: GNSS antennas of the interface (VesselMotion's four).
ANTENNAS = 4

#: Interpolation of a group: ``linear`` between samples, or ``hold`` (sample-and-hold of epochs).
LINEAR, HOLD = "linear", "hold"


@dataclass(frozen=True)
class Group:
    """One sensor or reference signal of the interface.

    Attributes
    ----------
    name : str
        Group name in the mapping and in messages (``"imu"``, ``"gnss"``, ``"ref.roll"``).
    channels : tuple of str
        Output names of its channels, in output order.
    quantity : str
        Physical quantity of the channels (selects the allowed units, :data:`UNITS`).
    frame : str
        How frames convert it: ``"body"`` (a body-axis vector), ``"world"`` (a world-axis vector),
        ``"angle"`` (a ZYX Euler angle), ``"heave"`` (a vertical position), ``"heading"``.
    kind : str
        :data:`LINEAR` or :data:`HOLD`.
    valid : str
        Name of its validity output.
    """

    name: str
    channels: tuple[str, ...]
    quantity: str
    frame: str
    kind: str
    valid: str


def _axes(prefix: str, axes: str) -> tuple[str, ...]:
    return tuple(f"{prefix}.{a}" for a in axes)


GROUPS: tuple[Group, ...] = (
    Group("imu.acc", _axes("imu.acc", "xyz"), "acceleration", "body", LINEAR, "imu.valid"),
    Group("imu.gyro", _axes("imu.gyro", "xyz"), "rate", "body", LINEAR, "imu.valid"),
    Group("gnss", tuple(c for k in range(1, ANTENNAS + 1) for c in _axes(f"gnss.ant{k}", "ned")), "length", "world", HOLD,
          "gnss.valid"),
    Group("heading", ("heading",), "angle", "heading", LINEAR, "heading.valid"),
    Group("ref.roll", ("ref.roll",), "angle", "angle", LINEAR, "ref.roll.valid"),
    Group("ref.pitch", ("ref.pitch",), "angle", "angle", LINEAR, "ref.pitch.valid"),
    Group("ref.yaw", ("ref.yaw",), "angle", "angle", LINEAR, "ref.yaw.valid"),
    Group("ref.heave", ("ref.heave",), "length", "heave", LINEAR, "ref.heave.valid"),
    Group("ref.imu", _axes("ref.imu", "ned"), "length", "world", LINEAR, "ref.imu.valid"),
    Group("ref.imu_vel", _axes("ref.imu_vel", "ned"), "velocity", "world", LINEAR, "ref.imu_vel.valid"),
    Group("ref.cog", _axes("ref.cog", "ned"), "length", "world", LINEAR, "ref.cog.valid"),
    Group("ref.point", _axes("ref.point", "ned"), "length", "world", LINEAR, "ref.point.valid"),
    Group("ref.rate", _axes("ref.rate", "xyz"), "rate", "body", LINEAR, "ref.rate.valid"),
    Group("ref.imu_f", _axes("ref.imu_f", "xyz"), "acceleration", "body", LINEAR, "ref.imu_f.valid"),
)
GROUP = {g.name: g for g in GROUPS}

#: Allowed units per quantity and their factor to SI.
UNITS: dict[str, dict[str, float]] = {
    "acceleration": {"m/s2": 1.0, "m/s^2": 1.0, "g": 9.80665, "mm/s2": 1e-3, "cm/s2": 1e-2},
    "rate": {"rad/s": 1.0, "deg/s": 0.017453292519943295},
    "angle": {"rad": 1.0, "deg": 0.017453292519943295},
    "length": {"m": 1.0, "mm": 1e-3, "cm": 1e-2},
    "velocity": {"m/s": 1.0, "mm/s": 1e-3, "cm/s": 1e-2},
}
#: The SI unit of each quantity (the default of a mapping).
SI = {"acceleration": "m/s2", "rate": "rad/s", "angle": "rad", "length": "m", "velocity": "m/s"}

_DESCRIPTIONS = {
    "imu.acc": ("m/s2", "Recorded specific force at the IMU, body frame (FRD)"),
    "imu.gyro": ("rad/s", "Recorded angular rate, body frame (FRD)"),
    "heading": ("rad", "Recorded compass heading (yaw), NED"),
    "ref.roll": ("rad", "Reference roll from the record (ZYX Euler, NED/FRD)"),
    "ref.pitch": ("rad", "Reference pitch from the record (ZYX Euler, NED/FRD)"),
    "ref.yaw": ("rad", "Reference yaw from the record (ZYX Euler, NED/FRD)"),
    "ref.heave": ("m", "Reference heave at the IMU from the record, positive down"),
    "ref.imu": ("m", "Reference IMU position from the record, NED"),
    "ref.imu_vel": ("m/s", "Reference IMU velocity from the record, NED"),
    "ref.cog": ("m", "Reference COG position from the record, NED"),
    "ref.point": ("m", "Reference monitoring-point position from the record, NED"),
    "ref.rate": ("rad/s", "Reference (error-free) angular rate from the record, body frame (FRD)"),
    "ref.imu_f": ("m/s2", "Reference (error-free) specific force at the IMU from the record, body frame (FRD)"),
}


def _real_outputs() -> list[Variable]:
    out: list[Variable] = []
    for g in GROUPS:
        if g.name == "gnss":
            for k in range(1, ANTENNAS + 1):
                out += vec(f"gnss.ant{k}", "ned", 0.0, "m", f"Recorded position of GNSS antenna {k} (held between epochs), NED")
            continue
        unit, text = _DESCRIPTIONS[g.name]
        if len(g.channels) == 1:
            out.append(real(g.channels[0], 0.0, unit, text))
        else:
            out += vec(g.name, tuple(c.rsplit(".", 1)[1] for c in g.channels), 0.0, unit, text)
    out.append(real("record.time", 0.0, "s", "Time in the record played at this step (first sample = 0)"))
    return out


#: Real outputs, in the order of :meth:`~.player.SensorRecording.step`'s vector.
REAL_OUTPUTS: list[Variable] = _real_outputs()
#: Index of each real output.
REAL_INDEX = {v.name: i for i, v in enumerate(REAL_OUTPUTS)}

#: Validity outputs, one per group (the IMU's acc and gyro share ``imu.valid``), in order.
VALID_NAMES: tuple[str, ...] = tuple(dict.fromkeys(g.valid for g in GROUPS))
BOOLEAN_OUTPUTS: list[Variable] = [
    Variable("gnss.valid", "boolean", False, "", "True when the held GNSS epoch is a good one, not older than the mapping's max_gap, and the record has not ended"),
    Variable("gnss.new", "boolean", False, "", "True on the step in which a new GNSS epoch arrived"),
    Variable("imu.valid", "boolean", False, "", "True when both IMU samples around the step are good (no NaN) and closer than max_gap"),
    Variable("heading.valid", "boolean", False, "", "True when the record has a good compass heading at this step"),
    *[Variable(n, "boolean", False, "", f"True when the record has a good {n[:-6]} at this step (false if it has none)")
      for n in VALID_NAMES if n.startswith("ref.")],
    Variable("record.active", "boolean", False, "", "True until the end of the record (then every output holds its last value)"),
]
BOOLEAN_INDEX = {v.name: i for i, v in enumerate(BOOLEAN_OUTPUTS)}
