"""Benchmark part ``defaults``, GnssAccFusion: the fusion at its defaults, given geometry only,
against the best fixed setting the project knows, on the grid of :mod:`.cases`.

Given geometry only means the accelerometer's lever arm (the case's IMU placement,
:func:`~.cases.placements`) and VesselMotion's default antennas, which are
GnssAccFusionParams' defaults (:data:`~marinefmu.estimators.gnss_fusion.antenna_attitude.DEFAULT_ANTENNAS`);
the receiver is VesselMotion's default (5 Hz RTK, σ_h 1 cm, σ_v 1.5 cm per antenna).

Each case: the real-time COG position RMS error per NED axis [cm] over
``[SETTLE, FUSION_DURATION]`` (:data:`~.cases.SETTLE`) at the defaults
(``noise_sizing="auto"``) and with each setting of :data:`FUSION_GRID`
(``noise_sizing="fixed"``). The figure of merit is the 3-D RMS, √(e_N² + e_E² + e_D²): the
fusion outputs one position, q and r trade the axes against each other (``q_down`` moves the
down axis only), and the largest axis would flip between axes from one setting to the next on
differences of a millimetre. The goal: the defaults within :data:`~.cases.RATIO_GOAL` of
the grid's best on every case.

The records are :data:`FUSION_DURATION` long, not the 600 s of :mod:`.cases`: one fusion
run over 600 s costs about a minute of one core, and the scored 150 s after the settling
already hold 15-30 wave periods. Every run here, the defaults' too, sets ``coast="inertial"``
(:data:`BENCH_COAST`): the records have no GNSS gap, and without one the wave coast never
gives a pseudo-fix and the fused position is the same to the bit (the tests check it), at half
the cost.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..estimators.gnss_fusion.filter import GnssAccFusionParams
from ..estimators.gnss_fusion.runs import fuse
from ..sea.motion_model import stack
from .cases import CASES, DT, RATIO_GOAL, SETTLE, case_record, placements

#: Record length of a fusion case [s] (module docstring).
FUSION_DURATION = 300.0
#: The coast of every run of this part (module docstring): no gap, so the position is the
#: default coast's.
BENCH_COAST = "inertial"
#: The fixed settings the project knows (``q``, ``q_down`` [m²/s³], ``r`` [m²·s]): the
#: paper-001 tuning (1 Hz RTK; the fixed defaults), the ``system`` scenario's (5 Hz RTK) and
#: settings about them. ``noise_sizing="fixed"``: R = r/Δt as given.
FUSION_GRID: tuple[dict, ...] = (
    {"q": 5e-3, "q_down": None, "r": 1e-5},      # the paper-001 tuning (1 Hz)
    {"q": 1e-3, "q_down": 1e-4, "r": 4.5e-5},    # the system scenario (5 Hz)
    {"q": 5e-3, "q_down": 1e-4, "r": 4.5e-5},
    {"q": 1e-3, "q_down": 1e-5, "r": 4.5e-5},
)


def cog_rms_cm(rec: dict[str, np.ndarray], params: GnssAccFusionParams, settle: float = SETTLE) -> tuple[float, ...]:
    """Real-time COG position RMS error of the fusion per NED axis [cm] on ``rec`` (a
    VesselMotion record) from ``settle`` [s] on."""
    acc, gyro = stack(rec, "imu.acc"), stack(rec, "imu.gyro")
    gnss = np.hstack([stack(rec, f"gnss.ant{i}", "ned") for i in range(1, 5)])
    out = fuse(acc, DT, gnss, rec["gnss.new"], gyro, params, gnss_valid=rec["gnss.valid"])
    k0 = int(round(settle / DT))
    err = out["pos"][k0:] - stack(rec, "truth.cog", "ned")[k0:]
    return tuple(100.0 * float(x) for x in np.sqrt(np.mean(err ** 2, axis=0)))


def merit(rms: tuple[float, ...]) -> float:
    """The figure of merit [cm]: the 3-D RMS of the per-axis RMS errors (module docstring)."""
    return float(np.sqrt(np.sum(np.square(rms))))


def fusion_case(preset: str, hs: float, tp: float, place: str, grid: tuple[dict, ...] = FUSION_GRID,
                duration: float = FUSION_DURATION) -> dict:
    """The fusion at its defaults and with every setting of ``grid`` on one case.

    Returns
    -------
    dict
        ``preset``, ``hs`` [m], ``tp`` [s], ``imu``; ``default_cm`` (N, E, D RMS [cm]) and
        ``default`` (its figure of merit [cm]); ``grid``: each setting with ``rms_cm`` and
        ``merit``; ``best`` the grid's best; ``ratio`` = default / best merit.
    """
    rec = case_record(preset, hs, tp, place, duration=duration)
    base = GnssAccFusionParams(acc_lever_arm=placements(preset)[place], coast=BENCH_COAST)
    default = cog_rms_cm(rec, base)
    rows = []
    for g in grid:
        rms = cog_rms_cm(rec, replace(base, noise_sizing="fixed", **g))
        rows.append({**g, "rms_cm": rms, "merit": merit(rms)})
    best = min(rows, key=lambda r: r["merit"])
    return {"preset": preset, "hs": hs, "tp": tp, "imu": place, "default_cm": default, "default": merit(default),
            "grid": rows, "best": best, "ratio": merit(default) / best["merit"]}


def print_fusion(rows: list[dict]) -> None:
    """Print the cases of :func:`fusion_case` as a table, and the worst ratio."""
    print(f"GnssAccFusion at its defaults (geometry only) against the best fixed setting of {len(rows[0]['grid'])}: "
          f"COG RMS error from {SETTLE:g} s [cm]; figure of merit the 3-D RMS; goal <= {RATIO_GOAL} x the best")
    print(f"{'vessel':<13} {'Hs':>4} {'Tp':>4} {'IMU':<4} {'default N/E/D':>20} {'3-D':>5} {'best N/E/D':>20} "
          f"{'3-D':>5} {'q':>7} {'q_down':>7} {'r':>7} {'ratio':>6}")
    for r in rows:
        d, b = r["default_cm"], r["best"]
        qd = "q" if b["q_down"] is None else f"{b['q_down']:.0e}"
        print(f"{r['preset']:<13} {r['hs']:4.1f} {r['tp']:4.0f} {r['imu']:<4} "
              f"{d[0]:6.2f}/{d[1]:6.2f}/{d[2]:6.2f} {r['default']:5.2f} "
              f"{b['rms_cm'][0]:6.2f}/{b['rms_cm'][1]:6.2f}/{b['rms_cm'][2]:6.2f} {b['merit']:5.2f} "
              f"{b['q']:7.0e} {qd:>7} {b['r']:7.1e} {r['ratio']:6.2f}")
    worst = max(r["ratio"] for r in rows)
    print(f"worst ratio {worst:.2f} (goal {RATIO_GOAL}); over the goal on "
          f"{sum(r['ratio'] > RATIO_GOAL for r in rows)} of {len(rows)} cases")


def fusion_bench(cases: tuple = CASES, grid: tuple[dict, ...] = FUSION_GRID, progress: bool = True) -> list[dict]:
    """Every case of ``cases`` in one process, printed by :func:`print_fusion`; about
    (1 + len(grid)) × 30 s of one core per case."""
    rows = []
    for i, case in enumerate(cases):
        rows.append(fusion_case(*case, grid=grid))
        if progress:
            r = rows[-1]
            print(f"[{i + 1}/{len(cases)}] {case}: default {np.round(r['default_cm'], 3).tolist()} "
                  f"{r['default']:.3f} cm; grid " + "; ".join(f"{np.round(g['rms_cm'], 3).tolist()} {g['merit']:.3f}"
                                                              for g in r["grid"]) + f"; ratio {r['ratio']:.2f}", flush=True)
    print_fusion(rows)
    return rows
