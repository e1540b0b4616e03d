"""How well *could* a real-time estimator know roll and pitch from the IMU alone? The
least-variance causal linear estimate of the tilt, for the IMU model and the sea (beyond the
papers; issue 50).

As :func:`~marinefmu.papers.paper003.causal_bound` does for heave, the answer is a least-squares
fit: roll and pitch at each time from the past ``memory`` seconds of the IMU's six channels,
block-averaged, plus a constant, trained on long records of the same sea and IMU with other
seeds (the joint statistics of the waves and the sensor errors, which an adaptive estimator
would have to estimate) and scored on the checks' record. Per block the fit sees nine numbers:
the mean rate (3), the mean specific force (3) and the mean angle change from the block to now
(3, the rate's running trapezoidal integral relative to the row's sample). So it can represent
what an attitude estimator does:

* the angle is the integral of the rate: the angle now is the angle at any past block plus the
  angle change since, exactly, whatever the blocks' lengths;
* the angle in a past block comes from the accelerometer: its horizontal specific force is
  g × tilt minus the horizontal acceleration, which the waves keep at wave frequencies (none
  below half the peak frequency in VesselMotion's sea), so a low-pass combination of the
  blocks gives the tilt;
* the gyro's bias is a Gauss–Markov process: over a finite memory its integral is a random
  walk the fit weighs against the accelerometer's wave leak, as a Kalman filter's gain does.

Blocks are short for the recent past and grow with age (:func:`~marinefmu.estimators.mru.joint.block_edges`): a tenth of their
age by default, at most ``longest`` seconds, so that three minutes at 20 Hz need ninety
blocks per channel.

**Linearised inputs.** Roll and pitch enter the IMU's measurements nonlinearly: the body rates
are not the Euler rates (φ̇ = p + (q sin φ + r cos φ) tan θ), and the accelerometer sees the
tilt scaled by g − a_d and the acceleration rotated by the attitude. A real estimator (a
strapdown quaternion and an error-state filter in NED) handles these exactly; a linear
regression on the raw channels cannot, and at the 0.01° of an MRU the second-order terms
(yaw rate × pitch, heave acceleration × tilt) are as large as the error itself: on the raw
channels the fit errs more than the AttitudeEstimator told the mru grade. So, by default
(``linearise``), the fit is given the channels with the second-order terms removed using the
true attitude: the Euler rates from the measured body rate, T(φ, θ) ω_m, and the specific force
in NED plus the tilt's first-order term, R_nb f_m + g [θ, −φ, 0], whose acceleration part is the
second derivative of the IMU's bounded position (in a frame turning with the yaw, the yaw's
oscillation would rectify the wave acceleration into the low frequencies the tilt lives in).
Each differs from the raw channel by second-order terms only, so the linear information is the
IMU's, and the result is the floor of the linearised problem. With a perfect IMU it is below
0.0001°; ``linearise=False`` fits the raw channels (a looser figure).

It estimates the best linear estimator's error from above: finite memory and training, block
means. Hand-written normal equations (numpy), as in
:func:`~marinefmu.papers.paper003.causal_bound`; neither scipy nor python-control fits a
multichannel causal Wiener filter from data. The lever-arm accelerations of an IMU away from
the COG are in the records and so in the bound: neither it nor the AttitudeEstimator is told
the lever arm.

Frames: NED, FRD body, ZYX Euler angles [rad]; errors are reported in degrees.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
from ..estimators.mru.joint import block_edges
from ..sea.motion_model import VesselMotion, VesselMotionParams, simulate_record, stack
from ..sea.sensors import IMU_GRADES

G = 9.80665
#: Sample interval of the records [s] (20 Hz, as paper 003's checks; the estimator's trapezoidal
#: strapdown errs by (ω Δt)²/12 = 0.03 % of the rate at the Tp 5 s sea's peak, 1.3 rad/s).
DT = 0.05
#: Start of the scored part of each record [s] (the estimator's levelling and convergence).
SETTLE = 300.0
#: Wave travel direction relative to the bow [rad]: bow-quartering, roll and pitch both.
HEADING = 0.75 * math.pi
#: Seeds (sea and sensors) of the training records; the scored record is :data:`SCORED_SEED`.
TRAIN_SEEDS = (4, 5, 6)
SCORED_SEED = 3
#: Seas of the table (Hs [m], Tp [s]) and IMU placements (lever arm from the COG, body [m]).
SEAS = ((1.0, 5.0), (3.0, 10.0), (6.0, 14.0))
PLACEMENTS = {"COG": (0.0, 0.0, 0.0), "50 m fwd, 10 m up": (50.0, 0.0, -10.0)}
#: Ridge on the normal equations, relative to their mean diagonal (block means of smooth
#: signals are nearly collinear).
RIDGE = 1e-10
#: The `system` scenario's aiding of the AttitudeEstimator.
SYSTEM_AIDING = {"vel_sigma": 1.0, "pos_sigma": 3.0, "aid_rate": 10.0}


def vessel_params(hs: float, tp: float, seed: int, lever_arm=(0.0, 0.0, 0.0),
                  imu: dict | None = None) -> VesselMotionParams:
    """VesselMotion parameters of the bound's records: polar_supply, :data:`HEADING`, the sea and
    sensor ``seed``, the IMU at ``lever_arm`` [m, body, from the COG]; ``imu``: more ``imu.*``
    parameters by FMI name (e.g. ``{"imu.grade": "mru"}``)."""
    flat = {"sea.hs": hs, "sea.tp": tp, "sea.heading": HEADING, "sea.seed": seed, "sensors.seed": seed,
            **{f"imu.{a}": float(x) for a, x in zip("xyz", lever_arm)}, **(imu or {})}
    return VesselMotionParams.from_flat(flat)


def record(hs: float, tp: float, seed: int, duration: float, lever_arm=(0.0, 0.0, 0.0), imu: dict | None = None,
           dt: float = DT, motion: dict | None = None) -> dict[str, np.ndarray]:
    """A :func:`~marinefmu.sea.motion_model.simulate_record` record of the bound's set-up
    (:func:`vessel_params`). ``motion``: a record of the same sea, seed, lever arm, duration and
    ``dt`` with any IMU; its motion is kept and only the IMU is measured again (vectorised,
    :meth:`~marinefmu.sea.sensors.Imu.measure_many`), which gives the same numbers as a new
    simulation in a fraction of its time."""
    params = vessel_params(hs, tp, seed, lever_arm, imu)
    if motion is None:
        return simulate_record(params, duration, dt)
    meas = VesselMotion(params).imu.measure_many(stack(motion, "truth.imu_f"), stack(motion, "truth.rate"), dt)
    rec = dict(motion)
    for i, name in enumerate(("imu.acc.x", "imu.acc.y", "imu.acc.z", "imu.gyro.x", "imu.gyro.y", "imu.gyro.z")):
        rec[name] = meas[:, i]
    return rec


def channels(rec: dict[str, np.ndarray], linearise: bool = True) -> np.ndarray:
    """(N, 6) inputs of the fit: rate (3) then specific force (3); linearised with the true attitude
    (module docstring: the Euler rates T(φ, θ) ω_m [rad/s] and the specific force in NED plus the
    tilt's first-order term, R_nb f_m + g [θ, −φ, 0] [m/s²]) or raw (``linearise=False``: the body
    rate and specific force)."""
    w, f = stack(rec, "imu.gyro"), stack(rec, "imu.acc")
    if not linearise:
        return np.column_stack([w, f])
    phi, theta, psi = rec["truth.roll"], rec["truth.pitch"], rec["truth.yaw"]
    sf, cf, st, ct, sp, cp = np.sin(phi), np.cos(phi), np.sin(theta), np.cos(theta), np.sin(psi), np.cos(psi)
    p, q, r = w.T
    u = np.column_stack([p + (q * sf + r * cf) * st / ct, q * cf - r * sf, (q * sf + r * cf) / ct])
    fx, fy, fz = f.T
    y = cf * fy - sf * fz                       # R_x(φ) f, then R_y(θ), then R_z(ψ): R_nb f
    z = sf * fy + cf * fz
    x = ct * fx + st * z
    return np.column_stack([u, cp * x - sp * y + G * theta, sp * x + cp * y - G * phi, -st * fx + ct * z])


def angle_changes(rate: np.ndarray, dt: float) -> np.ndarray:
    """(N, c) running trapezoidal integral of each rate column [rad/s → rad], 0 at the first sample:
    the rows take its block means relative to the row's own sample (:meth:`BoundSetup.rows`), the
    angle change from each block to now, which block means of the rate give only to within a
    block's length."""
    c = np.zeros_like(rate)
    c[1:] = np.cumsum(0.5 * (rate[1:] + rate[:-1]), axis=0) * dt
    return c


def block_rows(x: np.ndarray, edges: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """Regression rows: for each sample index of ``ends``, the block means (:func:`~marinefmu.estimators.mru.joint.block_edges`)
    of every column of ``x`` ((N, c)), then a constant; (len(ends), c·(len(edges) − 1) + 1).
    With one channel and equal blocks this is :func:`~marinefmu.papers.paper003.fir_rows`'s
    layout, oldest block first."""
    csum = np.vstack([np.zeros((1, x.shape[1])), np.cumsum(x, axis=0)])
    upper = csum[ends[:, None] + 1 - edges[None, :-1]]         # (rows, B, c): sums to k − e_j
    lower = csum[ends[:, None] + 1 - edges[None, 1:]]
    means = (upper - lower) / np.diff(edges)[None, :, None]
    means = means[:, ::-1, :]                                    # oldest block first
    return np.column_stack([means.transpose(0, 2, 1).reshape(len(ends), -1), np.ones(len(ends))])


@dataclass(frozen=True)
class BoundSetup:
    """How the fit sees a record: memory [s], block ``resolution`` and ``longest`` block [s], a row
    every ``stride`` s, the linearised channels or not, ``dt`` [s], and the start of the scored
    part ``settle`` [s] (at least ``memory``)."""

    memory: float = 180.0
    resolution: float = 0.1
    longest: float = 5.0
    stride: float = 0.5
    linearise: bool = True
    dt: float = DT
    settle: float = SETTLE

    def __post_init__(self) -> None:
        if self.memory > self.settle:
            raise ValueError(f"memory {self.memory:g} s is longer than the settling time {self.settle:g} s")

    def edges(self) -> np.ndarray:
        """:func:`~marinefmu.estimators.mru.joint.block_edges` of this set-up [samples]."""
        return block_edges(self.memory, self.dt, self.resolution, self.longest)

    def ends(self, n: int, start: float) -> np.ndarray:
        """Sample indices of the rows of a record of ``n`` samples: one every ``stride`` s from
        ``start`` s on, none before the memory is full."""
        step = max(1, int(round(self.stride / self.dt)))
        return np.arange(max(self.edges()[-1], int(round(start / self.dt)) - 1), n, step)

    def features(self, rec: dict[str, np.ndarray], ends: np.ndarray) -> np.ndarray:
        """Rows at the samples ``ends`` (module docstring): per block the angle change to now (3),
        then :func:`block_rows` of :func:`channels` (rate, specific force, constant)."""
        edges = self.edges()
        inputs = channels(rec, self.linearise)
        x = block_rows(inputs, edges, ends)
        turned = angle_changes(inputs[:, :3], self.dt)
        change = block_rows(turned, edges, ends)[:, :-1] - np.repeat(turned[ends], len(edges) - 1, axis=1)
        return np.column_stack([change, x])

    def rows(self, rec: dict[str, np.ndarray], start: float) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`features` and (rows, 2) targets (true roll, pitch [rad]) from ``start`` s on
        (:meth:`ends`)."""
        ends = self.ends(len(rec["truth.roll"]), start)
        return self.features(rec, ends), np.column_stack([rec["truth.roll"][ends], rec["truth.pitch"][ends]])


def fit(pairs: list[tuple[np.ndarray, np.ndarray]], ridge: float = RIDGE) -> np.ndarray:
    """Least-squares weights (features, targets) over the (rows, targets) of ``pairs``."""
    normal, moment = 0.0, 0.0
    for x, y in pairs:
        normal, moment = normal + x.T @ x, moment + x.T @ y
    normal = normal + ridge * np.trace(normal) / len(normal) * np.eye(len(normal))
    return np.linalg.solve(normal, moment)


def rms_deg(err: np.ndarray) -> list[float]:
    """RMS per column [°] of errors [rad]."""
    return [math.degrees(float(e)) for e in np.sqrt(np.mean(np.asarray(err) ** 2, axis=0))]


def causal_tilt_bound(hs: float, tp: float, lever_arm=(0.0, 0.0, 0.0), imu: dict | None = None,
                      setup: BoundSetup = BoundSetup(), train: tuple[int, ...] = TRAIN_SEEDS,
                      train_duration: float = 3600.0, duration: float = 1920.0,
                      motions: dict | None = None) -> dict:
    """Estimated lower bound on the real-time roll and pitch error of any causal linear estimator
    fed this IMU, on the scored record (seed :data:`SCORED_SEED`, RMS from ``setup.settle``).

    Parameters
    ----------
    hs, tp : float
        Significant wave height [m] and peak period [s].
    lever_arm : tuple of float
        IMU position from the COG, body frame [m].
    imu : dict, optional
        ``imu.*`` VesselMotion parameters by FMI name, e.g. ``{"imu.grade": "mru"}``.
    setup : BoundSetup
        Memory, blocks, row stride, linearisation.
    train : tuple of int
        Seeds of the training records.
    train_duration, duration : float
        Length of each training record and of the scored record [s].
    motions : dict, optional
        Cache of motion records by (hs, tp, seed, lever arm, duration, dt), filled and reused
        (:func:`record`'s ``motion``) so that several IMUs share one simulation of the sea.

    Returns
    -------
    dict
        ``roll_deg``, ``pitch_deg`` (RMS error [°]), ``roll_std_deg``, ``pitch_std_deg`` (the true
        angles' std over the scored part [°]), ``features`` and ``rows`` (training), and
        ``scored`` (the scored record, for the estimators).
    """
    motions = {} if motions is None else motions
    pairs, scored = [], None
    for seed in (*train, SCORED_SEED):
        length = duration if seed == SCORED_SEED else train_duration
        key = (hs, tp, seed, tuple(lever_arm), length, setup.dt)
        rec = record(hs, tp, seed, length, lever_arm, imu, setup.dt, motions.get(key))
        motions.setdefault(key, rec)
        if seed == SCORED_SEED:
            scored = rec
        else:
            pairs.append(setup.rows(rec, 0.0))
    w = fit(pairs)
    x, y = setup.rows(scored, setup.settle)
    roll, pitch = rms_deg(x @ w - y)
    k0 = int(round(setup.settle / setup.dt))
    return {"roll_deg": roll, "pitch_deg": pitch,
            "roll_std_deg": math.degrees(float(np.std(scored["truth.roll"][k0:]))),
            "pitch_std_deg": math.degrees(float(np.std(scored["truth.pitch"][k0:]))),
            "features": x.shape[1], "rows": sum(len(p[0]) for p in pairs), "scored": scored}


def estimator_errors(rec: dict[str, np.ndarray], params: AttitudeEstimatorParams | None = None,
                     dt: float = DT, settle: float = SETTLE) -> tuple[float, float]:
    """RMS roll and pitch error [°] of the real-time AttitudeEstimator on ``rec`` ((N,) arrays at
    t_k = (k + 1)·``dt``) from ``settle`` s on."""
    est = estimate_attitude(stack(rec, "imu.gyro"), stack(rec, "imu.acc"), dt, params)
    k0 = int(round(settle / dt))
    err = np.column_stack([est["roll"] - rec["truth.roll"], est["pitch"] - rec["truth.pitch"]])[k0:]
    roll, pitch = rms_deg(err)
    return roll, pitch


def told(grade: str, **aiding: float) -> AttitudeEstimatorParams:
    """AttitudeEstimator parameters told the noise and bias figures of ``grade``, with ``aiding``."""
    g = IMU_GRADES[grade]
    return AttitudeEstimatorParams(gyro_noise=max(g.gyro_noise, 1e-12), acc_noise=max(g.acc_noise, 1e-12),
                                   gyro_bias_sigma=max(g.gyro_bias_instability, 1e-12), gyro_bias_tau=g.bias_tau,
                                   **aiding)


#: The estimators of :func:`tilt_table`: name → parameters for a grade (None: the defaults).
ESTIMATORS = {
    "defaults": lambda grade: None,
    "system aiding": lambda grade: AttitudeEstimatorParams(**SYSTEM_AIDING),
    "told the grade, system aiding": lambda grade: told(grade, **SYSTEM_AIDING),
}


def tilt_table(grades: tuple[str, ...] = tuple(IMU_GRADES), seas: tuple = SEAS, placements: dict = PLACEMENTS,
               setup: BoundSetup = BoundSetup(), estimators: dict = ESTIMATORS, train_duration: float = 3600.0,
               duration: float = 1920.0, raw: bool = True) -> list[dict]:
    """The bound and the AttitudeEstimator's errors, RMS roll and pitch [°], for each grade, sea
    (Hs [m], Tp [s]) and IMU placement (name → lever arm [m]): one row per case with ``bound``,
    ``bound_raw`` (the fit on the raw channels, if ``raw``) and one entry per estimator of
    ``estimators`` (name → function of the grade giving its parameters), each (roll, pitch);
    and the true angles' std. The sea is simulated once per sea and placement and measured by
    each grade's IMU (:func:`record`). Prints each row as it comes (minutes per sea on a
    loaded 2-core machine)."""
    rows = []
    for hs, tp in seas:
        for where, arm in placements.items():
            motions: dict = {}
            for grade in grades:
                imu = {"imu.grade": grade}
                b = causal_tilt_bound(hs, tp, arm, imu, setup, train_duration=train_duration, duration=duration,
                                      motions=motions)
                row = {"grade": grade, "sea": (hs, tp), "placement": where, "bound": (b["roll_deg"], b["pitch_deg"]),
                       "std": (b["roll_std_deg"], b["pitch_std_deg"])}
                if raw:
                    r = causal_tilt_bound(hs, tp, arm, imu, replace(setup, linearise=False),
                                          train_duration=train_duration, duration=duration, motions=motions)
                    row["bound_raw"] = (r["roll_deg"], r["pitch_deg"])
                done: dict = {}
                for name, make in estimators.items():
                    params = make(grade)
                    if params not in done:
                        done[params] = estimator_errors(b["scored"], params, setup.dt, setup.settle)
                    row[name] = done[params]
                rows.append(row)
                print(format_row(row), flush=True)
    return rows


def format_row(row: dict) -> str:
    """One markdown table line of a :func:`tilt_table` row: roll / pitch [°] per column."""
    cells = [row["grade"], f"Hs {row['sea'][0]:g} Tp {row['sea'][1]:g}", row["placement"],
             f"{row['std'][0]:.2f} / {row['std'][1]:.2f}"]
    cells += [f"{row[k][0]:.4f} / {row[k][1]:.4f}" for k in row if k not in ("grade", "sea", "placement", "std")]
    return "| " + " | ".join(cells) + " |"


def main() -> list[dict]:
    """Print :func:`tilt_table` as a markdown table."""
    print("| grade | sea | IMU | true std | bound | bound, raw channels | "
          + " | ".join(f"estimator, {k}" for k in ESTIMATORS) + " |")
    print("|---" * (6 + len(ESTIMATORS)) + "|")
    return tilt_table()


if __name__ == "__main__":
    main()
