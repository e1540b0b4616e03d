"""Benchmark part ``defaults``, DisplacementReconstructor: its defaults, given geometry only,
against the settings the project knows, on the grid of :mod:`marinefmu.bench.cases`.

Each case (:data:`~marinefmu.bench.cases.CASES`: three vessel presets × three seas × two IMU
placements) is a VesselMotion record of :data:`DURATION` s (:func:`~marinefmu.bench.cases.case_record`)
with the default MEMS IMU at :func:`~marinefmu.bench.cases.placements`. The reconstructor is fed
the IMU's specific force and the AttitudeEstimator's roll, pitch and yaw at its defaults (what a
user who chains the two FMUs gets; the yaw is gyro-integrated and drifts slowly, which the
reconstructor's COG transfer must bear), and is given only ``lever_arm`` = the IMU placement.

Score (:func:`score_output`): the output ``disp`` at step k estimates the COG at k − ``delay``.
Over the true-time span [:data:`SETTLE` + W_max/2, duration − W_max/2] (W_max the longest window
of :data:`RECONSTRUCTION_GRID`; the same span for every setting, and every output scored comes
from a window that starts after the attitude estimator has settled), the RMS error of the
estimate against the true COG, each about its mean over the span (a reconstruction from
acceleration has no absolute position), in % of the true COG motion's standard deviation per
NED axis. The figure of merit is the largest of the three axes: a user relies on every axis, and
the horizontal axes, where the attitude error's g·ε acceleration lands, are the hard ones.
The goal: the defaults within :data:`~marinefmu.bench.cases.RATIO_GOAL` of the grid's best on
every case.

:data:`DURATION` = 700 s: the default 200 s window fills at 200 s, the first output scored is
of a window starting after the attitude estimator's :data:`SETTLE` = 150 s and the last is
100 s before the end, which leaves a common scored span of 350 s (25 to 70 peak periods). A
case (the record, the attitude estimate and seven reconstructor runs of 70 000 steps) takes 3 to
5 minutes of one core; a 400 s window would need 1000 s records and about twice that, and is
not in the grid.
"""
from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ..estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
from ..estimators.reconstruction.sliding import DisplacementReconstructor, DisplacementReconstructorParams
from ..sea.motion_model import stack
from .cases import CASES, DT, RATIO_GOAL, SETTLE, case_record, placements

DURATION = 700.0
#: Settings the project knows: the paper-000 semi-submersible reproduction's 0.04 Hz screening,
#: and a shorter window, lower and higher screening and a lower fmax around the defaults
#: (window 200 s, cutoff 0.03 Hz, 60 components, fmax 0.5 Hz); one parameter changed at a time.
RECONSTRUCTION_GRID: tuple[dict, ...] = (
    {"window": 100.0},
    {"cutoff": 0.02},
    {"cutoff": 0.04},
    {"cutoff": 0.05},
    {"cutoff": 0.07},
    {"fmax": 0.3},
)


def run_reconstructor(acc: np.ndarray, euler: np.ndarray, params: DisplacementReconstructorParams) -> dict:
    """Step the reconstructor over a record.

    Parameters
    ----------
    acc : numpy.ndarray
        (N, 3) specific force at the IMU [m/s², body frame].
    euler : numpy.ndarray
        (N, 3) roll, pitch, yaw [rad].
    params : DisplacementReconstructorParams
        The setting.

    Returns
    -------
    dict
        ``disp`` (N, 3) output [m, NED], NaN where not valid; ``delay`` [s]; ``seconds`` wall time.
    """
    start = time.perf_counter()
    rc = DisplacementReconstructor(params, dt=DT)
    disp = np.full((len(acc), 3), np.nan)
    delay = 0.0
    for k in range(len(acc)):
        r = rc.step(acc[k], euler[k], DT)
        if r.valid:
            disp[k] = r.disp
            delay = r.delay
    return {"disp": disp, "delay": delay, "seconds": time.perf_counter() - start}


def score_output(out: dict, cog: np.ndarray, t0: float, t1: float) -> list[float]:
    """RMS error of the output ``out`` (:func:`run_reconstructor`) against the true COG ``cog``
    (N, 3) [m, NED] over true times [t0, t1] [s], each about its mean, in % of the truth's
    standard deviation per N/E/D axis (module docstring). NaN if an output in the span is not valid."""
    lag = int(round(out["delay"] / DT))
    k = np.arange(int(round(t0 / DT)), int(round(t1 / DT)))
    est, truth = out["disp"][k + lag], cog[k]
    err = (est - est.mean(axis=0)) - (truth - truth.mean(axis=0))
    return (100.0 * np.sqrt(np.mean(err ** 2, axis=0)) / truth.std(axis=0)).tolist()


def reconstruction_case(preset: str, hs: float, tp: float, place: str, duration: float = DURATION,
                        grid: tuple[dict, ...] = RECONSTRUCTION_GRID) -> dict:
    """The reconstructor at its defaults and at every setting of ``grid`` on one case.

    Returns
    -------
    dict
        ``default_pct`` [n, e, d] and, per setting, ``grid[i]["pct"]``: RMS error in % of the
        true COG motion's std (:func:`score_output`); ``best``: the setting of ``grid`` with
        the smallest largest axis; ``ratio``: the defaults' largest axis over the smaller of the
        best's and the defaults' (≥ 1; 1 when no setting beats the defaults); ``std_m``: the true COG motion's std [m, N/E/D]; ``seconds``.
    """
    start = time.perf_counter()
    rec = case_record(preset, hs, tp, place, duration=duration)
    acc, gyro = stack(rec, "imu.acc"), stack(rec, "imu.gyro")
    att = estimate_attitude(gyro, acc, DT, AttitudeEstimatorParams())
    euler = np.column_stack((att["roll"], att["pitch"], att["yaw"]))
    cog = stack(rec, "truth.cog", "ned")
    base = DisplacementReconstructorParams(lever_arm=tuple(float(a) for a in placements(preset)[place]))
    w_max = max([base.window] + [g.get("window", base.window) for g in grid])
    t0, t1 = SETTLE + 0.5 * w_max, duration - 0.5 * w_max
    default = score_output(run_reconstructor(acc, euler, base), cog, t0, t1)
    rows = [{**g, "pct": score_output(run_reconstructor(acc, euler, replace(base, **g)), cog, t0, t1)}
            for g in grid]
    best = min(rows, key=lambda r: max(r["pct"]))
    best_max = min(max(best["pct"]), max(default))
    return {"preset": preset, "hs": hs, "tp": tp, "imu": place, "default_pct": default, "grid": rows,
            "best": best, "ratio": max(default) / best_max,
            "std_m": cog[int(t0 / DT):int(t1 / DT)].std(axis=0).tolist(), "seconds": time.perf_counter() - start}


def budget_case(preset: str, hs: float, tp: float, place: str, duration: float = DURATION,
                grid: tuple[dict, ...] = RECONSTRUCTION_GRID) -> dict:
    """The error budget of :func:`~marinefmu.papers.band_budget.band_budget` on one case, for the
    defaults' band and every other band of ``grid``, on the span :func:`reconstruction_case` scores,
    fed the AttitudeEstimator at its defaults.

    Returns
    -------
    dict
        ``budget_pct``: per band (``"defaults"`` and each setting's label whose band differs), the
        budget's ``ideal``, ``screen``, ``sensor`` and ``attitude`` [n, e, d] in % of the true COG
        motion's std; ``seconds``.
    """
    from ..papers.band_budget import band_budget

    start = time.perf_counter()
    rec = case_record(preset, hs, tp, place, duration=duration)
    acc, gyro = stack(rec, "imu.acc"), stack(rec, "imu.gyro")
    att = estimate_attitude(gyro, acc, DT, AttitudeEstimatorParams())
    s0 = int(round(SETTLE / DT))
    fed = np.column_stack((att["roll"], att["pitch"], att["yaw"]))[s0:]
    true = np.column_stack((rec["truth.roll"], rec["truth.pitch"], rec["truth.yaw"]))[s0:]
    f_true, cog = stack(rec, "truth.imu_f")[s0:], stack(rec, "truth.cog", "ned")[s0:]
    base = DisplacementReconstructorParams(lever_arm=tuple(float(a) for a in placements(preset)[place]))
    w_max = max([base.window] + [g.get("window", base.window) for g in grid])
    span = (int(round(0.5 * w_max / DT)), int(round((duration - SETTLE - 0.5 * w_max) / DT)))
    bands = {"defaults": base, **{_label(g): replace(base, **g) for g in grid if set(g) & {"cutoff", "fmax"}}}
    return {"preset": preset, "hs": hs, "tp": tp, "imu": place, "seconds": time.perf_counter() - start,
            "budget_pct": {label: band_budget(acc[s0:], f_true, fed, true, cog, DT, p.cutoff, p.fmax, span, p.lever_arm)
                           for label, p in bands.items()}}


def _label(g: dict) -> str:
    return ", ".join(f"{k} {v:g}" for k, v in g.items() if k not in ("pct", "sizing")) or "defaults"


def print_reconstruction(rows: list[dict]) -> None:
    """Print the table of :func:`reconstruction_case` rows: the defaults' N/E/D error, the best
    setting's, which it is, and the ratio of their largest axes."""
    print(f"DisplacementReconstructor at its defaults (lever arm only, AttitudeEstimator attitude) against "
          f"{len(RECONSTRUCTION_GRID)} settings; RMS error in % of the COG motion's std, N/E/D; goal ratio <= {RATIO_GOAL}")
    print(f"{'vessel':<13} {'Hs':>4} {'Tp':>4} {'IMU':<4} {'default N/E/D %':>20} {'best N/E/D %':>20} "
          f"{'best setting':<20} {'ratio':>6}")
    for r in rows:
        d, b = r["default_pct"], r["best"]["pct"]
        print(f"{r['preset']:<13} {r['hs']:4.1f} {r['tp']:4.0f} {r['imu']:<4} "
              f"{d[0]:6.1f} /{d[1]:5.1f} /{d[2]:5.1f} {b[0]:6.1f} /{b[1]:5.1f} /{b[2]:5.1f} "
              f"{_label(r['best']):<20} {r['ratio']:6.2f}")
    worst = max(r["ratio"] for r in rows)
    print(f"worst ratio {worst:.2f} (goal {RATIO_GOAL}); over the goal on "
          f"{sum(r['ratio'] > RATIO_GOAL for r in rows)} of {len(rows)} cases")


def print_budget(rows: list[dict]) -> None:
    """Print the rows of :func:`budget_case`: per case and band, the ideal band-pass's error and
    its attitude, sensor and screen parts (largest axis each), and the band with the least ideal
    error."""
    labels = list(rows[0]["budget_pct"])
    print("DisplacementReconstructor's error budget (ideal band-pass fed the same attitude; largest axis, % of the "
          "COG motion's std): ideal = attitude + sensor + screen parts")
    print(f"{'vessel':<13} {'Hs':>4} {'Tp':>4} {'IMU':<4} " + " ".join(f"{lb:>24}" for lb in labels) + f" {'least ideal':>12}")
    for r in rows:
        b = r["budget_pct"]
        cells = [f"{max(b[lb]['ideal']):7.1f} ({max(b[lb]['attitude']):5.1f}/{max(b[lb]['sensor']):4.1f}/"
                 f"{max(b[lb]['screen']):4.1f})" for lb in labels]
        least = min(labels, key=lambda lb: max(b[lb]["ideal"]))
        print(f"{r['preset']:<13} {r['hs']:4.1f} {r['tp']:4.0f} {r['imu']:<4} " + " ".join(f"{c:>24}" for c in cells)
              + f" {least:>12}")


def main(cases: tuple = CASES, grid: tuple[dict, ...] = RECONSTRUCTION_GRID, save: str | None = None) -> list[dict]:
    """Run ``cases`` one after the other (single process), printing progress, then the table;
    ``save``: a JSON-lines file that receives each case's row as it is done."""
    import json

    rows = []
    for i, case in enumerate(cases):
        r = reconstruction_case(*case, grid=grid)
        rows.append(r)
        if save:
            with open(save, "a") as fh:
                fh.write(json.dumps(r) + "\n")
        print(f"[{i + 1}/{len(cases)}] {case}: default {max(r['default_pct']):.1f} %, best {max(r['best']['pct']):.1f} % "
              f"({_label(r['best'])}), ratio {r['ratio']:.2f}, {r['seconds']:.0f} s; "
              + "; ".join(f"{_label(g)}: {max(g['pct']):.1f}" for g in r["grid"]), flush=True)
    print_reconstruction(rows)
    return rows


if __name__ == "__main__":
    main()
