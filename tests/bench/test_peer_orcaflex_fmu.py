"""The OrcaFlex peer record through the FMUs (SensorRecording → AttitudeEstimator →
HeaveObserver and GnssAccFusion with attitude = input) gives the in-process figures."""
from pathlib import Path

import numpy as np
import pytest

from marinefmu.bench import peer_orcaflex as po
from marinefmu.sea.recording.mapping import load_mapping, parse_mapping

ROOT = Path(__file__).resolve().parents[2]


def test_the_worked_example_is_the_harness_mapping():
    a = load_mapping(ROOT / "examples" / "recordings" / "orcaflex.toml")
    b = parse_mapping(po.MAPPING)
    assert a.channels == b.channels and a.max_gap == b.max_gap and (a.time_column, a.time_rate) == (b.time_column, b.time_rate)
    assert (a.body, a.world, a.acc, a.heave) == (b.body, b.world, b.acc, b.heave)


@pytest.mark.fmu
def test_fmu_path_gives_the_in_process_figures(fmu_dir):
    from marinefmu.estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude

    rec = po.load_orcaflex()
    runs = po.fmu_runs(fmu_dir, rec, band=False)
    np.testing.assert_array_equal(runs.acc, rec.acc)      # the recording FMU plays the samples exactly
    fixes = np.arange(len(rec.acc)) % po.FIX_EVERY == 0   # the 1 Hz fixes, held between
    np.testing.assert_array_equal(runs.gnss[fixes], rec.gnss[fixes])
    np.testing.assert_array_equal(runs.heading, rec.heading)
    acc_n, gyro_n = po.sensor_noise(rec)
    ours = estimate_attitude(rec.gyro, rec.acc, 1.0 / po.RATE, AttitudeEstimatorParams(acc_noise=acc_n, gyro_noise=gyro_n, **po.FIXED_AIDING))
    np.testing.assert_array_equal(runs.roll, ours["roll"])  # the same estimator, sample for sample
    np.testing.assert_array_equal(runs.pitch, ours["pitch"])
    k0 = po.SETTLE_SAMPLES
    # heave: the FMU gets the previous sample's roll and pitch (one-step coupling): within 5 %
    fmu_heave = po.heave_score(rec, runs.heave, runs.heave_valid)["heave_cm"]
    live = po.heave_scores(rec, ours["roll"], ours["pitch"])["heave_cm"]
    assert fmu_heave == pytest.approx(live, rel=0.05)
    # the fusion FMU is the in-process estimator, sample for sample, on the inputs it was given: the
    # AttitudeEstimator's roll and pitch one sample late (one-step coupling; attitude_lag = one step)
    q = tuple(f * acc_n ** 2 for f in po.RECEIVER_Q_FACTORS)
    step = 1.0 / po.RATE
    np.testing.assert_array_equal(runs.fusion_euler[1:, :2], np.c_[runs.roll, runs.pitch][:-1])
    np.testing.assert_array_equal(runs.gyro, rec.gyro)
    same = po.receiver_fusion(runs.acc, runs.fusion_euler, runs.gnss, step, q, runs.gyro, lag=step)
    np.testing.assert_array_equal(runs.pos, same)
    # and, the late roll and pitch turned forward by the gyro, the harness's in-process figure (roll
    # and pitch of the same sample, not turned; dt the record's mean interval): within 0.1 % per axis
    # (measured 0.05 % north)
    live = po.receiver_fusion(rec.acc, np.c_[ours["roll"], ours["pitch"], rec.heading], rec.gnss, rec.dt, q)
    rms = lambda pos: np.sqrt(np.mean((pos[k0:] - rec.pos[k0:]) ** 2, axis=0))  # noqa: E731
    np.testing.assert_allclose(rms(runs.pos), rms(live), rtol=1e-3)
