"""The streaming reader: blocks, empty fields, time units, compression, and bad input refused
naming the file, the column and the line."""
import gzip

import numpy as np
import pytest

from marinefmu.sea.recording import reader as reader_mod
from marinefmu.sea.recording.mapping import RecordingError, parse_mapping
from marinefmu.sea.recording.reader import Record

from .conftest import BASIC_MAPPING, write


def test_scan_counts_samples_epochs_and_duration(basic):
    csv, toml = basic
    rec = Record(csv, parse_mapping(toml.read_text(), str(toml)))
    s = rec.summary
    assert s.rows == 11 and s.duration == pytest.approx(1.0)
    assert s.samples["imu.acc"] == 11 and s.samples["gnss"] == 3 and s.bad["gnss"] == 0
    assert s.max_interval["gnss"] == pytest.approx(0.5)
    b = rec.read(0)
    assert b.epoch.tolist() == [k % 5 == 0 for k in range(11)]
    assert np.isnan(b.values["gnss"][1]).all() and not b.present["gnss"][1]


def test_blocks_stream_a_longer_record_compressed(tmp_path, monkeypatch):
    monkeypatch.setattr(reader_mod, "BLOCK_ROWS", 64)
    monkeypatch.setattr(reader_mod, "CACHE_ROWS", 100)
    n = 1000
    t = np.arange(n) * 0.01
    data = np.column_stack([t, np.sin(t), np.cos(t), -9.8 + 0 * t])
    path = tmp_path / "long.csv.gz"
    with gzip.open(path, "wt") as fh:
        fh.write("t,ax,ay,az\n")
        np.savetxt(fh, data, delimiter=",", fmt="%.17g")
    m = parse_mapping('[time]\ncolumn = "t"\n[imu]\nacc = { x = "ax", y = "ay", z = "az" }')
    rec = Record(path, m)
    assert rec.blocks == 16 and rec.summary.rows == n
    k = rec.block_of(5.0)
    b = rec.read(k)
    assert b.first_row == 64 * k and b.time[0] <= 5.0 < b.time[0] + 64 * 0.01
    np.testing.assert_array_equal(b.values["imu.acc"][:, 0], np.sin(t[b.first_row:b.first_row + len(b)]))


@pytest.mark.parametrize("unit, stamps, expected", [
    ("ms", ["1000", "1010", "1030"], [0.0, 0.01, 0.03]),
    ("us", ["5", "10005", "20005"], [0.0, 0.01, 0.02]),
    ("iso8601", ["2026-12-01T10:00:00Z", "2026-12-01T10:00:00.25Z", "2026-12-01T10:00:01.5Z"], [0.0, 0.25, 1.5]),
    ("iso8601", ["2026-12-01T11:00:00+01:00", "2026-12-01T10:00:00.5+00:00", "2026-12-01T10:00:01+00:00"], [0.0, 0.5, 1.0]),
])
def test_time_units(tmp_path, unit, stamps, expected):
    csv = write(tmp_path, "t.csv", "when,r\n" + "".join(f"{s},0.1\n" for s in stamps))
    m = parse_mapping(f'[time]\ncolumn = "when"\nunit = "{unit}"\n[ref]\nroll = "r"')
    np.testing.assert_allclose(Record(csv, m).read(0).time, expected, atol=1e-12)


# --- bad input: each refusal names the file, the column and the line --------------------------

def _mapping():
    return parse_mapping(BASIC_MAPPING, "basic.toml")


def test_missing_file(tmp_path):
    with pytest.raises(RecordingError, match=r"record .*absent.csv: no such file"):
        Record(tmp_path / "absent.csv", _mapping())


def test_unreadable_file(tmp_path):
    bad = tmp_path / "bad.csv.gz"
    bad.write_bytes(b"\x1f\x8b\x08\x00garbage")
    with pytest.raises(RecordingError, match=r"bad.csv.gz: cannot be read"):
        Record(bad, _mapping())


def test_missing_column_names_the_column_and_the_signal(basic, tmp_path):
    csv, _ = basic
    text = csv.read_text().replace("gx,", "gyro_x,", 1)
    with pytest.raises(RecordingError, match=r"r2.csv, column 'gx': has no column 'gx' \(mapping basic.toml maps it to imu.gyro.x\).*'gyro_x'"):
        Record(write(tmp_path, "r2.csv", text), _mapping())


def test_non_numeric_value_names_line_and_column(basic, tmp_path):
    csv, _ = basic
    lines = csv.read_text().splitlines()
    lines[4] = lines[4].replace(",-9.8,", ",oops,", 1)
    with pytest.raises(RecordingError, match=r"r3.csv, line 5, column 'az': 'oops' is not a number"):
        Record(write(tmp_path, "r3.csv", "\n".join(lines) + "\n"), _mapping())


@pytest.mark.parametrize("stamp, how", [("0.2", "repeats"), ("0.1", "goes backwards")])
def test_time_going_backwards_or_repeating_names_the_line(basic, tmp_path, stamp, how):
    csv, _ = basic
    lines = csv.read_text().splitlines()
    lines[4] = stamp + lines[4][3:]    # file line 5 holds t = 0.3
    with pytest.raises(RecordingError, match=rf"line 5, column 't': time stamp {how} \(from line 4\)"):
        Record(write(tmp_path, "r4.csv", "\n".join(lines) + "\n"), _mapping())


def test_missing_time_stamp_names_the_line(basic, tmp_path):
    csv, _ = basic
    lines = csv.read_text().splitlines()
    lines[6] = "," + lines[6].split(",", 1)[1]
    with pytest.raises(RecordingError, match=r"line 7, column 't': time stamp is missing"):
        Record(write(tmp_path, "r5.csv", "\n".join(lines) + "\n"), _mapping())


def test_bad_iso_time_names_the_line(tmp_path):
    csv = write(tmp_path, "t.csv", "when,r\n2026-12-01T10:00:00,1\nyesterday,2\n")
    m = parse_mapping('[time]\ncolumn = "when"\nunit = "iso8601"\n[ref]\nroll = "r"')
    with pytest.raises(RecordingError, match=r"line 3, column 'when': time stamp 'yesterday' is not ISO-8601"):
        Record(csv, m)


def test_empty_record_and_parquet_without_pyarrow(tmp_path):
    with pytest.raises(RecordingError, match=r"has no data rows"):
        Record(write(tmp_path, "e.csv", "t,ax,ay,az,gx,gy,gz,n1,e1,d1,roll\n"), _mapping())
    pq = tmp_path / "r.parquet"
    pq.write_bytes(b"PAR1" + b"\0" * 16 + b"PAR1")
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        with pytest.raises(RecordingError, match=r"r.parquet: is a Parquet file, which needs the optional package pyarrow"):
            Record(pq, _mapping())
