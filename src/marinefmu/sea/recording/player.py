"""The SensorRecording model: plays a record back as VesselMotion-named outputs.

Each output is brought to the communication point the way its signal needs:

- **linear** (IMU, compass, every ``ref.*``): interpolated between the two samples around the
  time; an angle (roll, yaw, heading) across the ±π wrap the short way round. At a sample's own
  time the sample itself comes out, bit for bit, so a record made at the co-simulation step
  replays exactly;
- **hold** (GNSS): the latest epoch at or before the time is held, ``gnss.new`` is true on the
  step in which a new epoch arrived.

A sensor whose samples around the time are bad (NaN, Inf, partly empty) or further apart than
the mapping's ``max_gap`` (GNSS: an epoch older than it) has its ``valid`` output false, keeps
its last good outputs (zeros before the first) and is logged when it goes bad and when it comes
back: outputs are always finite. After the last sample every output holds its last value, every
``valid`` is false, ``record.active`` is false, and that is logged once.

Simulation time t maps to record time τ = (t − t_start) + ``start``, record time 0 being the
first sample; a τ within :data:`SNAP` (1 ns) of a sample is that sample's time. The record is read in blocks (:mod:`.reader`): only the rows within ``max_gap``
of the current time and one block ahead are in memory.
"""
from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import ParameterError, check_finite
from .mapping import Mapping, RecordingError, load_mapping
from .reader import BLOCK_ROWS, Record
from .schema import BOOLEAN_INDEX, BOOLEAN_OUTPUTS, GROUP, LINEAR, REAL_INDEX, REAL_OUTPUTS

_TWO_PI = 2.0 * math.pi
#: A communication point this close to a sample [s] is that sample's time (libcosim counts
#: time in integer nanoseconds, so its points are up to 0.5 ns off the record's stamps).
SNAP = 1e-9
#: Angle outputs interpolated the short way round the circle.
_WRAPPED = ("ref.roll", "ref.yaw", "heading")


@dataclass(frozen=True)
class SensorRecordingParams:
    """Parameters of the SensorRecording model.

    Attributes
    ----------
    file : str
        The record: CSV, ``.csv.gz`` or Parquet.
    mapping : str
        Its mapping sidecar (TOML, :mod:`.mapping`).
    start : float
        Offset into the record [s] played at the simulation's start time, [0, record length).
    """

    file: str = ""
    mapping: str = ""
    start: float = 0.0

    def __post_init__(self) -> None:
        for name in ("file", "mapping"):
            if not isinstance(getattr(self, name), str):
                raise ParameterError(f"{name} must be a path string, got {getattr(self, name)!r}")
        if not self.mapping:
            raise RecordingError("mapping: no sidecar given (the parameter 'mapping' is empty)")
        start = check_finite("start", self.start, "s")
        if start < 0.0:
            raise ParameterError(f"start = {start!r} is out of range: must be >= 0 [s]")


def _wrap(x: float) -> float:
    return (x + math.pi) % _TWO_PI - math.pi


class SensorRecording:
    """Play a record (module docstring).

    Parameters
    ----------
    params : SensorRecordingParams
        Validated parameters; the mapping is read and the record scanned here.
    start_time : float
        Simulation time of the record's ``start`` [s].

    Raises
    ------
    RecordingError
        For a record or mapping that cannot be used (:mod:`.reader`, :mod:`.mapping`), or a
        ``start`` at or after the end of the record.

    Examples
    --------
    >>> rec = SensorRecording(SensorRecordingParams("run.csv", "run.toml"))   # doctest: +SKIP
    >>> y = rec.step(0.01, 0.01)                 # outputs at t = 0.01 s, ordered as REAL_OUTPUTS
    >>> rec.boolean_outputs()[BOOLEAN_INDEX["imu.valid"]]                      # doctest: +SKIP
    True
    """

    def __init__(self, params: SensorRecordingParams, start_time: float = 0.0) -> None:
        self.params = params
        self.mapping: Mapping = load_mapping(params.mapping)
        file = Path(params.file)
        if params.file and not file.is_absolute() and not file.exists():   # relative to the sidecar
            beside = Path(params.mapping).parent / file
            file = beside if beside.exists() else file
        self.record = Record(file, self.mapping)
        self.duration = self.record.summary.duration
        if params.start >= self.duration and self.record.summary.rows > 1:
            raise RecordingError(f"record {file}: start = {params.start:g} s is at or after the end of the record "
                                 f"({self.duration:g} s from the first sample)")
        self.start_time = float(start_time)
        m = self.mapping
        self.linear = [g for g in m.channels if GROUP[g].kind == LINEAR]
        self.gap = {g: m.max_gap[g] for g in m.channels}
        self._max_gap = max(self.gap.values())
        self._min_lin_gap = min((self.gap[g] for g in self.linear), default=math.inf)
        # output slots: linear channels in the concatenated matrix, and where each goes
        self._lin_slices: dict[str, slice] = {}
        self._out_index: list[int] = []
        col = 0
        for g in self.linear:
            chans = GROUP[g].channels
            self._lin_slices[g] = slice(col, col + len(chans))
            self._out_index += [REAL_INDEX[c] for c in chans]
            col += len(chans)
        self._n_lin = col
        self._all_bits = (1 << len(self.linear)) - 1
        self._wrapped = [self._out_index.index(REAL_INDEX[n]) for n in _WRAPPED if n in self.linear]
        self._out_lin_contiguous = self._out_index == list(range(self._out_index[0], self._out_index[0] + col)) if col else False
        self.has_gnss = "gnss" in m.channels
        if self.has_gnss:
            self._gnss_out = [REAL_INDEX[c] for c in GROUP["gnss"].channels]
            self._gnss_mapped = [i for i, c in enumerate(GROUP["gnss"].channels)
                                 if c.rsplit(".", 1)[0] in {f"gnss.ant{k}" for k in m.antennas()}]
        # which groups feed which validity output
        self._valid_groups: dict[str, list[str]] = {}
        for g in m.channels:
            self._valid_groups.setdefault(GROUP[g].valid, []).append(g)
        self.reset()

    # --- the window of rows ------------------------------------------------------------------
    def _load(self, k: int) -> None:
        """Append block ``k`` to the window."""
        b = self.record.read(k)
        n = len(b)
        lin = np.empty((n, self._n_lin))
        bits = np.zeros(n, dtype=np.int64)
        present = np.zeros((n, len(self.linear)), dtype=bool)
        for j, g in enumerate(self.linear):
            lin[:, self._lin_slices[g]] = b.values[g]
            bits |= b.good[g].astype(np.int64) << j
            present[:, j] = b.present[g]
        parts = {"t": b.time, "lin": lin, "bits": bits, "present": present}
        if self.has_gnss:
            parts["gnss"] = b.values["gnss"]
            parts["epoch"] = b.epoch
            parts["egood"] = b.good["gnss"]
        if self._w is None:
            self._w = {k2: v.copy() for k2, v in parts.items()}
            self._base = b.first_row
        else:
            self._w = {k2: np.concatenate((self._w[k2], v)) for k2, v in parts.items()}
        self._next_block = k + 1
        self._refresh()

    def _refresh(self) -> None:
        w = self._w
        self._t = w["t"].tolist()
        self._bits = w["bits"].tolist()
        if self.has_gnss:
            self._epochs = (np.flatnonzero(w["epoch"]) + self._base).tolist()

    def _more(self) -> bool:
        """Load the next block; False at the end of the record."""
        if self._next_block >= self.record.blocks:
            return False
        self._load(self._next_block)
        return True

    def _trim(self, tau: float) -> None:
        """Drop rows older than max_gap before ``tau`` (keeping a block's margin)."""
        k = bisect.bisect_left(self._t, tau - self._max_gap) - 2
        if k > BLOCK_ROWS:
            self._w = {key: v[k:] for key, v in self._w.items()}
            self._base += k
            self._i -= k
            self._refresh()

    def _seek(self, tau: float) -> None:
        """Fill the window for record time ``tau`` from scratch (reset, state restore)."""
        self._w = None
        self._base = 0
        k = self.record.block_of(tau - self._max_gap)
        self._load(k)
        while self._t[-1] <= tau and self._more():
            pass
        self._i = max(0, bisect.bisect_right(self._t, tau) - 1)

    # --- the model ------------------------------------------------------------------------------
    def reset(self) -> None:
        """Back to the start of the record, as built."""
        self.real_out = [float(v.default) for v in REAL_OUTPUTS]
        self.bool_out = [bool(v.default) for v in BOOLEAN_OUTPUTS]
        self.messages: list[str] = []
        self.ended = False
        self.invalid_steps = dict.fromkeys(self._valid_groups, 0)
        self._valid = dict.fromkeys(self._valid_groups, None)   # last state, for logging transitions
        self._why: dict[str, str] = {}
        self._all_valid = False      # every linear sensor was valid on the last step
        self._consumed_row = -1      # GNSS epochs in rows up to this one have been taken
        self._held_time = -math.inf
        self._held_good = False
        self._w = None
        self._seek(self.params.start)
        self._tau_prev = -math.inf
        self._advance(self.params.start, initial=True)

    def tau(self, t: float) -> float:
        """Record time [s] played at simulation time ``t`` [s]."""
        return (t - self.start_time) + self.params.start

    def peek(self) -> list[float]:
        """The real outputs now (ordered as :data:`~.schema.REAL_OUTPUTS`)."""
        return list(self.real_out)

    def step(self, t: float, dt: float) -> list[float]:
        """Outputs at simulation time ``t`` [s] (``dt``, the step [s], is not needed: the record
        says what happened in it). Booleans are in :meth:`boolean_outputs`, messages to log in
        :attr:`messages` (emptied here)."""
        self.messages = []
        self._advance(self.tau(t))
        return list(self.real_out)

    def boolean_outputs(self) -> list[bool]:
        """Values ordered as :data:`~.schema.BOOLEAN_OUTPUTS`."""
        return list(self.bool_out)

    def _set_valid(self, name: str, ok: bool, tau: float, why: str = "") -> None:
        self.bool_out[BOOLEAN_INDEX[name]] = ok
        if not ok:
            self.invalid_steps[name] += 1
        prev = self._valid[name]
        if prev is None and not ok:   # not yet valid since the start: nothing to report
            self._why[name] = why
            return
        if ok == prev and (ok or why == self._why.get(name)):
            return
        if not ok and not self.ended:
            self.messages.append(f"{name[:-6]}: {why} at record time {tau:.4f} s; holding the last good values, {name} = false")
        elif ok and prev is False and not self.ended:
            self.messages.append(f"{name[:-6]}: good samples again at record time {tau:.4f} s; {name} = true")
        self._valid[name] = ok
        self._why[name] = why

    def _advance(self, tau: float, initial: bool = False) -> None:
        if tau > self.duration or (self.ended and not initial):
            if not self.ended:
                self.ended = True
                self.messages.append(f"end of the record at record time {self.duration:.4f} s (simulation time "
                                     f"{self.start_time + self.duration - self.params.start:.4f} s): holding the last "
                                     "values, every valid = false, record.active = false")
            self._all_valid = False
            for name in self._valid_groups:
                self.bool_out[BOOLEAN_INDEX[name]] = False
                self.invalid_steps[name] += 1
            self.bool_out[BOOLEAN_INDEX["gnss.new"]] = False
            self.bool_out[BOOLEAN_INDEX["record.active"]] = False
            return
        t = self._t
        while t[-1] <= tau and self._more():
            t = self._t
        i = self._i
        n = len(t)
        while i + 1 < n and t[i + 1] <= tau:
            i += 1
        if i + 1 < n and t[i + 1] - tau <= SNAP:
            i += 1
        if abs(tau - t[i]) <= SNAP or tau < t[i]:   # (before the first sample: the first sample)
            tau = t[i]
        self._i = i
        self.real_out[REAL_INDEX["record.time"]] = tau
        self.bool_out[BOOLEAN_INDEX["record.active"]] = True
        if self.linear:
            self._linear(tau, i)
        if self.has_gnss:
            self._gnss(tau, i, initial)
        self._tau_prev = tau
        if i > 3 * BLOCK_ROWS:
            self._trim(tau)

    def _linear(self, tau: float, i: int) -> None:
        t, w = self._t, self._w
        lin = w["lin"]
        exact = t[i] == tau or i + 1 >= len(t)
        if exact:
            y = lin[i]
            ok_bits = self._bits[i]
            span = 0.0
        else:
            t0, t1 = t[i], t[i + 1]
            span = t1 - t0
            y = lin[i] + (lin[i + 1] - lin[i]) * ((tau - t0) / span)
            ok_bits = self._bits[i] & self._bits[i + 1]
        vals = y.tolist()
        if self._wrapped and not exact:
            for j in self._wrapped:
                d = lin[i + 1, j] - lin[i, j]
                if abs(d) > math.pi:
                    vals[j] = float(lin[i, j] + _wrap(d) * ((tau - t[i]) / span))
        fast = ok_bits == self._all_bits and span <= self._min_lin_gap
        if fast:   # every linear sensor good: the common case, kept short
            ro = self.real_out
            for k, v in zip(self._out_index, vals):
                ro[k] = v
            if not self._all_valid:
                for name in self._valid_groups:
                    if name != "gnss.valid":
                        self._set_valid(name, True, tau)
                self._all_valid = True
            return
        self._all_valid = False
        ok = {}
        for j, g in enumerate(self.linear):
            sl = self._lin_slices[g]
            if fast or (ok_bits >> j & 1 and span <= self.gap[g]):
                good, why = True, ""
            else:
                good, why, interp = self._slow(g, j, tau, i)
                if good:
                    vals[sl] = interp
            ok[g] = (good, why)
            if good:
                for k, v in zip(self._out_index[sl], vals[sl]):
                    self.real_out[k] = v
        for name, groups in self._valid_groups.items():
            if name == "gnss.valid":
                continue
            bad = [ok[g][1] for g in groups if not ok[g][0]]
            self._set_valid(name, not bad, tau, bad[0] if bad else "")

    def _slow(self, g: str, j: int, tau: float, i: int) -> tuple[bool, str, list[float]]:
        """Validity and value of group ``g`` (bit ``j``) when the rows around ``tau`` do not both
        have it good: look for its own samples around ``tau`` (an empty field is no sample)."""
        w, t = self._w, self._t
        present = w["present"][:, j]
        gap = self.gap[g]
        a = i
        while a >= 0 and not present[a]:
            if tau - t[a] > gap:
                return False, f"no sample for more than max_gap = {gap:g} s", []
            a -= 1
        if a < 0:
            return False, "no sample yet", []
        if not self._bits[a] >> j & 1:
            return False, "bad sample (NaN, Inf or a missing field)", []
        if t[a] == tau:
            return True, "", w["lin"][a, self._lin_slices[g]].tolist()
        b = i + 1
        while True:
            while b >= len(t):
                if not self._more():
                    return False, "no later sample", []
                w, t = self._w, self._t
                present = w["present"][:, j]
            if present[b]:
                break
            if t[b] - t[a] > gap:
                return False, f"a gap longer than max_gap = {gap:g} s", []
            b += 1
        if t[b] - t[a] > gap:
            return False, f"a gap of {t[b] - t[a]:.4g} s, longer than max_gap = {gap:g} s", []
        if not self._bits[b] >> j & 1:
            return False, "bad sample (NaN, Inf or a missing field)", []
        lin = w["lin"][:, self._lin_slices[g]]
        frac = (tau - t[a]) / (t[b] - t[a])
        y = lin[a] + (lin[b] - lin[a]) * frac
        if g in _WRAPPED:
            y = np.array([lin[a, 0] + _wrap(lin[b, 0] - lin[a, 0]) * frac])
        return True, "", y.tolist()

    def _gnss(self, tau: float, i: int, initial: bool) -> None:
        epochs = self._epochs
        last_row = self._base + i
        new = False
        pos = bisect.bisect_right(epochs, self._consumed_row)
        while pos < len(epochs) and epochs[pos] <= last_row:
            r = epochs[pos] - self._base
            new = True
            self._held_time = self._t[r]
            self._held_good = bool(self._w["egood"][r])
            if self._held_good:
                vals = self._w["gnss"][r].tolist()
                for k in self._gnss_mapped:
                    self.real_out[self._gnss_out[k]] = vals[k]
            pos += 1
        self._consumed_row = last_row
        self.bool_out[BOOLEAN_INDEX["gnss.new"]] = new and not initial
        gap = self.gap["gnss"]
        if not self._held_good:
            why = "no epoch yet" if self._held_time == -math.inf else "bad epoch (NaN, a missing field or flagged invalid)"
            self._set_valid("gnss.valid", False, tau, why)
        elif tau - self._held_time > gap:
            self._set_valid("gnss.valid", False, tau, f"no epoch for more than max_gap = {gap:g} s")
        else:
            self._set_valid("gnss.valid", True, tau)

    # --- state ------------------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable state: where in the record it is, the held values and flags."""
        finite = lambda x: x if math.isfinite(x) else None  # noqa: E731 - JSON has no infinity
        return {"tau": finite(self._tau_prev), "row": self._base + self._i, "real_out": list(self.real_out),
                "bool_out": list(self.bool_out), "ended": self.ended, "invalid_steps": dict(self.invalid_steps),
                "valid": dict(self._valid), "why": dict(self._why), "held_time": finite(self._held_time),
                "held_good": self._held_good, "consumed_row": self._consumed_row}

    def set_state(self, state: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        tau = -math.inf if state["tau"] is None else state["tau"]
        self._seek(tau if math.isfinite(tau) else self.params.start)
        self._i = state["row"] - self._base
        self.real_out = list(state["real_out"])
        self.bool_out = list(state["bool_out"])
        self.ended = bool(state["ended"])
        self.invalid_steps = dict(state["invalid_steps"])
        self._valid = dict(state["valid"])
        self._why = dict(state["why"])
        self._held_time = -math.inf if state["held_time"] is None else state["held_time"]
        self._held_good = state["held_good"]
        self._tau_prev = tau
        self._consumed_row = state["consumed_row"]
        self._all_valid = False
        self.messages = []


#: Folder of a self-contained recording FMU's record and sidecar, inside its ``resources/``.
BUNDLE_DIR = "recording"
#: The sidecar's name in :data:`BUNDLE_DIR`.
BUNDLE_MAPPING = "mapping.toml"


def bundled_paths(file: str, mapping: str, resources: str | Path | None) -> tuple[str, str]:
    """``file`` and ``mapping``, each taken from the FMU's bundled record
    (``resources/recording/``) when empty and the FMU has one."""
    folder = Path(resources) / BUNDLE_DIR if resources else None
    if folder is None or not folder.is_dir():
        return file, mapping
    if not mapping:
        mapping = str(folder / BUNDLE_MAPPING)
    if not file:
        records = sorted(p for p in folder.iterdir() if p.name != BUNDLE_MAPPING)
        file = str(records[0]) if records else ""
    return file, mapping
