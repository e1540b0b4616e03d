"""Benchmark part ``defaults``: each estimator at its defaults, given geometry only, against the
best fixed setting the project knows, on a grid of vessels, seas and IMU placements.

A user who drops an FMU into a system sets what only they know (lever arms) and leaves the
rest. This part measures what that user gets, on the grid of :mod:`.cases`
(:data:`~.cases.CASES`: the three vessel presets × three seas × two IMU placements, default MEMS
IMU, one seed per case).

AttitudeEstimator: roll and pitch RMS over ``[SETTLE, duration]`` at the defaults
(``aid_sizing = "auto"``) and with each fixed aiding of :data:`ATTITUDE_GRID` (σ_v 0.05 … 4 m/s,
σ_p = 3 σ_v, 10 Hz, and the paper-000 reproduction's 3 m/s, 10 m, 1 Hz); the figure of merit is
the larger of roll and pitch. The goals: the defaults within :data:`~.cases.RATIO_GOAL` of the grid's
best on every case, and at most :data:`ATTITUDE_GOAL_DEG`.

HeaveObserver: given only its monitoring point (:func:`~.cases.monitoring_point`, relative to the IMU), at its
defaults, fed by the AttitudeEstimator at its defaults, against the same observer fed by the
case's best fixed aiding and by the true roll and pitch (what no attitude estimate beats); the
real-time heave RMS error at the point from :data:`~.cases.SETTLE` or the observer's first valid
sample, whichever is later (:func:`point_heave_cm`). The goals: within :data:`~.cases.RATIO_GOAL` of
the best fixed aiding's, and the project's heave goal max(2 cm, 2.5 % of the point's heave std).

The GnssAccFusion, DisplacementReconstructor and CentreOfRotation on the same cases are in
:mod:`.defaults_fusion`, :mod:`.defaults_reconstruction` and :mod:`.defaults_cr`;
:func:`defaults_bench` runs all five.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
from ..estimators.heave.common import HeaveObserverParams
from ..estimators.heave.observer import HeaveObserver
from ..sea.motion_model import stack
from .cases import CASES, DT, RATIO_GOAL, SETTLE, case_record, monitoring_point, placements

#: The AttitudeEstimator's goal at its defaults: roll and pitch RMS [deg].
ATTITUDE_GOAL_DEG = 0.035
#: The fixed aiding settings the defaults are measured against (module docstring).
ATTITUDE_GRID: tuple[dict, ...] = (
    *({"aid_sizing": "fixed", "vel_sigma": v, "pos_sigma": 3.0 * v, "aid_rate": 10.0}
      for v in (0.05, 0.1, 0.25, 0.5, 1.0, 2.0, 4.0)),
    {"aid_sizing": "fixed", "vel_sigma": 3.0, "pos_sigma": 10.0, "aid_rate": 1.0},
)


def attitude_rms_deg(rec: dict[str, np.ndarray], params: AttitudeEstimatorParams | None = None,
                     settle: float = SETTLE, out: dict[str, np.ndarray] | None = None) -> tuple[float, float]:
    """Roll and pitch RMS error [deg] of the AttitudeEstimator over ``rec`` from ``settle`` on
    (``out``: its run on ``rec`` if already made, else it is run with ``params``)."""
    if out is None:
        out = estimate_attitude(stack(rec, "imu.gyro"), stack(rec, "imu.acc"), DT, params)
    k = int(settle / DT)
    roll = np.angle(np.exp(1j * (out["roll"][k:] - rec["truth.roll"][k:])))
    pitch = out["pitch"][k:] - rec["truth.pitch"][k:]
    return (float(np.degrees(np.sqrt(np.mean(roll ** 2)))), float(np.degrees(np.sqrt(np.mean(pitch ** 2)))))


def point_heave_cm(rec: dict[str, np.ndarray], roll: np.ndarray, pitch: np.ndarray,
                   arm: tuple[float, float, float], settle: float = SETTLE) -> tuple[float, float]:
    """Real-time heave RMS error and true heave std [cm] at the monitoring point of ``rec``
    (VesselMotion's ``point``; ``arm`` is it relative to the IMU, body frame [m]) of the
    HeaveObserver at its defaults fed by ``roll``/``pitch`` [rad], from ``settle`` or its first
    valid sample, whichever is later. Both the truth's and the error's means are removed: heave
    is the motion about the mean position, and the observer has no output at zero frequency."""
    obs = HeaveObserver(HeaveObserverParams(point=arm), quiet=True)
    acc = stack(rec, "imu.acc")
    heave = np.empty(len(acc))
    valid = np.empty(len(acc), dtype=bool)
    for k in range(len(acc)):
        r = obs.step(acc[k], float(roll[k]), float(pitch[k]), DT)
        heave[k], valid[k] = r.point_heave, r.valid
    k0 = max(int(settle / DT), int(np.argmax(valid)) if valid.any() else len(valid))
    truth = rec["truth.point.d"][k0:]
    err = heave[k0:] - (truth - truth.mean())
    err -= err.mean()
    return 100.0 * float(np.sqrt(np.mean(err ** 2))), 100.0 * float(np.std(truth))


def attitude_case(preset: str, hs: float, tp: float, place: str, extra: dict | None = None) -> dict:
    """The defaults and every setting of :data:`ATTITUDE_GRID` on one case, and the heave at
    :func:`monitoring_point` fed by the defaults, by the best fixed setting and by the true angles."""
    rec = case_record(preset, hs, tp, place, extra=extra)
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    base = AttitudeEstimatorParams()
    runs = [estimate_attitude(gyro, acc, DT, base)]
    runs += [estimate_attitude(gyro, acc, DT, replace(base, **g)) for g in ATTITUDE_GRID]
    default = attitude_rms_deg(rec, out=runs[0])
    grid = [{**g, "rms_deg": attitude_rms_deg(rec, out=out)} for g, out in zip(ATTITUDE_GRID, runs[1:])]
    i_best = min(range(len(grid)), key=lambda i: max(grid[i]["rms_deg"]))
    best = grid[i_best]
    arm = tuple(round(float(p - q), 3) for p, q in zip(monitoring_point(preset, place), placements(preset)[place]))
    heave = {name: point_heave_cm(rec, out["roll"], out["pitch"], arm)
             for name, out in (("default", runs[0]), ("best_fixed", runs[1 + i_best]),
                               ("true_angles", {"roll": rec["truth.roll"], "pitch": rec["truth.pitch"]}))}
    std = heave["default"][1]
    return {"preset": preset, "hs": hs, "tp": tp, "imu": place, "default_deg": default, "grid": grid,
            "best": best, "ratio": max(default) / max(best["rms_deg"]),
            "heave": {"arm_m": arm, "std_cm": std, "goal_cm": max(2.0, 0.025 * std),
                      **{f"{k}_cm": v[0] for k, v in heave.items()},
                      "ratio": heave["default"][0] / heave["best_fixed"][0]}}


def defaults_bench(progress: bool = True) -> dict:
    """Every case of :data:`CASES` (module docstring) for the AttitudeEstimator and the
    HeaveObserver here, and for the GnssAccFusion, DisplacementReconstructor and
    CentreOfRotation (:mod:`.defaults_fusion`, :mod:`.defaults_reconstruction`,
    :mod:`.defaults_cr`), printed as tables; two cases at a time, about 2.5 hours on a 2-core
    machine (the reconstructor's grid is the most of it)."""
    from concurrent.futures import ProcessPoolExecutor

    from tqdm import tqdm

    from .defaults_cr import cr_case, print_cr
    from .defaults_fusion import fusion_case, print_fusion
    from .defaults_reconstruction import budget_case, print_budget, print_reconstruction, reconstruction_case

    kinds = {"attitude": attitude_case, "fusion": fusion_case, "reconstruction": reconstruction_case,
             "budget": budget_case, "cr": cr_case}
    with ProcessPoolExecutor(max_workers=min(2, len(CASES))) as pool:  # one case per core
        jobs = [(kind, pool.submit(run, *case)) for kind, run in kinds.items() for case in CASES]
        done: dict[str, list] = {kind: [] for kind in kinds}
        for kind, job in tqdm(jobs, unit="case", desc="defaults", disable=not progress):
            done[kind].append(job.result())
    rows = done["attitude"]
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
    print(f"HeaveObserver at its defaults, given the monitoring point only, fed by the AttitudeEstimator: real-time heave "
          f"RMS error at the point [cm]; goals: <= {RATIO_GOAL} x fed by the best fixed aiding, <= max(2 cm, 2.5 % of std)")
    print(f"{'vessel':<13} {'Hs':>4} {'Tp':>4} {'IMU':<4} {'arm x/y/z m':>17} {'std':>6} {'default':>8} "
          f"{'best fixed':>10} {'true angles':>11} {'goal':>5} {'ratio':>6}")
    for r in rows:
        h = r["heave"]
        arm = "/".join(f"{a:g}" for a in h["arm_m"])
        print(f"{r['preset']:<13} {r['hs']:4.1f} {r['tp']:4.0f} {r['imu']:<4} {arm:>17} {h['std_cm']:6.1f} "
              f"{h['default_cm']:8.2f} {h['best_fixed_cm']:10.2f} {h['true_angles_cm']:11.2f} {h['goal_cm']:5.2f} "
              f"{h['ratio']:6.2f}")
    heave_ratio = max(r["heave"]["ratio"] for r in rows)
    heave_over = [r for r in rows if r["heave"]["default_cm"] > r["heave"]["goal_cm"]]
    print(f"heave: worst ratio {heave_ratio:.2f} (goal {RATIO_GOAL}); over the heave goal on {len(heave_over)} of "
          f"{len(rows)} cases")
    print_fusion(done["fusion"])
    print_reconstruction(done["reconstruction"])
    print_budget(done["budget"])
    cr = print_cr(done["cr"])
    return {"attitude": {"cases": rows, "worst_deg": worst, "worst_ratio": worst_ratio,
                         "goal_deg": ATTITUDE_GOAL_DEG, "goal_ratio": RATIO_GOAL},
            "heave": {"worst_ratio": heave_ratio, "over_goal": len(heave_over), "goal_ratio": RATIO_GOAL},
            "fusion": {"cases": done["fusion"], "worst_ratio": max(r["ratio"] for r in done["fusion"])},
            "reconstruction": {"cases": done["reconstruction"], "budget": done["budget"]},
            "cr": {"cases": done["cr"], **cr}}
