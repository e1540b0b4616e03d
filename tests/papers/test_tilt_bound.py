"""The floor of real-time roll and pitch (papers.tilt_bound): its rows are causal, its records are
VesselMotion's, and on a short record it is finite, below the AttitudeEstimator, ordered by the
IMU grade and near zero for a perfect IMU."""
import numpy as np
import pytest

from marinefmu.papers import paper003
from marinefmu.papers import tilt_bound as tb
from marinefmu.sea.motion_model import simulate_record

#: A short set-up (the module's defaults train on 3 × 1 h): Hs 3 / Tp 10, IMU at the COG, 20 Hz,
#: two 15-minute training records, a 10-minute scored record from 3 minutes on.
SETUP = tb.BoundSetup(memory=120.0, settle=180.0, dt=0.05)
SHORT = {"train": (4, 5), "train_duration": 900.0, "duration": 600.0}
#: Every random error off (a density of 0 is allowed; 1e-30 keeps the Gauss-Markov state defined).
PERFECT = {"imu.acc_noise": 1e-30, "imu.gyro_noise": 1e-30, "imu.acc_bias_instability": 1e-30,
           "imu.gyro_bias_instability": 1e-30}
CASES = {"mems": {"imu.grade": "mems"}, "tactical": {"imu.grade": "tactical"}, "mru": {"imu.grade": "mru"},
         "perfect": PERFECT}


@pytest.fixture(scope="module")
def bounds():
    """Bounds [°] of each case on one simulation of the sea (the IMU measured again per case),
    the raw-channel fit of mru, and the scored records."""
    motions: dict = {}
    out = {name: tb.causal_tilt_bound(3.0, 10.0, (0.0, 0.0, 0.0), imu, SETUP, motions=motions, **SHORT)
           for name, imu in CASES.items()}
    out["mru raw"] = tb.causal_tilt_bound(3.0, 10.0, (0.0, 0.0, 0.0), CASES["mru"], tb.replace(SETUP, linearise=False),
                                          motions=motions, **SHORT)
    return out


def pair(r):
    return np.array([r["roll_deg"], r["pitch_deg"]])


def test_the_bound_is_finite_and_ordered_by_the_imu_grade(bounds):
    """Each better grade lowers the floor in both angles, by more than its own tolerance: a
    better gyro bounds the angle changes, a better accelerometer the angle it starts from."""
    b = {k: pair(v) for k, v in bounds.items()}
    for k in CASES:
        assert np.all(np.isfinite(b[k])) and np.all(b[k] > 0), k
    assert np.all(b["mems"] > 1.5 * b["tactical"]) and np.all(b["tactical"] > 2.0 * b["mru"])
    assert np.all(b["mems"] < 0.02), b["mems"]            # well below the true angles' std of ~1°
    assert bounds["mems"]["roll_std_deg"] > 1.0 and bounds["mems"]["pitch_std_deg"] > 0.5


def test_a_perfect_imu_leaves_almost_nothing(bounds):
    """With no sensor error the angle changes are exact and the tilt they start from is the
    accelerometer's, free of waves below half the peak frequency: what is left is the fit's
    own (finite memory and training), under a quarter of the mru grade's bound and under 0.0002°."""
    perfect = pair(bounds["perfect"])
    assert np.all(perfect < 2e-4) and np.all(perfect < 0.25 * pair(bounds["mru"])), perfect


@pytest.mark.parametrize("grade", ["mems", "mru"])
def test_the_bound_is_below_the_attitude_estimator_told_the_grade(bounds, grade):
    """The real-time AttitudeEstimator with the system scenario's aiding and the grade's figures,
    on the scored record: the floor is below it in both angles."""
    est = np.array(tb.estimator_errors(bounds[grade]["scored"], tb.told(grade, **tb.SYSTEM_AIDING), SETUP.dt,
                                       SETUP.settle))
    assert np.all(pair(bounds[grade]) < est), (pair(bounds[grade]), est)


def test_the_raw_channels_leave_the_kinematics_second_order_terms(bounds):
    """Without the linearisation the fit cannot remove yaw rate × pitch and heave acceleration ×
    tilt, which with the mru grade are larger than the sensor's own error."""
    assert np.all(pair(bounds["mru raw"]) > 2.0 * pair(bounds["mru"]))


def test_a_record_measured_again_equals_a_new_simulation():
    arm, imu = (50.0, 0.0, -10.0), {"imu.grade": "tactical", "imu.acc_noise": 1e-3}
    motion = tb.record(2.0, 8.0, 3, 10.0, arm, None, 0.05)
    again = tb.record(2.0, 8.0, 3, 10.0, arm, imu, 0.05, motion=motion)
    fresh = simulate_record(tb.vessel_params(2.0, 8.0, 3, arm, imu), 10.0, 0.05)
    for name in ("imu.acc.x", "imu.acc.z", "imu.gyro.y", "truth.roll"):
        np.testing.assert_allclose(again[name], fresh[name], rtol=0, atol=1e-12)
    assert not np.allclose(again["imu.gyro.y"], motion["imu.gyro.y"])


def test_block_rows_with_equal_blocks_are_paper003s_fir_rows():
    rng = np.random.default_rng(1)
    a, z = rng.normal(size=500), rng.normal(size=500)
    x3, target, ends = paper003.fir_rows(a, z, taps=12, decimate=8)
    x = tb.block_rows(a[:, None], np.arange(0, 13) * 8, ends)
    np.testing.assert_allclose(x, x3, rtol=0, atol=1e-12)


def test_a_row_uses_the_memory_and_nothing_after_its_sample():
    """Changing the samples after the row's, or older than its memory, leaves the row as it was
    (to rounding: the block means are differences of running sums); changing the oldest sample
    inside the memory does not (so the check can fail)."""
    setup = tb.BoundSetup(memory=4.0, settle=10.0, dt=0.05, stride=1.0)
    rng = np.random.default_rng(2)
    names = [f"imu.{s}.{a}" for s in ("acc", "gyro") for a in "xyz"] + ["truth.roll", "truth.pitch", "truth.yaw"]
    rec = {n: 0.05 * rng.normal(size=400) for n in names}
    x, y = setup.rows(rec, 10.0)
    k = 10.0 / 0.05 - 1                      # the first row's sample
    memory = int(4.0 / 0.05)
    for i, same in ((int(k) + 1, True), (int(k) - memory, True), (int(k) - memory + 1, False), (int(k), False)):
        changed = {n: v.copy() for n, v in rec.items()}
        changed["imu.gyro.x"][i] += 1.0
        changed["imu.acc.y"][i] += 1.0
        moved = np.abs(setup.rows(changed, 10.0)[0][0] - x[0]).max()
        assert (moved < 1e-12) if same else (moved > 1e-3), (i, moved)


def test_block_edges_grow_with_age_and_span_the_memory():
    edges = tb.block_edges(180.0, 0.05, resolution=0.1, longest=5.0)
    lengths = np.diff(edges)
    assert edges[0] == 0 and edges[-1] == 3600 and np.all(lengths >= 1) and np.all(lengths <= 100)
    assert np.all(np.diff(lengths[:-1]) >= 0) and 60 < len(lengths) < 120


def test_a_memory_longer_than_the_settling_time_is_refused():
    with pytest.raises(ValueError, match="memory 400 s is longer than the settling time 300 s"):
        tb.BoundSetup(memory=400.0)
