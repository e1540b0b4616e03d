"""How well *could* a real-time estimator bridge a GNSS gap on paper 001's set-up? The best
linear estimator that knows the sea's and the sensors' joint statistics (beyond the paper).

Why: the wave coast of :mod:`~marinefmu.estimators.gnss_fusion.wave_coast` must bridge a 30 s
dropout within the project goal of < 10 cm per axis, and its worst cases sit close to it (east,
in a beam sea). Whether that goal is within reach of *any* causal estimator fed these sensors
is a measurement, not an opinion. As
for the heave observer (:func:`~marinefmu.papers.paper003.causal_bound`), the answer is a
least-squares fit: for each time τ into a gap, one linear map from everything a real-time
estimator has at t0 + τ to the COG position then,

* the accelerometer and gyro, block means at :data:`RATE` Hz from ``memory`` s before the gap
  up to t0 + τ (specific force along the axis and down, the rate about the axis's tilt — roll
  for east, pitch for north — and yaw rate);
* the antenna fixes of the ``memory`` s before the gap (1 Hz): the centroid along the axis,
  relative to the last fix, and three linear attitude proxies (down of starboard minus port
  antennas, fore minus aft, east of fore minus aft);
* a constant,

relative to the last fix. It is trained on long records of the same sea with other seeds (the
joint statistics, which an adaptive estimator would have to estimate) and scored on the
dropouts. The fit knows the vessel's transfer functions and so the coherence between the
channels — in a long-crested beam sea the roll that the gyro measures predicts the sway — which
is why it does much better than the per-axis wave model. It estimates the best linear
estimator's error from above (finite memory and training, 4 Hz block means). An estimator that
must learn the statistics in service cannot expect to reach it: refitted on the few minutes of
fixes before each gap, the same fit errs far more than the wave coast (the dropout coast's
decision records give the figures). So it shows the goal within reach in principle, and where
the information is; it is not a floor that explains the wave coast's errors.

Hand-written normal equations (numpy), as in :func:`~marinefmu.papers.paper003.causal_bound`:
neither scipy nor python-control fits a multichannel causal Wiener filter from data.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import paper001

#: Block-mean rate of the IMU channels [Hz].
RATE = 4
#: Times into the gap at which the estimator is fitted and scored [s] (its max error is taken
#: over these).
TAUS = tuple(float(t) for t in range(1, 31))
#: Seeds of the training records (not among :data:`~.paper001.DROPOUTS`' seeds 1-40).
TRAIN_SEEDS = tuple(range(1001, 1009))
#: Ridge on the normal equations, relative to their mean diagonal: the block means of smooth
#: signals are nearly collinear; 1e-9 changes the fitted errors by < 1 %.
RIDGE = 1e-9
#: Axis index of each name (NED).
AXES = {"north": 0, "east": 1}


@dataclass(frozen=True)
class GapData:
    """One record reduced to what the bound uses (:func:`prepare`)."""

    imu: np.ndarray       # (4, blocks) block means: f along the axis, f down, tilt rate, yaw rate
    fixes: np.ndarray     # (4, epochs) centroid along the axis [m] and three attitude proxies [m]
    t_fix: np.ndarray     # (epochs,) epoch times [s]
    truth: np.ndarray     # (samples,) the COG along the axis [m], sample k at (k + 1)·dt
    dt: float


def prepare(rec: dict, axis: str = "east", dt: float = paper001.DT) -> GapData:
    """Reduce a :func:`~.paper001.simulate` record (epochs where ``gnss_valid`` is false are
    left out)."""
    a = AXES[axis]
    block = int(round(1.0 / (RATE * dt)))
    m = len(rec["acc"]) // block * block

    def means(x: np.ndarray) -> np.ndarray:
        return x[:m].reshape(-1, block).mean(axis=1)

    imu = np.stack([means(rec["acc"][:, a]), means(rec["acc"][:, 2]), means(rec["gyro"][:, 1 - a]),
                    means(rec["gyro"][:, 2])])
    k = np.flatnonzero(np.asarray(rec["gnss_new"]) & np.asarray(rec.get("gnss_valid", rec["gnss_new"])))
    ant = np.asarray(rec["gnss"])[k].reshape(len(k), 4, 3)
    port, starboard = [0, 2], [1, 3]     # paper001.ANT: y = −4, +4 m
    fore, aft = [0, 1], [2, 3]           # x = +10, −10 m
    fixes = np.stack([ant[:, :, a].mean(axis=1),
                      ant[:, starboard, 2].mean(axis=1) - ant[:, port, 2].mean(axis=1),
                      ant[:, fore, 2].mean(axis=1) - ant[:, aft, 2].mean(axis=1),
                      ant[:, fore, 1].mean(axis=1) - ant[:, aft, 1].mean(axis=1)])
    return GapData(imu, fixes, (k + 1) * dt, np.asarray(rec["cog"])[:, a], dt)


def row(d: GapData, t0: float, tau: float, memory: float) -> tuple[np.ndarray, float]:
    """Features and target of a gap whose first missing fix is at ``t0`` [s], estimated ``tau``
    s into it: IMU blocks that end by t0 + τ, fixes before t0; the target is the COG at
    t0 + τ, both relative to the last fix's centroid."""
    k0, k1 = int(round((t0 - memory) * RATE)), int(round((t0 + tau) * RATE))
    j = int(np.searchsorted(d.t_fix, t0 - 1e-6))
    n_fix = int(round(memory))
    if k0 < 0 or j < n_fix or k1 > d.imu.shape[1]:
        raise ValueError(f"gap at {t0} s, tau {tau} s: the record does not cover memory {memory} s before and tau after")
    f = d.fixes[:, j - n_fix:j]
    last = f[0, -1]
    feats = np.concatenate([d.imu[:, k0:k1].ravel(), f[0] - last, f[1:].ravel(), [1.0]])
    return feats, float(d.truth[int(round((t0 + tau) / d.dt)) - 1] - last)


def fit(records: list[GapData], memory: float, taus=TAUS, step: float = 1.0) -> dict[float, np.ndarray]:
    """Least-squares weights per τ over gaps starting every ``step`` s of each record."""
    normal = {}
    for d in records:
        starts = np.arange(memory + 5.0, len(d.truth) * d.dt - max(taus) - 5.0, step)
        for tau in taus:
            pairs = [row(d, t0, tau, memory) for t0 in starts]
            x = np.array([f for f, _ in pairs])
            y = np.array([z for _, z in pairs])
            a, b = x.T @ x, x.T @ y
            if tau in normal:
                normal[tau][0] += a
                normal[tau][1] += b
            else:
                normal[tau] = [a, b]
    weights = {}
    for tau, (a, b) in normal.items():
        ridge = RIDGE * np.trace(a) / len(a)
        weights[tau] = np.linalg.solve(a + ridge * np.eye(len(a)), b)
    return weights


def gap_bound(cases=paper001.DROPOUTS, axis: str = "east", memory: float = 90.0, duration: float = 30.0,
              train_seeds=TRAIN_SEEDS, train_duration: float = 3600.0, goal: float = 0.10) -> dict:
    """The bound's largest error [m] along ``axis`` through each dropout of ``cases``
    ((start, seed), as :func:`~.paper001.dropouts`), over τ = 1 … ``duration`` s.

    Returns ``cases`` (start, seed, max_error_m), ``over_goal``, ``worst_m``, ``mean_m`` and the
    settings. Trains on ``len(train_seeds)`` records of ``train_duration`` s (8 h: about 4 min).
    """
    taus = tuple(t for t in TAUS if t <= duration)
    train = [prepare(paper001.simulate(train_duration, {"gnss.rate": 1.0, "sea.seed": s, "sensors.seed": s}), axis)
             for s in train_seeds]
    weights = fit(train, memory, taus)
    rows = []
    for start, seed in cases:
        d = prepare(paper001.dropout_record(start, seed, duration), axis)
        err = max(abs(float(f @ weights[tau]) - z) for tau in taus for f, z in [row(d, start, tau, memory)])
        rows.append({"start": start, "seed": seed, "max_error_m": err})
    e = np.array([r["max_error_m"] for r in rows])
    return {"cases": rows, "axis": axis, "memory_s": memory, "train_hours": len(train_seeds) * train_duration / 3600.0,
            "goal_m": goal, "over_goal": int(np.sum(e >= goal)), "worst_m": float(e.max()), "mean_m": float(e.mean())}
