"""Benchmark part ``defaults``: each estimator at its defaults, given geometry only, against the
best fixed setting the project knows, on a grid of vessels, seas and IMU placements.

A user who drops an FMU into a system sets what only they know (lever arms) and leaves the
rest. This part measures what that user gets. The grid (:data:`CASES`) is the three vessel
presets × three seas (:data:`SEAS`: Hs 1 m / Tp 5 s, 3 m / 10 s, 6 m / 14 s, bow-quartering)
× two IMU placements (:func:`placements`: at the COG, and 40 % of the length forward, 40 % of
the beam to starboard and 10 m above the COG), default MEMS IMU, one seed per case.

AttitudeEstimator: roll and pitch RMS over ``[SETTLE, duration]`` at the defaults
(``aid_sizing = "auto"``) and with each fixed aiding of :data:`ATTITUDE_GRID` (σ_v 0.05 … 4 m/s,
σ_p = 3 σ_v, 10 Hz, and the paper-000 reproduction's 3 m/s, 10 m, 1 Hz); the figure of merit is
the larger of roll and pitch. The goals: the defaults within :data:`RATIO_GOAL` of the grid's
best on every case, and at most :data:`ATTITUDE_GOAL_DEG`.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
from ..sea.motion_model import VesselMotionParams, simulate_record, stack
from ..sea.vessel import PRESETS

DT = 0.01
SEAS = ((1.0, 5.0), (3.0, 10.0), (6.0, 14.0))
HEADING = 0.75 * math.pi
DURATION = 600.0
SETTLE = 150.0
SEED = 3
RATIO_GOAL = 1.15
ATTITUDE_GOAL_DEG = 0.035
ATTITUDE_GRID: tuple[dict, ...] = (
    *({"aid_sizing": "fixed", "vel_sigma": v, "pos_sigma": 3.0 * v, "aid_rate": 10.0}
      for v in (0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0)),
    {"aid_sizing": "fixed", "vel_sigma": 3.0, "pos_sigma": 10.0, "aid_rate": 1.0},
)


def placements(preset: str) -> dict[str, tuple[float, float, float]]:
    """The two IMU positions of a preset relative to its COG, body frame [m]."""
    h = PRESETS[preset]
    return {"cog": (0.0, 0.0, 0.0), "far": (round(0.4 * h.length, 1), round(0.4 * h.beam, 1), -10.0)}


CASES: tuple[tuple[str, float, float, str], ...] = tuple(
    (preset, hs, tp, place) for preset in PRESETS for hs, tp in SEAS for place in ("cog", "far"))


def case_record(preset: str, hs: float, tp: float, place: str, duration: float = DURATION,
                extra: dict | None = None) -> dict[str, np.ndarray]:
    """VesselMotion record of one case (:data:`SEED`, bow-quartering); ``extra``: more
    VesselMotion parameters (e.g. ``{"imu.grade": "mru"}``)."""
    imu = placements(preset)[place]
    flat = {"sea.hs": hs, "sea.tp": tp, "sea.seed": SEED, "sea.heading": HEADING, "vessel.preset": preset,
            **{f"imu.{a}": v for a, v in zip("xyz", imu)}, **(extra or {})}
    return simulate_record(VesselMotionParams.from_flat(flat), duration, DT)


def attitude_rms_deg(rec: dict[str, np.ndarray], params: AttitudeEstimatorParams | None = None,
                     settle: float = SETTLE) -> tuple[float, float]:
    """Roll and pitch RMS error [deg] of the AttitudeEstimator over ``rec`` from ``settle`` on."""
    out = estimate_attitude(stack(rec, "imu.gyro"), stack(rec, "imu.acc"), DT, params)
    k = int(settle / DT)
    roll = np.angle(np.exp(1j * (out["roll"][k:] - rec["truth.roll"][k:])))
    pitch = out["pitch"][k:] - rec["truth.pitch"][k:]
    return (float(np.degrees(np.sqrt(np.mean(roll ** 2)))), float(np.degrees(np.sqrt(np.mean(pitch ** 2)))))


def attitude_case(preset: str, hs: float, tp: float, place: str, extra: dict | None = None) -> dict:
    """The defaults and every setting of :data:`ATTITUDE_GRID` on one case."""
    rec = case_record(preset, hs, tp, place, extra=extra)
    base = AttitudeEstimatorParams()
    default = attitude_rms_deg(rec, base)
    grid = [{**g, "rms_deg": attitude_rms_deg(rec, replace(base, **g))} for g in ATTITUDE_GRID]
    best = min(grid, key=lambda g: max(g["rms_deg"]))
    return {"preset": preset, "hs": hs, "tp": tp, "imu": place, "default_deg": default, "grid": grid,
            "best": best, "ratio": max(default) / max(best["rms_deg"])}


def defaults_bench(progress: bool = True) -> dict:
    """Every case of :data:`CASES` (module docstring), printed as a table; about 20 minutes on
    a 2-core machine (two cases at a time)."""
    from concurrent.futures import ProcessPoolExecutor

    from tqdm import tqdm

    with ProcessPoolExecutor(max_workers=min(2, len(CASES))) as pool:  # one case per core
        jobs = [pool.submit(attitude_case, *case) for case in CASES]
        rows = [job.result() for job in tqdm(jobs, unit="case", desc="defaults", disable=not progress)]
    print(f"AttitudeEstimator at its defaults (geometry only) against the best fixed aiding of {len(ATTITUDE_GRID)}; "
          f"goals: <= {ATTITUDE_GOAL_DEG} deg and <= {RATIO_GOAL} x the best")
    print(f"{'vessel':<13} {'Hs':>4} {'Tp':>4} {'IMU':<4} {'default roll/pitch deg':>23} {'best fixed':>17} "
          f"{'sigma_v':>7} {'ratio':>6}")
    for r in rows:
        d, b = r["default_deg"], r["best"]
        print(f"{r['preset']:<13} {r['hs']:4.1f} {r['tp']:4.0f} {r['imu']:<4} {d[0]:11.4f} / {d[1]:.4f} "
              f"{b['rms_deg'][0]:8.4f} / {b['rms_deg'][1]:.4f} {b['vel_sigma']:7.2f} {r['ratio']:6.2f}")
    worst = max(max(r["default_deg"]) for r in rows)
    worst_ratio = max(r["ratio"] for r in rows)
    print(f"worst default {worst:.4f} deg (goal {ATTITUDE_GOAL_DEG}), worst ratio {worst_ratio:.2f} (goal {RATIO_GOAL})")
    return {"attitude": {"cases": rows, "worst_deg": worst, "worst_ratio": worst_ratio,
                         "goal_deg": ATTITUDE_GOAL_DEG, "goal_ratio": RATIO_GOAL}}
