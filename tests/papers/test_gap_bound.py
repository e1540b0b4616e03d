"""The linear bound of a GNSS gap (papers.gap_bound): its features are causal."""
import numpy as np
import pytest

from marinefmu.papers.gap_bound import prepare, row

DT = 0.01


def record(seed=0, duration=200.0):
    """A random record in the layout of paper001.simulate (fixes at 1 Hz)."""
    rng = np.random.default_rng(seed)
    n = int(duration / DT)
    new = np.zeros(n, dtype=bool)
    new[99::100] = True                                  # samples at t = 1, 2, … s
    return {"acc": rng.normal(size=(n, 3)), "gyro": rng.normal(size=(n, 3)), "gnss": rng.normal(size=(n, 12)),
            "gnss_new": new, "gnss_valid": np.ones(n, dtype=bool), "cog": rng.normal(size=(n, 3))}


def test_a_gap_row_uses_nothing_after_now_and_no_fix_from_the_gap():
    """Changing the IMU after t0 + τ, the fixes from t0 on and the truth except at t0 + τ leaves
    the row and its target as they were; changing the last IMU block before t0 + τ or the last
    fix before t0 does not (so the check can fail)."""
    t0, tau, memory = 100.0, 10.0, 30.0
    rec = record()
    feats, target = row(prepare(rec), t0, tau, memory)
    k_now = int(round((t0 + tau) / DT))                  # first sample after t0 + τ
    later = {k: v.copy() for k, v in rec.items()}
    later["acc"][k_now:] += 5.0
    later["gyro"][k_now:] -= 5.0
    later["gnss"][int(round(t0 / DT)) - 1:] += 7.0       # the fix at t0 and after
    keep = later["cog"][k_now - 1].copy()
    later["cog"][:] = 0.0
    later["cog"][k_now - 1] = keep
    f2, t2 = row(prepare(later), t0, tau, memory)
    assert np.array_equal(feats, f2) and t2 == target
    assert target == rec["cog"][k_now - 1, 1] - rec["gnss"][int(round(t0 / DT)) - 101, 1::3].mean()
    for key, k in (("acc", k_now - 1), ("gnss", int(round(t0 / DT)) - 101)):
        changed = {kk: v.copy() for kk, v in rec.items()}
        changed[key][k] += 1.0
        assert not np.array_equal(row(prepare(changed), t0, tau, memory)[0], feats), key


def test_a_gap_the_record_does_not_cover_is_refused():
    d = prepare(record(duration=60.0))
    with pytest.raises(ValueError, match="memory 90"):
        row(d, 50.0, 5.0, 90.0)
