"""Parquet records (the optional extra ``marinefmu[parquet]``, pyarrow): a Parquet copy of a CSV
record plays back exactly as the CSV, in process and through the SensorRecording FMU; bad input
is refused naming the file, the column and the row; without pyarrow a Parquet file is refused
with the install hint."""
import datetime as dt
import sys

import numpy as np
import pytest

from marinefmu.sea.recording import SensorRecording, SensorRecordingParams
from marinefmu.sea.recording import player as player_mod
from marinefmu.sea.recording import reader as reader_mod
from marinefmu.sea.recording.mapping import RecordingError, parse_mapping
from marinefmu.sea.recording.reader import Record
from marinefmu.sea.recording.schema import BOOLEAN_INDEX as B

from .conftest import BASIC_MAPPING, write

pa = pytest.importorskip("pyarrow", reason="Parquet records need pyarrow: pip install -e .[dev] (or marinefmu[parquet])")
pa_csv = pytest.importorskip("pyarrow.csv")
pq = pytest.importorskip("pyarrow.parquet")

#: A 3 s record at 100 Hz: IMU, GNSS at 5 Hz with its new and valid flags, a roll reference.
MAPPING = """
[time]
column = "t"
[imu]
max_gap = 0.025
acc = { x = "ax", y = "ay", z = "az" }
gyro = { x = "gx", y = "gy", z = "gz", unit = "deg/s" }
[gnss]
max_gap = 0.3
new = "new"
valid = "ok"
ant1 = { n = "n1", e = "e1", d = "d1", lever_arm = [1.0, 0.0, -2.0] }
[ref]
roll = { column = "roll", unit = "deg" }
"""


def _to_parquet(csv, path, text=False, row_group_size=None):
    """``csv`` read by pyarrow (its own type inference: int64, double, null for an empty field;
    or every column as text with ``text``) and written to ``path`` as Parquet."""
    convert = None
    if text:
        names = csv.read_text().splitlines()[0].split(",")
        convert = pa_csv.ConvertOptions(column_types={n: pa.string() for n in names}, strings_can_be_null=False)
    table = pa_csv.read_csv(csv, convert_options=convert)
    pq.write_table(table, path, row_group_size=row_group_size)
    return path


@pytest.fixture
def record(tmp_path):
    """The :data:`MAPPING` record as CSV (17 significant digits, seeded noise): a NaN in the
    accelerometer at 0.50 s, rows 1.20-1.26 s missing (a gap), empty GNSS fields between epochs,
    the epoch at 2.0 s flagged invalid, and integer columns (``ay``, ``new``, ``ok``)."""
    rng = np.random.default_rng(20261201)
    rows = []
    for k in range(301):
        t = k / 100
        if 120 <= k <= 126:
            continue
        a = rng.normal(size=3) + [0.0, 0.0, -9.81]
        g = rng.normal(scale=0.5, size=3)
        ax = "nan" if k == 50 else repr(float(a[0]))
        epoch = k % 20 == 0
        gnss = ",".join(repr(float(v)) for v in rng.normal(scale=3.0, size=3)) if epoch else ",,"
        rows.append(f"{t!r},{ax},{k % 7 - 3},{float(a[2])!r},{float(g[0])!r},{float(g[1])!r},{float(g[2])!r},"
                    f"{gnss},{int(epoch)},{int(k != 200) if epoch else ''},{float(rng.normal(scale=2.0))!r}")
    csv = write(tmp_path, "rec.csv", "t,ax,ay,az,gx,gy,gz,n1,e1,d1,new,ok,roll\n" + "\n".join(rows) + "\n")
    return csv, write(tmp_path, "rec.toml", MAPPING)


def _play(file, toml, times):
    """Real and Boolean outputs of the in-process player at each of ``times`` (arrays), and the player."""
    p = SensorRecording(SensorRecordingParams(str(file), str(toml)))
    real, flags, last = [], [], 0.0
    for t in times:
        real.append(list(p.step(t, t - last)))
        flags.append(list(p.boolean_outputs()))
        last = t
    return np.array(real), np.array(flags), p


@pytest.mark.parametrize("text", [False, True], ids=["typed", "text"])
def test_parquet_copy_plays_back_exactly_as_the_csv(record, tmp_path, monkeypatch, text):
    """A Parquet copy of a CSV record (pyarrow's own column types, or every column as text) gives
    the CSV's outputs bit for bit at every communication point, on the samples (0.01 s) and between
    them (0.007 s): the interpolated IMU, the held GNSS and ``gnss.new``, the validity through the
    NaN, the gap and the invalid epoch, and the scan's summary. Small blocks and cache: several
    blocks, read again from the file, also after an FMU state restore."""
    for mod in (reader_mod, player_mod):
        monkeypatch.setattr(mod, "BLOCK_ROWS", 64)
    monkeypatch.setattr(reader_mod, "CACHE_ROWS", 100)
    csv, toml = record
    parquet = _to_parquet(csv, tmp_path / "rec.parquet", text=text, row_group_size=100)
    if not text:
        types = pq.read_schema(parquet)
        assert types.field("ay").type == pa.int64() and types.field("ok").type == pa.int64()
    times = np.unique(np.concatenate([np.arange(1, 300) * 0.01, np.arange(1, 428) * 0.007]))
    real_csv, flags_csv, p_csv = _play(csv, toml, times)
    real_pq, flags_pq, p_pq = _play(parquet, toml, times)
    assert p_pq.record.blocks == p_csv.record.blocks == 5
    assert p_pq.record.summary == p_csv.record.summary
    np.testing.assert_array_equal(real_pq, real_csv)
    np.testing.assert_array_equal(flags_pq, flags_csv)
    # the record's features are in what was compared
    s = p_pq.record.summary
    assert s.rows == 294 and s.samples["gnss"] == 15 and s.bad["gnss"] == 1 and s.bad["imu.acc"] == 1
    assert s.gaps["imu.acc"] == 1 and s.samples["ref.roll"] == 294
    new, imu_ok, gnss_ok = flags_pq[:, B["gnss.new"]], flags_pq[:, B["imu.valid"]], flags_pq[:, B["gnss.valid"]]
    # gnss.new on each epoch's arrival: 0.2 ... 2.8 s without 1.2 s (in the gap); 0 s is the start
    assert new.sum() == 13 and not imu_ok.all() and imu_ok.sum() > 0.9 * len(times) and not gnss_ok.all()
    # a state restore reads the blocks from the file again: the same outputs
    q = SensorRecording(SensorRecordingParams(str(parquet), str(toml)))
    k = int(np.searchsorted(times, 2.5))
    for t, t0 in zip(times[:k], np.concatenate([[0.0], times[:k - 1]])):
        q.step(t, t - t0)
    state = q.get_state()
    fresh = SensorRecording(SensorRecordingParams(str(parquet), str(toml)))
    fresh.set_state(state)
    for j in range(k, len(times)):
        np.testing.assert_array_equal(fresh.step(times[j], times[j] - times[j - 1]), real_csv[j])
        np.testing.assert_array_equal(fresh.boolean_outputs(), flags_csv[j])


# --- bad input: each refusal names the file, the column and (where it can) the row ---------------

def _basic_table(**replace):
    """The ``basic`` fixture's record (conftest) as a pyarrow table, columns replaced by ``replace``."""
    n = 11
    cols = {"t": [round(k * 0.1, 1) for k in range(n)], "ax": [float(k) for k in range(n)], "ay": [2.0 * k for k in range(n)],
            "az": [-9.8] * n, "gx": [0.1 * k for k in range(n)], "gy": [0.0] * n, "gz": [0.0] * n,
            "n1": [float(k) if k % 5 == 0 else None for k in range(n)],
            "e1": [-float(k) if k % 5 == 0 else None for k in range(n)],
            "d1": [0.5 if k % 5 == 0 else None for k in range(n)], "roll": [0.01 * k for k in range(n)]}
    cols.update(replace)
    return pa.table({k: v for k, v in cols.items() if v is not None})


def _mapping():
    return parse_mapping(BASIC_MAPPING, "basic.toml")


def _write(tmp_path, table, name="r.parquet"):
    pq.write_table(table, tmp_path / name)
    return tmp_path / name


def test_basic_table_reads_as_the_basic_csv(basic, tmp_path):
    """The helper's table is the ``basic`` CSV: same times, values, presence and epochs."""
    csv, _ = basic
    a, b = Record(csv, _mapping()).read(0), Record(_write(tmp_path, _basic_table()), _mapping()).read(0)
    np.testing.assert_array_equal(b.time, a.time)
    for g in a.values:
        np.testing.assert_array_equal(b.values[g], a.values[g])
        np.testing.assert_array_equal(b.present[g], a.present[g])
        np.testing.assert_array_equal(b.good[g], a.good[g])
    np.testing.assert_array_equal(b.epoch, a.epoch)


@pytest.mark.parametrize("az, message", [
    (pa.array(["-9.8"] * 4 + ["oops"] + ["-9.8"] * 6), r"r.parquet, row 4, column 'az': 'oops' is not a number"),
    (pa.array(["-9.8", " -9.8 ", ""] + ["-9.8"] * 7 + ["1..2"]), r"r.parquet, row 10, column 'az': '1..2' is not a number"),
    (pa.array([dt.datetime(2026, 12, 1)] * 11, pa.timestamp("us")),
     r"r.parquet, column 'az': has non-numeric values \(Parquet type timestamp\[us\]\)"),
    (pa.array([b"\x00"] * 11, pa.binary()), r"r.parquet, column 'az': has non-numeric values \(Parquet type binary\)"),
    (pa.array([[1.0]] * 11, pa.list_(pa.float64())), r"r.parquet, column 'az': has non-numeric values \(Parquet type list"),
], ids=["text", "text-last-row", "timestamp", "binary", "list"])
def test_non_numeric_column_names_file_column_and_row(tmp_path, az, message):
    """A mapped column that is not a number is refused: text naming the row (from 0) and the
    value, any other non-numeric Parquet type naming its type."""
    with pytest.raises(RecordingError, match=message):
        Record(_write(tmp_path, _basic_table(az=az)), _mapping())


def test_numbers_as_text_booleans_and_decimals_read_as_in_the_csv(basic, tmp_path):
    """Text holding numbers (blanks around them ignored, an empty string = no sample, ``nan`` a bad
    sample), booleans and decimals read as the same fields of a CSV: values, presence and validity."""
    import decimal

    ax = ["0", " 1.5", "2 ", "", "nan"] + ["1e1"] * 6
    table = _basic_table(ax=pa.array(ax), ay=pa.array([k % 2 == 0 for k in range(11)]),
                         az=pa.array([decimal.Decimal("-9.81")] * 11, pa.decimal128(5, 2)))
    csv, _ = basic
    lines = csv.read_text().splitlines()
    for k in range(11):
        f = lines[k + 1].split(",")
        f[1:4] = [ax[k], str(int(k % 2 == 0)), "-9.81"]
        lines[k + 1] = ",".join(f)
    a = Record(write(tmp_path, "mixed.csv", "\n".join(lines) + "\n"), _mapping()).read(0)
    b = Record(_write(tmp_path, table), _mapping()).read(0)
    for what in ("values", "present", "good"):
        np.testing.assert_array_equal(getattr(b, what)["imu.acc"], getattr(a, what)["imu.acc"], err_msg=what)
    acc = b.values["imu.acc"]
    np.testing.assert_array_equal(acc[[0, 1, 2, 5], 0], [0.0, 1.5, 2.0, 10.0])
    np.testing.assert_array_equal(acc[:, 1], [1.0, 0.0] * 5 + [1.0])
    np.testing.assert_array_equal(acc[:, 2], [-9.81] * 11)
    assert np.isnan(acc[3:5, 0]).all() and not b.good["imu.acc"][3:5].any() and b.good["imu.acc"][[0, 1, 2, 5]].all()


@pytest.mark.parametrize("block_rows", [4096, 3], ids=["one-block", "across-blocks"])
@pytest.mark.parametrize("stamp, how", [(0.2, "repeats"), (0.1, "goes backwards")])
def test_time_going_backwards_or_repeating_names_the_time_column_and_row(tmp_path, monkeypatch, block_rows, stamp, how):
    """Row 3 (t = 0.3 s) stamped 0.2 or 0.1 s is refused naming the time column, the row and the
    row before it, also when row 3 starts a new block."""
    monkeypatch.setattr(reader_mod, "BLOCK_ROWS", block_rows)
    t = [k * 0.1 for k in range(11)]
    t[3] = stamp
    with pytest.raises(RecordingError, match=rf"r.parquet, row 3, column 't': time stamp {how} \(from row 2\)"):
        Record(_write(tmp_path, _basic_table(t=t)), _mapping())


def test_missing_time_stamp_names_the_row(tmp_path):
    """A null time stamp is refused naming its row."""
    t = [k * 0.1 for k in range(11)]
    t[6] = None
    with pytest.raises(RecordingError, match=r"r.parquet, row 6, column 't': time stamp is missing"):
        Record(_write(tmp_path, _basic_table(t=t)), _mapping())


def test_missing_column_names_the_column_and_the_signal(tmp_path):
    """A column the mapping names that the Parquet file lacks is refused naming it, the signal it
    maps to and the closest column the file has."""
    table = _basic_table(gx=None).append_column("gyro_x", pa.array([0.0] * 11))
    with pytest.raises(RecordingError, match=r"r.parquet, column 'gx': has no column 'gx' \(mapping basic.toml "
                                             r"maps it to imu.gyro.x\).*'gyro_x'"):
        Record(_write(tmp_path, table), _mapping())


def test_unreadable_or_empty_parquet(tmp_path):
    """A file with Parquet's magic bytes that is not Parquet is refused as such, a Parquet file
    without rows as having none."""
    bad = tmp_path / "bad.parquet"
    bad.write_bytes(b"PAR1" + b"\0" * 16 + b"PAR1")
    with pytest.raises(RecordingError, match=r"bad.parquet: cannot be read as Parquet"):
        Record(bad, _mapping())
    with pytest.raises(RecordingError, match=r"r.parquet: has no data rows$"):
        Record(_write(tmp_path, _basic_table().slice(0, 0)), _mapping())


# --- ISO-8601 time ---------------------------------------------------------------------------------

ISO = ["2026-12-01T11:00:00+01:00", "2026-12-01T10:00:00.25Z", "2026-12-01T10:00:00.5+00:00", "2026-12-01T10:00:01.5Z"]
ISO_MAPPING = '[time]\ncolumn = "when"\nunit = "iso8601"\n[ref]\nroll = "r"'


def test_iso_text_time_reads_as_in_the_csv(tmp_path):
    """ISO-8601 text in a Parquet string column (``Z`` and UTC offsets) gives the same record
    times as the same text in a CSV, 0, 0.25, 0.5 and 1.5 s."""
    csv = write(tmp_path, "t.csv", "when,r\n" + "".join(f"{s},0.1\n" for s in ISO))
    m = parse_mapping(ISO_MAPPING)
    parquet = _write(tmp_path, pa.table({"when": ISO, "r": [0.1] * 4}))
    a, b = Record(csv, m), Record(parquet, m)
    np.testing.assert_array_equal(b.read(0).time, a.read(0).time)
    np.testing.assert_array_equal(b.read(0).time, [0.0, 0.25, 0.5, 1.5])
    assert b.summary.start_time == a.summary.start_time == "2026-12-01T10:00:00.000000000"


def test_timestamp_column_with_a_time_zone_is_taken_in_utc(tmp_path):
    """A Parquet timestamp column (here microseconds, Europe/Oslo) reads as absolute time: the
    same record times as the ISO text, the start in UTC."""
    stamps = [dt.datetime.fromisoformat(s.replace("Z", "+00:00")) for s in ISO]
    table = pa.table({"when": pa.array(stamps, pa.timestamp("us", "UTC")).cast(pa.timestamp("us", "Europe/Oslo")),
                      "r": [0.1] * 4})
    rec = Record(_write(tmp_path, table), parse_mapping(ISO_MAPPING))
    np.testing.assert_array_equal(rec.read(0).time, [0.0, 0.25, 0.5, 1.5])
    assert rec.summary.start_time == "2026-12-01T10:00:00.000000000"


@pytest.mark.parametrize("when, unit, message", [
    (["2026-12-01T10:00:00", "yesterday"], "iso8601", r"row 1, column 'when': time stamp 'yesterday' is not ISO-8601"),
    (["2026-12-01T10:00:00", None], "iso8601", r"row 1, column 'when': time stamp is missing"),
    ([0.0, 1.0], "iso8601", r"column 'when': is Parquet type double: time.unit = 'iso8601' needs a timestamp or "
                            r"ISO-8601 text column"),
    (pa.array([0, 1_000_000], pa.timestamp("us")), "s",
     r"column 'when': has non-numeric values \(Parquet type timestamp\[us\]\) \(set time.unit = \"iso8601\""),
], ids=["bad-text", "null", "number", "timestamp-as-seconds"])
def test_bad_iso_time_is_refused_clearly(tmp_path, when, unit, message):
    """ISO time that is not ISO-8601 text, a null stamp, a numeric column under ``iso8601``, and a
    timestamp column under a numeric unit are refused naming the column (and the row)."""
    m = parse_mapping(f'[time]\ncolumn = "when"\nunit = "{unit}"\n[ref]\nroll = "r"')
    with pytest.raises(RecordingError, match=message):
        Record(_write(tmp_path, pa.table({"when": when, "r": [0.1, 0.2]})), m)


def test_without_pyarrow_a_parquet_record_is_refused_with_the_install_hint(tmp_path, monkeypatch):
    """With pyarrow not importable, a (valid) Parquet record is refused naming the file, the
    package and the extra that installs it."""
    path = _write(tmp_path, _basic_table())
    for name in ("pyarrow", "pyarrow.parquet", "pyarrow.compute"):
        monkeypatch.setitem(sys.modules, name, None)
    with pytest.raises(RecordingError, match=r"r.parquet: is a Parquet file, which needs the optional package "
                                             r"pyarrow \(pip install marinefmu\[parquet\]"):
        Record(path, _mapping())


# --- the FMU -----------------------------------------------------------------------------------------

@pytest.mark.fmu
def test_parquet_through_the_fmu_gives_the_csv_outputs(fmu_dir, record, tmp_path):
    """The built SensorRecording FMU under FMPy, 3 s at 0.01 s, on the CSV and on its Parquet copy:
    every output identical at every step (no error logged), with the NaN, the gap and the epochs in
    them."""
    from ...fmu.test_sensor_recording_fmu import Rec

    csv, toml = record
    parquet = _to_parquet(csv, tmp_path / "rec.parquet")
    runs = {}
    for name, file in (("csv", csv), ("parquet", parquet)):
        r = Rec(fmu_dir / "SensorRecording.fmu", tmp_path, name)
        r.init(file, toml)
        steps = [r.step(k) for k in range(300)]
        r.close()
        assert not [msg for status, msg in r.log if status >= 3], name     # doStep raises on an error
        runs[name] = (np.array([s[1] for s in steps]), np.array([s[2] for s in steps]))
    np.testing.assert_array_equal(runs["parquet"][0], runs["csv"][0])
    np.testing.assert_array_equal(runs["parquet"][1], runs["csv"][1])
    flags = runs["parquet"][1]
    # gnss.new on each epoch's arrival: 0.2 ... 3.0 s without 1.2 s (in the gap)
    assert flags[:, B["gnss.new"]].sum() == 14 and not flags[:, B["imu.valid"]].all() and not flags[:, B["gnss.valid"]].all()
