"""The worked mapping examples of docs/recordings.md (examples/recordings/) each load and map a
small sample of the record they describe, into the project's conventions."""
import math
from pathlib import Path

import numpy as np
import pytest

from marinefmu.sea.recording import SensorRecording, SensorRecordingParams
from marinefmu.sea.recording.mapping import G, load_mapping
from marinefmu.sea.recording.reader import Record
from marinefmu.sea.recording.schema import REAL_INDEX as R

EXAMPLES = Path(__file__).resolve().parents[3] / "examples" / "recordings"


def test_vesselmotion_export(tmp_path):
    """A results.csv as `marinefmu simulate` writes it (the columns the mapping reads, SI)."""
    m = load_mapping(EXAMPLES / "vesselmotion_export.toml")
    cols = [c for c in m.columns if c != "time"]
    rows = []
    for k in range(5):
        vals = {c: 0.001 * (i + 1) * k for i, c in enumerate(cols)}
        vals["vessel.imu.acc.z"] = -9.8
        vals["vessel.gnss.new"] = float(k % 2)
        vals["vessel.gnss.valid"] = 1.0
        rows.append(",".join([f"{0.01 * k:.2f}"] + [f"{vals[c]:.10g}" for c in cols]))
    csv = tmp_path / "results.csv"
    csv.write_text(",".join(["time", *cols]) + "\n" + "\n".join(rows) + "\n")
    b = Record(csv, m).read(0)
    assert b.values["imu.acc"][3, 2] == -9.8 and b.epoch.tolist() == [False, True, False, True, False]
    assert m.lever_arms["imu"] == (5.0, 1.0, -3.0) and m.antennas() == [1, 2, 3, 4]
    p = SensorRecording(SensorRecordingParams(str(csv), str(EXAMPLES / "vesselmotion_export.toml")))
    y = p.step(0.02, 0.01)
    assert y[R["ref.heave"]] == pytest.approx(b.values["ref.heave"][2, 0])


def test_orcaflex_record():
    from marinefmu.bench.peer_orcaflex import data_file, load_orcaflex

    rec = load_orcaflex()
    b = Record(data_file(), load_mapping(EXAMPLES / "orcaflex.toml")).read(0)
    n = len(b)
    np.testing.assert_array_equal(b.values["imu.acc"], rec.acc[:n])
    np.testing.assert_allclose(b.values["imu.gyro"], rec.gyro[:n], rtol=1e-15)
    np.testing.assert_allclose(b.values["ref.roll"][:, 0], rec.euler[:n, 0], rtol=1e-15)
    np.testing.assert_allclose(b.time, np.arange(n) / 10.24)          # time.rate: uniform samples
    assert b.epoch.all()                                               # a GNSS position on every row


def test_generic_mru_export():
    m = load_mapping(EXAMPLES / "generic_mru.toml")
    csv = EXAMPLES / "generic_mru_sample.csv"
    b = Record(csv, m).read(0)
    np.testing.assert_allclose(b.time, [0.0, 0.05, 0.1, 0.15, 0.2], atol=1e-12)
    # flu → frd: y and z change sign; roll kept, pitch negated; heave up → down, mm → m
    roll, pitch = math.radians(1.20), math.radians(0.50)
    assert b.values["ref.roll"][0, 0] == pytest.approx(roll) and b.values["ref.pitch"][0, 0] == pytest.approx(pitch)
    assert b.values["ref.heave"][0, 0] == pytest.approx(-0.120)
    # gravity removed → specific force: a level sensor at rest would read [0, 0, -g]
    a = np.array([0.0210, 0.0080, -0.0020]) * G
    g_b = G * np.array([-math.sin(pitch), math.sin(roll) * math.cos(pitch), math.cos(roll) * math.cos(pitch)])
    np.testing.assert_allclose(b.values["imu.acc"][0], a - g_b, rtol=1e-12)
    np.testing.assert_allclose(b.values["imu.gyro"][0], np.radians([0.50, 0.20, -0.10]), rtol=1e-12)
    assert m.lever_arms["imu"] == (12.0, 1.5, -4.0)
