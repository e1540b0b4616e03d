"""``marinefmu record`` and ``marinefmu replay``: the plan (wiring, lever arms, refusals), the
commands, the lag-aligned scores and the report."""
import numpy as np
import pytest

from marinefmu.cli import main
from marinefmu.cosim.replay import plan_replay
from marinefmu.errors import MarineFmuError


@pytest.fixture(scope="module")
def rec(tmp_path_factory):
    from marinefmu.cosim.record import record

    return record("system", tmp_path_factory.mktemp("rec") / "sys.csv", duration=75.0)


def test_record_writes_vessel_names_ref_columns_and_a_sidecar(rec):
    header = rec.csv.read_text().split("\n", 1)[0].split(",")
    assert header[:4] == ["time", "imu.acc.x", "imu.acc.y", "imu.acc.z"]
    assert {"gnss.ant4.d", "gnss.valid", "gnss.new", "ref.roll", "ref.heave", "ref.cog.d"} <= set(header)
    assert rec.rows == 7501 and rec.step == 0.01
    text = rec.mapping.read_text()
    assert "lever_arm = [5.0, 1.0, -3.0]" in text and "lever_arm = [62.0, 0.0, -12.0]" in text


def test_plan_wires_the_system_scenario_with_the_records_lever_arms(rec):
    plan = plan_replay(rec.csv, rec.mapping, "heave,fusion", point="60,0,-10")
    comps = {c.name: c for c in plan.system.components}
    assert list(comps) == ["rec", "att", "heave", "fusion"] and "AttitudeEstimator was added" in plan.notes[0]
    assert comps["fusion"].parameters["acc_lever_arm.x"] == 5.0 and comps["fusion"].parameters["ant2.x"] == 10.0
    assert (comps["heave"].parameters["point.x"], comps["heave"].parameters["point.z"]) == (55.0, -7.0)
    wires = {(c.start, c.start_var, c.end, c.end_var) for c in plan.system.connections}
    assert ("rec", "imu.acc.z", "heave", "acc.z") in wires and ("att", "roll", "heave", "roll") in wires
    assert ("rec", "gnss.new", "fusion", "gnss.new") in wires


def test_plan_refusals_and_a_run_longer_than_the_record(rec, tmp_path):
    with pytest.raises(MarineFmuError, match="unknown 'kalman'"):
        plan_replay(rec.csv, rec.mapping, "kalman")
    with pytest.raises(MarineFmuError, match=r"--imu = '1,2' must be three numbers"):
        plan_replay(rec.csv, rec.mapping, "attitude", imu="1,2")
    one = tmp_path / "one.toml"
    one.write_text('[time]\ncolumn = "time"\n[imu]\nacc = { x = "imu.acc.x", y = "imu.acc.y", z = "imu.acc.z" }\n'
                   '[gnss]\nant1 = { n = "gnss.ant1.n", e = "gnss.ant1.e", d = "gnss.ant1.d" }\n')
    with pytest.raises(MarineFmuError, match=r"GnssAccFusion needs four GNSS antennas, or one receiver and a compass "
                                             r"heading for its yaw; the mapping .*one.toml has 1 antenna\(s\) and no \[heading\]"):
        plan_replay(rec.csv, one, "fusion")
    with pytest.raises(MarineFmuError, match=r"attitude|att: needs imu.gyro"):
        plan_replay(rec.csv, one, "attitude")
    plan = plan_replay(rec.csv, rec.mapping, "attitude", duration=100.0)
    assert any("longer than the record" in n for n in plan.notes)


def one_receiver_mapping(rec, path):
    """The record's mapping with antenna 1 only and its true yaw as a compass heading."""
    lines = [ln for ln in rec.mapping.read_text().splitlines() if not ln.startswith(("ant2", "ant3", "ant4"))]
    path.write_text("\n".join(lines) + '\n[heading]\ncolumn = "ref.yaw"\n')
    return path


def test_a_one_receiver_record_wires_the_fusion_to_the_attitude_estimator_and_the_compass(rec, tmp_path):
    plan = plan_replay(rec.csv, one_receiver_mapping(rec, tmp_path / "one.toml"), "fusion")
    comps = {c.name: c for c in plan.system.components}
    assert list(comps) == ["rec", "att", "fusion"] and "AttitudeEstimator was added" in plan.notes[0]
    fus = comps["fusion"].parameters
    assert fus["attitude"] == "input" and fus["attitude_lag"] == plan.system.step == 0.01
    assert (fus["ant1.x"], fus["ant1.y"], fus["ant1.z"]) == (10.0, -4.0, -10.0) and fus["acc_lever_arm.x"] == 5.0
    wires = {(c.start, c.start_var, c.end, c.end_var) for c in plan.system.connections}
    assert {("att", "roll", "fusion", "roll"), ("att", "pitch", "fusion", "pitch"), ("rec", "heading", "fusion", "yaw"),
            ("rec", "gnss.ant1.n", "fusion", "gnss.ant1.n"), ("rec", "imu.gyro.x", "fusion", "gyro.x")} <= wires
    assert not any(c.end == "fusion" and c.end_var.startswith("gnss.ant2") for c in plan.system.connections)
    # without its lever arm the receiver is taken at the IMU
    text = (tmp_path / "one.toml").read_text().replace(", lever_arm = [10.0, -4.0, -10.0]", "")
    (tmp_path / "bare.toml").write_text(text)
    plan = plan_replay(rec.csv, tmp_path / "bare.toml", "attitude,fusion")
    fus = {c.name: c for c in plan.system.components}["fusion"].parameters
    assert (fus["ant1.x"], fus["ant1.z"]) == (5.0, -3.0) and any("receiver is taken at the IMU" in n for n in plan.notes)


def test_replay_of_a_one_receiver_record_scores_the_fusion(rec, fmu_dir, tmp_path):
    """``--estimators attitude,fusion`` on antenna 1 of the system record (5 Hz RTK) and its true
    yaw as the compass: the fusion is valid and scored against ref.cog from 60 s after it turned
    valid (measured 0.85 / 0.69 / 0.74 cm RMS N / E / D; bound 2 cm)."""
    from marinefmu.analysis.replay_report import replay_and_report

    plan = plan_replay(rec.csv, one_receiver_mapping(rec, tmp_path / "one.toml"), "attitude,fusion", duration=75.0)
    r = replay_and_report(plan, fmu_dir, tmp_path / "out", progress=False)
    res = np.load(tmp_path / "out" / "results.npy")
    assert res["fusion.valid"][-1000:].all()
    scores = {k: v["rms"] for k, v in r["scores"].items() if k.startswith("fusion.pos")}
    assert len(scores) == 3 and all(rms < 2.0 for rms in scores.values()), scores


def test_best_lag_finds_a_known_delay():
    from marinefmu.analysis.replay_report import best_lag

    t = np.arange(5000) * 0.01
    ref = np.sin(0.7 * t) + 0.3 * np.sin(2.1 * t)
    est = np.roll(ref, 37)
    lag, rms, rms0 = best_lag(est[100:], ref[100:], 500)
    assert lag == 37 and rms < 1e-12 < rms0


def test_replay_command_scores_against_ref_and_writes_the_report(rec, fmu_dir, tmp_path, capsys):
    out = tmp_path / "replay"
    assert main(["replay", str(rec.csv), "--mapping", str(rec.mapping), "--estimators", "attitude", "--out", str(out),
                 "--fmus", str(fmu_dir), "--duration", "75", "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "att.roll" in text and "RMS" in text and ", lag " in text and "(at lag 0:" in text
    page = (out / "report.html").read_text()
    assert "Estimates against the record" in page and "att.roll" in page and "bad samples" in page
    assert (out / "results.npy").exists() and (out / "results.csv").exists()
    res = np.load(out / "results.npy")
    assert res["rec.imu.valid"][1:].all() and res["att.valid"][-1]


def test_replay_without_reference_shows_estimates_and_counts_bad_samples(rec, fmu_dir, tmp_path):
    from marinefmu.analysis.replay_report import replay_and_report

    lines = rec.csv.read_text().splitlines()[:2001]
    cols = lines[0].split(",")
    ax = cols.index("imu.acc.x")
    for k in (500, 501, 900):
        f = lines[k].split(",")
        f[ax] = "nan"
        lines[k] = ",".join(f)
    csv = tmp_path / "noref.csv"
    csv.write_text("\n".join(lines) + "\n")
    toml = tmp_path / "noref.toml"
    toml.write_text('[time]\ncolumn = "time"\n[imu]\nacc = { x = "imu.acc.x", y = "imu.acc.y", z = "imu.acc.z" }\n'
                    'gyro = { x = "imu.gyro.x", y = "imu.gyro.y", z = "imu.gyro.z" }\n')
    plan = plan_replay(csv, toml, "attitude")
    r = replay_and_report(plan, fmu_dir, tmp_path / "out", progress=False)
    assert r["scores"] == {}
    rows = {g: (n, bad, steps) for g, n, bad, gaps, steps, _ in r["validity"]}
    assert rows["imu.acc"][:2] == (2000, 3) and rows["imu.acc"][2] == 3     # steps landing on the NaN rows
    page = r["report"].read_text()
    assert "no reference signal" in page and "validity timeline" in page and "spectra" in page
