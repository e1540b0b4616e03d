"""How well *could* a real-time estimator know the surge, sway and heave of a point on the vessel
from the IMU alone? The least-variance causal linear estimate of a point's level-frame motion,
for the IMU model, the vessel and the sea (beyond the papers; issue 52).

It is :func:`~marinefmu.papers.tilt_bound.causal_tilt_bound`'s fit with more targets: the same
rows (:meth:`~marinefmu.papers.tilt_bound.BoundSetup.features`: the past ``memory`` seconds of
the IMU's six linearised channels, block-averaged, with the angle change from each block to now,
and a constant), trained on long records of the same sea and IMU with other seeds and scored on
the checks' record. The targets are the IMU's position in VesselMotion's NED (whose north is the
mean heading: surge, sway and heave of the level frame) and the three Euler angles; a point at
lever arm r from the IMU is then estimated as p̂ + R_nb(φ̂, θ̂, ψ̂) r, as a real estimator turns its
lever arms with its own attitude, and scored against
:func:`~marinefmu.sea.motion_model.point_truth`.
Least squares is linear in its targets, so to first order this is the least-squares fit of the
point itself; a fit of the point's position would keep the rotation's second-order terms
(r (1 − cos θ), products of the angles), which no linear function of the channels gives and
which 60 m away in a 6 m sea are larger than the goals.

**Why the rows can carry the motion.** The linearised specific force is the IMU's acceleration
in NED plus g times the tilt (:func:`~marinefmu.papers.tilt_bound.channels`) and the tilt is a
linear function of the rows (the tilt bound), so the position, a double integral of the
acceleration, is one too. VesselMotion's sea has no energy below half the peak frequency, so the
best filter is a band-pass double integrator whose response lasts tens of wave periods: the
memory must hold it, and the old blocks must be short beside a wave period to follow it. Blocks
of at most 2 s (:data:`SETUP`; the tilt bound's 5 s suffice for the tilt's low frequencies) do:
on polar_supply in Hs 6 m / Tp 14 s, blocks of at most 0.5 s, or a 300 s memory, move this
bound and :func:`axis_floor` by under 0.1 cm (the longer memory raises them a little: more
weights, the same training), while the tilt bound's blocks raise :func:`axis_floor` by up to
30 %. 180 s is also :func:`~marinefmu.papers.paper003.causal_bound`'s memory for heave.

**Linearised channels** (the tilt bound's docstring says why): the body rates and specific force
are turned into Euler rates and NED specific force with the true attitude, which removes the
kinematics' second-order terms that a real estimator handles exactly (with its own attitude, to
within its error times the acceleration) and a linear regression cannot. The sensor's noise and
biases stay in the channels, so the linear information is the IMU's.

**What the fit knows.** The training records give it the joint statistics of the sea, the
vessel and the sensor, which an adaptive estimator would have to learn. In VesselMotion's
default long-crested sea one wave train drives all six motions through the vessel's response,
so the gyro's angles predict the accelerations and each axis's motion is told by every channel:
the bound lies well below :func:`axis_floor`, the floor of one filter per axis fed the true
attitude (what :class:`~marinefmu.estimators.mru.unit.MotionReferenceUnit` does). A short-crested
sea (``sea.spreading``) breaks that link and raises both this bound and the tilt bound; there
the fit also needs far more training records than the three here to converge.

**Delayed outputs** (``lag`` > 0): the same rows, fitted to the motion ``lag`` s before their
newest sample, give the floor of a fixed-lag smoother fed this IMU, what the unit's delayed
outputs are (the rows' blocks are up to 2 s long ``lag`` s back, where the target is). With
the default set-up and a 20 s lag it is 0.16-0.31 × the real-time floor on every axis, at the
IMU and 59.8 m from it, on polar_supply in Hs 3 m / Tp 10 s and Hs 6 m / Tp 14 s: the
goal "delayed ≤ half the real-time error" is well above what the IMU's information allows.

It estimates the linear floor from above: finite memory and training, block means and the
first-order composition above; it is the achieved error of a real causal filter on one record.
Hand-written normal equations (numpy, :func:`~marinefmu.papers.tilt_bound.fit`): neither scipy
nor python-control fits a multichannel causal Wiener filter from data.

Frames: NED (north = mean heading), FRD body, ZYX Euler angles [rad]; lever arms [m, body];
errors and standard deviations in centimetres, about their means (the motion about the mean
position, as :mod:`marinefmu.bench.mru` scores it).
"""
from __future__ import annotations

import numpy as np
from scipy.signal import butter, sosfiltfilt

from ..errors import ParameterError, check_choice, check_range
from ..estimators.mru.goals import POINTS as MRU_POINTS
from ..estimators.mru.goals import goals, rms_about_mean
from ..frames import G, rot_nb
from ..sea.motion_model import point_truth
from .tilt_bound import SCORED_SEED, TRAIN_SEEDS, BoundSetup, angle_changes, block_rows, channels, fit, record

#: Fitted targets: the IMU's NED position [m] and the ZYX Euler angles [rad].
TARGETS = ("truth.imu.n", "truth.imu.e", "truth.imu.d", "truth.roll", "truth.pitch", "truth.yaw")
#: Monitoring points relative to the IMU, body frame [m]: the IMU itself and the MRU bench's
#: farthest point (:data:`marinefmu.estimators.mru.goals.POINTS`), 59.8 m away.
POINTS = ((0.0, 0.0, 0.0), MRU_POINTS[-1])
#: The rows of both fits (module docstring): the tilt bound's, with blocks of at most 2 s.
SETUP = BoundSetup(longest=2.0)
#: Crossover of :func:`gyro_tilt` [Hz]: below every benchmark sea (VesselMotion's has no
#: energy below half the peak frequency, 0.036 Hz at Tp 14 s).
GYRO_CROSSOVER = 0.01
#: The tilts :func:`axis_floor` turns the specific force with.
TILTS = ("true", "gyro")


def targets(rec: dict[str, np.ndarray], ends: np.ndarray) -> np.ndarray:
    """(len(ends), 6) :data:`TARGETS` of ``rec`` at the samples ``ends``."""
    return np.column_stack([rec[name][ends] for name in TARGETS])


def point_positions(est: np.ndarray, arm) -> np.ndarray:
    """(N, 3) NED positions [m] of the point at ``arm`` from the IMU (body frame [m]) given
    (N, 6) :data:`TARGETS` (estimated or true): p + R_nb(φ, θ, ψ) ``arm``."""
    rots = np.array([rot_nb(*angles) for angles in est[:, 3:]])
    return est[:, :3] + rots @ np.asarray(arm, dtype=float)


def records(hs: float, tp: float, preset: str, lever_arm, imu: dict | None, setup: BoundSetup,
            train: tuple[int, ...], train_duration: float, duration: float,
            motions: dict | None) -> tuple[list[dict[str, np.ndarray]], dict[str, np.ndarray]]:
    """The training records (seeds ``train``, ``train_duration`` s) and the scored record (seed
    :data:`~marinefmu.papers.tilt_bound.SCORED_SEED`, ``duration`` s) of one case
    (:func:`~marinefmu.papers.tilt_bound.record`, VesselMotion's ``vessel.preset`` = ``preset``;
    the arguments as :func:`causal_motion_bound`'s). ``motions`` is filled and reused."""
    motions = {} if motions is None else motions
    params = {"vessel.preset": preset, **(imu or {})}
    recs = []
    for seed, length in [*((s, train_duration) for s in train), (SCORED_SEED, duration)]:
        key = (preset, hs, tp, seed, tuple(lever_arm), length, setup.dt)
        recs.append(record(hs, tp, seed, length, lever_arm, params, setup.dt, motions.get(key)))
        motions.setdefault(key, recs[-1])
    return recs[:-1], recs[-1]


def causal_motion_bound(hs: float, tp: float, preset: str = "polar_supply", lever_arm=(0.0, 0.0, 0.0),
                        points=POINTS, imu: dict | None = None, setup: BoundSetup = SETUP,
                        train: tuple[int, ...] = TRAIN_SEEDS, train_duration: float = 3600.0,
                        duration: float = 1920.0, motions: dict | None = None, lag: float = 0.0) -> dict:
    """Estimated lower bound on the real-time (or ``lag`` s delayed) surge, sway and heave error
    at each point of any causal linear estimator fed this IMU, on the scored record (seed
    :data:`~marinefmu.papers.tilt_bound.SCORED_SEED`, from ``setup.settle``; module docstring).

    Parameters
    ----------
    hs, tp : float
        Significant wave height [m] and peak period [s].
    preset : str
        VesselMotion's ``vessel.preset``.
    lever_arm : tuple of float
        IMU position from the COG, body frame [m].
    points : sequence of tuple of float
        Monitoring points relative to the IMU, body frame [m]; (0, 0, 0) is the IMU.
    imu : dict, optional
        More VesselMotion parameters by FMI name, e.g. ``{"imu.grade": "mru"}``.
    setup : BoundSetup
        Memory, blocks, row stride, linearisation, sample interval, start of the scored part.
    train : tuple of int
        Seeds of the training records.
    train_duration, duration : float
        Length of each training record and of the scored record [s].
    motions : dict, optional
        Cache of motion records by (preset, hs, tp, seed, lever arm, duration, dt), filled and
        reused (:func:`~marinefmu.papers.tilt_bound.record`'s ``motion``) so that several IMUs
        share one simulation of the sea.
    lag : float
        Delay of the estimate [s], [0, ``setup.memory``): 0 for real time; > 0 for the motion
        ``lag`` s before the newest sample the rows read, a fixed-lag smoother's.

    Returns
    -------
    dict
        ``points``: per point, ``arm_m``, ``bound_cm`` (RMS error about the mean of surge, sway,
        heave [cm]), ``std_cm`` (the truth's std [cm]) and ``goal_cm``, the real-time goal
        with this bound (:func:`~marinefmu.estimators.mru.goals.goals`; None for a ``lag``: the
        delayed goal is relative to the estimator's real-time error); ``angles_deg`` (RMS error
        of roll, pitch, yaw [°]); ``features`` and ``rows`` (training); ``scored`` (the scored
        record).
    """
    check_range("lag", lag, lo=0.0, hi=setup.memory, hi_open=True, unit="s")
    back = int(round(lag / setup.dt))
    training, scored = records(hs, tp, preset, lever_arm, imu, setup, train, train_duration, duration, motions)
    pairs = []
    for rec in training:
        ends = setup.ends(len(rec["truth.roll"]), 0.0)
        pairs.append((setup.features(rec, ends), targets(rec, ends - back)))
    weights = fit(pairs)
    ends = setup.ends(len(scored["truth.roll"]), setup.settle)
    est = setup.features(scored, ends) @ weights
    at_rows = {name: values[ends - back] for name, values in scored.items()}
    out = []
    for arm in points:
        truth, _ = point_truth(at_rows, arm)
        std = 100 * np.std(truth, axis=0)
        bound = 100 * rms_about_mean(point_positions(est, arm) - truth)
        out.append({"arm_m": tuple(float(a) for a in arm), "bound_cm": bound.tolist(), "std_cm": std.tolist(),
                    "goal_cm": None if back else goals(std, bound).tolist()})
    angle_err = est[:, 3:] - targets(scored, ends - back)[:, 3:]
    return {"points": out, "angles_deg": np.degrees(np.sqrt(np.mean(angle_err ** 2, axis=0))).tolist(),
            "features": weights.shape[0], "rows": sum(len(x) for x, _ in pairs), "scored": scored}


def gyro_tilt(rec: dict[str, np.ndarray], dt: float, crossover: float = GYRO_CROSSOVER,
              linear: np.ndarray | None = None) -> np.ndarray:
    """(N, 2) roll and pitch [rad] that are the truth below ``crossover`` [Hz] and the integrated
    gyro above it: θ + HP(∫u − θ), u the Euler rates of the measured gyro (turned with the true
    attitude), HP scipy's zero-phase second-order Butterworth high-pass. Its only error is the
    gyro's, integrated, above the crossover (its white noise and its bias's wander faster than
    the crossover): what any attitude smoother fed this gyro keeps in the wave band, where the
    aid's information on the tilt (the horizontal acceleration, known to ω² times the motion's
    error) is worth less than the gyro's (``docs/decisions/mru-design.md``). ``dt``: the
    record's sample interval [s]. Zero-phase, so not causal (its magnitude is the
    Butterworth's squared, fourth order): a smoother's tilt, what :func:`axis_floor` takes
    with ``lag`` > 0. ``linear``: ``channels(rec)`` if already computed (its Euler rates are u)."""
    rates = (channels(rec) if linear is None else linear)[:, :2]
    truth = np.column_stack([rec["truth.roll"], rec["truth.pitch"]])
    sos = butter(2, crossover, "high", fs=1.0 / dt, output="sos")
    return truth + sosfiltfilt(sos, angle_changes(rates, dt) - truth, axis=0)


def level_specific_force(rec: dict[str, np.ndarray], tilt: str = "true", dt: float | None = None) -> np.ndarray:
    """(N, 3) measured specific force turned into NED by the true attitude, plus gravity,
    R_nb f_m + g_n [m/s²]: what :func:`marinefmu.bench.mru.true_attitude_cm` feeds the unit's
    axis filters (the linearised channel of :func:`~marinefmu.papers.tilt_bound.channels`
    without its tilt term). ``tilt = "gyro"``: the horizontal part turned instead by
    :func:`gyro_tilt` (first order, as the linearised channel: f + g [θ − θ_c, −(φ − φ_c), 0]),
    ``dt`` the record's sample interval [s]."""
    check_choice("tilt", tilt, TILTS)
    linear = channels(rec)
    roll, pitch = rec["truth.roll"], rec["truth.pitch"]
    if tilt == "gyro":
        if dt is None or not dt > 0.0:
            raise ParameterError(f"dt: the record's sample interval (> 0 s) is needed with tilt = 'gyro', got {dt!r}")
        roll, pitch = gyro_tilt(rec, dt, linear=linear).T
    angles = np.column_stack([pitch, -roll, np.zeros(len(roll))])
    return linear[:, 3:] - G * angles + np.array([0.0, 0.0, G])


def axis_floor(hs: float, tp: float, preset: str = "polar_supply", lever_arm=(0.0, 0.0, 0.0),
               imu: dict | None = None, setup: BoundSetup = SETUP, train: tuple[int, ...] = TRAIN_SEEDS,
               train_duration: float = 3600.0, duration: float = 1920.0, motions: dict | None = None,
               lag: float = 0.0, tilt: str = "true") -> list[float]:
    """RMS error about the mean [cm] of the IMU's surge, sway and heave, each estimated by the
    best causal linear filter of its own axis of :func:`level_specific_force` alone (the same
    blocks and records as :func:`causal_motion_bound`, whose arguments these are, ``lag``
    included: > 0 for the fixed-lag smoother's): the floor of one filter per axis fed the true
    attitude, which :func:`marinefmu.bench.mru.true_attitude_cm` measures for the unit's
    filters. It lies above :func:`causal_motion_bound` by what the other channels tell: in a
    long-crested sea one wave train drives all six motions, so the gyro's angles predict the
    accelerations.

    ``tilt = "gyro"``: the force turned by :func:`gyro_tilt`, the true tilt below
    :data:`GYRO_CROSSOVER` and the integrated gyro above it. Its delayed floor is what one
    smoother per axis can reach with the best attitude this gyro allows in the wave band; the
    MotionReferenceUnit's delayed surge and sway are such smoothers."""
    check_range("lag", lag, lo=0.0, hi=setup.memory, hi_open=True, unit="s")
    check_choice("tilt", tilt, TILTS)
    back = int(round(lag / setup.dt))
    training, scored = records(hs, tp, preset, lever_arm, imu, setup, train, train_duration, duration, motions)
    edges = setup.edges()

    def rows(rec: dict[str, np.ndarray], start: float) -> tuple[list[np.ndarray], np.ndarray]:
        ends = setup.ends(len(rec["truth.roll"]), start)
        acc = level_specific_force(rec, tilt, setup.dt)
        return [block_rows(acc[:, [i]], edges, ends) for i in range(3)], targets(rec, ends - back)[:, :3]

    fitted = [rows(rec, 0.0) for rec in training]
    x, y = rows(scored, setup.settle)
    return [100 * float(rms_about_mean(x[i] @ fit([(xs[i], ys[:, i]) for xs, ys in fitted]) - y[:, i]))
            for i in range(3)]
