"""The mapping sidecar: parsing, units, frames, and refusals that name the key."""
import pytest

from marinefmu.sea.recording.mapping import RecordingError, load_mapping, parse_mapping

from .conftest import BASIC_MAPPING


def test_basic_mapping_lists_columns_groups_and_lever_arms():
    m = parse_mapping(BASIC_MAPPING, "basic.toml")
    assert m.columns[0] == "t" and "ax" in m.columns and "n1" in m.columns
    assert list(m.channels) == ["imu.acc", "imu.gyro", "gnss", "ref.roll"]
    assert m.antennas() == [1]
    assert m.lever_arms["gnss.ant1"] == (1.0, 0.0, -2.0)
    assert m.max_gap["imu.acc"] == 0.15 and m.max_gap["gnss"] == 0.5


def test_units_scale_and_offset_give_the_si_factor():
    m = parse_mapping('[time]\ncolumn = "t"\n[imu]\nacc = { x = "a", y = { column = "b", scale = -2.0, offset = 1.0 }, '
                      'z = "c", unit = "g" }\ngyro = { x = "p", y = "q", z = { column = "r", unit = "rad/s" }, unit = "deg/s" }')
    acc = {c.output: c for c in m.channels["imu.acc"]}
    assert acc["imu.acc.x"].factor == 9.80665 and acc["imu.acc.y"].scale == -2.0 and acc["imu.acc.y"].offset == 1.0
    gyro = {c.output: c for c in m.channels["imu.gyro"]}
    assert gyro["imu.gyro.x"].factor == pytest.approx(0.017453292519943295) and gyro["imu.gyro.z"].factor == 1.0


def test_flu_lever_arms_become_frd_and_enu_needs_enu_axis_letters():
    m = parse_mapping('[time]\ncolumn = "t"\n[frames]\nbody = "flu"\nworld = "enu"\n'
                      '[imu]\nlever_arm = [1.0, 2.0, 3.0]\nacc = { x = "a", y = "b", z = "c" }\n'
                      '[gnss]\nant1 = { e = "x", n = "y", u = "z" }')
    assert m.lever_arms["imu"] == (1.0, -2.0, -3.0)
    with pytest.raises(RecordingError, match=r"gnss.ant1: unknown key\(s\) d.*world = 'enu'"):
        parse_mapping('[time]\ncolumn = "t"\n[frames]\nworld = "enu"\n[gnss]\nant1 = { n = "x", e = "y", d = "z" }')


@pytest.mark.parametrize("text, match", [
    ('[time]\ncolumn = "t"\nunit = "minutes"\n[imu]\nacc = { x = "a", y = "b", z = "c" }', r"time.unit = 'minutes' is not known"),
    ('[time]\ncolumn = "t"\n[imu]\nacc = { x = "a", y = "b", z = "c", unit = "ft/s2" }', r"imu.acc.unit = 'ft/s2' is not known.*m/s2"),
    ('[time]\ncolumn = "t"\n[frames]\nbody = "nwu"\n[imu]\nacc = { x = "a", y = "b", z = "c" }', r"frames.body = 'nwu' is not known"),
    ('[time]\ncolumn = "t"\n[frames]\nworld = "ecef"\n[imu]\nacc = { x = "a", y = "b", z = "c" }', r"frames.world = 'ecef'"),
    ('[time]\ncolumn = "t"\n[frames]\nacc = "linear"\n[imu]\nacc = { x = "a", y = "b", z = "c" }', r"frames.acc = 'linear'"),
    ('[time]\ncolumn = "t"\n[frames]\nacc = "gravity_removed"\n[imu]\nacc = { x = "a", y = "b", z = "c" }', r"needs ref.roll and ref.pitch"),
    ('[time]\ncolumn = "t"\n[imu]\nacc = { x = "a", y = "b" }', r"imu.acc: missing axis z"),
    ('[time]\ncolumn = "t"\n[imu]\naccel = { x = "a", y = "b", z = "c" }', r"\[imu\]: unknown key\(s\) accel"),
    ('[time]\ncolumn = "t"', r"maps no signal"),
    ('[imu]\nacc = { x = "a", y = "b", z = "c" }', r"missing \[time\]"),
    ('[time\ncolumn = "t"', r"not valid TOML"),
])
def test_bad_mappings_are_refused_naming_the_key(text, match):
    with pytest.raises(RecordingError, match=match):
        parse_mapping(text, "bad.toml")


def test_a_missing_sidecar_is_refused_naming_it(tmp_path):
    with pytest.raises(RecordingError, match=r"mapping .*nope.toml: cannot be read"):
        load_mapping(tmp_path / "nope.toml")
