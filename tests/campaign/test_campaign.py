"""Campaigns on Dask (docs/campaigns.md): the spec's refusals, the grid, and a real LocalCluster
run with a deliberately failing run, resume and a torn log line."""
from __future__ import annotations

import json
import math

import pytest

from marinefmu.campaign import CampaignError, CampaignSpecError, load_spec, parse_spec, run_campaign
from marinefmu.campaign.table import LOG_NAME, read_table

pytestmark = pytest.mark.fmu

# VesselMotion and the AttitudeEstimator alone: the cheapest system with a scored estimator.
SCENARIO = """
[scenario]
name = "att_only"
duration = 30.0
[components.vessel]
fmu = "VesselMotion"
[components.vessel.parameters]
sea = { hs = 2.0, tp = 9.0 }
[components.att]
fmu = "AttitudeEstimator"
[[connections]]
from = "vessel.imu.acc.x"
to = "att.acc.x"
[[connections]]
from = "vessel.imu.acc.y"
to = "att.acc.y"
[[connections]]
from = "vessel.imu.acc.z"
to = "att.acc.z"
[[connections]]
from = "vessel.imu.gyro.x"
to = "att.gyro.x"
[[connections]]
from = "vessel.imu.gyro.y"
to = "att.gyro.y"
[[connections]]
from = "vessel.imu.gyro.z"
to = "att.gyro.z"
"""

# 2 × 2 × 2 runs of 30 s. sea.omega_min = 0.6 and sea.omega_max = 0.5 are each valid alone (the
# other one is then chosen from Tp), but not together: VesselMotion refuses that pair at
# initialisation, so two runs (one per Hs) fail for real, after the spec's checks passed.
SPEC = """
[campaign]
name = "small"
scenario = "att_only.toml"
duration = 30.0
settle = 5.0
[grid]
"vessel.sea.hs" = [1.0, 2.0]
"vessel.sea.omega_min" = [0.0, 0.6]
"vessel.sea.omega_max" = [0.0, 0.5]
"""


@pytest.fixture()
def spec_file(tmp_path):
    (tmp_path / "att_only.toml").write_text(SCENARIO)
    path = tmp_path / "small.toml"
    path.write_text(SPEC)
    return path


def _spec(tmp_path, fmu_dir, text: str, check_values: bool = False):
    (tmp_path / "att_only.toml").write_text(SCENARIO)
    return parse_spec(text, fmu_dir, "spec.toml", tmp_path, check_values)


@pytest.mark.parametrize("change, message", [
    (("[grid]", "[grid]\n\"vessel.sea.gamma\" = []"), "grid.'vessel.sea.gamma' is empty"),
    (("[grid]", "[grid]\n\"boat.sea.gamma\" = [2.0]"), "'boat.sea.gamma' must be 'component.parameter' with a component"),
    (("[grid]", "[grid]\n\"vessel.sea.hss\" = [2.0]"), "has no variable 'sea.hss' (did you mean 'sea.hs'"),
    (("[grid]", "[grid]\n\"vessel.sea.seed\" = [1.5]"), "vessel.sea.seed is Integer; cannot set it to 1.5"),
    (("[grid]", "[grid]\n\"vessel.truth.roll\" = [1.0]"), "vessel.truth.roll has causality 'output', expected parameter"),
    (("settle = 5.0", "settle = 5.0\nworkers = 3"), "[campaign]: unknown key(s) workers"),
    (("settle = 5.0", "settle = 50.0"), "campaign.settle = 50 is out of range: must be below campaign.duration = 30 s"),
    (("duration = 30.0", "duration = -1.0"), "campaign.duration = -1.0 is out of range: must be in (0, 1e+06]"),
    (("settle = 5.0", "settle = 5.0\nmetrics = [\"att.heave_cm\"]"), "a AttitudeEstimator has no metric 'heave_cm'"),
    (("settle = 5.0", "settle = 5.0\nmetrics = [\"vessel.roll_deg\"]"), "'vessel' is not a scored component"),
    (("[grid]", "[sets.s.a]\n\"vessel.sea.hs\" = 3.0\n[grid]"), "sets.s.a: vessel.sea.hs is also in [grid]"),
    (("[grid]", "[sets.s.a]\n\"vessel.sea.tp\" = 8.0\n[sets.s.b]\n\"vessel.sea.gamma\" = 2.0\n[grid]"),
     "sets.s: every label must set the same parameters"),
    (("[grid]", "[grid]\n\"vessel.sea.tp\" = { start = 6.0, stop = 9.0 }"),
     "must be a list or a table {start, stop, step} or {start, stop, num}"),
    (("\"vessel.sea.hs\" = [1.0, 2.0]", "\"vessel.sea.hs\" = [1.0, 1.0]"), "repeats a value"),
])
def test_a_bad_spec_is_refused_naming_the_key(tmp_path, fmu_dir, change, message):
    with pytest.raises(CampaignSpecError) as exc:
        _spec(tmp_path, fmu_dir, SPEC.replace(*change, 1))
    assert message in str(exc.value)


def test_a_value_the_fmu_refuses_is_refused_before_anything_runs(tmp_path, fmu_dir):
    text = SPEC.replace("[1.0, 2.0]", "[1.0, 40.0]", 1)
    with pytest.raises(CampaignSpecError) as exc:
        _spec(tmp_path, fmu_dir, text, check_values=True)
    assert "grid.'vessel.sea.hs' = 40.0: refused" in str(exc.value)
    assert "sea.hs = 40" in str(exc.value) and "30" in str(exc.value)   # the FMU's own range
    assert not (tmp_path / LOG_NAME).exists()


def test_the_runs_are_the_grid_times_the_sets_with_stable_ids(tmp_path, fmu_dir):
    text = SPEC.replace("[grid]", '[sets.imu.bow]\n"vessel.imu" = { x = 50.0, y = 0.0, z = -5.0 }\n'
                                  '[sets.imu.cog]\n"vessel.imu" = { x = 0.0, y = 0.0, z = 0.0 }\n[grid]')
    text = text.replace('"vessel.sea.omega_min" = [0.0, 0.6]', '"vessel.sea.tp" = { start = 6.0, stop = 12.0, step = 3.0 }')
    spec = _spec(tmp_path, fmu_dir, text)
    runs = spec.runs()
    assert spec.grid["vessel.sea.tp"] == (6.0, 9.0, 12.0)
    assert spec.axes == ["vessel.sea.hs", "vessel.sea.tp", "vessel.sea.omega_max", "imu"]
    assert len(runs) == 2 * 3 * 2 * 2 and len({r.id for r in runs}) == len(runs)
    first = runs[0]
    assert first.values == {"vessel.sea.hs": 1.0, "vessel.sea.tp": 6.0, "vessel.sea.omega_max": 0.0, "imu": "bow"}
    assert first.overrides == {"vessel": {"sea.hs": 1.0, "sea.tp": 6.0, "sea.omega_max": 0.0,
                                          "imu.x": 50.0, "imu.y": 0.0, "imu.z": -5.0}}
    assert [r.id for r in _spec(tmp_path, fmu_dir, text).runs()] == [r.id for r in runs]   # stable: resume finds them
    longer = _spec(tmp_path, fmu_dir, text.replace("duration = 30.0", "duration = 40.0"))
    assert not {r.id for r in longer.runs()} & {r.id for r in runs}   # another duration is another run


@pytest.mark.isolated(timeout=600)
def test_a_local_cluster_runs_the_grid_records_a_failure_and_resumes(spec_file, tmp_path, fmu_dir):
    from marinefmu.cosim.system import SystemRunner
    from marinefmu.analysis.scoring import COMMON_METRICS, METRICS, score

    spec = load_spec(spec_file, fmu_dir)
    out = tmp_path / "out"
    first = run_campaign(spec, out, workers=2, progress=False)
    assert (first.total, first.ran, first.ok, first.failed, first.skipped) == (8, 8, 6, 2, 0)
    rows = read_table(out / "results.csv")
    assert [r["id"] for r in rows] == [r.id for r in spec.runs()]   # every run, in the campaign's order
    for row in rows:
        bad = row["vessel.sea.omega_min"] == 0.6 and row["vessel.sea.omega_max"] == 0.5
        assert row["status"] == ("failed" if bad else "ok")
        if bad:
            assert "sea.omega_max = 0.5" in row["error"] and "vessel: initialisation failed" in row["error"]
            assert math.isnan(row["att.roll_deg"])
        else:
            assert 0.0 < row["att.roll_deg"] < 0.5 and 0.0 < row["att.pitch_deg"] < 0.5
            assert 10.0 < row["att.scored_s"] <= 25.0   # after valid (the estimator's start-up) + 5 s
    assert len({r["worker"] for r in rows}) == 2                     # both workers took runs
    records = [json.loads(line) for line in (out / LOG_NAME).read_text().splitlines()]
    for rec in records:
        for name in rec["metrics"]:
            comp, metric = name.split(".", 1)
            assert comp == "att" and metric in METRICS["AttitudeEstimator"] + COMMON_METRICS

    # the table holds what a run of the same system in this process gives, to the last digit
    run = spec.runs()[0]
    system = spec.scenario.system.with_parameters(run.overrides)
    result = SystemRunner(system, fmu_dir).run(spec.duration, progress=False)
    direct = score(result, system, "vessel", spec.settle)["att"]
    assert {m: rows[0][f"att.{m}"] for m in direct} == direct

    again = run_campaign(spec, out, workers=2, progress=False)          # resume: nothing to do
    assert (again.ran, again.skipped, again.ok, again.failed) == (0, 8, 6, 2)
    assert [json.loads(line) for line in (out / LOG_NAME).read_text().splitlines()] == records

    # a run cut off in the middle of writing its line (a crash, a Ctrl-C) is run again
    log_text = (out / LOG_NAME).read_text()
    (out / LOG_NAME).write_text(log_text[: log_text.rindex("\n", 0, -1) + 1] + log_text.splitlines()[-1][:40])
    torn = run_campaign(spec, out, workers=1, progress=False)
    assert (torn.ran, torn.skipped, torn.ok + torn.failed) == (1, 7, 8)
    assert [r["id"] for r in read_table(out / "results.csv")] == [r.id for r in spec.runs()]

    retried = run_campaign(spec, out, workers=2, progress=False, retry_failed=True)
    assert (retried.ran, retried.failed) == (2, 2)                   # the failing pair fails again


@pytest.mark.isolated(timeout=600)
def test_ctrl_c_between_a_runs_log_line_and_the_table_rewrite_keeps_them_equal(spec_file, tmp_path, fmu_dir,
                                                                                 monkeypatch):
    """Ctrl-C right after the first run's line reached ``runs.jsonl``, before ``results.csv``
    was rewritten (seen once in CI: the interrupted CLI said 1 run was in the table, which had
    none). The table follows the log again before the interrupt goes on."""
    from marinefmu.campaign import engine

    calls = []
    real = engine.write_table

    def interrupted_rewrite(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:                  # the rewrite after the first finished run
            raise KeyboardInterrupt
        return real(*args, **kwargs)

    monkeypatch.setattr(engine, "write_table", interrupted_rewrite)
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_campaign(load_spec(spec_file, fmu_dir), out, workers=1, progress=False)
    logged = [json.loads(line)["id"] for line in (out / LOG_NAME).read_text().splitlines()]
    assert len(logged) == 1 and len(calls) == 3
    assert [r["id"] for r in read_table(out / "results.csv")] == logged


def test_an_unreachable_scheduler_fails_fast_naming_it(spec_file, tmp_path, fmu_dir, monkeypatch):
    import time

    from marinefmu.campaign import engine

    monkeypatch.setattr(engine, "CONNECT_TIMEOUT", 2.0)
    spec = load_spec(spec_file, fmu_dir, check_values=False)
    t0 = time.perf_counter()
    with pytest.raises(CampaignError, match=r"--scheduler 'tcp://127.0.0.1:9': cannot reach a Dask scheduler"):
        run_campaign(spec, tmp_path / "out", scheduler="tcp://127.0.0.1:9", progress=False)
    assert time.perf_counter() - t0 < 30.0


def test_the_cli_refuses_a_bad_spec_and_a_bad_worker_count(spec_file, fmu_dir, capsys):
    from marinefmu.cli import main

    assert main(["campaign", str(spec_file), "--workers", "0", "--fmus", str(fmu_dir)]) == 2
    assert "--workers = 0 is out of range: must be an integer >= 1" in capsys.readouterr().err
    spec_file.write_text(SPEC.replace("[0.0, 0.6]", "[0.0, -0.6]"))
    assert main(["campaign", str(spec_file), "--fmus", str(fmu_dir)]) == 2
    err = capsys.readouterr().err
    assert "grid.'vessel.sea.omega_min' = -0.6: refused" in err and "sea.omega_min" in err


@pytest.mark.isolated(timeout=600)
def test_the_cli_runs_a_campaign_of_an_ssp_package_and_draws_its_map_and_comparison(tmp_path, fmu_dir, capsys):
    from marinefmu.cli import main
    from marinefmu.cosim.ssp import write_ssp
    from marinefmu.cosim.scenarios import parse_scenario

    write_ssp(parse_scenario(SCENARIO).system, fmu_dir, tmp_path / "att_only.ssp")   # the system with its FMUs
    spec = tmp_path / "maps.toml"
    spec.write_text('[campaign]\nname = "maps"\nscenario = "att_only.ssp"\nduration = 15.0\nsettle = 1.0\n'
                    '[grid]\n"vessel.sea.hs" = [1.0, 3.0]\n"vessel.sea.tp" = [6.0, 10.0]\n'
                    '[sets.imu.bow]\n"vessel.imu" = { x = 40.0, y = 0.0, z = -5.0 }\n'
                    '[sets.imu.cog]\n"vessel.imu" = { x = 0.0, y = 0.0, z = 0.0 }\n')
    out = tmp_path / "out"
    assert main(["campaign", str(spec), "--workers", "2", "--out", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert "8 run(s) now, 0 already in the table; 8 succeeded, 0 failed of 8" in printed
    assert (out / "maps" / "att.png").stat().st_size > 10_000 and (out / "compare_imu.png").stat().st_size > 10_000
    rows = read_table(out / "results.csv")
    assert len(rows) == 8 and all(r["status"] == "ok" and r["att.roll_deg"] > 0 for r in rows)
    assert (out / "spec.toml").read_text() == spec.read_text()
    # rerun: nothing left to do, no cluster started (the package unpacked elsewhere: the same runs)
    assert main(["campaign", str(spec), "--out", str(out), "--no-progress", "--no-plots"]) == 0
    assert "0 run(s) now, 8 already in the table" in capsys.readouterr().out


@pytest.mark.isolated(timeout=600)
def test_ctrl_c_leaves_a_consistent_table_and_a_rerun_goes_on(spec_file, tmp_path, fmu_dir):
    """SIGINT to the whole process group, as Ctrl-C at a terminal sends it."""
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "marinefmu.cli", "campaign", str(spec_file), "--workers", "1", "--out", str(out),
           "--fmus", str(fmu_dir), "--no-progress", "--no-plots"]
    # SIGINT back to its default in the child: a shell's background job (CI's, say) starts with it
    # ignored, and Python then installs no KeyboardInterrupt handler
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    log = out / LOG_NAME
    deadline = time.monotonic() + 300
    while not (log.exists() and log.read_text().count("\n") >= 1) and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err[-3000:]
    done = len(log.read_text().splitlines())
    assert 1 <= done < 8
    assert f"interrupted: {done} of 8 run(s) are in {out / 'results.csv'}; run the same command again" in err
    assert "Traceback" not in err                                    # the workers left quietly
    assert len(read_table(out / "results.csv")) == done              # the table holds exactly the finished runs
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert again.returncode == 1                                     # the two failing runs of the grid
    assert f"{8 - done} run(s) now, {done} already in the table; 6 succeeded, 2 failed of 8" in again.stdout
