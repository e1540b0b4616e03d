"""The OrcaFlex peer record through the FMUs (SensorRecording → AttitudeEstimator →
HeaveObserver, and the one-receiver fusion on what they output) gives the in-process figures."""
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
    np.testing.assert_array_equal(runs.gnss, rec.gnss)
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
    # the one-receiver fusion on the FMUs' outputs: the in-process figure (the harness's dt differs by 1e-6)
    q = tuple(f * acc_n ** 2 for f in po.RECEIVER_Q_FACTORS)
    pos_fmu = po.receiver_fusion(po.rotate_to_ned(runs.acc, runs.roll, runs.pitch, runs.heading), runs.gnss, rec.dt, q)
    pos_live = po.receiver_fusion(po.rotate_to_ned(rec.acc, ours["roll"], ours["pitch"], rec.heading), rec.gnss, rec.dt, q)
    np.testing.assert_array_equal(pos_fmu[k0:], pos_live[k0:])
