"""Attitude from gyros by quaternion integration (paper 000, section 3.1) and a drift-corrected
variant aided by the accelerometer's gravity direction.

Paper 000 integrates the body angular rate ω_b in the quaternion kinematics

.. math::
    \\dot Q = \\tfrac12\\, Q ⊗ [0, ω_b]                      \\qquad (6, 7)

and reads Euler angles from the quaternion (eqs. 8-9). Here ``Q`` represents R_nb (body → NED,
see the design page) and each step applies the **exact** rotation of the step instead of a first-order
update of eq. 7: q_{k+1} = q_k ⊗ exp(½ ω̄ Δt), with ω̄ the mean of the two rate samples that
bound the step (trapezoidal, second order in Δt), then normalised
(:func:`integrate_gyro`). With any gyro bias b this drifts: the angle error grows as b·t.

Mode 1 (default) corrects roll and pitch with the accelerometer. A plain complementary/Mahony
filter compares the measured specific force with gravity; on a vessel in waves that is
corrupted by the vessel's own horizontal acceleration (a/g ≈ 0.05 rad for 0.5 m/s²), so its
crossover has to sit far below the wave band, and then it cannot follow the gyro's bias
instability (a 5e-5 rad/s Gauss–Markov bias with τ = 50 s leaves ≈ 0.4° of tilt error).
We use instead the marine-VRU construction (aided strapdown, as in the VRU of smsfusion):
the tilt-corrected acceleration a_n = R̂ f_b + g_n is integrated to a horizontal velocity and
position, and zero-mean pseudo-measurements "horizontal velocity = 0 ± σ_v, position = 0 ± σ_p"
at ``aid_rate`` feed an error-state Kalman filter (filterpy ``KalmanFilter``) with states

.. math::
    δx = [δp_N, δp_E, δv_N, δv_E, ε_N, ε_E, δb_x, δb_y],\\qquad
    δ\\dot p = δv,\\quad δ\\dot v = f_n × ε,\\quad \\dot ε = -\\hat R_{nb}\\, δb,\\quad δ\\dot b = -δb/τ_b

(ε: small rotation with R_true = (I + [ε×]) R̂; b: gyro bias, first-order Gauss–Markov).
A tilt error ε makes a horizontal acceleration error g·ε that integrates into a velocity
*ramp* (a position parabola), while the wave velocity and position stay bounded and
oscillatory: each integration separates the two by a further factor ω, so the filter rejects wave accelerations far better
than a first-order complementary filter with the same crossover, and it estimates the x/y gyro
bias. After each update the error is injected into the nominal state (q, v, b̂) and reset.

The best ``vel_sigma`` and ``pos_sigma`` depend on the motion at the IMU: a vessel at rest wants
them tight (the gyro is then the only error, and the tighter the aid the less drift), a small
vessel in a high sea or an IMU high above the roll centre wants them loose (0.1-2 m/s across
the benchmark's vessels, seas and placements). With ``aid_sizing = "auto"`` (default) the
estimator sizes them from the data as it runs (what commercial motion sensors call
auto-tuning): the horizontal tilt-compensated acceleration, high-passed, is integrated by a
leaky integrator (time constant :data:`LEAK_TAU`, far below any wave frequency) into the wave
velocity, whose running RMS v_rms per axis (exponential, time constant :data:`STATS_TAU`,
corrected for the start as Adam's moments are) sets

.. math::
    σ_v = \\max(σ_{v,min},\\; c_v\\, v_{rms}),\\qquad σ_p = r_p\\, σ_v

(:data:`AID_GAIN`, :data:`POS_RATIO`, :data:`SIGMA_V_MIN`; fitted on the benchmark grid, see
the decision record on the attitude defaults). The integrator does not see the filter's
corrections, so the sizing does not feed back on itself. Until the statistics have filled
(the first :data:`LEAK_TAU` seconds after levelling) ``vel_sigma`` and ``pos_sigma`` are used;
``aid_sizing = "fixed"`` uses them throughout.

The gyro's noise is sized the same way, because the estimator does not know the grade of the
IMU it is given (a MEMS unit's gyro is seventeen times noisier than an MRU's, and a filter that
assumes MEMS trusts an MRU's gyro too little: 0.010° instead of 0.002° roll on the ``mru``
grade). With ``aid_sizing = "auto"`` the white-noise density comes from the second difference of
the gyro samples: for white noise of standard deviation σ per sample, d_k = ω_{k+1} − 2ω_k +
ω_{k−1} has variance 6σ², while a vessel's rate, smooth at 100 Hz, contributes its third
derivative times Δt², below 2·10⁻⁵ rad/s even for a 5° roll at 1.3 rad/s. So

.. math::
    \\hat N = \\sqrt{\\overline{d^2}\\,Δt / 6},\\qquad
    N_{gyro} = \\max(N_{min}, \\hat N),\\qquad
    σ_b = σ_{b,0}\\, N_{gyro} / N_0

(the running mean over the three axes, time constant :data:`STATS_TAU`; N_0, σ_{b,0} the
``gyro_noise`` and ``gyro_bias_sigma`` given, whose ratio, 1 s^-½ by default as the ``mems``
grade, is kept: of the grades, bias instability falls with the noise; the MEMS ratio
overstates an MRU's bias twelvefold, and the ``mru`` grade then reaches 0.004° roll and pitch
against 0.002° told its own figures; :data:`GYRO_NOISE_MIN`). A vibrating mount raises N̂, which makes the filter trust the gyro less:
the safe side. The noise model is used from :data:`NOISE_SETTLE` seconds of samples on; until
then, and with ``aid_sizing = "fixed"`` throughout, ``gyro_noise`` and ``gyro_bias_sigma`` as
given. Rejected samples (held) do not enter the mean. The initial bias covariance stays
``gyro_bias_sigma``²: it is the prior on the unknown turn-on bias, which the sizing does not
measure (a quiet gyro may still start with a large bias).
Yaw has no aid (no heading sensor): it is the integrated (bias-free-in-x/y) gyro yaw and
drifts with the z-gyro bias.

Initial attitude: given angles (``init="given"``), or levelled from the accelerometer
(``init="level"``): the specific force of the first ``level_time`` seconds is averaged after
rotating each sample back to the start frame with the integrated gyro, so rotation during the
levelling does not blur it; the outputs are not valid until then.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from filterpy.kalman import KalmanFilter

from ...errors import check_choice, check_int, check_range, check_vector
from ...frames import euler_to_quat, level_angles, quat_from_rotvec, quat_mul, quat_to_euler, quat_to_rot
from ..noise_meter import WhiteNoiseMeter
from ..samples import force_beyond_limit, rate_beyond_limit

log = logging.getLogger(__name__)

INIT_CHOICES = ("given", "level")
AID_SIZINGS = ("auto", "fixed")

#: Time constant of the running RMS that sizes the aiding [s].
STATS_TAU = 120.0
#: Time constant of the leaky integrator that turns acceleration into wave velocity [s]
#: (a high-pass far below the wave band: 1/(2π·40 s) = 0.004 Hz).
LEAK_TAU = 40.0
#: σ_v per RMS wave velocity, σ_p per σ_v, and the least σ_v [m/s] of the auto sizing.
AID_GAIN = 1.5
POS_RATIO = 3.0
SIGMA_V_MIN = 0.05
#: Least gyro white-noise density of the auto sizing [rad/s/√Hz]: 0.0003 °/√h, below the best
#: navigation-grade fibre-optic gyros (0.0005-0.001 °/√h), so a noiseless or quantised input
#: (a recording of a unit at rest) still gets a positive process noise.
GYRO_NOISE_MIN = 1e-7
#: Samples of gyro noise statistics [s] before the sized gyro noise is used.
NOISE_SETTLE = 10.0


@dataclass(frozen=True)
class AttitudeEstimatorParams:
    """Parameters of :class:`AttitudeEstimator` (FMU names in brackets).

    Parameters
    ----------
    mode : int
        0 gyro-only quaternion integration as paper 000; 1 drift-corrected (default). [``mode``]
    init : str
        ``"given"`` start from ``init_euler``; ``"level"`` level from the accelerometer. [``init``]
    init_euler : tuple of float
        Initial roll, pitch, yaw [rad] for ``init="given"`` (yaw also for ``"level"``).
        [``init.roll``, ``init.pitch``, ``init.yaw``]
    level_time : float
        Levelling time [s], 0.1 … 600. [``level_time``]
    gyro_noise : float
        Gyro white-noise density [rad/s/√Hz], (0, 1]; with ``aid_sizing = "auto"`` the start
        of the sizing and, with ``gyro_bias_sigma``, the ratio it keeps. [``gyro_noise``]
    acc_noise : float
        Accelerometer white-noise density [m/s²/√Hz], (0, 10]. [``acc_noise``]
    gyro_bias_sigma : float
        Gyro bias standard deviation (Gauss–Markov) [rad/s], (0, 1]. [``gyro_bias_sigma``]
    gyro_bias_tau : float
        Gyro bias correlation time [s], 1 … 1e6. [``gyro_bias_tau``]
    vel_sigma : float
        Standard deviation of the zero-horizontal-velocity pseudo-measurement [m/s], (0, 100].
        [``vel_sigma``]
    pos_sigma : float
        Standard deviation of the zero-horizontal-position pseudo-measurement [m], (0, 1000].
        [``pos_sigma``] Larger values aid more slowly: less wave acceleration leaks into the
        tilt, more gyro drift stays in it; the best values depend on the motion, so by default
        they only start the auto sizing (``aid_sizing``).
    aid_rate : float
        Rate of the pseudo-measurement [Hz], (0, 100]. [``aid_rate``]
    aid_sizing : str
        ``"auto"`` (default) sizes ``vel_sigma`` and ``pos_sigma`` from the measured motion, and
        ``gyro_noise`` and ``gyro_bias_sigma`` from the gyro's measured noise, as it runs
        (module docstring); ``"fixed"`` uses them as given. [``aid_sizing``]
    """

    mode: int = 1
    init: str = "level"
    init_euler: tuple[float, float, float] = (0.0, 0.0, 0.0)
    level_time: float = 10.0
    gyro_noise: float = 5e-5
    acc_noise: float = 7e-4
    gyro_bias_sigma: float = 5e-5
    gyro_bias_tau: float = 50.0
    vel_sigma: float = 1.0
    pos_sigma: float = 3.0
    aid_rate: float = 10.0
    aid_sizing: str = "auto"

    def __post_init__(self) -> None:
        check_int("mode", self.mode, lo=0, hi=1)
        check_choice("init", self.init, INIT_CHOICES)
        roll, pitch, yaw = check_vector("init.{roll,pitch,yaw}", self.init_euler, unit="rad")
        check_range("init.roll", roll, lo=-math.pi, hi=math.pi, unit="rad")
        check_range("init.pitch", pitch, lo=-math.pi / 2, hi=math.pi / 2, lo_open=True, hi_open=True, unit="rad")
        check_range("init.yaw", yaw, lo=-2 * math.pi, hi=2 * math.pi, unit="rad")
        check_range("level_time", self.level_time, lo=0.1, hi=600.0, unit="s")
        check_range("gyro_noise", self.gyro_noise, lo=0.0, hi=1.0, lo_open=True, unit="rad/s/sqrt(Hz)")
        check_range("acc_noise", self.acc_noise, lo=0.0, hi=10.0, lo_open=True, unit="m/s2/sqrt(Hz)")
        check_range("gyro_bias_sigma", self.gyro_bias_sigma, lo=0.0, hi=1.0, lo_open=True, unit="rad/s")
        check_range("gyro_bias_tau", self.gyro_bias_tau, lo=1.0, hi=1e6, unit="s")
        check_range("vel_sigma", self.vel_sigma, lo=0.0, hi=100.0, lo_open=True, unit="m/s")
        check_range("pos_sigma", self.pos_sigma, lo=0.0, hi=1000.0, lo_open=True, unit="m")
        check_range("aid_rate", self.aid_rate, lo=0.0, hi=100.0, lo_open=True, unit="Hz")
        check_choice("aid_sizing", self.aid_sizing, AID_SIZINGS)


@dataclass(frozen=True)
class AttitudeResult:
    """Output of one :meth:`AttitudeEstimator.step`.

    Attributes
    ----------
    roll, pitch, yaw : float
        ZYX Euler angles [rad].
    q : tuple of float
        Unit quaternion (w, x, y, z) of R_nb.
    gyro_bias : tuple of float
        Estimated gyro bias [rad/s, b] (z is not observable and stays 0).
    valid : bool
        False while levelling and on a rejected sample.
    warning : str or None
        Why the sample was rejected, if it was.
    """

    roll: float
    pitch: float
    yaw: float
    q: tuple[float, float, float, float]
    gyro_bias: tuple[float, float, float]
    valid: bool
    warning: str | None = None


def integrate_gyro(q: np.ndarray, omega: np.ndarray, dt: float) -> np.ndarray:
    """One exact strapdown step of eq. 6: q ⊗ exp(½ ω Δt), normalised.

    Parameters
    ----------
    q : numpy.ndarray
        (4,) unit quaternion of R_nb at the start of the step.
    omega : numpy.ndarray
        (3,) body angular rate over the step [rad/s, b] (held constant over the step).
    dt : float
        Step [s].

    Returns
    -------
    numpy.ndarray
        (4,) unit quaternion at the end of the step.
    """
    qn = quat_mul(q, quat_from_rotvec(np.asarray(omega) * dt))
    return qn / math.sqrt(qn @ qn)


def integrate_gyro_euler(q: np.ndarray, omega: np.ndarray, dt: float) -> np.ndarray:
    """Paper 000's literal first-order update of eq. 7, q + ½ Ω(ω) q Δt, normalised (kept to
    compare with :func:`integrate_gyro`; its error per step is O((ωΔt)²))."""
    wx, wy, wz = omega
    omat = 0.5 * np.array([[0.0, -wx, -wy, -wz], [wx, 0.0, wz, -wy], [wy, -wz, 0.0, wx], [wz, wy, -wx, 0.0]])
    qn = q + omat @ q * dt
    return qn / math.sqrt(qn @ qn)


def _bad_sample(gyro: np.ndarray, acc: np.ndarray) -> str | None:
    if not (np.all(np.isfinite(gyro)) and np.all(np.isfinite(acc))):
        return "non-finite gyro or acc sample"
    return rate_beyond_limit(gyro) or force_beyond_limit(acc)


class AttitudeEstimator:
    """Attitude (roll, pitch, yaw, quaternion) from gyro and accelerometer samples.

    Parameters
    ----------
    params : AttitudeEstimatorParams
        Validated parameters.

    Examples
    --------
    >>> est = AttitudeEstimator(AttitudeEstimatorParams(init="given"))
    >>> r = est.step([0.0, 0.0, 0.01], [0.0, 0.0, -9.80665], 0.01)
    >>> round(r.yaw, 6)
    0.0001
    """

    def __init__(self, params: AttitudeEstimatorParams | None = None) -> None:
        self.params = params or AttitudeEstimatorParams()
        self.reset()

    def reset(self) -> None:
        """Back to the initial state."""
        p = self.params
        self.q = euler_to_quat(*p.init_euler)
        self.bias = np.zeros(3)
        self.vel = np.zeros(2)
        self.last_gyro: np.ndarray | None = None
        self.last_acc: np.ndarray | None = None
        self.levelling = p.init == "level"
        self.level_steps = 0
        self.level_sum = np.zeros(3)
        self.q_rel = np.array([1.0, 0.0, 0.0, 0.0])
        self.since_aid = 0.0
        self.pos = np.zeros(2)
        self.kf = KalmanFilter(dim_x=8, dim_z=4)
        self.kf.P = np.diag([p.pos_sigma ** 2] * 2 + [p.vel_sigma ** 2] * 2 + [math.radians(2.0) ** 2] * 2
                            + [p.gyro_bias_sigma ** 2] * 2)
        self.kf.H = np.hstack((np.eye(4), np.zeros((4, 4))))
        self.kf.R = np.diag([p.pos_sigma ** 2] * 2 + [p.vel_sigma ** 2] * 2)
        self._q_diag = np.diag([0.0, 0.0] + [p.acc_noise ** 2] * 2 + [0.0] * 4)  # gyro entries below
        # auto sizing: the leaky integrator and its running statistics
        self.acc_mean: np.ndarray | None = None
        self.leak_v = np.zeros(2)
        self.ms_v = np.zeros(2)
        self.stats_weight = 0.0
        self.stats_time = 0.0
        # auto sizing of the gyro noise: the running mean of its second difference
        self.gyro_meter = WhiteNoiseMeter(STATS_TAU)
        self.gyro_noise_used = p.gyro_noise
        self.gyro_bias_sigma_used = p.gyro_bias_sigma
        self._set_gyro_process_noise()

    # ---- step ---------------------------------------------------------------------------------
    def step(self, gyro: Any, acc: Any, dt: float) -> AttitudeResult:
        """Process one sample.

        Parameters
        ----------
        gyro : array_like
            (3,) angular rate at the end of the step [rad/s, b].
        acc : array_like
            (3,) specific force at the end of the step [m/s², b].
        dt : float
            Step [s] (> 0).

        Returns
        -------
        AttitudeResult
            A non-finite or absurd sample is rejected: the last good sample is used instead
            (coasting), ``valid`` is False and ``warning`` says why.
        """
        gyro = np.asarray(gyro, dtype=float)
        acc = np.asarray(acc, dtype=float)
        warning = _bad_sample(gyro, acc)
        if warning is not None:
            log.warning("attitude: %s; coasting on the last good sample", warning)
            if self.last_gyro is None:
                return self._result(False, warning)
            gyro, acc = self.last_gyro, self.last_acc
            self.gyro_meter.break_chain()  # a second difference spans consecutive good samples only
        elif self.params.aid_sizing == "auto":
            self.gyro_meter.push(gyro, dt)
        w_prev = gyro if self.last_gyro is None else self.last_gyro
        omega = 0.5 * (w_prev + gyro) - self.bias
        self.last_gyro, self.last_acc = gyro, acc
        if self.levelling:
            self._level(omega, acc, dt)
            return self._result(False, warning)
        self.q = integrate_gyro(self.q, omega, dt)
        if self.params.mode == 1:
            self._aid(acc, dt)
        return self._result(warning is None, warning)

    def _level(self, omega: np.ndarray, acc: np.ndarray, dt: float) -> None:
        """Accumulate the specific force in the frame of the first sample (gyro-derotated)."""
        if self.level_steps > 0:
            self.q_rel = integrate_gyro(self.q_rel, omega, dt)
        self.level_sum += quat_to_rot(self.q_rel) @ acc
        self.level_steps += 1
        if self.level_steps * dt >= self.params.level_time - 1e-9:
            roll, pitch = level_angles(self.level_sum / self.level_steps)
            q0 = euler_to_quat(roll, pitch, self.params.init_euler[2])
            self.q = quat_mul(q0, self.q_rel)
            self.levelling = False

    def _aid(self, acc: np.ndarray, dt: float) -> None:
        """Velocity- and position-aided tilt and gyro-bias correction (module docstring)."""
        p = self.params
        rot = quat_to_rot(self.q)
        f_n = rot @ acc
        self.pos += self.vel * dt + 0.5 * f_n[:2] * dt * dt  # horizontal a_n = R f_b + g_n has no g
        self.vel += f_n[:2] * dt
        if p.aid_sizing == "auto":
            self._wave_statistics(f_n[:2], dt)
        fz = f_n[2]
        F = np.zeros((8, 8))
        F[0:2, 2:4] = np.eye(2)
        F[2:4, 4:6] = [[0.0, -fz], [fz, 0.0]]  # f_n × ε for ε = [ε_N, ε_E, 0]
        F[4:6, 6:8] = -rot[0:2, 0:2]
        F[6:8, 6:8] = -np.eye(2) / p.gyro_bias_tau
        kf = self.kf
        kf.F = np.eye(8) + F * dt
        kf.Q = self._q_diag * dt
        kf.predict()
        self.since_aid += dt
        if self.since_aid >= 1.0 / p.aid_rate - 1e-9:
            self.since_aid = 0.0
            if p.aid_sizing == "auto" and self.stats_time >= LEAK_TAU:
                sigma_v = np.maximum(SIGMA_V_MIN, AID_GAIN * np.sqrt(self.ms_v / self.stats_weight))
                kf.R = np.diag(np.concatenate(((POS_RATIO * sigma_v) ** 2, sigma_v ** 2)))
            if p.aid_sizing == "auto" and self.gyro_meter.time >= NOISE_SETTLE:
                self._size_gyro_noise(dt)
            kf.update(np.concatenate((self.pos, self.vel)))
            dx = kf.x.ravel()
            self.pos -= dx[0:2]
            self.vel -= dx[2:4]
            self.q = quat_mul(quat_from_rotvec(np.array([dx[4], dx[5], 0.0])), self.q)
            self.q /= math.sqrt(self.q @ self.q)
            self.bias[0:2] += dx[6:8]
            kf.x[:] = 0.0

    def _wave_statistics(self, a_h: np.ndarray, dt: float) -> None:
        """Running mean square of the wave velocity [m/s, n]: the horizontal acceleration
        [m/s², n] less its slow mean, through a leaky integrator (:data:`LEAK_TAU`); exponential
        mean, time constant :data:`STATS_TAU`, its weight 1 − (1 − β)^k kept to correct the start."""
        if self.acc_mean is None:
            self.acc_mean = a_h.copy()
        self.acc_mean += (dt / LEAK_TAU) * (a_h - self.acc_mean)
        self.leak_v += (a_h - self.acc_mean - self.leak_v / LEAK_TAU) * dt
        beta = dt / STATS_TAU
        self.ms_v += beta * (self.leak_v * self.leak_v - self.ms_v)
        self.stats_weight += beta * (1.0 - self.stats_weight)
        self.stats_time += dt

    def _size_gyro_noise(self, dt: float) -> None:
        """The gyro's white-noise density and bias σ from its second difference into the
        process noise (module docstring)."""
        p = self.params
        n_hat = self.gyro_meter.density(dt)
        self.gyro_noise_used = max(GYRO_NOISE_MIN, n_hat)
        self.gyro_bias_sigma_used = p.gyro_bias_sigma * self.gyro_noise_used / p.gyro_noise
        self._set_gyro_process_noise()

    def _set_gyro_process_noise(self) -> None:
        """The gyro's entries of the process-noise density: white noise on ε, Gauss–Markov
        driving noise 2σ_b²/τ_b on the bias."""
        self._q_diag[4, 4] = self._q_diag[5, 5] = self.gyro_noise_used ** 2
        self._q_diag[6, 6] = self._q_diag[7, 7] = 2.0 * self.gyro_bias_sigma_used ** 2 / self.params.gyro_bias_tau

    def _result(self, valid: bool, warning: str | None) -> AttitudeResult:
        roll, pitch, yaw = quat_to_euler(self.q)
        return AttitudeResult(roll, pitch, yaw, tuple(self.q.tolist()), tuple(self.bias.tolist()), valid, warning)

    # ---- FMU state ---------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable internal state (quaternion, bias, velocity, filter, levelling)."""
        return {
            "q": self.q.tolist(), "bias": self.bias.tolist(), "vel": self.vel.tolist(), "pos": self.pos.tolist(),
            "last_gyro": None if self.last_gyro is None else self.last_gyro.tolist(),
            "last_acc": None if self.last_acc is None else self.last_acc.tolist(),
            "levelling": self.levelling, "level_steps": self.level_steps, "level_sum": self.level_sum.tolist(),
            "q_rel": self.q_rel.tolist(), "since_aid": self.since_aid,
            "kf_x": self.kf.x.tolist(), "kf_P": self.kf.P.tolist(), "kf_R": self.kf.R.tolist(),
            "acc_mean": None if self.acc_mean is None else self.acc_mean.tolist(),
            "leak_v": self.leak_v.tolist(), "ms_v": self.ms_v.tolist(),
            "stats_weight": self.stats_weight, "stats_time": self.stats_time,
            "gyro_meter": self.gyro_meter.get_state(), "gyro_noise_used": self.gyro_noise_used,
            "gyro_bias_sigma_used": self.gyro_bias_sigma_used,
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.q = np.array(s["q"])
        self.bias = np.array(s["bias"])
        self.vel = np.array(s["vel"])
        self.pos = np.array(s["pos"])
        self.last_gyro = None if s["last_gyro"] is None else np.array(s["last_gyro"])
        self.last_acc = None if s["last_acc"] is None else np.array(s["last_acc"])
        self.levelling, self.level_steps = bool(s["levelling"]), int(s["level_steps"])
        self.level_sum, self.q_rel = np.array(s["level_sum"]), np.array(s["q_rel"])
        self.since_aid = float(s["since_aid"])
        self.kf.x, self.kf.P, self.kf.R = np.array(s["kf_x"]), np.array(s["kf_P"]), np.array(s["kf_R"])
        self.acc_mean = None if s["acc_mean"] is None else np.array(s["acc_mean"])
        self.leak_v, self.ms_v = np.array(s["leak_v"]), np.array(s["ms_v"])
        self.stats_weight, self.stats_time = float(s["stats_weight"]), float(s["stats_time"])
        self.gyro_meter.set_state(s["gyro_meter"])
        self.gyro_noise_used, self.gyro_bias_sigma_used = float(s["gyro_noise_used"]), float(s["gyro_bias_sigma_used"])
        self._set_gyro_process_noise()


def estimate_attitude(gyro: np.ndarray, acc: np.ndarray, dt: float, params: AttitudeEstimatorParams | None = None) -> dict[str, np.ndarray]:
    """Run :class:`AttitudeEstimator` over whole records.

    Parameters
    ----------
    gyro, acc : numpy.ndarray
        (N, 3) angular rate [rad/s, b] and specific force [m/s², b] at t_k = (k + 1)·dt.
    dt : float
        Sample interval [s].
    params : AttitudeEstimatorParams, optional
        Defaults to :class:`AttitudeEstimatorParams` ().

    Returns
    -------
    dict of numpy.ndarray
        ``roll``, ``pitch``, ``yaw`` (N,) [rad], ``q`` (N, 4), ``valid`` (N,) bool.
    """
    gyro = np.asarray(gyro, dtype=float)
    acc = np.asarray(acc, dtype=float)
    est = AttitudeEstimator(params)
    n = len(gyro)
    euler = np.empty((n, 3))
    quat = np.empty((n, 4))
    valid = np.empty(n, dtype=bool)
    for k in range(n):
        r = est.step(gyro[k], acc[k], dt)
        euler[k] = r.roll, r.pitch, r.yaw
        quat[k] = r.q
        valid[k] = r.valid
    return {"roll": euler[:, 0], "pitch": euler[:, 1], "yaw": euler[:, 2], "q": quat, "valid": valid}
