"""How much the DisplacementReconstructor errs at each lag behind the latest sample: its output
(the window centre, ``delay`` = window/2 late) and the window model extrapolated to the present
(lag 0, which the FMU does not output because it errs more than the motion itself).

The record: VesselMotion's default hull (``polar_supply``) and default MEMS IMU in a JONSWAP sea
Hs 3 m, Tp 10 s, bow-quartering (waves travelling 135° off the bow, ``sea.heading`` = 3π/4),
100 Hz; the IMU at the COG or 50 m forward of it (lever arm (50, 0, 0) m, given to the
reconstructor); roll, pitch and yaw either the truth or the AttitudeEstimator's at its defaults
on the same IMU. The reconstructor runs at its defaults (window 200 s, hop 10 s, cutoff 0.03 Hz).

Score: from ``settle`` s after ``valid`` first goes true to the end, the RMS error of the estimate
at lag L against the true COG L s earlier, each about its mean over the scored span (a
reconstruction from acceleration has no absolute position), in % of the true COG motion's
standard deviation over that span, per NED axis: as :mod:`marinefmu.analysis.scoring` scores
the output in a system run.

:func:`extrapolation_variants` scores the ways tried to make the extrapolation useful, on the
windows the reconstructor fitted: the model as fitted, with its growing components dropped, with
every component continued undamped from the window's end, and the model's displacement and
velocity 5 s before the window's end carried forward by integrating the acceleration twice.

Run ``python -m marinefmu.bench.reconstruction_outputs`` (about 10 minutes on two cores;
``--variants`` adds :func:`extrapolation_variants` for two of the cases).
"""
from __future__ import annotations

import json
import math
import sys
import time
from dataclasses import asdict

import numpy as np

from ..estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
from ..estimators.reconstruction.decomposition import tilt_correct
from ..estimators.reconstruction.sliding import DisplacementReconstructor, DisplacementReconstructorParams
from ..sea.motion_model import VesselMotionParams, simulate_record, stack

DT = 0.01
#: The sea: Hs 3 m, Tp 10 s, waves travelling 135° off the bow (bow-quartering).
SEA = {"sea.hs": 3.0, "sea.tp": 10.0, "sea.heading": 0.75 * math.pi}
#: IMU positions relative to the COG, body frame [m].
LEVER_ARMS = {"at the COG": (0.0, 0.0, 0.0), "50 m forward": (50.0, 0.0, 0.0)}
#: Roll, pitch, yaw fed to the reconstructor.
ATTITUDES = ("truth", "AttitudeEstimator")
#: Lags behind the latest sample [s]: 0 is the extrapolation, 100 (window/2) the output.
LAGS = (0.0, 5.0, 10.0, 20.0, 50.0, 100.0)


def record(lever_arm: tuple[float, float, float], duration: float = 1200.0, seed: int = 1) -> dict[str, np.ndarray]:
    """VesselMotion record of :data:`SEA` with the IMU at ``lever_arm`` [m, body, from the COG]:
    ``acc``, ``gyro`` (N, 3) at the IMU, true ``euler`` (N, 3) [rad] and ``cog`` (N, 3) [m, NED]."""
    values = {**SEA, "sea.seed": seed, "imu.x": lever_arm[0], "imu.y": lever_arm[1], "imu.z": lever_arm[2]}
    rec = simulate_record(VesselMotionParams.from_flat(values), duration, DT)
    return {"acc": stack(rec, "imu.acc"), "gyro": stack(rec, "imu.gyro"),
            "euler": stack(rec, "truth", ("roll", "pitch", "yaw")), "cog": stack(rec, "truth.cog", "ned")}


def errors(rec: dict[str, np.ndarray], lever_arm: tuple[float, float, float], attitude: str,
           lags: tuple[float, ...] = LAGS, settle: float = 60.0,
           params: DisplacementReconstructorParams | None = None) -> dict:
    """Run the reconstructor over ``rec`` (:func:`record`) with the ``attitude`` (``"truth"`` or
    ``"AttitudeEstimator"``, at its defaults) and score its estimate at each of ``lags`` [s].

    Returns
    -------
    dict
        ``rms_pct``: {lag: [n, e, d]} RMS error in % of the motion's standard deviation;
        ``motion_std_m``: [n, e, d] of the true COG over the scored span; ``attitude_rms_deg``:
        roll, pitch, yaw error of the attitude fed; ``scored_s``; ``seconds`` (wall time).
    """
    start = time.perf_counter()
    euler = _attitude(rec, attitude)
    p = params or DisplacementReconstructorParams(lever_arm=tuple(float(a) for a in lever_arm))
    rc = DisplacementReconstructor(p, dt=DT)
    n = len(rec["acc"])
    est = np.full((len(lags), n, 3), np.nan)
    first = None
    for k in range(n):
        r = rc.step(rec["acc"][k], euler[k], DT)
        if r.valid and first is None:
            first = k
        if rc.models is not None:
            for i, lag in enumerate(lags):
                est[i, k] = rc.estimate_at(lag)[0]
    if first is None:
        raise ValueError("the record is shorter than the window")
    k = np.arange(first + int(round(settle / DT)), n)
    rms = {}
    std = None
    for i, lag in enumerate(lags):
        truth = rec["cog"][k - int(round(lag / DT))]
        e = est[i, k]
        err = (e - e.mean(axis=0)) - (truth - truth.mean(axis=0))
        s = truth.std(axis=0)
        rms[lag] = (100.0 * np.sqrt(np.mean(err ** 2, axis=0)) / s).tolist()
        if lag == lags[-1]:
            std = s.tolist()
    att_err = np.degrees(np.sqrt(np.mean((euler[k] - rec["euler"][k]) ** 2, axis=0))).tolist()
    return {"rms_pct": rms, "motion_std_m": std, "attitude_rms_deg": att_err, "scored_s": len(k) * DT,
            "seconds": time.perf_counter() - start}


def _attitude(rec: dict[str, np.ndarray], attitude: str) -> np.ndarray:
    if attitude == "truth":
        return rec["euler"]
    if attitude == "AttitudeEstimator":
        att = estimate_attitude(rec["gyro"], rec["acc"], DT, AttitudeEstimatorParams())
        return np.column_stack((att["roll"], att["pitch"], att["yaw"]))
    raise ValueError(f"attitude must be 'truth' or 'AttitudeEstimator', got {attitude!r}")


#: Times past the end of the fitted window at which :func:`extrapolation_variants` scores [s].
PAST_END = (0.0, 2.0, 5.0, 10.0)
#: How far before the window's end the integrated variant starts [s].
ANCHOR = 5.0


def _evaluate(models: list, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    disp, vel = np.zeros((len(t), 3)), np.zeros((len(t), 3))
    for axis, (lam, c2, c1) in enumerate(models):
        if len(lam):
            e = np.exp(np.outer(t, lam))
            disp[:, axis], vel[:, axis] = (e @ c2).real, (e @ c1).real
    return disp, vel


def _drop_growing(models: list, t_end: float) -> list:
    return [(lam[lam.real <= 0], c2[lam.real <= 0], c1[lam.real <= 0]) for lam, c2, c1 in models]


def _undamped(models: list, t_end: float) -> list:
    """Each component continued from its value at the window's end with its frequency, undamped."""
    out = []
    for lam, c2, c1 in models:
        w = 1j * lam.imag
        scale = np.exp((lam - w) * t_end)
        out.append((w, c2 * scale, c2 * scale * w))
    return out


def extrapolation_variants(rec: dict[str, np.ndarray], lever_arm: tuple[float, float, float], attitude: str,
                           settle: float = 60.0, past_end: tuple[float, ...] = PAST_END) -> dict[str, dict]:
    """RMS error of the COG displacement, in % of the motion's standard deviation per NED axis,
    at each of ``past_end`` s past the end of every window the reconstructor (defaults) fits
    over ``rec`` from ``settle`` s after the first: {variant: {time past the end: [n, e, d]}}.

    Variants: ``as fitted`` (at 0 s, what refitting at every step would output; up to ``hop``
    = 10 s, the former ``disp.*``), ``growing dropped`` (components with Re λ > 0 screened),
    ``undamped`` (every component continued from its value at the window's end without
    damping, |λ| = 1 in discrete time) and ``integrated`` (the model's displacement and velocity
    :data:`ANCHOR` s before the window's end carried forward with the tilt-corrected
    acceleration integrated twice, trapezoidal).
    """
    euler = _attitude(rec, attitude)
    rc = DisplacementReconstructor(DisplacementReconstructorParams(lever_arm=tuple(float(a) for a in lever_arm)), dt=DT)
    fits, last = [], None
    for k in range(len(rec["acc"])):
        rc.step(rec["acc"][k], euler[k], DT)
        if rc.models is not None and rc.models is not last:
            last = rc.models
            fits.append((k, rc.models, rc.t_start, rc.trend.copy()))
    arm = np.einsum("nij,j->ni", _rotations(euler), np.asarray(lever_arm, dtype=float))
    acc_n = tilt_correct(rec["acc"], euler)
    cog = rec["cog"]
    first = fits[0][0] + int(round(settle / DT))
    cog_mean, cog_std = cog[first:].mean(axis=0), cog[first:].std(axis=0)
    steps = np.round(np.asarray(past_end) / DT).astype(int)
    variants = {"as fitted": None, "growing dropped": _drop_growing, "undamped": _undamped, "integrated": None}
    errs: dict[str, list] = {v: [] for v in variants}
    n_anchor = int(round(ANCHOR / DT))
    for k_end, models, t_start, trend in fits:
        if k_end < first or k_end + steps.max() >= len(cog):
            continue
        k0 = int(round(t_start / DT))
        j = k_end + steps
        t = (j - k0) * DT
        t_end = (k_end - k0) * DT
        cog_arm = arm[j] - (trend[0] + np.outer(t, trend[1]))
        truth = cog[j] - cog_mean
        for name, change in variants.items():
            if name == "integrated":
                ka = k_end - n_anchor
                d0, v0 = _evaluate(models, np.array([(ka - k0) * DT]))
                a = acc_n[ka:j.max() + 1]
                v = v0 + np.vstack((np.zeros((1, 3)), np.cumsum(0.5 * (a[1:] + a[:-1]) * DT, axis=0)))
                x = d0 + np.vstack((np.zeros((1, 3)), np.cumsum(0.5 * (v[1:] + v[:-1]) * DT, axis=0)))
                disp = x[j - ka]
            else:
                disp = _evaluate(models if change is None else change(models, t_end), t)[0]
            errs[name].append(disp - cog_arm - truth)
    out = {}
    for name, e in errs.items():
        pct = 100.0 * np.sqrt(np.mean(np.array(e) ** 2, axis=0)) / cog_std
        out[name] = {float(tp): row.tolist() for tp, row in zip(past_end, pct)}
    return out


def _rotations(euler: np.ndarray) -> np.ndarray:
    from ..frames import rot_nb

    return np.array([rot_nb(*e) for e in euler])


def measure(duration: float = 1200.0, seed: int = 1, lags: tuple[float, ...] = LAGS) -> dict:
    """:func:`errors` for every IMU position of :data:`LEVER_ARMS` and attitude of
    :data:`ATTITUDES`, with the conditions: {case: result, ..., "conditions": {...}}."""
    from .parts import machine

    out: dict = {}
    for where, arm in LEVER_ARMS.items():
        rec = record(arm, duration, seed)
        for attitude in ATTITUDES:
            out[f"IMU {where}, {attitude} attitude"] = errors(rec, arm, attitude, lags)
    out["conditions"] = {
        "date": time.strftime("%Y-%m-%d"), "machine": machine(), "duration_s": duration, "seed": seed, "sea": SEA,
        "lever_arms_m": LEVER_ARMS, "reconstructor": asdict(DisplacementReconstructorParams()),
        "attitude_estimator": asdict(AttitudeEstimatorParams()),
    }
    return out


def main(argv: list[str] | None = None) -> int:
    """Print the table of :func:`measure` (and its JSON with ``--json``)."""
    argv = sys.argv[1:] if argv is None else argv
    result = measure()
    for case, r in result.items():
        if case == "conditions":
            continue
        print(f"{case} (motion std N/E/D {' / '.join(f'{s:.3f}' for s in r['motion_std_m'])} m, "
              f"attitude error {' / '.join(f'{a:.3f}' for a in r['attitude_rms_deg'])} deg)")
        for lag, pct in r["rms_pct"].items():
            print(f"  lag {lag:5.0f} s: {' / '.join(f'{x:6.1f}' for x in pct)} %")
    if "--variants" in argv:
        result["variants"] = {}
        for where, attitude in (("at the COG", "truth"), ("50 m forward", "AttitudeEstimator")):
            arm = LEVER_ARMS[where]
            case = f"IMU {where}, {attitude} attitude"
            result["variants"][case] = v = extrapolation_variants(record(arm), arm, attitude)
            print(f"{case}: the window's model past the end of its window")
            for name, rows in v.items():
                print(f"  {name:16s}" + "  ".join(f"{tp:g} s: {' / '.join(f'{x:.0f}' for x in pct)} %"
                                                 for tp, pct in rows.items()))
    if "--json" in argv:
        print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
