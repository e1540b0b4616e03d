"""Streaming reader of a recorded file: CSV (optionally gzip-compressed) or Parquet.

A record is read in blocks of :data:`BLOCK_ROWS` rows and never held whole, so a 24-hour
record at 100 Hz plays in bounded memory. At opening, one streaming pass (:meth:`Record.scan`)
parses every mapped column of every row, so that bad input is refused before a run starts with a
message naming the file, the column and the line: a missing or unreadable file, a column the
mapping names that the file lacks, a non-numeric value, a time stamp that goes backwards or
repeats. The pass also notes where each block starts (byte offset and time), so playing can jump
to any time (FMU state restore) by reading one block, and counts each sensor's bad samples.

An empty field is "no sample in this row" (a GNSS epoch in a record that interleaves a 5 Hz
receiver with a 100 Hz IMU); ``nan`` (or ``inf``) written in a field is a bad sample.

Parquet needs the optional package ``pyarrow`` (``pip install marinefmu[parquet]``); without it
a Parquet record is refused with a message saying so. A Parquet record has no lines: its messages
name the row instead, counted from 0 among the data rows. Its mapped columns may be integer,
floating-point, boolean or decimal, or text holding numbers as a CSV field would (surrounding
blanks ignored); a null is an empty field (no sample), a NaN a bad sample. Any other type (a
timestamp, binary, a list ...) is refused naming the column and its type, text that is not a
number naming the row. The time column with ``time.unit = "iso8601"`` is a Parquet timestamp
(with a time zone: taken in UTC) or ISO-8601 text, read as in a CSV; with a numeric unit it is a
number like any other column.
"""
from __future__ import annotations

import csv
import difflib
import gzip
import io
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, BinaryIO

import numpy as np

from .convert import convert
from .mapping import TIME_UNITS, Mapping, RecordingError

#: Rows per block read and converted at once.
BLOCK_ROWS = 4096
#: Records with at most this many rows keep every converted block in memory after the scan.
CACHE_ROWS = 1 << 17
#: What an empty field parses to before it becomes NaN with its ``present`` flag false.
_EMPTY = "-8.98846567431158e307"
_EMPTY_VALUE = float(_EMPTY)


@dataclass
class Block:
    """Converted rows of a record.

    Attributes
    ----------
    first_row : int
        Index of the first row in the record (0-based, data rows only).
    time : numpy.ndarray
        (n,) record time [s] from the first sample.
    values : dict of str to numpy.ndarray
        Group → (n, channels) SI values in NED/FRD (NaN where missing or bad).
    present : dict of str to numpy.ndarray
        Group → (n,) True where the row has any of the group's fields.
    good : dict of str to numpy.ndarray
        Group → (n,) True where the row has all of them, finite (for ``gnss``: and the epoch's
        valid flag set, if mapped).
    epoch : numpy.ndarray or None
        (n,) True on rows carrying a GNSS epoch (the ``new`` column if mapped, else ``present``).
    """

    first_row: int
    time: np.ndarray
    values: dict[str, np.ndarray]
    present: dict[str, np.ndarray]
    good: dict[str, np.ndarray]
    epoch: np.ndarray | None

    def __len__(self) -> int:
        return len(self.time)


@dataclass
class Summary:
    """What the scan found.

    Attributes
    ----------
    rows : int
        Data rows.
    duration : float
        Time from the first to the last sample [s].
    start_time : str
        The first time stamp as written in the record.
    samples, bad : dict of str to int
        Group → rows carrying it, and of those the bad ones (NaN, Inf, partly empty, or a GNSS
        epoch flagged invalid).
    max_interval : dict of str to float
        Group → longest interval between two of its samples [s].
    gaps : dict of str to int
        Group → intervals longer than the mapping's ``max_gap``.
    """

    rows: int = 0
    duration: float = 0.0
    start_time: str = ""
    samples: dict[str, int] = field(default_factory=dict)
    bad: dict[str, int] = field(default_factory=dict)
    max_interval: dict[str, float] = field(default_factory=dict)
    gaps: dict[str, int] = field(default_factory=dict)


def _open(path: Path) -> BinaryIO:
    with open(path, "rb") as fh:
        magic = fh.read(2)
    return gzip.open(path, "rb") if magic == b"\x1f\x8b" else open(path, "rb")


def is_parquet(path: str | Path) -> bool:
    """Whether ``path`` is a Parquet file (by its magic bytes, else its suffix)."""
    try:
        with open(path, "rb") as fh:
            return fh.read(4) == b"PAR1"
    except OSError:
        return str(path).lower().endswith(".parquet")


class Record:
    """A record and its mapping, opened and checked (:meth:`scan` runs here).

    Parameters
    ----------
    path : str or Path
        CSV, ``.csv.gz`` or Parquet file.
    mapping : Mapping
        Its sidecar.

    Raises
    ------
    RecordingError
        For every refusal of the module docstring.
    """

    def __init__(self, path: str | Path, mapping: Mapping) -> None:
        self.path = Path(path)
        self.mapping = mapping
        if not str(path):
            raise RecordingError("record: no file given (the parameter 'file' is empty)")
        if not self.path.is_file():
            raise RecordingError(f"record {self.path}: no such file")
        self.parquet = is_parquet(self.path)
        self._offsets: list[int] = []     # byte offset (CSV) or row (Parquet) of each block
        self._lines: list[int] = []       # first line number of each block
        self._first_rows: list[int] = []  # first data row of each block
        self._pinned = False              # every block is in the cache
        self._block_times: list[float] = []
        self._cache: dict[int, Block] = {}
        self._t_origin: Any = None         # raw time of the first sample (float, or datetime64[ns])
        self.summary = Summary()
        self.columns = self._read_header()
        self.scan()

    # --- the file -----------------------------------------------------------------------------
    @property
    def _line_word(self) -> str:
        """What a position in the file is called in a message: a CSV line, a Parquet row."""
        return "row" if self.parquet else "line"

    def _fail(self, what: str, line: int | None = None, column: str | None = None) -> RecordingError:
        at = f"{self._line_word} {line}" if line is not None and (line or self.parquet) else ""
        where = "".join(f", {w}" for w in (at, f"column {column!r}" if column else "") if w)
        return RecordingError(f"record {self.path}{where}: {what}")

    def _read_header(self) -> list[str]:
        m = self.mapping
        if self.parquet:
            names = self._parquet().schema_arrow.names
        else:
            try:
                with _open(self.path) as fh:
                    for _ in range(m.header_line - 1):
                        fh.readline()
                    raw = fh.readline()
                    self._data_offset = fh.tell()
            except (OSError, EOFError, gzip.BadGzipFile) as exc:
                raise self._fail(f"cannot be read: {exc}") from None
            if not raw.strip():
                raise self._fail("has no header line (the column names)", line=m.header_line)
            try:
                text = raw.decode("utf-8-sig")
            except UnicodeDecodeError:
                text = raw.decode("latin-1")
            names = [n.strip() for n in next(csv.reader([text.strip("\r\n")], delimiter=m.delimiter))]
        index = {}
        for i, n in enumerate(names):
            index.setdefault(n, i)
        used = {}
        owner = {c.column: c.output for chans in m.channels.values() for c in chans}
        owner.update({m.time_column: "time"})
        owner.update({c: f"gnss.{k}" for k, c in (("new", m.gnss_new), ("valid", m.gnss_valid)) if c})
        for col in m.columns:
            if col not in index:
                close = difflib.get_close_matches(col, names, n=3)
                hint = f"; closest: {', '.join(map(repr, close))}" if close else f"; it has {len(names)} column(s): " + ", ".join(map(repr, names[:12]))
                raise self._fail(f"has no column {col!r} (mapping {m.source} maps it to {owner[col]}){hint}", column=col)
            used[col] = index[col]
        self._index = used
        return names

    def _arrow(self):
        """pyarrow, pyarrow.compute and pyarrow.parquet: the optional Parquet dependency, imported
        only here (so an FMU's requirements list it as optional); without it a Parquet file is
        refused naming the file and the install."""
        try:
            import pyarrow as pa
            import pyarrow.compute as pc
            import pyarrow.parquet as pq
        except ImportError:
            raise self._fail("is a Parquet file, which needs the optional package pyarrow (pip install marinefmu[parquet], "
                             "or pip install pyarrow); "
                             "or convert it to CSV") from None
        return pa, pc, pq

    def _parquet(self):
        pq = self._arrow()[2]
        try:
            return pq.ParquetFile(self.path)
        except Exception as exc:  # noqa: BLE001 - pyarrow raises its own types
            raise self._fail(f"cannot be read as Parquet: {exc}") from None

    # --- reading blocks ------------------------------------------------------------------------
    def _raw_blocks(self, start_block: int = 0):
        """Yield (first_line, raw columns, time texts or None, n) for each block from ``start_block``."""
        if self.parquet:
            yield from self._parquet_blocks(start_block)
            return
        m = self.mapping
        with _open(self.path) as fh:
            if start_block == 0:
                fh.seek(self._data_offset)
                line = m.header_line + 1
            else:
                fh.seek(self._offsets[start_block])
                line = self._lines[start_block]
            k = start_block
            while True:
                if k == len(self._offsets):
                    self._offsets.append(fh.tell() if k else self._data_offset)
                    self._lines.append(line)
                lines = []
                for raw in fh:
                    lines.append(raw)
                    if len(lines) == BLOCK_ROWS:
                        break
                if not lines:
                    return
                text_lines = [b.decode("utf-8", errors="replace").rstrip("\r\n") for b in lines]
                keep = [i for i, s in enumerate(text_lines) if s.strip()]
                if len(keep) < len(text_lines):
                    text_lines = [text_lines[i] for i in keep]
                line_numbers = np.asarray(keep, dtype=np.int64) + line
                line += len(lines)
                if text_lines:
                    yield (line_numbers, *self._parse(text_lines, line_numbers))
                k += 1

    def _parse(self, lines: list[str], line_numbers: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray | None]:
        m = self.mapping
        d = m.delimiter
        iso = m.time_unit == "iso8601"
        cols = [c for c in self._index if not (iso and c == m.time_column)]
        idx = [self._index[c] for c in cols]
        text = "\n".join(lines)
        if d + d in text or text.startswith(d) or (d + "\n") in text or ("\n" + d) in text or text.endswith(d):
            text = text.replace(d + d, d + _EMPTY + d).replace(d + d, d + _EMPTY + d)
            text = text.replace("\n" + d, "\n" + _EMPTY + d).replace(d + "\n", d + _EMPTY + "\n")
            if text.startswith(d):
                text = _EMPTY + text
            if text.endswith(d):
                text = text + _EMPTY
        raw: dict[str, np.ndarray] = {}
        if cols:
            try:
                data = np.loadtxt(io.StringIO(text), delimiter=d, usecols=idx, dtype=float, quotechar='"', ndmin=2,
                                  comments=None)
            except ValueError:
                raise self._locate(text.split("\n"), line_numbers, cols) from None
            for j, c in enumerate(cols):
                raw[c] = data[:, j]
        times = None
        if iso:
            try:
                s = np.loadtxt(io.StringIO(text), delimiter=d, usecols=[self._index[m.time_column]], dtype=str,
                               quotechar='"', ndmin=1, comments=None)
            except ValueError:
                raise self._locate(text.split("\n"), line_numbers, [m.time_column], numeric=False) from None
            times = self._iso(np.atleast_1d(s), line_numbers)
        return raw, times

    def _iso(self, s: np.ndarray, line_numbers: np.ndarray) -> np.ndarray:
        import warnings

        s = np.char.strip(s.astype(str))
        try:
            with warnings.catch_warnings():   # numpy warns on a UTC offset: take the exact route below
                warnings.simplefilter("error")
                return np.array(np.char.rstrip(s, "Z"), dtype="datetime64[ns]")
        except (ValueError, UserWarning, DeprecationWarning):
            pass
        import datetime as dt

        out = np.empty(len(s), dtype="datetime64[ns]")
        for i, text in enumerate(s):
            try:
                stamp = dt.datetime.fromisoformat(str(text))
            except ValueError:
                raise self._fail(f"time stamp {str(text)!r} is not ISO-8601 text (time.unit = 'iso8601')",
                                 line=int(line_numbers[i]), column=self.mapping.time_column) from None
            if stamp.tzinfo is not None:
                stamp = stamp.astimezone(dt.timezone.utc).replace(tzinfo=None)
            out[i] = np.datetime64(stamp, "ns")
        return out

    def _locate(self, lines: list[str], line_numbers: np.ndarray, cols: list[str], numeric: bool = True) -> RecordingError:
        """The first bad field of a block that failed to parse, as a message (slow, only on error)."""
        d = self.mapping.delimiter
        for row, text in enumerate(lines):
            fields = next(csv.reader([text], delimiter=d))
            for c in cols:
                i = self._index[c]
                if i >= len(fields):
                    return self._fail(f"has {len(fields)} field(s); the column is field {i + 1}", line=int(line_numbers[row]), column=c)
                if numeric:
                    v = fields[i].strip()
                    if v == _EMPTY:
                        continue
                    try:
                        float(v)
                    except ValueError:
                        return self._fail(f"{v!r} is not a number", line=int(line_numbers[row]), column=c)
        return self._fail("cannot be parsed (inconsistent number of fields)", line=int(line_numbers[0]))

    def _parquet_blocks(self, start_block: int):
        """Yield (row numbers, raw columns, times or None) for each batch from ``start_block``;
        the row numbers count the data rows from 0 (a Parquet file has no lines)."""
        pf = self._parquet()
        m = self.mapping
        row = 0
        k = 0
        for batch in pf.iter_batches(batch_size=BLOCK_ROWS, columns=list(self._index)):
            n = batch.num_rows
            if not n:        # an empty row group: no block (the blocks are counted the same on every read)
                continue
            if k >= start_block:
                if k >= len(self._offsets):
                    self._offsets.append(row)
                    self._lines.append(row)
                rows = np.arange(n, dtype=np.int64) + row
                raw, times = {}, None
                for c in self._index:
                    arr = batch.column(c)
                    if c == m.time_column and m.time_unit == "iso8601":
                        times = self._parquet_times(arr, rows)
                    else:
                        raw[c] = self._parquet_numbers(arr, rows, c)
                yield rows, raw, times
            row += n
            k += 1

    def _parquet_numbers(self, arr, rows: np.ndarray, column: str) -> np.ndarray:
        """A Parquet column as float, null → the empty marker (module docstring: accepted types)."""
        pa, pc, _ = self._arrow()
        if pa.types.is_dictionary(arr.type):
            arr = arr.dictionary_decode()
        t = arr.type
        if pa.types.is_string(t) or pa.types.is_large_string(t):
            arr = pc.utf8_trim_whitespace(arr)
            arr = pc.if_else(pc.equal(arr, ""), pa.scalar(None, arr.type), arr)
            try:
                arr = arr.cast(pa.float64())
            except (pa.ArrowInvalid, pa.ArrowNotImplementedError):   # Python's float(), as a CSV field
                out = np.empty(len(arr))
                for i, v in enumerate(arr.to_pylist()):
                    try:
                        out[i] = _EMPTY_VALUE if v is None else float(v)
                    except ValueError:
                        raise self._fail(f"{v!r} is not a number", line=int(rows[i]), column=column) from None
                return out
        elif not (pa.types.is_integer(t) or pa.types.is_floating(t) or pa.types.is_boolean(t)
                  or pa.types.is_decimal(t) or pa.types.is_null(t)):
            hint = ' (set time.unit = "iso8601" for a timestamp time column)' if (
                column == self.mapping.time_column and (pa.types.is_timestamp(t) or pa.types.is_date(t))) else ""
            raise self._fail(f"has non-numeric values (Parquet type {t}){hint}", column=column)
        else:
            arr = arr.cast(pa.float64())
        # a copy: the block converts in place, and pyarrow's zero-copy arrays are read-only
        return np.array(arr.fill_null(_EMPTY_VALUE).to_numpy(zero_copy_only=False), dtype=float)

    def _parquet_times(self, arr, rows: np.ndarray) -> np.ndarray:
        """The time column of ``time.unit = "iso8601"``: a Parquet timestamp (UTC if it has a time
        zone) or ISO-8601 text (as in a CSV), to datetime64[ns]; a null is NaT (refused later)."""
        pa = self._arrow()[0]
        if pa.types.is_dictionary(arr.type):
            arr = arr.dictionary_decode()
        t = arr.type
        if pa.types.is_timestamp(t) or pa.types.is_date(t):
            return np.asarray(arr.cast(pa.timestamp("ns")).to_numpy(zero_copy_only=False), dtype="datetime64[ns]")
        if not (pa.types.is_string(t) or pa.types.is_large_string(t)):
            raise self._fail(f"is Parquet type {t}: time.unit = 'iso8601' needs a timestamp or ISO-8601 text column",
                             column=self.mapping.time_column)
        texts = arr.to_pylist()
        missing = [i for i, v in enumerate(texts) if v is None or not v.strip()]
        if missing:
            raise self._fail("time stamp is missing", line=int(rows[missing[0]]), column=self.mapping.time_column)
        return self._iso(np.array(texts, dtype=str), rows)

    # --- the scan and the conversion -----------------------------------------------------------
    def _times(self, raw: dict[str, np.ndarray], times: np.ndarray | None, line_numbers: np.ndarray,
               first_row: int) -> np.ndarray:
        t = self._stamps(raw, times, line_numbers)
        rate = self.mapping.time_rate
        if rate is None:
            return t
        k = np.arange(first_row, first_row + len(t))
        uniform = k / rate
        off = np.abs(t - uniform) > 0.5 / rate
        if off.any():
            i = int(np.argmax(off))
            raise self._fail(f"time stamp is {t[i]:.6g} s from the first, {t[i] - uniform[i]:+.3g} s off row "
                             f"{k[i]} / time.rate = {uniform[i]:.6g} s: more than half a sample (drop time.rate "
                             "for a record that is not uniform)", line=int(line_numbers[i]), column=self.mapping.time_column)
        return uniform

    def _stamps(self, raw: dict[str, np.ndarray], times: np.ndarray | None, line_numbers: np.ndarray) -> np.ndarray:
        m = self.mapping
        if times is None:
            t_raw = raw[m.time_column]
            bad = ~np.isfinite(t_raw) | (t_raw == _EMPTY_VALUE)
            if bad.any():
                i = int(np.argmax(bad))
                raise self._fail("time stamp is missing or not a finite number", line=int(line_numbers[i]), column=m.time_column)
            if self._t_origin is None:
                self._t_origin = float(t_raw[0])
            return (t_raw - self._t_origin) * TIME_UNITS[m.time_unit]
        if np.isnat(times).any():
            i = int(np.argmax(np.isnat(times)))
            raise self._fail("time stamp is missing", line=int(line_numbers[i]), column=m.time_column)
        if self._t_origin is None:
            self._t_origin = times[0]
        return (times - self._t_origin).astype("timedelta64[ns]").astype(np.int64) * 1e-9

    def _block(self, first_row: int, raw: dict[str, np.ndarray], t: np.ndarray) -> Block:
        m = self.mapping
        present: dict[str, np.ndarray] = {}
        for name, chans in m.channels.items():
            p = np.zeros(len(t), dtype=bool)
            for c in chans:
                col = raw[c.column]
                empty = col == _EMPTY_VALUE
                p |= ~empty
            present[name] = p
        for col, arr in raw.items():   # empty → NaN (after the presence test above)
            arr[arr == _EMPTY_VALUE] = np.nan
        values = convert(m, raw)
        good = {name: present[name] & np.isfinite(values[name]).all(axis=1) for name in values}
        epoch = None
        if "gnss" in values:
            if m.gnss_new:
                new = raw[m.gnss_new]
                epoch = np.isfinite(new) & (new != 0.0)
            else:
                epoch = present["gnss"]
            if m.gnss_valid:
                ok = raw[m.gnss_valid]
                good["gnss"] = good["gnss"] & np.isfinite(ok) & (ok != 0.0)
        return Block(first_row, t, values, present, good, epoch)

    def scan(self) -> Summary:
        """Parse every row once: refuse bad input (module docstring), note where each block
        starts, and count each sensor's samples, bad samples and gaps (:attr:`summary`)."""
        m = self.mapping
        self._offsets, self._lines, self._block_times, self._first_rows, self._cache = [], [], [], [], {}
        self._t_origin = None
        self._pinned = False
        s = Summary(samples=dict.fromkeys(m.channels, 0), bad=dict.fromkeys(m.channels, 0),
                    max_interval=dict.fromkeys(m.channels, 0.0), gaps=dict.fromkeys(m.channels, 0))
        last_t = -math.inf
        last_line = None
        last_sample = dict.fromkeys(m.channels, math.nan)
        rows = 0
        keep = []
        for line_numbers, raw, times in self._raw_blocks(0):
            t = self._times(raw, times, line_numbers, rows)
            if rows == 0:
                s.start_time = str(self._t_origin)
            dt = np.diff(np.concatenate(([last_t], t)))
            bad = ~(dt > 0.0)
            if bad.any():
                i = int(np.argmax(bad))
                prev_line = int(line_numbers[i - 1]) if i > 0 else last_line
                how = "repeats" if dt[i] == 0.0 else "goes backwards"
                raise self._fail(f"time stamp {how} (from {self._line_word} {prev_line}): time stamps must increase",
                                 line=int(line_numbers[i]), column=m.time_column)
            block = self._block(rows, raw, t)
            self._block_times.append(float(t[0]))
            self._first_rows.append(rows)
            for name in m.channels:
                rows_g = block.epoch if name == "gnss" else block.present[name]
                tg = t[rows_g]
                s.samples[name] += int(rows_g.sum())
                s.bad[name] += int((rows_g & ~block.good[name]).sum())
                if len(tg):
                    iv = np.diff(np.concatenate(([last_sample[name]], tg)))
                    iv = iv[np.isfinite(iv)]
                    if len(iv):
                        s.max_interval[name] = max(s.max_interval[name], float(iv.max()))
                        s.gaps[name] += int((iv > m.max_gap[name]).sum())
                    last_sample[name] = float(tg[-1])
            rows += len(t)
            if keep is not None:
                keep.append(block)
                if rows > CACHE_ROWS:
                    keep = None
            last_t, last_line = float(t[-1]), int(line_numbers[-1])
        if rows == 0:
            raise self._fail("has no data rows" + ("" if self.parquet else " after the header"))
        if keep is not None:
            self._cache = dict(enumerate(keep))
            self._pinned = True
        s.rows, s.duration = rows, last_t
        self.summary = s
        return s

    @property
    def blocks(self) -> int:
        """Number of blocks."""
        return len(self._block_times)

    def block_of(self, t: float) -> int:
        """Index of the block holding record time ``t`` [s] (the last block starting at or before it)."""
        import bisect

        return max(0, bisect.bisect_right(self._block_times, t) - 1)

    def read(self, k: int) -> Block:
        """Block ``k``, converted (from memory for a small record)."""
        if k in self._cache:
            return self._cache[k]
        for line_numbers, raw, times in self._raw_blocks(k):
            t = self._times(raw, times, line_numbers, self._first_rows[k])
            block = self._block(self._first_rows[k], raw, t)
            if len(self._cache) > 2:
                self._cache.pop(next(iter(self._cache)))
            self._cache[k] = block
            return block
        raise IndexError(k)
