"""The player: interpolation per signal, GNSS epochs, validity on NaN and gaps, the end of the
record, state and reset."""
import json
import math

import numpy as np
import pytest

from marinefmu.sea.recording.mapping import RecordingError
from marinefmu.sea.recording.player import SensorRecording, SensorRecordingParams
from marinefmu.sea.recording.schema import BOOLEAN_INDEX as B
from marinefmu.sea.recording.schema import REAL_INDEX as R

from .conftest import write


def player(csv, toml, **kw):
    return SensorRecording(SensorRecordingParams(str(csv), str(toml), **kw))


def test_linear_imu_and_held_gnss_with_new_on_the_arrival_step(basic):
    p = player(*basic)
    assert p.peek()[R["imu.acc.x"]] == 0.0 and p.peek()[R["gnss.ant1.n"]] == 0.0
    y = p.step(0.25, 0.25)
    assert y[R["imu.acc.x"]] == pytest.approx(2.5) and y[R["imu.acc.y"]] == pytest.approx(5.0)
    assert y[R["ref.roll"]] == pytest.approx(0.025)
    f = p.boolean_outputs()
    assert f[B["imu.valid"]] and f[B["ref.roll.valid"]] and not f[B["gnss.new"]] and f[B["gnss.valid"]]
    y = p.step(0.55, 0.3)   # the epoch at 0.5 s arrived in this step
    assert p.boolean_outputs()[B["gnss.new"]] and y[R["gnss.ant1.n"]] == 5.0 and y[R["gnss.ant1.e"]] == -5.0
    p.step(0.6, 0.05)
    assert not p.boolean_outputs()[B["gnss.new"]] and p.real_out[R["gnss.ant1.n"]] == 5.0
    assert not p.boolean_outputs()[B["heading.valid"]] and not p.boolean_outputs()[B["ref.cog.valid"]]


def test_non_uniform_stamps_interpolate_on_their_own_times(tmp_path):
    csv = write(tmp_path, "nu.csv", "t,r\n0,0\n0.1,1\n0.35,2\n0.4,3\n")
    toml = write(tmp_path, "nu.toml", '[time]\ncolumn = "t"\n[ref]\nroll = "r"\n')
    p = player(csv, toml)
    assert p.step(0.225, 0.225)[R["ref.roll"]] == pytest.approx(1.5)
    assert p.step(0.375, 0.15)[R["ref.roll"]] == pytest.approx(2.5)


def test_yaw_interpolates_across_the_wrap(tmp_path):
    csv = write(tmp_path, "y.csv", "t,y\n0,179\n1,-179\n")
    toml = write(tmp_path, "y.toml", '[time]\ncolumn = "t"\n[ref]\nmax_gap = 2.0\nyaw = { column = "y", unit = "deg" }\n')
    assert abs(player(csv, toml).step(0.5, 0.5)[R["ref.yaw"]]) == pytest.approx(math.pi)


def test_nan_and_gap_set_valid_false_hold_finite_values_and_log(tmp_path):
    rows = [f"{k * 0.01:.2f},{k},0,-9.8" for k in range(30)]
    rows[10] = "0.10,nan,0,-9.8"
    del rows[20:25]                       # a 0.06 s gap
    csv = write(tmp_path, "g.csv", "t,ax,ay,az\n" + "\n".join(rows) + "\n")
    toml = write(tmp_path, "g.toml", '[time]\ncolumn = "t"\n[imu]\nmax_gap = 0.03\nacc = { x = "ax", y = "ay", z = "az" }\n')
    p = player(csv, toml)
    valid, ax, logs = {}, {}, []
    for k in range(29):
        t = (k + 0.5) * 0.01              # between samples
        y = p.step(t, 0.01)
        valid[k], ax[k] = p.boolean_outputs()[B["imu.valid"]], y[R["imu.acc.x"]]
        logs += p.messages
    assert all(math.isfinite(v) for v in ax.values())
    assert valid[8] and not valid[9] and not valid[10] and valid[11]   # the NaN at 0.10 s spoils 0.095 and 0.105
    assert ax[9] == ax[10] == ax[8] == pytest.approx(8.5)              # held
    assert valid[18] and not any(valid[k] for k in range(19, 25)) and valid[25]   # the gap 0.19 .. 0.25 s
    assert any("bad sample" in m and "imu.valid = false" in m for m in logs)
    assert any("gap of 0.06" in m for m in logs) and any("good samples again" in m for m in logs)
    assert p.invalid_steps["imu.valid"] == sum(not v for v in valid.values())


def test_end_of_record_holds_sets_valid_false_and_logs_once(basic):
    p = player(*basic)
    p.step(1.0, 1.0)
    last = list(p.real_out)
    assert p.boolean_outputs()[B["imu.valid"]] and p.boolean_outputs()[B["record.active"]]
    logs = []
    for k in range(5):
        p.step(1.1 + 0.1 * k, 0.1)
        logs += p.messages
    assert [m for m in logs if "end of the record" in m] == logs and len(logs) == 1
    assert p.real_out[:-1] == last[:-1] and not any(p.boolean_outputs())


def test_start_offset_and_start_beyond_the_record(basic):
    p = player(*basic, start=0.5)
    assert p.peek()[R["imu.acc.x"]] == pytest.approx(5.0) and p.peek()[R["gnss.ant1.n"]] == 5.0
    assert p.step(0.1, 0.1)[R["imu.acc.x"]] == pytest.approx(6.0)
    with pytest.raises(RecordingError, match=r"start = 2 s is at or after the end of the record \(1 s"):
        player(*basic, start=2.0)


def test_state_restore_and_reset_repeat_bit_for_bit(tmp_path, monkeypatch):
    from marinefmu.sea.recording import player as player_mod
    from marinefmu.sea.recording import reader as reader_mod

    monkeypatch.setattr(reader_mod, "BLOCK_ROWS", 32)
    monkeypatch.setattr(player_mod, "BLOCK_ROWS", 32)
    monkeypatch.setattr(reader_mod, "CACHE_ROWS", 10)     # blocks read from the file again
    t = np.arange(600) * 0.01
    rng = np.random.default_rng(1)
    gnss = np.where(np.arange(600) % 20 == 0, t, np.nan)
    acc = np.sin(t) + 0.01 * rng.normal(size=600)
    acc[[100, 333]] = np.nan
    lines = ["t,ax,ay,az,n"] + [f"{float(a)!r},{float(b)!r},0,-9.8,{'' if np.isnan(c) else repr(float(c))}" for a, b, c in zip(t, acc, gnss)]
    csv = write(tmp_path, "s.csv", "\n".join(lines) + "\n")
    toml = write(tmp_path, "s.toml", '[time]\ncolumn = "t"\n[imu]\nacc = { x = "ax", y = "ay", z = "az" }\n'
                                     '[gnss]\nmax_gap = 0.3\nant1 = { n = "n", e = "n", d = "n" }\n')
    p = player(csv, toml)

    def run(m, k0, k1):
        return [(m.step(k * 0.0137, 0.0137), m.boolean_outputs()) for k in range(k0, k1)]

    first = run(p, 1, 200)
    state = json.loads(json.dumps(p.get_state()))
    rest = run(p, 200, 450)
    p.set_state(state)
    assert run(p, 200, 450) == rest
    fresh = player(csv, toml)
    fresh.set_state(state)
    assert run(fresh, 200, 450) == rest
    p.reset()
    assert run(p, 1, 200) == first
