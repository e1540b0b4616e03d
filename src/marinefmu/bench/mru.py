"""Benchmark part ``mru``: the MotionReferenceUnit at its defaults, given its monitoring points
only, against VesselMotion's truth, beside the datasheets of commercial units.

The grid is the ``defaults`` part's (:data:`~.cases.CASES`: the three vessel presets × the
three benchmark seas × the IMU at the COG and far from it), default MEMS IMU, one seed,
:data:`DURATION` s, scored from the first sample the joint filter gives (``motion.joint``; at
the defaults and 100 Hz after about 14 minutes) or, if it never does, from
:data:`~.cases.SETTLE` s or the first valid sample, whichever is later: the goals are the
unit's accuracy once settled, as a datasheet's. The monitoring points
(:data:`~marinefmu.estimators.mru.goals.POINTS`, relative to the IMU, body frame) reach 59.8 m
from the IMU.

The goals are :mod:`marinefmu.estimators.mru.goals`' (RMS errors about the mean against the
truth's std; :func:`~marinefmu.estimators.mru.goals.goals`), with roll and pitch as the
AttitudeEstimator at its defaults (it is that estimator). The heave goal's causal bound is
:func:`case_bound`'s: the least-variance causal linear estimate of the point's motion from this
IMU (:func:`marinefmu.papers.motion_bound.causal_motion_bound`) on its own records of the same
sea, vessel, IMU and placement.
"""
from __future__ import annotations

import math

import numpy as np

from ..estimators.mru.goals import POINTS, goals, rms_about_mean
from ..estimators.mru.params import MotionReferenceUnitParams
from ..estimators.mru.unit import AXES, MotionReferenceUnit
from ..frames import rot_nb
from ..papers.motion_bound import causal_motion_bound
from ..sea.motion_model import point_truth, stack
from .cases import CASES, DT, SETTLE, case_record, placements

#: Length of each case's record [s]: the joint filter's first fit (two rows per weight, 640 s of
#: taught rows at the defaults, after the axis filters' first delayed output at about 175 s) and
#: then 15 minutes scored.
DURATION = 1800.0

def run_mru(rec: dict[str, np.ndarray], params: MotionReferenceUnitParams, dt: float = DT,
            timed: bool = False) -> dict[str, np.ndarray]:
    """The MotionReferenceUnit over a VesselMotion record of step ``dt`` [s]: (N, ·) arrays of
    every output; with ``timed``, also each step's wall time [s] (``step_s``)."""
    import time

    mru = MotionReferenceUnit(params, quiet=True)
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    n, rows = len(acc), len(params.points) + 1
    out = {"roll": np.empty(n), "pitch": np.empty(n), "position": np.empty((n, rows, 3)),
           "velocity": np.empty((n, rows, 3)), "delayed": np.empty((n, rows, 3)), "valid": np.empty(n, bool),
           "delayed_valid": np.empty(n, bool), "joint": np.empty(n, bool), "step_s": np.zeros(n)}
    clock = time.perf_counter if timed else (lambda: 0.0)
    for k in range(n):
        t = clock()
        r = mru.step(gyro[k], acc[k], dt)
        out["step_s"][k] = clock() - t
        out["roll"][k], out["pitch"][k] = r.roll, r.pitch
        out["position"][k], out["velocity"][k], out["delayed"][k] = r.position, r.velocity, r.delayed_position
        out["valid"][k], out["delayed_valid"][k], out["joint"][k] = r.motion_valid, r.delayed_valid, r.joint
    out["delay"] = np.array(mru.delay)
    return out


def scored_from(out: dict[str, np.ndarray], dt: float = DT) -> int:
    """The first scored sample of a run (module docstring): the joint filter's first output, or
    :data:`~.cases.SETTLE` s or the first valid sample, whichever is later."""
    k0 = max(int(SETTLE / dt), int(np.argmax(out["valid"])))
    if out["joint"].any():
        k0 = max(k0, int(np.argmax(out["joint"])))
    return k0


def score_locations(rec: dict[str, np.ndarray], out: dict[str, np.ndarray], k0: int, dt: float = DT,
                    bounds: list[list[float]] | None = None) -> list[dict]:
    """Per location (the IMU, then :data:`~marinefmu.estimators.mru.goals.POINTS`) from sample
    ``k0``: the real-time and delayed position errors and the velocity error (RMS about the
    mean, cm and cm/s), the truth's std and the goals, with the heave goal's causal bound
    ``bounds`` (:func:`case_bound`) if given."""
    lag = int(round(float(out["delay"]) / dt))
    rows = []
    for j, arm in enumerate(((0.0, 0.0, 0.0), *POINTS)):
        pos, vel = point_truth(rec, arm)
        err = rms_about_mean(out["position"][k0:, j] - pos[k0:])
        vel_err = rms_about_mean(out["velocity"][k0:, j] - vel[k0:])
        delayed = rms_about_mean(out["delayed"][k0 + lag:, j] - pos[k0:len(pos) - lag])
        std = np.std(pos[k0:], axis=0)
        bound = None if bounds is None else bounds[j]
        rows.append({"arm_m": arm, "distance_m": float(np.linalg.norm(arm)), "std_cm": (100 * std).tolist(),
                     "rt_cm": (100 * err).tolist(), "delayed_cm": (100 * delayed).tolist(),
                     "vel_cms": (100 * vel_err).tolist(), "vel_std_cms": (100 * np.std(vel[k0:], axis=0)).tolist(),
                     "bound_cm": bound, "goal_cm": goals(100 * std, None if bound is None else np.array(bound)).tolist()})
    return rows


def angle_errors_deg(rec: dict[str, np.ndarray], out: dict[str, np.ndarray], k0: int) -> tuple[float, float]:
    """RMS roll and pitch errors [deg] from sample ``k0`` (the roll's wrapped)."""
    roll = np.degrees(np.sqrt(np.mean(np.angle(np.exp(1j * (out["roll"][k0:] - rec["truth.roll"][k0:]))) ** 2)))
    pitch = np.degrees(np.sqrt(np.mean((out["pitch"][k0:] - rec["truth.pitch"][k0:]) ** 2)))
    return float(roll), float(pitch)


def true_attitude_cm(rec: dict[str, np.ndarray], params: MotionReferenceUnitParams, k0: int) -> list[float]:
    """Real-time RMS error [cm] of surge, sway, heave at the IMU from ``k0`` of three axis
    filters at the unit's motion parameters, designed for the accelerometer's noise alone (the
    noise an exact attitude leaves; the unit's surge and sway add the gyro tilt's), fed the
    measured specific force turned into the level frame by the *true* attitude: what the
    filters do when the attitude is exact, so that the rest of the unit's error is the
    AttitudeEstimator's."""
    from ..estimators.heave.common import SilentLog
    from ..estimators.heave.wiener import WienerAxis
    from ..frames import G

    axes = [WienerAxis(params.motion, SilentLog(), name, reject_below=name != "heave", find_steps=name == "heave")
            for name in AXES]
    for axis in axes:
        axis.start(DT)
    acc = stack(rec, "imu.acc")
    angles = np.column_stack([rec["truth.roll"], rec["truth.pitch"], rec["truth.yaw"]])
    a_h = np.einsum("nij,nj->ni", np.array([rot_nb(*a) for a in angles]), acc) + np.array([0.0, 0.0, G])
    est = np.zeros((len(acc), 3))
    for k in range(len(acc)):
        for i, axis in enumerate(axes):
            out = axis.push(float(a_h[k, i]))
            est[k, i] = 0.0 if out is None else out[0]
    pos, _ = point_truth(rec, (0.0, 0.0, 0.0))
    return (100 * rms_about_mean(est[k0:] - pos[k0:])).tolist()


def case_bound(preset: str, hs: float, tp: float, place: str, extra: dict | None = None) -> list[list[float]]:
    """The causal bound [cm] of surge, sway and heave at the IMU and each monitoring point
    (:data:`~marinefmu.estimators.mru.goals.POINTS`) for one case
    (:func:`marinefmu.papers.motion_bound.causal_motion_bound` at its defaults, the IMU where the
    case puts it, ``extra`` the case's VesselMotion parameters); about 25 s."""
    bound = causal_motion_bound(hs, tp, preset, lever_arm=placements(preset)[place], points=((0.0, 0.0, 0.0), *POINTS),
                                imu=extra)
    return [p["bound_cm"] for p in bound["points"]]


def mru_case(preset: str, hs: float, tp: float, place: str, extra: dict | None = None,
             duration: float = DURATION) -> dict:
    """One case: the real-time and delayed errors [cm] at the IMU and each point of
    :data:`POINTS` per axis, the truth's std, the goals, roll and pitch [deg], and the IMU's
    real-time errors with the axis filters alone (``motion_model = "axis"``) and with those fed
    the true attitude; scored from ``scored_from_s`` (module docstring)."""
    rec = case_record(preset, hs, tp, place, duration=duration, extra=extra)
    out = run_mru(rec, MotionReferenceUnitParams(points=POINTS))
    if not out["valid"].any():        # no sea above the noise the filters assume: no motion output
        return {"preset": preset, "hs": hs, "tp": tp, "imu": place, "valid": False}
    k0 = scored_from(out)
    axis = run_mru(rec, MotionReferenceUnitParams(motion_model="axis"))
    imu, _ = point_truth(rec, (0.0, 0.0, 0.0))
    rows = score_locations(rec, out, k0, bounds=case_bound(preset, hs, tp, place, extra))
    roll, pitch = angle_errors_deg(rec, out, k0)
    return {"preset": preset, "hs": hs, "tp": tp, "imu": place, "valid": True, "roll_deg": roll,
            "pitch_deg": pitch, "scored_from_s": k0 * DT, "joint": bool(out["joint"][k0:].all()),
            "axis_imu_cm": (100 * rms_about_mean(axis["position"][k0:, 0] - imu[k0:])).tolist(),
            "delay_s": float(out["delay"]), "points": rows,
            "true_attitude_imu_cm": true_attitude_cm(rec, MotionReferenceUnitParams(points=POINTS), k0)}


#: Sample rates [Hz] of the rate table (:func:`rate_case`): commercial units output at 10 to
#: 200 Hz.
RATES = (10.0, 20.0, 50.0, 100.0, 200.0)
#: The rate table's case: polar_supply in Hs 3 m / Tp 10 s, the IMU at the COG.
RATE_CASE = ("polar_supply", 3.0, 10.0, "cog")


def rate_case(rate: float, duration: float = DURATION) -> dict:
    """The unit at the defaults plus :data:`~marinefmu.estimators.mru.goals.POINTS` on
    :data:`RATE_CASE`'s sea sampled at ``rate`` [Hz], scored as :func:`mru_case` (the goals
    without the causal bound, which only raises the heave goal): roll and pitch [deg], every
    location's errors (:func:`score_locations`), when ``motion_valid`` and ``joint`` first hold
    [s], and the step's mean and worst wall time in-process [µs, ms] (the designs, the bias-step
    searches and the refits included)."""
    dt = 1.0 / rate
    rec = case_record(*RATE_CASE, duration=duration, dt=dt)
    out = run_mru(rec, MotionReferenceUnitParams(points=POINTS), dt, timed=True)
    k0 = scored_from(out, dt)
    roll, pitch = angle_errors_deg(rec, out, k0)
    return {"rate_hz": rate, "roll_deg": roll, "pitch_deg": pitch, "scored_from_s": k0 * dt,
            "valid_from_s": float(np.argmax(out["valid"]) + 1) * dt,
            "joint_from_s": float(np.argmax(out["joint"]) + 1) * dt if out["joint"].any() else None,
            "points": score_locations(rec, out, k0, dt),
            "mean_step_us": 1e6 * float(np.mean(out["step_s"])), "worst_step_ms": 1e3 * float(np.max(out["step_s"]))}


def rate_summary(r: dict) -> tuple[dict, dict, int, str]:
    """Of one :func:`rate_case`: the IMU's and the farthest point's rows, how many location ×
    axis errors are over their goals, and when the joint filter took over [s] as text."""
    imu, far = r["points"][0], max(r["points"], key=lambda p: p["distance_m"])
    over = sum(int(np.sum(np.asarray(p["rt_cm"]) > np.asarray(p["goal_cm"]))) for p in r["points"])
    return imu, far, over, "never" if r["joint_from_s"] is None else f"{r['joint_from_s']:.0f}"


def print_rates(rows: list[dict]) -> None:
    """The rate table: per rate, roll / pitch, the IMU's real-time and delayed errors, the
    farthest point's real-time heave against its goal, when the motion and the joint filter
    start, and the step's cost."""
    print(f"MotionReferenceUnit at other sample rates ({' '.join(map(str, RATE_CASE))}), defaults and the four points")
    print(f"{'Hz':>5} {'roll/pitch deg':>15} {'IMU rt cm':>17} {'IMU delayed cm':>17} {'59.8 m heave (goal)':>20} "
          f"{'valid / joint s':>16} {'mean us':>8} {'worst ms':>9} {'over goal':>9}")
    for r in rows:
        imu, far, over, joint = rate_summary(r)
        print(f"{r['rate_hz']:5g} {r['roll_deg']:7.4f}/{r['pitch_deg']:.4f} "
              f"{'/'.join(f'{x:.2f}' for x in imu['rt_cm']):>17} {'/'.join(f'{x:.2f}' for x in imu['delayed_cm']):>17} "
              f"{far['rt_cm'][2]:10.2f} ({far['goal_cm'][2]:.2f}) {r['valid_from_s']:7.0f} / {joint:<6} "
              f"{r['mean_step_us']:8.0f} {r['worst_step_ms']:9.1f} {over:9d}")


def print_mru(rows: list[dict]) -> dict:
    """The part's tables; returns the summary (cases over each goal)."""
    print("MotionReferenceUnit at its defaults, given the monitoring points only: RMS error [cm] "
          "(real-time / delayed) per axis against the goal; worst point of each case")
    print(f"{'vessel':<13} {'Hs':>4} {'Tp':>4} {'IMU':<4} {'roll/pitch deg':>15} "
          + " ".join(f"{a + ' rt/dl/goal':>20}" for a in AXES)
          + "\n(second line: at the IMU; the axis filters alone, and fed the true attitude, real time)")
    over, delayed_over = 0, 0
    rows = [{**r, "points": [{k: np.asarray(v) for k, v in p.items()} for p in r["points"]]} for r in rows]
    for r in rows:
        worst = [max(r["points"], key=lambda p, i=i: p["rt_cm"][i] / p["goal_cm"][i]) for i in range(3)]
        cells = [f"{w['rt_cm'][i]:.2f}/{w['delayed_cm'][i]:.2f}/{w['goal_cm'][i]:.2f}" for i, w in enumerate(worst)]
        print(f"{r['preset']:<13} {r['hs']:4.1f} {r['tp']:4.0f} {r['imu']:<4} {r['roll_deg']:7.4f}/{r['pitch_deg']:.4f} "
              + " ".join(f"{c:>20}" for c in cells))
        imu = r["points"][0]
        at_imu = [f"{imu['rt_cm'][i]:.2f}/{imu['delayed_cm'][i]:.2f}/{imu['goal_cm'][i]:.2f}" for i in range(3)]
        print(f"{'':<13} {'':>4} {'':>4} {'':<4} {'at the IMU':>15} " + " ".join(f"{c:>20}" for c in at_imu)
              + "   axis filters " + "/".join(f"{x:.2f}" for x in r["axis_imu_cm"])
              + "   true attitude " + "/".join(f"{x:.2f}" for x in r["true_attitude_imu_cm"])
              + f"   scored from {r['scored_from_s']:.0f} s" + ("" if r["joint"] else " (no joint filter)"))
        over += any(np.any(p["rt_cm"] > p["goal_cm"]) for p in r["points"])
        delayed_over += any(np.any(p["delayed_cm"] > 0.5 * p["rt_cm"]) for p in r["points"])
    print(f"real-time over its goal on {over} of {len(rows)} cases; delayed above half the real-time error on "
          f"{delayed_over} of {len(rows)}")
    return {"over_goal": over, "delayed_over": delayed_over, "n_cases": len(rows)}


def filter_feed(gyro: np.ndarray, acc: np.ndarray, params: MotionReferenceUnitParams
                ) -> tuple[list[list[float | None]], list[np.ndarray | None], dict[int, tuple]]:
    """What a MotionReferenceUnit run over the IMU samples ``gyro``, ``acc`` (N, 3) gives its
    motion filters (:class:`~marinefmu.estimators.heave.wiener.WienerGroup`) step by step, the
    level-frame accelerations and, with points, the yaw rate, what they return (copies), and
    the filters' parameters at each step where the unit changed them (the surge and sway
    filters' noise, sized before their designs: ``MotionReferenceUnit._size_tilt_noise``)."""
    unit = MotionReferenceUnit(params, quiet=True)
    fed: list[list[float | None]] = []
    got: list[np.ndarray | None] = []
    sizing: dict[int, tuple] = {}
    unit.start(DT)
    push = unit.group.push
    last = tuple(axis.params for axis in unit.group.axes)

    def recorded(values):
        nonlocal last
        now = tuple(axis.params for axis in unit.group.axes)
        if any(a is not b for a, b in zip(now, last)):
            sizing[len(fed)] = last = now
        out = push(values)
        fed.append(list(values))
        got.append(None if out is None else out.copy())
        return out

    unit.group.push = recorded
    for k in range(len(acc)):
        unit.step(gyro[k], acc[k], DT)
    return fed, got, sizing


def fresh_filters(params: MotionReferenceUnitParams):
    """A fresh unit's motion filters (its :class:`~marinefmu.estimators.heave.wiener.WienerGroup`),
    started at :data:`~.cases.DT`."""
    unit = MotionReferenceUnit(params, quiet=True)
    unit.start(DT)
    return unit.group


def replay_step(group, fed: list[list[float | None]], sizing: dict[int, tuple], k: int) -> np.ndarray | None:
    """Step ``k`` of the replay: the parameters the unit set before it, if any, then the push."""
    if k in sizing:
        for axis, p in zip(group.axes, sizing[k]):
            axis.params = p
    return group.push(fed[k])


def replay_filters(fed: list[list[float | None]], params: MotionReferenceUnitParams,
                   sizing: dict[int, tuple] | None = None) -> list[np.ndarray | None]:
    """The unit's motion filters, fresh, fed ``fed`` with the parameters ``sizing``
    (:func:`filter_feed`): their outputs."""
    group, sizing = fresh_filters(params), sizing or {}
    return [replay_step(group, fed, sizing, k) for k in range(len(fed))]


def cost_per_step(steps: int = 30000, warm: int = 100000) -> dict[str, float]:
    """In-process µs per step of the MotionReferenceUnit with the four monitoring points
    (:data:`~marinefmu.estimators.mru.goals.POINTS`) and with none, the AttitudeEstimator and
    the HeaveObserver at their defaults, on the first case's record: each model runs ``warm``
    steps untimed (1000 s at 100 Hz: the joint filter taught, every spectrum window at its
    longest) and then ``steps`` timed (best of two runs each, the models taking turns; the
    design, refit and bias-step work amortised over the timed steps, which span five designs
    per axis and two refits).

    The budget is the AttitudeEstimator's plus 1.5 × the HeaveObserver's. The unit without
    points is what the budget compares: the attitude and the motion at the IMU (three axis
    filters; the yaw filter serves the points only). ``points_us``, the difference, is what the
    points' lever arms add (their rates, accelerations and the delayed arm).

    The floor, ``floor_us``, is what no arrangement of the unit's own code can save: its
    AttitudeEstimator's step plus its three axis filters' (``filters_us``: the same
    :class:`~marinefmu.estimators.heave.wiener.WienerGroup`, fresh, replayed on the values the
    unit gave it, :func:`replay_filters`; designs and bias-step searches included). The unit
    without points costs that plus its level frame and its outputs."""
    import time

    from ..estimators.attitude.estimator import AttitudeEstimator
    from ..estimators.heave.observer import HeaveObserver

    rec = case_record(*CASES[0][:4], duration=(warm + steps) * DT)
    gyro, acc = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    roll, pitch = rec["truth.roll"], rec["truth.pitch"]

    def imu_step(m, k):
        m.step(gyro[k], acc[k], DT)

    models = {"mru_us": (lambda: MotionReferenceUnit(MotionReferenceUnitParams(points=POINTS), quiet=True), imu_step),
              "mru_no_points_us": (lambda: MotionReferenceUnit(quiet=True), imu_step),
              "mru_axis_us": (lambda: MotionReferenceUnit(MotionReferenceUnitParams(motion_model="axis"), quiet=True),
                              imu_step),
              "attitude_us": (AttitudeEstimator, imu_step),
              "heave_us": (lambda: HeaveObserver(quiet=True), lambda m, k: m.step(acc[k], roll[k], pitch[k], DT))}
    fed, _, sizing = filter_feed(gyro, acc, MotionReferenceUnitParams())
    models["filters_us"] = (lambda: fresh_filters(MotionReferenceUnitParams()),
                            lambda group, k: replay_step(group, fed, sizing, k))
    best = dict.fromkeys(models, math.inf)
    taught = True
    for _ in range(2):
        for name, (make, run) in models.items():
            model = make()
            for k in range(warm):
                run(model, k)
            if name.startswith("mru_") and name != "mru_axis_us":
                taught = taught and model.joint is not None and model.joint.ready
            t = time.perf_counter()
            for k in range(warm, warm + steps):
                run(model, k)
            best[name] = min(best[name], 1e6 * (time.perf_counter() - t) / steps)
    return {**best, "joint_taught": taught, "points_us": best["mru_us"] - best["mru_no_points_us"],
            "floor_us": best["attitude_us"] + best["filters_us"],
            "budget_us": best["attitude_us"] + 1.5 * best["heave_us"]}


def print_heave_and_angles(rows: list[dict]) -> None:
    """Roll and pitch [deg] and the real-time heave at the farthest point against its goal."""
    print(f"{'vessel':<13} {'Hs':>4} {'Tp':>4} {'roll/pitch deg':>15} {'heave rt cm at 59.8 m':>22} {'goal':>6}")
    for r in rows:
        if not r.get("valid", True):
            print(f"{r['preset']:<13} {r['hs']:4.1f} {r['tp']:4.0f}  no valid motion: no sea above the filters' noise")
            continue
        far = max(r["points"], key=lambda p: p["distance_m"])
        print(f"{r['preset']:<13} {r['hs']:4.1f} {r['tp']:4.0f} {r['roll_deg']:7.4f}/{r['pitch_deg']:.4f} "
              f"{far['rt_cm'][2]:22.2f} {far['goal_cm'][2]:6.2f}")


def mru_bench(progress: bool = True) -> dict:
    """Every case of :data:`~.cases.CASES`, two at a time (about 12 minutes on a 2-core
    machine, the causal bounds included), printed as a table; the rate table (:data:`RATES`,
    one at a time, so that their step times are the machine's own, about 3 minutes); and the
    cost per step against its budget (the AttitudeEstimator's plus 1.5 × the HeaveObserver's)."""
    from concurrent.futures import ProcessPoolExecutor

    from tqdm import tqdm

    grade = {"imu.grade": "mru"}
    with ProcessPoolExecutor(max_workers=2) as pool:
        jobs = [pool.submit(mru_case, *case) for case in CASES]
        graded = [pool.submit(mru_case, *case, extra=grade) for case in CASES if case[3] == "cog"]
        rows = [job.result() for job in tqdm(jobs, unit="case", desc="mru", disable=not progress)]
        mru_rows = [job.result() for job in tqdm(graded, unit="case", desc="mru grade", disable=not progress)]
    summary = print_mru(rows)
    print("with imu.grade = mru (IMU at the COG): goals <= 0.01 deg roll and pitch, and the heave goal at every point")
    print_heave_and_angles(mru_rows)
    rates = [rate_case(rate) for rate in tqdm(RATES, unit="rate", desc="mru rates", disable=not progress)]
    print_rates(rates)
    cost = cost_per_step()
    print(f"cost per step in-process: MotionReferenceUnit (4 points) {cost['mru_us']:.1f} us, without points "
          f"{cost['mru_no_points_us']:.1f} us, axis filters alone {cost['mru_axis_us']:.1f} us (joint filter "
          f"{'taught' if cost['joint_taught'] else 'NOT taught'}); budget {cost['budget_us']:.1f} us = AttitudeEstimator "
          f"{cost['attitude_us']:.1f} + 1.5 x HeaveObserver {cost['heave_us']:.1f}; floor {cost['floor_us']:.1f} us "
          f"= the attitude + its three axis filters {cost['filters_us']:.1f}")
    return {"cases": rows, **summary, "mru_grade": mru_rows, "rates": rates, "cost": cost}


def markdown(data: dict) -> str:
    """The docs page's tables from this part's output (``bench.json``'s ``mru``): per case, the
    worst point's real-time / delayed error against the goal per axis, and the IMU's with the
    true attitude; then the ``mru`` grade's angles and farthest-point heave; then, if measured,
    the rate table (:func:`rate_case`)."""
    lines = ["| vessel | Hs m | Tp s | IMU | roll / pitch ° | surge cm | sway cm | heave cm | IMU, axis filters cm "
             "| IMU, true attitude cm |",
             "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|"]
    for r in data["cases"]:
        pts = [{k: np.asarray(v) for k, v in p.items()} for p in r["points"]]
        cells = []
        for i in range(3):
            w = max(pts, key=lambda p: p["rt_cm"][i] / p["goal_cm"][i])
            mark = "" if w["rt_cm"][i] <= w["goal_cm"][i] else " ✗"
            cells.append(f"{w['rt_cm'][i]:.1f} / {w['delayed_cm'][i]:.1f} ({w['goal_cm'][i]:.1f}){mark}")
        true = " / ".join(f"{x:.1f}" for x in r["true_attitude_imu_cm"])
        axis = " / ".join(f"{x:.1f}" for x in r["axis_imu_cm"])
        lines.append(f"| {r['preset']} | {r['hs']:g} | {r['tp']:g} | {r['imu']} | {r['roll_deg']:.3f} / "
                     f"{r['pitch_deg']:.3f} | {' | '.join(cells)} | {axis} | {true} |")
    lines += ["", "| vessel, `imu.grade = mru` | Hs m | Tp s | roll / pitch ° | heave at 59.8 m cm (goal) |",
              "|---|---:|---:|---:|---:|"]
    for r in data.get("mru_grade", []):
        if not r.get("valid", True) or "points" not in r:
            lines.append(f"| {r['preset']} | {r['hs']:g} | {r['tp']:g} | — | no valid motion (no sea above the "
                         "filters' noise) |")
            continue
        far = max(r["points"], key=lambda p: p["distance_m"])
        lines.append(f"| {r['preset']} | {r['hs']:g} | {r['tp']:g} | {r['roll_deg']:.4f} / {r['pitch_deg']:.4f} | "
                     f"{far['rt_cm'][2]:.2f} ({far['goal_cm'][2]:.2f}) |")
    if data.get("rates"):
        lines += ["", "| rate Hz | roll / pitch ° | IMU real-time surge / sway / heave cm | IMU delayed cm | heave at "
                  "59.8 m cm (goal) | locations × axes over the goal | `motion.joint` from s | mean / worst step |",
                  "|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for r in data["rates"]:
            imu, far, over, joint = rate_summary(r)
            lines.append(f"| {r['rate_hz']:g} | {r['roll_deg']:.3f} / {r['pitch_deg']:.3f} | "
                         f"{' / '.join(f'{x:.2f}' for x in imu['rt_cm'])} | "
                         f"{' / '.join(f'{x:.2f}' for x in imu['delayed_cm'])} | {far['rt_cm'][2]:.2f} "
                         f"({far['goal_cm'][2]:.2f}) | {over} of {3 * len(r['points'])} | {joint} | "
                         f"{r['mean_step_us']:.0f} µs / {r['worst_step_ms']:.0f} ms |")
    return "\n".join(lines)
