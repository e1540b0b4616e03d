"""The fault and bad-input contract of every FMU (README, "FMU contract"), case by case.

Each case runs ``fmu_worker.py CASE FMU`` in its own process with a timeout, so a native crash
or a hang is one failed test, not a dead test run. The cases are started two at a time (the CI
machine has two cores) as soon as the first of them is needed; each test waits for its own.
"""
from __future__ import annotations

import json
import subprocess
import sys
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from fmu_worker import FMUS  # noqa: E402

from tests.conftest import spawn_env  # noqa: E402

pytestmark = pytest.mark.fmu
TIMEOUT = 300.0  # s per case; the slowest takes ~15 s on the 2-core CI machine
ESTIMATORS = [n for n in FMUS if n != "VesselMotion"]
#: (case, FMUs it applies to), in the order they are started.
PLAN = [
    ("quaternion_norm", ["AttitudeEstimator"]),  # the longest case (~30 s) first
    ("faults", ESTIMATORS),
    ("state", FMUS),
    ("two_instances", FMUS),
    ("reset", FMUS),
    ("step_sizes", FMUS),
    ("logging_off", FMUS),
    ("many_instances", FMUS),
    ("zero_hour", ESTIMATORS),
    ("gnss_dropout", ["GnssAccFusion"]),
    ("gnss_jump", ["GnssAccFusion"]),
]


def run_worker(case: str, name: str, fmu_dir: Path, work: Path) -> dict:
    """Run one case in a fresh process; its JSON result, or a failure naming how it died."""
    cmd = [sys.executable, str(HERE / "fmu_worker.py"), case, name, str(fmu_dir), str(work)]
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT, cwd=work,
                              env=spawn_env())
    except subprocess.TimeoutExpired:
        return {"_failure": f"{case} {name}: no answer within {TIMEOUT:.0f} s (hang)"}
    lines = done.stdout.strip().splitlines()
    try:
        result = json.loads(lines[-1])
    except (IndexError, json.JSONDecodeError):
        how = f"signal {-done.returncode}" if done.returncode < 0 else f"exit code {done.returncode}"
        return {"_failure": f"{case} {name}: died ({how}) before its result:\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"}
    if done.returncode != 0:
        # the case finished but the process did not exit cleanly (a crash at teardown)
        result["_exit"] = done.returncode
        result["_stderr"] = done.stderr[-2000:]
    return result


@pytest.fixture(scope="session")
def conformance(fmu_dir, tmp_path_factory):
    """Futures of every planned case, started two at a time after the VesselMotion record. (That
    each FMU runs from its own resources, in an environment without marinefmu, is
    ``test_clean_environment.py``'s: a fresh virtual environment of the FMUs' own requirements.)"""
    work = tmp_path_factory.mktemp("conformance")
    record = run_worker("record", "VesselMotion", fmu_dir, work)
    assert "_failure" not in record and record.get("_exit", 0) == 0 and record["finite"], record
    pool = ThreadPoolExecutor(max_workers=2)
    futures: dict[tuple[str, str], Future] = {
        (case, name): pool.submit(run_worker, case, name, fmu_dir, work) for case, names in PLAN for name in names}
    yield futures
    pool.shutdown(wait=True, cancel_futures=True)


def result_of(conformance, case: str, name: str) -> dict:
    result = conformance[(case, name)].result()
    if "_failure" in result:
        pytest.fail(result["_failure"], pytrace=False)
    assert result.get("_exit", 0) == 0, f"{case} {name}: the process exited with {result['_exit']}: {result['_stderr']}"
    return result


def cases(case: str):
    return pytest.mark.parametrize("name", dict(PLAN)[case])


@cases("faults")
def test_bad_samples_are_rejected_flagged_logged_and_recovered_from(conformance, name):
    """NaN, ±Inf and 1e12 on every real input, one at a time: the step returns OK, ``valid`` is
    false on that step, a warning is logged, the outputs stay finite and are valid again 2 s later."""
    report = result_of(conformance, "faults", name)
    assert set(report) == {"nan", "inf", "-inf", "1e12"}
    for label, r in report.items():
        assert r["finite"], (label, r)
        assert len(r["rows"]) >= 3, r  # every real input was tried (3 for AhcController ... 30 for GnssAccFusion, with its two attitude sources)
        for row in r["rows"]:
            assert row == {**row, "status": 0, "valid": False, "warned": True, "recovered": True}, (label, row)


@cases("state")
def test_fmu_state_save_restore_and_serialization_repeat_the_run(conformance, name):
    r = result_of(conformance, "state", name)
    assert r["can_get_set"] and r["can_serialize"]
    assert r["valid_at_save"]
    assert r["restore_identical"] and r["deserialize_identical"], r
    # the restored run repeats outputs that kept changing, so the internal state came back too
    assert r["outputs_moving"] >= min(5, r["real_outputs"]), r


@cases("two_instances")
def test_two_instances_in_one_process_do_not_interfere(conformance, name):
    r = result_of(conformance, "two_instances", name)
    assert r["identical"], r
    assert r["other_differs"], r  # the second instance really computed something else


@cases("reset")
def test_reset_and_reinstantiation_repeat_the_run(conformance, name):
    r = result_of(conformance, "reset", name)
    assert r["reset_identical"] and r["reinstantiate_identical"], r


@cases("step_sizes")
def test_step_sizes(conformance, name):
    """Zero, negative and NaN steps are refused with Discard and a log message and change
    nothing; tiny (1e-6 s), large (10 s) and varying steps are accepted with finite outputs."""
    r = result_of(conformance, "step_sizes", name)
    for label, refused in r["refused"].items():
        assert refused["status"] == 2, (label, refused)
        assert refused["unchanged"], (label, refused)
        assert "refused: must be a finite number > 0" in refused["logged"][0], (label, refused)
    assert r["continues_identically"], r
    for label in ("tiny", "large", "varying"):
        assert r[label] == {"statuses": [0], "finite": True}, (label, r[label])


@cases("logging_off")
def test_failures_return_non_ok_with_logging_off(conformance, name):
    r = result_of(conformance, "logging_off", name)
    assert r["refused_parameter_status"] == 2 and r["zero_step_status"] == 2, r


@cases("many_instances")
def test_many_instances_in_one_process(conformance, name):
    """30 instances one after another: every step OK; pythonfmu runs the model script again for
    each, and the script reuses its class (one alive, not 30: about 5 KB kept per instance
    otherwise) without losing its namespace; no repeated sys.path entries."""
    r = result_of(conformance, "many_instances", name)
    assert r == {"statuses": [0], "slave_classes": 1, "repeated_sys_path": 0}, r


@cases("zero_hour")
def test_an_hour_of_zero_input(conformance, name):
    """Every input 0 for an hour (free fall: an absurd but finite specific force): every step OK,
    every output finite."""
    r = result_of(conformance, "zero_hour", name)
    assert r["statuses"] == [0] and r["finite"] and r["seconds"] == 3600.0, r


def test_quaternion_norm_after_a_million_steps(conformance):
    r = result_of(conformance, "quaternion_norm", "AttitudeEstimator")
    assert r["steps"] == 1_000_000 and r["statuses"] == [0], r
    assert r["max_norm_error"] < 1e-9, r


def test_five_minute_gnss_dropout(conformance):
    """GNSS invalid for 300 s: steps OK, outputs finite, valid false once ``max_coast`` (60 s) has
    passed, the wave coast holding the position through the whole gap, and back within a second
    of the first fix (the filter re-initialises on it). The largest error on the largest axis in
    the gap: measured 1.04 m at the defaults (q 1e-3: the filter trusts the accelerometer more
    than with the paper's q 0.005, 0.91 m, and so carries more of its error into the gap) and
    bounded at 1.5 m: the bound tells the wave coast's hold from an inertial coast, which after
    five minutes is kilometres off; the position is flagged invalid from 60 s into the gap."""
    r = result_of(conformance, "gnss_dropout", "GnssAccFusion")
    assert r["statuses"] == [0] and r["finite"], r
    assert r["valid_before"] and r["valid_false_during"], r
    assert r["max_error_during"] < 1.5, r
    assert r["valid_again_after_s"] is not None and r["valid_again_after_s"] <= 1.0, r
    assert r["max_error_after_10s"] < 0.1, r  # m: back to GNSS accuracy
    # the re-initialisation is logged as an event with a valid output, not as a rejection
    assert any("re-initialised" in w and w.endswith("; valid = true") for w in r["warnings"]), r


def test_65_m_gnss_jump(conformance):
    """All antennas 65 m north for 20 s (shorter than ``reinit_time``): every jumped epoch is
    gated out (valid false on it, a warning logged), the position coasts on the wave model and
    is back within GNSS accuracy 10 s after the jump."""
    r = result_of(conformance, "gnss_jump", "GnssAccFusion")
    assert r["statuses"] == [0] and r["finite"], r
    assert r["valid_before"] and r["valid_false_during"], r
    assert r["max_error_during"] < 2.0, r  # m, against 65 m of jump
    assert r["max_error_after_10s"] < 0.1, r
    assert any("rejected" in w and w.endswith("valid = false") for w in r["warnings"]), r
