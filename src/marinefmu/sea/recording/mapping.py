"""The mapping sidecar (TOML): which column of a record is which signal, in which unit and frame.

A sidecar names the time column and its unit, a column per signal (with an optional scale and
offset), the units, the record's frames and the sensors' lever arms. Everything is converted at
the boundary into the project's conventions (NED world, FRD body, specific force, heave positive
down, SI units, radians; the design page):

.. code-block:: toml

    [record]                 # optional
    delimiter = ","          # CSV field delimiter
    header_line = 1          # the line holding the column names (lines before it are skipped)

    [time]
    column = "time"
    unit = "s"               # s, ms, us (or µs), ns, or iso8601 (text such as YYYY-MM-DDThh:mm:ss.ffZ)
    rate = 10.24             # optional [Hz]: uniform samples whose stamps are only rounded: row k is at
                             # k / rate, each stamp checked to lie within half a sample of it

    [frames]                 # optional; these are the defaults
    body = "frd"             # frd (x forward, y starboard, z down) or flu (x forward, y port, z up)
    world = "ned"            # ned or enu
    acc = "specific_force"   # or "gravity_removed": body-axis acceleration without gravity
    heave = "down"           # ref.heave positive down, or "up"

    [imu]
    max_gap = 0.5            # [s] a longer gap between two samples sets imu.valid false
    lever_arm = [5.0, 1.0, -3.0]   # [m] IMU relative to the COG, record's body axes (optional)
    acc = { x = "ax", y = "ay", z = "az", unit = "g" }
    gyro = { x = "gx", y = "gy", z = { column = "gz", scale = -1.0, offset = 0.0 }, unit = "deg/s" }

    [gnss]
    max_gap = 2.0            # [s] since the last epoch
    new = "fix_new"          # optional column: non-zero on rows that carry a new epoch
    valid = "fix_ok"         # optional column: non-zero for a good epoch
    ant1 = { n = "n1", e = "e1", d = "d1", unit = "m", lever_arm = [10.0, -5.0, -20.0] }

    [heading]                # a compass (optional)
    column = "hdg"
    unit = "deg"

    [ref]                    # reference signals, scored by `marinefmu replay` (all optional)
    max_gap = 0.5
    roll = { column = "roll", unit = "deg" }
    pitch = { column = "pitch", unit = "deg" }
    yaw = { column = "yaw", unit = "deg" }
    heave = { column = "heave", unit = "m" }
    imu = { n = "x", e = "y", d = "z" }              # also cog, point (point takes a lever_arm)
    imu_vel = { n = "vx", e = "vy", d = "vz" }
    rate = { x = "p", y = "q", z = "r", unit = "deg/s" }
    imu_f = { x = "fx", y = "fy", z = "fz" }

A channel is a column name, or a table ``{column, scale = 1, offset = 0, unit}``: the SI value is
``(raw · scale + offset) · unit factor``. World vectors take the record's own axis letters
(``n, e, d`` for ``world = "ned"``, ``e, n, u`` for ``"enu"``); body vectors take ``x, y, z`` of
the record's body axes. Conversions:

- body ``flu`` → FRD: y and z change sign (vectors and lever arms);
- world ``enu`` → NED: n = n, e = e, d = −u;
- Euler angles (ZYX) of a record in other frames: for ``enu``/``flu`` roll is kept, pitch changes
  sign and yaw becomes π/2 − yaw; any other mix is converted through the rotation matrix
  R_nb = A R_rec B (A: record world axes → NED, B: FRD → record body axes) and needs all three
  angles;
- ``acc = "gravity_removed"``: f_b = a_b − R_nbᵀ g_n, g_n = [0, 0, g] (needs ``ref.roll`` and
  ``ref.pitch``);
- ``heave = "up"``: ref.heave changes sign.

Anything the mapping does not know (a key, a unit, a frame) is refused with a
:class:`RecordingError` naming the sidecar and the key.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ...errors import ParameterError
from .schema import ANTENNAS, GROUP, GROUPS, HOLD, SI, UNITS

G = 9.80665  # [m/s²] standard gravity, as frames.GRAVITY

TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6, "ns": 1e-9, "iso8601": 0.0}
BODY_FRAMES = ("frd", "flu")
WORLD_FRAMES = ("ned", "enu")
ACC_KINDS = ("specific_force", "gravity_removed")
HEAVE_SIGNS = ("down", "up")
#: Default max_gap [s] per section.
DEFAULT_GAP = {"imu": 0.5, "gnss": 2.0, "heading": 1.0, "ref": 0.5}

_TOP = {"record", "time", "frames", "imu", "gnss", "heading", "ref"}
_REF = {"roll", "pitch", "yaw", "heave", "imu", "imu_vel", "cog", "point", "rate", "imu_f", "max_gap"}


class RecordingError(ParameterError):
    """A record or its mapping cannot be used: the message names the file, the column and,
    where it applies, the line."""


@dataclass(frozen=True)
class Channel:
    """One mapped column.

    Attributes
    ----------
    output : str
        The output it feeds (``"imu.acc.x"``), before frame conversion (the record's own axis:
        ``"gnss.ant1.u"`` for an ENU record).
    column : str
        Column name in the record.
    scale, offset : float
        ``raw · scale + offset`` in the record's unit.
    factor : float
        Unit factor to SI.
    """

    output: str
    column: str
    scale: float = 1.0
    offset: float = 0.0
    factor: float = 1.0


@dataclass(frozen=True)
class Mapping:
    """A validated mapping sidecar (module docstring).

    Attributes
    ----------
    source : str
        Where it was read from (for messages).
    delimiter : str
        CSV delimiter.
    header_line : int
        1-based line of the column names.
    time_column, time_unit : str
        Time column and unit (:data:`TIME_UNITS`).
    time_rate : float or None
        Sample rate [Hz] of a uniform record with rounded stamps (row k at k / rate), or None.
    body, world, acc, heave : str
        The record's frames.
    channels : dict of str to tuple of Channel
        Group name → its channels in the record's axis order (only mapped groups).
    max_gap : dict of str to float
        Group name → longest gap between samples (``gnss``: since the last epoch) [s].
    gnss_new, gnss_valid : str or None
        Optional GNSS epoch flag columns.
    lever_arms : dict of str to tuple of float
        ``"imu"``, ``"gnss.ant1"`` … ``"ref.point"`` → lever arm relative to the COG, FRD [m]
        (only those the mapping states).
    """

    source: str
    delimiter: str = ","
    header_line: int = 1
    time_column: str = "time"
    time_unit: str = "s"
    time_rate: float | None = None
    body: str = "frd"
    world: str = "ned"
    acc: str = "specific_force"
    heave: str = "down"
    channels: dict[str, tuple[Channel, ...]] = field(default_factory=dict)
    max_gap: dict[str, float] = field(default_factory=dict)
    gnss_new: str | None = None
    gnss_valid: str | None = None
    lever_arms: dict[str, tuple[float, float, float]] = field(default_factory=dict)

    @property
    def columns(self) -> list[str]:
        """Every column the mapping reads (time first), each once."""
        cols = [self.time_column] + [c.column for chans in self.channels.values() for c in chans]
        cols += [c for c in (self.gnss_new, self.gnss_valid) if c]
        return list(dict.fromkeys(cols))

    def antennas(self) -> list[int]:
        """Numbers (1-based) of the mapped GNSS antennas."""
        return sorted({int(c.output.split(".")[1][3:]) for c in self.channels.get("gnss", ())})


def load_mapping(path: str | Path) -> Mapping:
    """Read and validate a mapping sidecar.

    Raises
    ------
    RecordingError
        The file is missing or unreadable, not TOML, or names an unknown key, unit or frame.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise RecordingError(f"mapping {path}: cannot be read: {exc.strerror or exc}") from None
    return parse_mapping(text, str(path))


def parse_mapping(text: str, source: str = "<mapping>") -> Mapping:
    """Parse and validate mapping TOML ``text``; ``source`` names it in messages."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise RecordingError(f"mapping {source}: not valid TOML: {exc}") from None
    return _Parser(source).parse(doc)


class _Parser:
    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, msg: str) -> RecordingError:
        return RecordingError(f"mapping {self.source}: {msg}")

    def table(self, doc: dict, key: str, allowed: set[str]) -> dict:
        t = doc.get(key, {})
        if not isinstance(t, dict):
            raise self.fail(f"[{key}] must be a table")
        extra = sorted(set(t) - allowed)
        if extra:
            raise self.fail(f"[{key}]: unknown key(s) {', '.join(extra)}; allowed: {', '.join(sorted(allowed))}")
        return t

    def choice(self, where: str, value: Any, choices: tuple[str, ...] | dict) -> str:
        if value not in choices:
            raise self.fail(f"{where} = {value!r} is not known: must be one of {', '.join(choices)}")
        return value

    def number(self, where: str, value: Any, positive: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise self.fail(f"{where} must be a finite number, got {value!r}")
        if positive and value <= 0:
            raise self.fail(f"{where} = {value!r} is out of range: must be > 0")
        return float(value)

    def arm(self, where: str, value: Any) -> tuple[float, float, float]:
        if not isinstance(value, list) or len(value) != 3:
            raise self.fail(f"{where} must be a list of three numbers [x, y, z] in metres, got {value!r}")
        x, y, z = (self.number(f"{where}[{i}]", v) for i, v in enumerate(value))
        return (x, -y, -z) if self.body == "flu" else (x, y, z)

    def channel(self, where: str, output: str, spec: Any, quantity: str, unit: str) -> Channel:
        if isinstance(spec, str):
            spec = {"column": spec}
        if not isinstance(spec, dict):
            raise self.fail(f"{where} must be a column name or a table {{column, scale, offset, unit}}, got {spec!r}")
        extra = sorted(set(spec) - {"column", "scale", "offset", "unit"})
        if extra:
            raise self.fail(f"{where}: unknown key(s) {', '.join(extra)}; allowed: column, offset, scale, unit")
        col = spec.get("column")
        if not isinstance(col, str) or not col:
            raise self.fail(f"{where}.column must name a column of the record")
        unit = spec.get("unit", unit)
        self.choice(f"{where}.unit", unit, UNITS[quantity])
        return Channel(output, col, self.number(f"{where}.scale", spec.get("scale", 1.0)),
                       self.number(f"{where}.offset", spec.get("offset", 0.0)), UNITS[quantity][unit])

    def vector(self, where: str, prefix: str, spec: Any, quantity: str, kind: str,
               extra_keys: set[str] = frozenset()) -> tuple[tuple[Channel, ...], dict]:
        """Channels of a 3-vector (``kind`` body or world) and the table's other keys."""
        axes = "xyz" if kind == "body" else ("ned" if self.world == "ned" else "enu")
        if not isinstance(spec, dict):
            raise self.fail(f"{where} must be a table with keys {', '.join(axes)}")
        allowed = set(axes) | {"unit"} | extra_keys
        bad = sorted(set(spec) - allowed)
        if bad:
            raise self.fail(f"{where}: unknown key(s) {', '.join(bad)}; allowed: {', '.join(sorted(allowed))}"
                            + (f" (world = {self.world!r})" if kind == "world" else ""))
        missing = [a for a in axes if a not in spec]
        if missing:
            raise self.fail(f"{where}: missing axis {', '.join(missing)} (all three of {', '.join(axes)} are needed)")
        unit = spec.get("unit", SI[quantity])
        self.choice(f"{where}.unit", unit, UNITS[quantity])
        chans = tuple(self.channel(f"{where}.{a}", f"{prefix}.{a}", spec[a], quantity, unit) for a in axes)
        return chans, {k: spec[k] for k in extra_keys if k in spec}

    def parse(self, doc: dict) -> Mapping:
        extra = sorted(set(doc) - _TOP)
        if extra:
            raise self.fail(f"unknown table(s) {', '.join(extra)}; allowed: {', '.join(sorted(_TOP))}")
        rec = self.table(doc, "record", {"delimiter", "header_line"})
        delimiter = rec.get("delimiter", ",")
        if not isinstance(delimiter, str) or len(delimiter) != 1 or delimiter in "\"\n\r":
            raise self.fail(f"record.delimiter = {delimiter!r} must be one character (not a quote or a newline)")
        header_line = rec.get("header_line", 1)
        if isinstance(header_line, bool) or not isinstance(header_line, int) or header_line < 1:
            raise self.fail(f"record.header_line = {header_line!r} must be an integer >= 1")
        if "time" not in doc:
            raise self.fail("missing [time] table (column and unit of the time stamps)")
        tt = self.table(doc, "time", {"column", "unit", "rate"})
        tcol = tt.get("column")
        if not isinstance(tcol, str) or not tcol:
            raise self.fail("time.column must name the time column of the record")
        tunit = self.choice("time.unit", tt.get("unit", "s"), TIME_UNITS)
        trate = self.number("time.rate", tt["rate"], positive=True) if "rate" in tt else None
        fr = self.table(doc, "frames", {"body", "world", "acc", "heave"})
        self.body = self.choice("frames.body", fr.get("body", "frd"), BODY_FRAMES)
        self.world = self.choice("frames.world", fr.get("world", "ned"), WORLD_FRAMES)
        acc_kind = self.choice("frames.acc", fr.get("acc", "specific_force"), ACC_KINDS)
        heave = self.choice("frames.heave", fr.get("heave", "down"), HEAVE_SIGNS)
        channels: dict[str, tuple[Channel, ...]] = {}
        gaps: dict[str, float] = {}
        arms: dict[str, tuple[float, float, float]] = {}

        imu = self.table(doc, "imu", {"acc", "gyro", "lever_arm", "max_gap"})
        gap = self.number("imu.max_gap", imu.get("max_gap", DEFAULT_GAP["imu"]), positive=True)
        for key in ("acc", "gyro"):
            if key in imu:
                channels[f"imu.{key}"], _ = self.vector(f"imu.{key}", f"imu.{key}", imu[key], GROUP[f"imu.{key}"].quantity, "body")
                gaps[f"imu.{key}"] = gap
        if "lever_arm" in imu:
            arms["imu"] = self.arm("imu.lever_arm", imu["lever_arm"])

        ant_keys = {f"ant{k}" for k in range(1, ANTENNAS + 1)}
        gnss = self.table(doc, "gnss", ant_keys | {"new", "valid", "max_gap"})
        gnss_chans: list[Channel] = []
        for k in range(1, ANTENNAS + 1):
            if f"ant{k}" in gnss:
                chans, more = self.vector(f"gnss.ant{k}", f"gnss.ant{k}", gnss[f"ant{k}"], "length", "world", {"lever_arm"})
                gnss_chans += chans
                if "lever_arm" in more:
                    arms[f"gnss.ant{k}"] = self.arm(f"gnss.ant{k}.lever_arm", more["lever_arm"])
        flags = {}
        for key in ("new", "valid"):
            v = gnss.get(key)
            if v is not None and (not isinstance(v, str) or not v):
                raise self.fail(f"gnss.{key} must name a column of the record")
            flags[key] = v
        if gnss_chans:
            channels["gnss"] = tuple(gnss_chans)
            gaps["gnss"] = self.number("gnss.max_gap", gnss.get("max_gap", DEFAULT_GAP["gnss"]), positive=True)
        elif flags["new"] or flags["valid"]:
            raise self.fail("gnss.new / gnss.valid given without any antenna (gnss.ant1 …)")

        hd = self.table(doc, "heading", {"column", "unit", "scale", "offset", "max_gap"})
        if hd:
            spec = {k: hd[k] for k in ("column", "unit", "scale", "offset") if k in hd}
            channels["heading"] = (self.channel("heading", "heading", spec, "angle", "rad"),)
            gaps["heading"] = self.number("heading.max_gap", hd.get("max_gap", DEFAULT_GAP["heading"]), positive=True)

        ref = self.table(doc, "ref", _REF)
        ref_gap = self.number("ref.max_gap", ref.get("max_gap", DEFAULT_GAP["ref"]), positive=True)
        for key in ("roll", "pitch", "yaw", "heave"):
            if key in ref:
                g = GROUP[f"ref.{key}"]
                channels[g.name] = (self.channel(f"ref.{key}", g.name, ref[key], g.quantity, SI[g.quantity]),)
                gaps[g.name] = ref_gap
        for key in ("imu", "imu_vel", "cog", "point", "rate", "imu_f"):
            if key in ref:
                g = GROUP[f"ref.{key}"]
                chans, more = self.vector(f"ref.{key}", g.name, ref[key], g.quantity, g.frame,
                                          {"lever_arm"} if key == "point" else set())
                channels[g.name] = chans
                gaps[g.name] = ref_gap
                if "lever_arm" in more:
                    arms["ref.point"] = self.arm("ref.point.lever_arm", more["lever_arm"])

        angles = {k for k in ("ref.roll", "ref.pitch", "ref.yaw") if k in channels}
        mixed = (self.world, self.body) not in (("ned", "frd"), ("enu", "flu"))
        if mixed and angles and len(angles) < 3:
            raise self.fail(f"frames world = {self.world!r} with body = {self.body!r}: converting Euler angles needs all "
                            f"three of ref.roll, ref.pitch, ref.yaw (the mapping has {', '.join(sorted(angles))})")
        if acc_kind == "gravity_removed" and not {"ref.roll", "ref.pitch"} <= angles:
            raise self.fail("frames.acc = 'gravity_removed' needs ref.roll and ref.pitch in the mapping "
                            "(gravity is added back along the recorded attitude)")
        if not channels:
            raise self.fail("maps no signal: give at least one of [imu], [gnss], [heading], [ref]")
        order = [g.name for g in GROUPS]
        channels = {k: channels[k] for k in sorted(channels, key=order.index)}
        assert all(GROUP[k].kind != HOLD or k == "gnss" for k in channels)
        return Mapping(self.source, delimiter, header_line, tcol, tunit, trate, self.body, self.world, acc_kind, heave,
                       channels, gaps, flags["new"], flags["valid"], arms)
