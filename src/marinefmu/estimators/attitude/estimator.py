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
at ``aid_rate`` feed an error-state Kalman filter (filterpy ``KalmanFilter``'s predict and Joseph-form
update, written out for this filter's F and H: :func:`aid_update`) with states

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
given. A rejected gyro sample (held, see *Bad samples*) does not enter the mean; a good one does, also
beside a rejected accelerometer sample. The initial bias covariance stays
``gyro_bias_sigma``²: it is the prior on the unknown turn-on bias, which the sizing does not
measure (a quiet gyro may still start with a large bias).
**Aid reference** (beyond the paper; what the MotionReferenceUnit's joint filter gives it):
with :attr:`AttitudeEstimator.aid_reference` set to the IMU's horizontal wave position and
velocity in the estimator's frame n, from an estimate that does not use this estimator's tilt,
the pseudo-measurements become "position = reference ± :data:`REFERENCE_POS_SIGMA`, velocity
= reference ± :data:`REFERENCE_VEL_SIGMA`": the wave motion no longer hides the tilt's
velocity ramp, so the aid can be a few centimetres instead of the wave's metres per second,
and the tilt error falls 2-3 × in waves.

Yaw has no aid (no heading sensor): it is the integrated (bias-free-in-x/y) gyro yaw and
drifts with the z-gyro bias.

Initial attitude: given angles (``init="given"``), or levelled from the accelerometer
(``init="level"``): the specific force of the first ``level_time`` seconds is averaged after
rotating each sample back to the start frame with the integrated gyro, so rotation during the
levelling does not blur it; the outputs are not valid until then.

**Bad samples** (a sensor fault: held, flagged, never passed on as NaN). The gyro and the
accelerometer triplet are checked each on its own: non-finite, a rate component beyond
:data:`~marinefmu.estimators.samples.MAX_RATE`, a specific force beyond
:data:`~marinefmu.estimators.samples.MAX_SPECIFIC_FORCE`. A bad triplet is replaced by its
sensor's last good one and a good triplet is used, so a saturated or dropped accelerometer does
not stop the gyro integration, which carries the attitude through an accelerometer gap as
through good samples. A held rate extrapolates the motion: the attitude errs by the rate's
change integrated over the gap (0.2-0.8° after 0.5 s in a 6 m sea, degrees after 2 s). In
mode 1 a bound on that error goes into the tilt's covariance as the gap goes on
(:mod:`~marinefmu.estimators.attitude.gyro_coast`), so the aid trusts its measurements again
and removes it sooner (to within 0.05° of the uninterrupted run: 14-86 s after a 0.5 s gap
in research36's 6 m sea and 20-96 s after a 2 s gap, where the steady gains alone take
49-108 s and 72-587 s), and ``valid`` stays false after the gap until the tilt's and the gyro
bias's variances are back near the uninterrupted filter's (20-91 s after a 0.5 or 2 s gap in
the benchmark's seas, up to 15 s after a 0.1 s one).
A held specific force is kept fixed in frame n (in the levelling frame while levelling),
turned back by each step's gyro rotation: its gravity stays vertical, where held fixed in the
body it would put g × (the angle turned in the gap) into the horizontal acceleration the aid
integrates. The aid goes on integrating and updating through an accelerometer gap: the held
force misses only the change of the horizontal wave acceleration over the gap, while leaving
the acceleration out of the integration misses all of it.
Every step with a bad triplet gives ``valid`` False and a ``warning`` naming the bad sensor and
what is held; a good sample after it is valid again (once levelled, and, after a gyro gap in
mode 1, once recovered: the steps between have no warning, the recovery's start and end are
logged at INFO level).
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import check_choice, check_int, check_range, check_vector
from ...frames import euler_to_quat, half_angle_coefficients, level_angles, quat_mul, quat_to_euler
from ..noise_meter import WhiteNoiseMeter
from ..samples import FORCE_PASS2, MAX_RATE, force_beyond_limit, rate_beyond_limit
from .gyro_coast import RECOVERED, RECOVERED_BIAS, GyroCoast

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
#: Standard deviations of an aid reference's position [m] and velocity [m/s]
#: (:attr:`AttitudeEstimator.aid_reference`): about twice the MotionReferenceUnit's joint
#: filter's real-time error in a 6 m sea; 0.03-0.1 m/s and 0.05-0.3 m moved its roll and pitch
#: by under 30 % (docs/decisions/mru-design.md).
REFERENCE_POS_SIGMA = 0.1
REFERENCE_VEL_SIGMA = 0.05


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
        False while levelling, on a sample with a rejected gyro or accelerometer triplet, and
        (mode 1) after a rejected gyro triplet until the aid has removed the coast error
        (module docstring, *Bad samples*).
    warning : str or None
        For a rejected triplet: which sensor's, why, and what is held, e.g.
        ``"non-finite accelerometer sample: holding the last good accelerometer sample"``;
        None otherwise.
    """

    roll: float
    pitch: float
    yaw: float
    q: tuple[float, float, float, float]
    gyro_bias: tuple[float, float, float]
    valid: bool
    warning: str | None = None


def _quat_step(qw: float, qx: float, qy: float, qz: float, vx: float, vy: float, vz: float) -> tuple[float, float, float, float]:
    """q ⊗ exp(½ v) for the rotation vector v [rad], normalised, on Python floats: the kernel of
    :func:`integrate_gyro` (:func:`~marinefmu.frames.quat_from_rotvec` and
    :func:`~marinefmu.frames.quat_mul` written out, term for term)."""
    s, c = half_angle_coefficients(vx * vx + vy * vy + vz * vz)
    rx, ry, rz = s * vx, s * vy, s * vz
    w = qw * c - qx * rx - qy * ry - qz * rz
    x = qw * rx + qx * c + qy * rz - qz * ry
    y = qw * ry - qx * rz + qy * c + qz * rx
    z = qw * rz + qx * ry - qy * rx + qz * c
    n = math.sqrt(w * w + x * x + y * y + z * z)
    return w / n, x / n, y / n, z / n


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
    qw, qx, qy, qz = (float(v) for v in q)
    wx, wy, wz = (float(v) for v in omega)
    return np.array(_quat_step(qw, qx, qy, qz, wx * dt, wy * dt, wz * dt))


def integrate_gyro_euler(q: np.ndarray, omega: np.ndarray, dt: float) -> np.ndarray:
    """Paper 000's literal first-order update of eq. 7, q + ½ Ω(ω) q Δt, normalised (kept to
    compare with :func:`integrate_gyro`; its error per step is O((ωΔt)²))."""
    wx, wy, wz = omega
    omat = 0.5 * np.array([[0.0, -wx, -wy, -wz], [wx, 0.0, wz, -wy], [wy, -wz, 0.0, wx], [wz, wy, -wx, 0.0]])
    qn = q + omat @ q * dt
    return qn / math.sqrt(qn @ qn)


def aid_update(P: np.ndarray, R: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Kalman update of the error state for the pseudo-measurement z = [p_N, p_E, v_N, v_E]
    of H = [I₄ 0] with a zero prior error state (filterpy ``KalmanFilter.update``, Joseph form,
    with its products by H written as slices: P Hᵀ = P[:, :4], H P Hᵀ = P[:4, :4]).

    Parameters
    ----------
    P : numpy.ndarray
        (8, 8) prior covariance.
    R : numpy.ndarray
        (4, 4) measurement covariance [m², m²/s²].
    z : numpy.ndarray
        (4, 1) the integrated position [m, n] and velocity [m/s, n], which the aid says are 0.

    Returns
    -------
    dx : numpy.ndarray
        (8, 1) posterior error state (K z).
    P : numpy.ndarray
        (8, 8) posterior covariance (I − KH) P (I − KH)ᵀ + K R Kᵀ.
    """
    pht = P[:, :4]
    k = np.dot(pht, np.linalg.inv(pht[:4] + R))
    i_kh = np.eye(8)
    i_kh[:, :4] -= k
    return np.dot(k, z), np.dot(np.dot(i_kh, P), i_kh.T) + np.dot(np.dot(k, R), k.T)


def _bad_sample(gyro: np.ndarray, acc: np.ndarray) -> tuple[str | None, str | None]:
    """Why the (3,) rate ``gyro`` [rad/s] and why the (3,) specific force ``acc`` [m/s²] are
    rejected, each None if it is good: non-finite, or beyond :data:`~marinefmu.estimators.samples.MAX_RATE` or
    :data:`~marinefmu.estimators.samples.MAX_SPECIFIC_FORCE`."""
    bad_gyro = "non-finite gyro sample" if not np.all(np.isfinite(gyro)) else rate_beyond_limit(gyro)
    bad_acc = "non-finite accelerometer sample" if not np.all(np.isfinite(acc)) else force_beyond_limit(acc)
    return bad_gyro, bad_acc


class ErrorStateFilter:
    """The arrays of the error-state Kalman filter: ``x`` (8, 1), zero between steps (each
    update is injected into the nominal state and reset), ``P`` (8, 8) and ``R`` (4, 4)."""

    __slots__ = ("x", "P", "R")

    def __init__(self, P: np.ndarray, R: np.ndarray) -> None:
        self.x = np.zeros((8, 1))
        self.P = P
        self.R = R


class AttitudeEstimator:
    """Attitude (roll, pitch, yaw, quaternion) from gyro and accelerometer samples.

    Cost per step: every step, the quaternion step and the rotation of the specific force on
    Python floats, the horizontal velocity and position, and the covariance prediction
    P ← F P Fᵀ + Q Δt on preallocated (8, 8) arrays (F = I + A Δt changes with R̂ and f_n
    every step, so it has no steady state); F's constant entries and Q Δt are rebuilt only
    when Δt or the gyro's sized noise changes. The error state's prediction is skipped: it is
    zero between updates (F·0 = 0). The gain, the update and the injection run at
    ``aid_rate``. While levelling only the gyro integration and the rotated force sum run.

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
        p = self.params
        self._mode1 = p.mode == 1
        self._auto = p.aid_sizing == "auto"
        self._aid_period = 1.0 / p.aid_rate - 1e-9
        self._bias_decay = -1.0 / p.gyro_bias_tau
        self._F = np.eye(8)
        self._FT = self._F.T                       # a view: F's entries change in place each step
        self._FP = np.empty((8, 8))
        self._z = np.empty((4, 1))
        #: Whether a gyro gap's coast error goes into the covariance and holds ``valid`` until
        #: the aid has removed it (module docstring, *Bad samples*). The MotionReferenceUnit
        #: turns it off: its aid reference comes from a motion filter that carries the coast
        #: error itself after the gap, so the inflated filter would follow it (17° swings after
        #: a 2 s gap), and the unit holds its angles for as long as its motion instead, when
        #: :meth:`GyroCoast.bound <.gyro_coast.GyroCoast.bound>` says the gap can matter.
        self.recover_from_gyro_gaps = True
        self.reset()

    def __setstate__(self, state: dict) -> None:
        """Unpickled or deep-copied: Fᵀ a view of the copy's F again (a copy copies the view's
        data apart, and it would go stale)."""
        self.__dict__.update(state)
        self._FT = self._F.T

    def reset(self) -> None:
        """Back to the initial state."""
        p = self.params
        self._q = tuple(euler_to_quat(*p.init_euler).tolist())
        self._bias = [0.0, 0.0, 0.0]
        self._vel = [0.0, 0.0]
        self._pos = [0.0, 0.0]
        self._last_gyro: tuple[float, float, float] | None = None
        self._last_acc: tuple[float, float, float] | None = None
        self.levelling = p.init == "level"
        self.level_steps = 0
        self._level_sum = [0.0, 0.0, 0.0]
        self._q_rel = (1.0, 0.0, 0.0, 0.0)
        self.since_aid = 0.0
        self.kf = ErrorStateFilter(
            np.diag([p.pos_sigma ** 2] * 2 + [p.vel_sigma ** 2] * 2 + [math.radians(2.0) ** 2] * 2
                    + [p.gyro_bias_sigma ** 2] * 2),
            np.diag([p.pos_sigma ** 2] * 2 + [p.vel_sigma ** 2] * 2))
        self._q_diag = np.diag([0.0, 0.0] + [p.acc_noise ** 2] * 2 + [0.0] * 4)  # gyro entries below
        self._dt: float | None = None  # the Δt that F's constant entries and Q Δt were built for
        self._q_dt = np.zeros((8, 8))
        # auto sizing: the leaky integrator and its running statistics
        self._acc_mean: list[float] | None = None
        self._leak_v = [0.0, 0.0]
        self._ms_v = [0.0, 0.0]
        self.stats_weight = 0.0
        self.stats_time = 0.0
        # auto sizing of the gyro noise: the running mean of its second difference
        self.gyro_meter = WhiteNoiseMeter(STATS_TAU)
        self.gyro_noise_used = p.gyro_noise
        self.gyro_bias_sigma_used = p.gyro_bias_sigma
        self._set_gyro_process_noise()
        #: (p_N, p_E, v_N, v_E) [m, m/s, frame n]: the aid's reference for the next update, or
        #: None for zero (module docstring).
        self.aid_reference: tuple[float, float, float, float] | None = None
        self._referenced = False                 # the last update used a reference
        self.coast = GyroCoast(STATS_TAU)        # a gyro gap's cost to the tilt, and the recovery
        #: Whether the gyro triplet of the last sample with a warning passed (on a step with a
        #: warning: whether the warning is the accelerometer's alone).
        self.gyro_good = True

    # ---- read-only views of the state as arrays ------------------------------------------------
    @property
    def q(self) -> np.ndarray:
        """(4,) unit quaternion (w, x, y, z) of R_nb."""
        return np.array(self._q)

    @property
    def bias(self) -> np.ndarray:
        """(3,) estimated gyro bias [rad/s, b]."""
        return np.array(self._bias)

    @property
    def vel(self) -> np.ndarray:
        """(2,) integrated horizontal velocity [m/s, n] (north, east)."""
        return np.array(self._vel)

    @property
    def pos(self) -> np.ndarray:
        """(2,) integrated horizontal position [m, n] (north, east)."""
        return np.array(self._pos)

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
            The attitude at the end of the step. A non-finite or absurd gyro or accelerometer
            triplet is rejected on its own (module docstring, *Bad samples*): a bad rate is
            replaced by the last good rate, so the attitude coasts on it; a bad specific force by
            the last good one held fixed in frame n, while a good rate beside it is integrated
            as usual (the attitude needs the gyro, the accelerometer only corrects its slow
            drift). ``valid`` is then False and ``warning`` names the bad sensor; after a gyro
            gap ``valid`` stays False until the recovery (module docstring). Before the first
            good sample there is nothing to hold: the state is left as it is.
        """
        gx, gy, gz = gyro
        ax, ay, az = acc
        gx, gy, gz, ax, ay, az = float(gx), float(gy), float(gz), float(ax), float(ay), float(az)
        # NaN fails every comparison, so a non-finite sample takes the full check too
        if (-MAX_RATE <= gx <= MAX_RATE and -MAX_RATE <= gy <= MAX_RATE and -MAX_RATE <= gz <= MAX_RATE
                and ax * ax + ay * ay + az * az <= FORCE_PASS2):
            warning = None
            gyro_good = True
            if self._auto:
                self.gyro_meter.push(np.array((gx, gy, gz)), dt)
        else:
            warning, sample = self._screen(gx, gy, gz, ax, ay, az, dt)
            if sample is None:                       # nothing to hold yet
                return self._result(False, warning)
            gx, gy, gz, ax, ay, az = sample
            gyro_good = self.gyro_good
        last = self._last_gyro
        px, py, pz = (gx, gy, gz) if last is None else last
        bx, by, bz = self._bias
        wx, wy, wz = 0.5 * (px + gx) - bx, 0.5 * (py + gy) - by, 0.5 * (pz + gz) - bz
        self._last_gyro, self._last_acc = (gx, gy, gz), (ax, ay, az)
        if self.levelling:
            self._level(wx, wy, wz, ax, ay, az, dt)
            return self._result(False, warning)
        qw, qx, qy, qz = self._q
        self._q = _quat_step(qw, qx, qy, qz, wx * dt, wy * dt, wz * dt)
        if self._mode1:
            self._aid(ax, ay, az, wx, wy, dt)
            if self.coast.shadow is not None:        # after a gyro gap, until the aid has removed its error
                return self._result(self._recovered(gyro_good) and warning is None, warning)
        return self._result(warning is None, warning)

    def _screen(self, gx: float, gy: float, gz: float, ax: float, ay: float, az: float,
                dt: float) -> tuple[str | None, tuple[float, float, float, float, float, float] | None]:
        """The full check of a sample that failed :meth:`step`'s float comparisons, per sensor.

        Returns
        -------
        warning : str or None
            None if both triplets pass (a specific force inside the float comparisons' margin).
        sample : tuple of float or None
            (ω_x, ω_y, ω_z [rad/s], f_x, f_y, f_z [m/s²], b) to use: a good triplet as given, a
            bad one replaced by its sensor's last good one; None if there is none yet.

        A held specific force is turned back by the step's gyro rotation, so that it stays
        fixed in frame n while the body turns. A good gyro sample goes to the noise meter; a
        bad one breaks its chain (a second difference spans consecutive good samples only).
        """
        bad_gyro, bad_acc = _bad_sample(np.array((gx, gy, gz)), np.array((ax, ay, az)))
        self.gyro_good = bad_gyro is None
        if bad_gyro is None:
            if self._auto:
                self.gyro_meter.push(np.array((gx, gy, gz)), dt)
        else:
            self.gyro_meter.break_chain()
        if bad_gyro is None and bad_acc is None:
            return None, (gx, gy, gz, ax, ay, az)
        held = ("gyro and accelerometer samples" if bad_gyro and bad_acc
                else "gyro sample" if bad_gyro else "accelerometer sample")
        warning = "; ".join(w for w in (bad_gyro, bad_acc) if w) + f": holding the last good {held}"
        log.warning("attitude: %s", warning)
        last = self._last_gyro
        if last is None:
            return warning, None
        if bad_gyro:
            gx, gy, gz = last
            if self._mode1 and not self.levelling:
                self.coast.break_chain()
                if self.recover_from_gyro_gaps:
                    self._coast(dt)
        if bad_acc:
            # Through an accelerometer gap the aid integrates and updates on the last good force
            # held fixed in frame n: it misses only the change of the wave acceleration over the
            # gap. Held fixed in the body its gravity would tilt with the body; left out of the
            # integration it would miss the whole wave acceleration (0.5 s gaps in Hs 6 m: roll
            # and pitch within 1 % of the uninterrupted run's, against +6 % and +20 % on average).
            # f_b ← R(Δq)ᵀ f_b for the step's rotation Δq = exp(½ ω̄ Δt), ω̄ as step integrates it
            bx, by, bz = self._bias
            px, py, pz = last
            w, x, y, z = _quat_step(1.0, 0.0, 0.0, 0.0, -(0.5 * (px + gx) - bx) * dt,
                                    -(0.5 * (py + gy) - by) * dt, -(0.5 * (pz + gz) - bz) * dt)
            fx, fy, fz = self._last_acc
            cx, cy, cz = y * fz - z * fy, z * fx - x * fz, x * fy - y * fx          # u × f
            ax = fx + 2.0 * (w * cx + y * cz - z * cy)                              # f + 2w u×f + 2 u×(u×f)
            ay = fy + 2.0 * (w * cy + z * cx - x * cz)
            az = fz + 2.0 * (w * cz + x * cy - y * cx)
        return warning, (gx, gy, gz, ax, ay, az)

    def _coast(self, dt: float) -> None:
        """One step on a held rate: the tilt's variances in P grow by the coast error's
        (:mod:`~marinefmu.estimators.attitude.gyro_coast`); at the gap's start
        the covariance without the inflation begins as a copy of P."""
        coast = self.coast
        P = self.kf.P
        if coast.shadow is None:
            coast.shadow = P.copy()
        grow = coast.held_step(dt)
        P[4, 4] += grow
        P[5, 5] += grow

    def _recovered(self, gyro_good: bool) -> bool:
        """Whether the tilt's and the x/y gyro bias's variances are back within
        :data:`~.gyro_coast.RECOVERED` and :data:`~.gyro_coast.RECOVERED_BIAS` × their values
        without the last gyro gap's inflation (then the recovery ends, logged)."""
        coast = self.coast
        if not gyro_good:
            return False
        if coast.held:
            log.info("attitude: gyro back after %.3g s on a held rate; roll and pitch are flagged invalid until "
                     "the aid has removed the coast error", coast.held)
            coast.gap_ended()
        P, S = self.kf.P, coast.shadow
        if (P[4, 4] + P[5, 5] > RECOVERED * (S[4, 4] + S[5, 5])
                or P[6, 6] + P[7, 7] > RECOVERED_BIAS * (S[6, 6] + S[7, 7])):
            return False
        coast.shadow = None
        log.info("attitude: recovered from the gyro gap (tilt and gyro bias variances within %g and %g x their values "
                 "without the gap)", RECOVERED, RECOVERED_BIAS)
        return True

    def aid_due(self, dt: float) -> bool:
        """Whether the next step, of ``dt`` s, makes an aid update (the one step that reads
        :attr:`aid_reference`): a caller that sets the reference need compute it only then."""
        return self.since_aid + dt >= self._aid_period

    def _level(self, wx: float, wy: float, wz: float, ax: float, ay: float, az: float, dt: float) -> None:
        """Accumulate the specific force in the frame of the first sample (gyro-derotated)."""
        if self.level_steps > 0:
            qw, qx, qy, qz = self._q_rel
            self._q_rel = _quat_step(qw, qx, qy, qz, wx * dt, wy * dt, wz * dt)
        w, x, y, z = self._q_rel
        s = self._level_sum
        s[0] += (w * w + x * x - y * y - z * z) * ax + 2.0 * (x * y - w * z) * ay + 2.0 * (x * z + w * y) * az
        s[1] += 2.0 * (x * y + w * z) * ax + (w * w - x * x + y * y - z * z) * ay + 2.0 * (y * z - w * x) * az
        s[2] += 2.0 * (x * z - w * y) * ax + 2.0 * (y * z + w * x) * ay + (w * w - x * x - y * y + z * z) * az
        self.level_steps += 1
        if self.level_steps * dt >= self.params.level_time - 1e-9:
            n = self.level_steps
            roll, pitch = level_angles((s[0] / n, s[1] / n, s[2] / n))
            q0 = euler_to_quat(roll, pitch, self.params.init_euler[2])
            self._q = tuple(quat_mul(q0, self._q_rel).tolist())
            self.levelling = False

    def _set_step(self, dt: float) -> None:
        """F's entries that depend on Δt only, and Q Δt."""
        F = self._F
        F[0, 2] = F[1, 3] = dt
        F[6, 6] = F[7, 7] = 1.0 + self._bias_decay * dt
        self._dt = dt
        np.multiply(self._q_diag, dt, out=self._q_dt)

    def _aid(self, ax: float, ay: float, az: float, wx: float, wy: float, dt: float) -> None:
        """Velocity- and position-aided tilt and gyro-bias correction (module docstring);
        ``wx``, ``wy`` the step's bias-corrected horizontal body rates [rad/s] for the rate
        statistics of :class:`~.gyro_coast.GyroCoast`."""
        w, x, y, z = self._q
        ww, xx, yy, zz = w * w, x * x, y * y, z * z
        r00, r01, r02 = ww + xx - yy - zz, 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)
        r10, r11, r12 = 2.0 * (x * y + w * z), ww - xx + yy - zz, 2.0 * (y * z - w * x)
        fn = r00 * ax + r01 * ay + r02 * az
        fe = r10 * ax + r11 * ay + r12 * az
        fz = 2.0 * (x * z - w * y) * ax + 2.0 * (y * z + w * x) * ay + (ww - xx - yy + zz) * az
        pos, vel = self._pos, self._vel
        vn, ve = vel
        pos[0] += vn * dt + 0.5 * fn * dt * dt  # horizontal a_n = R f_b + g_n has no g
        pos[1] += ve * dt + 0.5 * fe * dt * dt
        vel[0] = vn + fn * dt
        vel[1] = ve + fe * dt
        if self._auto:
            self._wave_statistics(fn, fe, dt)
        if dt != self._dt:
            self._set_step(dt)
        # F = I + A Δt: δṗ = δv, δv̇ = f_n × ε for ε = [ε_N, ε_E, 0], ε̇ = −R̂ δb, δḃ = −δb/τ_b
        F = self._F
        F[2, 5] = -fz * dt
        F[3, 4] = fz * dt
        F[4, 6] = -r00 * dt
        F[4, 7] = -r01 * dt
        F[5, 6] = -r10 * dt
        F[5, 7] = -r11 * dt
        kf = self.kf
        P = kf.P
        np.dot(F, P, out=self._FP)
        np.dot(self._FP, self._FT, out=P)
        P += self._q_dt
        shadow = self.coast.shadow
        if shadow is not None:                       # the covariance without a gyro gap's inflation
            shadow[...] = F @ shadow @ self._FT + self._q_dt
        self.since_aid += dt
        if self.since_aid >= self._aid_period:
            self.coast.push(wx, wy, self.since_aid)
            self.since_aid = 0.0
            ref = self.aid_reference
            R = kf.R
            if ref is not None:
                R[0, 0] = R[1, 1] = REFERENCE_POS_SIGMA * REFERENCE_POS_SIGMA
                R[2, 2] = R[3, 3] = REFERENCE_VEL_SIGMA * REFERENCE_VEL_SIGMA
            elif self._auto and self.stats_time >= LEAK_TAU:
                for i in range(2):
                    sigma_v = max(SIGMA_V_MIN, AID_GAIN * math.sqrt(self._ms_v[i] / self.stats_weight))
                    sigma_p = POS_RATIO * sigma_v
                    R[i, i] = sigma_p * sigma_p
                    R[2 + i, 2 + i] = sigma_v * sigma_v
            elif self._referenced:                   # back from a reference to the fixed or starting sizes
                p = self.params
                R[0, 0] = R[1, 1] = p.pos_sigma * p.pos_sigma
                R[2, 2] = R[3, 3] = p.vel_sigma * p.vel_sigma
            self._referenced = ref is not None
            if self._auto and self.gyro_meter.time >= NOISE_SETTLE:
                self._size_gyro_noise(dt)
            zv = self._z
            if ref is None:
                zv[0, 0], zv[1, 0], zv[2, 0], zv[3, 0] = pos[0], pos[1], vel[0], vel[1]
            else:
                zv[0, 0], zv[1, 0], zv[2, 0], zv[3, 0] = pos[0] - ref[0], pos[1] - ref[1], vel[0] - ref[2], vel[1] - ref[3]
            dx, kf.P = aid_update(P, kf.R, zv)
            if shadow is not None:
                shadow[...] = aid_update(shadow, kf.R, zv)[1]
            d = dx[:, 0].tolist()
            pos[0] -= d[0]
            pos[1] -= d[1]
            vel[0] -= d[2]
            vel[1] -= d[3]
            # q ← exp([ε×]) q̂ for ε = [δε_N, δε_E, 0]
            ex, ey = d[4], d[5]
            a2 = ex * ex + ey * ey
            if a2 < 1e-8:
                s = 0.5 - a2 / 48.0
                c = 1.0 - a2 / 8.0 + a2 * a2 / 384.0
            else:
                a = math.sqrt(a2)
                s = math.sin(0.5 * a) / a
                c = math.cos(0.5 * a)
            rx, ry = s * ex, s * ey
            w, x, y, z = self._q
            w, x, y, z = c * w - rx * x - ry * y, c * x + rx * w + ry * z, c * y - rx * z + ry * w, c * z + rx * y - ry * x
            n = math.sqrt(w * w + x * x + y * y + z * z)
            self._q = (w / n, x / n, y / n, z / n)
            self._bias[0] += d[6]
            self._bias[1] += d[7]

    def _wave_statistics(self, an: float, ae: float, dt: float) -> None:
        """Running mean square of the wave velocity [m/s, n]: the horizontal acceleration
        [m/s², n] less its slow mean, through a leaky integrator (:data:`LEAK_TAU`); exponential
        mean, time constant :data:`STATS_TAU`, its weight 1 − (1 − β)^k kept to correct the start."""
        if self._acc_mean is None:
            self._acc_mean = [an, ae]
        m, lv, ms = self._acc_mean, self._leak_v, self._ms_v
        k = dt / LEAK_TAU
        beta = dt / STATS_TAU
        for i, a in ((0, an), (1, ae)):
            m[i] += k * (a - m[i])
            lv[i] += (a - m[i] - lv[i] / LEAK_TAU) * dt
            ms[i] += beta * (lv[i] * lv[i] - ms[i])
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
        driving noise 2σ_b²/τ_b on the bias (and Q Δt from them)."""
        self._q_diag[4, 4] = self._q_diag[5, 5] = self.gyro_noise_used ** 2
        self._q_diag[6, 6] = self._q_diag[7, 7] = 2.0 * self.gyro_bias_sigma_used ** 2 / self.params.gyro_bias_tau
        if self._dt is not None:
            np.multiply(self._q_diag, self._dt, out=self._q_dt)

    def _result(self, valid: bool, warning: str | None) -> AttitudeResult:
        q = self._q
        roll, pitch, yaw = quat_to_euler(q)
        return AttitudeResult(roll, pitch, yaw, q, tuple(self._bias), valid, warning)

    # ---- FMU state ---------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable internal state (quaternion, bias, velocity, filter, levelling)."""
        return {
            "q": list(self._q), "bias": list(self._bias), "vel": list(self._vel), "pos": list(self._pos),
            "last_gyro": None if self._last_gyro is None else list(self._last_gyro),
            "last_acc": None if self._last_acc is None else list(self._last_acc),
            "levelling": self.levelling, "level_steps": self.level_steps, "level_sum": list(self._level_sum),
            "q_rel": list(self._q_rel), "since_aid": self.since_aid,
            "kf_x": self.kf.x.tolist(), "kf_P": self.kf.P.tolist(), "kf_R": self.kf.R.tolist(),
            "acc_mean": None if self._acc_mean is None else list(self._acc_mean),
            "leak_v": list(self._leak_v), "ms_v": list(self._ms_v),
            "stats_weight": self.stats_weight, "stats_time": self.stats_time,
            "gyro_meter": self.gyro_meter.get_state(), "gyro_noise_used": self.gyro_noise_used,
            "gyro_bias_sigma_used": self.gyro_bias_sigma_used,
            "aid_reference": None if self.aid_reference is None else list(self.aid_reference),
            "referenced": self._referenced, "coast": self.coast.get_state(), "gyro_good": self.gyro_good,
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        floats = lambda v: [float(x) for x in v]  # noqa: E731
        self._q = tuple(floats(s["q"]))
        self._bias = floats(s["bias"])
        self._vel = floats(s["vel"])
        self._pos = floats(s["pos"])
        self._last_gyro = None if s["last_gyro"] is None else tuple(floats(s["last_gyro"]))
        self._last_acc = None if s["last_acc"] is None else tuple(floats(s["last_acc"]))
        self.levelling, self.level_steps = bool(s["levelling"]), int(s["level_steps"])
        self._level_sum, self._q_rel = floats(s["level_sum"]), tuple(floats(s["q_rel"]))
        self.since_aid = float(s["since_aid"])
        # x is zero between steps (the update's error is injected and reset)
        self.kf.x = np.zeros((8, 1))
        self.kf.P = np.array(s["kf_P"], dtype=float)
        self.kf.R = np.array(s["kf_R"], dtype=float)
        self._acc_mean = None if s["acc_mean"] is None else floats(s["acc_mean"])
        self._leak_v, self._ms_v = floats(s["leak_v"]), floats(s["ms_v"])
        self.stats_weight, self.stats_time = float(s["stats_weight"]), float(s["stats_time"])
        self.gyro_meter.set_state(s["gyro_meter"])
        self.gyro_noise_used, self.gyro_bias_sigma_used = float(s["gyro_noise_used"]), float(s["gyro_bias_sigma_used"])
        ref = s.get("aid_reference")
        self.aid_reference = None if ref is None else tuple(floats(ref))
        self._referenced = bool(s.get("referenced", False))
        if "coast" in s:                             # a state saved before the coast statistics has none
            self.coast.set_state(s["coast"])
        self.gyro_good = bool(s.get("gyro_good", True))
        self._dt = None
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
