"""Someone else's data (docs/benchmarks.md): marinefmu's attitude, heave and GNSS fusion on the
OrcaFlex record of the smsfusion project (MIT licence, 4Subsea; see
src/marinefmu/data/peer/smsfusion_orcaflex/README.md), beside smsfusion on the same file.

The record is fixed and the runs are deterministic; absolute bounds are the measured figures
(docs/benchmarks.md, part ``orcaflex``) plus 10 %, room for BLAS and platform rounding, not for
a change of method."""
import numpy as np
import pytest

from marinefmu.bench import peer_orcaflex as po

pytest.importorskip("smsfusion")


@pytest.fixture(scope="module")
def record():
    return po.load_orcaflex()


@pytest.fixture(scope="module")
def scores(record):
    return po.compare_orcaflex(record)


def test_the_record_reads_in_our_units_and_frames(record):
    """The loader's units and conventions: R_nb f_b + g_n of the true specific force is the
    derivative of the true velocity (NED, g = 9.80665), to 0.4 % of the acceleration."""
    acc_n = po.rotate_to_ned(record.acc_true, *record.euler.T) + [0.0, 0.0, 9.80665]
    d_vel = np.gradient(record.vel, record.dt, axis=0)
    for i in range(3):
        assert np.std(acc_n[:, i] - d_vel[:, i]) < 4e-3 * np.std(d_vel[:, i])
    assert len(record.acc) == 3686 and abs(1.0 / record.dt - 10.24) < 1e-3
    acc_noise, gyro_noise = po.sensor_noise(record)
    assert 3e-4 < acc_noise < 6e-4 and 2e-5 < gyro_noise < 5e-5   # m/s²/√Hz, rad/s/√Hz


def test_roll_and_pitch_beat_smsfusion_vru_and_ahrs(scores):
    """Measured 0.019 / 0.014° (marinefmu) against 0.046 / 0.030° (VRU) and 0.049 / 0.031°
    (AHRS, with the compass) roll / pitch RMS; the peers start from the true attitude, ours
    levels itself."""
    ours = scores["marinefmu AttitudeEstimator"]
    for peer in ("smsfusion VRU", "smsfusion AHRS"):
        for a in ("roll_deg", "pitch_deg"):
            assert ours[a] <= scores[peer][a], scores
        assert 0.01 < scores[peer]["roll_deg"] < 0.2, scores   # the peer ran and tracks
    assert ours["roll_deg"] < 0.021 and ours["pitch_deg"] < 0.015, scores


def test_heave_from_the_accelerometer_alone(scores):
    """HeaveObserver on the AttitudeEstimator's roll and pitch, from the moment it turns valid
    (120 s), on a 75 cm (std) heave: the default (model = "wiener", the Wiener filter from the
    spectrum) 2.67 cm RMS, model = "band" 3.32 cm (bench part ``orcaflex``)."""
    h = scores["marinefmu HeaveObserver"]
    assert 119.0 < h["from_s"] < 121.0 and h["heave_std_cm"] > 60.0
    assert h["heave_cm"] < 2.9, scores
    band = scores["marinefmu HeaveObserver (band)"]
    assert 119.0 < band["from_s"] < 121.0 and band["heave_cm"] < 3.6, scores


def test_gnss_aided_position_beats_smsfusion_aided_ins_and_the_raw_fixes(scores):
    """1 Hz fixes with 5 cm noise and the compass: 3.56 / 3.25 / 2.69 cm (marinefmu) against
    4.56 / 4.41 / 4.45 cm (AidedINS) and 4.86 / 4.89 / 4.71 cm (the fixes) N / E / D."""
    ours, peer, raw = (scores[k] for k in ("marinefmu fusion (one receiver)", "smsfusion AidedINS", "raw GNSS"))
    for a in "ned":
        key = f"pos_{a}_cm"
        assert ours[key] <= peer[key] and peer[key] < 1.5 * raw[key], scores
    assert ours["pos_n_cm"] < 3.95 and ours["pos_e_cm"] < 3.6 and ours["pos_d_cm"] < 3.0, scores


def test_the_fusion_noise_is_chosen_on_our_simulator_not_on_this_record():
    """RECEIVER_Q_FACTORS is what the grid on a VesselMotion record with the same sensors picks."""
    assert po.tune_receiver_q() == po.RECEIVER_Q_FACTORS
