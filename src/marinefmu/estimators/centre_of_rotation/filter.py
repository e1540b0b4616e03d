"""Centre of rotation (CR) of a ship by a Kalman filter with lever-arm states (paper 002,
Zhang, Härting, Ntamba & Schwarz-Röhr).

The CR is the point whose linear acceleration is not affected by the rotations. A sensor at
offset ``o`` from the CR (here o = CR − sensor, body frame, see the design page) reads the specific force

.. math::
    f_b = R_{nb}^T (a_{CR} - g_n) - (α × o + ω × (ω × o))

with a_CR the CR's acceleration in NED, ω_b and α_b the body angular rate and acceleration.
This is paper 002's eq. 11 (``u = R_n^b (a_n + g) + α × r``, eqs. 6-10) converted to our
NED/FRD convention: the paper's frames are z-up/y-port (a rotation of π about x from ours, so
φ, a_x keep their sign, θ, ψ, a_y, a_z flip), its offset r points from the CR to the sensor
(r = −o), and its gravity enters with the opposite sign because its z axis points up
(:func:`eq11_specific_force` is the paper's formula as printed, tested against ours).
Two differences, each selectable:

* **Centripetal term.** The paper's eq. 10 keeps only α × r; the full rigid-body term adds
  ω × (ω × r) (``centripetal=True``, default; ``False`` is the paper's model).
* **Yaw terms.** Eq. 11 as printed also drops the ψ̈ terms of its own eq. 10 and uses the
  Euler-angle accelerations (φ̈, θ̈) in place of the body angular acceleration. We always use the
  full cross product with α_b, the derivative of the body rates (exact; equal to the paper's
  form for small angles and no yaw motion).

**Filter** (eqs. 1-5): state s = [a_CR (N, E, D), o (x, y, z)], a
random walk (F = I, eq. 1) with process-noise densities ``acc_rw`` and ``offset_rw``;
measurement z = f_b + R_nbᵀ g_n = H s with the time-varying H = [R_nbᵀ, −M(ω, α)],
M = [α×] + [ω×]² (eq. 11); Joseph-form covariance update (eq. 5): :func:`joseph_update`, the
operations of filterpy's ``KalmanFilter.update`` (a test checks the two agree).
The offset is identifiable only statistically: the filter finds the point whose acceleration
is uncorrelated with α. Over a finite record the CR's acceleration and the rotation have a
non-zero sample correlation, so even with exact data the estimate scatters about the true CR by
roughly corr · σ(a_CR)/σ(α) (metres for a ship in a 10-minute record; see
:func:`offset_floor`). Two sensors on one rigid body share that error, so their CR estimates
agree far better than either agrees with the truth: paper 002's "internally unique" result.

**Angles** (paper section 3.2, ``angles="gyro_hp"``): the Euler-angle rates T(Θ)ω_b are
integrated through a first-order high-pass of cutoff ``hp_cutoff`` (a leaky integrator
1/(s + ω_c), the integral followed by the high-pass s/(s + ω_c), discretised exactly for a
rate held over the step). The high-pass removes gyro-bias drift but distorts the wave-band
angles (gain 1/√(1 + (ω_c/ω)²), phase lead atan(ω_c/ω)), and the angle error couples gravity
into the horizontal axes. ``angles="input"`` takes roll, pitch, yaw from an attitude estimator
(or truth) instead.

**Angular acceleration** by filtered differentiation of the gyro rates: a centred
Savitzky–Golay derivative over ``diff_window`` seconds (:mod:`.centred_window`); every signal is
taken at the window centre, so the filter runs ``delay`` = diff_window/2 behind the newest
sample, without phase error between α and the accelerations. The paper does not say how it
differentiates.

**Window sized from the data** (``diff_sizing = "auto"``, default). The gyro's white noise,
differentiated into α, is an error in the regressor: it pulls the offset towards the sensor
(errors in variables). Because the a_CR states follow the CR's acceleration within a few
samples (``acc_rw`` against ``acc_sigma``), the offset is told apart from a_CR by what a_CR
cannot follow, the step-to-step change of α × o; so what matters is the noise in the *change*
of α against the change of the true α. The noise gives Δα the variance σ² Σ(Δd)²
(:func:`.centred_window.derivative_increment_gain`, σ² = N²/dt per sample for a gyro of density
N), falling as W⁻⁴ with the window W; the true Δα is α̇ dt. The fraction by which the noise
shrinks offset component i is about r_i(W) = 2σ²Σ(Δd)² / (var Δα_j + var Δα_k) over the two
other axes (measured on polar_supply, Hs 3 m, Tp 10 s, IMU 51 m from the CR: the error is
0.3 r_x at windows of 1.5-3 s, from 6 m at 1.5 s to 0.45 m at 3 s). A longer window loses the
fraction ε(W, ω_j) of the motion at the frequency ω_j = σ(α̇)/σ(α) that carries Δα
(:func:`.centred_window.derivative_gain_error`), which biases the offset the other way (a
small ship in a steep sea: research36, Hs 6 m, Tp 14 s, 0.09 m above the floor at 1.5 s and
0.39 m at 3 s). Every :data:`SIZING_EVERY` s the estimator measures N from the gyro's second
difference (white noise of variance σ² per sample gives 6σ² there; the wave motion adds
(ω dt)⁴ of itself, nothing at 100 Hz), and per axis the variances of α and of Δα less the
parts the present window's noise passes, and sets the window of :data:`WINDOW_CHOICES` that
minimises 0.3 maxᵢ r_i(W) + 2.7 ε(W, ω_j) (the measured weights, :data:`NOISE_WEIGHT`). ``diff_window`` is the window it starts with; ``"fixed"``
keeps it throughout (the filter as before). When the window changes, the centre moves by half
the change: the samples between the old and the new centre are not filtered twice (a longer
window) or are skipped (a shorter one), and ``delay`` follows.

**No rotation** (a vessel in harbour): the offset is observable only through α (and ω), so
with no rotation there is nothing to estimate it from, and a gyro's noise differentiated into α
is then taken for rotation: it pulls the offset towards the sensor (errors in variables) and
shrinks its covariance for no information. So the RMS of |α| over the last
:data:`EXCITATION_TAU` s is compared with :data:`MIN_ANG_ACC`; below it the offset is held (its
columns of H and its covariance with a_CR are zeroed, so the measurements do not move it and
its variance grows only by ``offset_rw``), ``valid`` is false, and a warning saying why is
logged once each time the rotation falls below the bound. In waves α is one to two orders of
magnitude above the bound and nothing changes.

Outputs: the offset and its standard deviation (filter covariance), its running mean after
``settle_time`` (the paper averages "after the Kalman filter has reached a settled state"), the
CR relative to the COG for a sensor at ``sensor`` (COG frame), the specific force a sensor at
the CR would read (acc_cr, body) and the CR's acceleration (NED).

**Cost per step.** Every filtered sample runs the Savitzky–Golay products over the window, the
rotation and H written out in floats, the prediction P + Q (F = I, so no products) and the
Joseph-form update (H changes with every sample, so the covariance has no steady state and is
updated every step); the sample checks, the angle integrator, the running statistics and the
outputs work on plain floats. The window sizing runs every :data:`SIZING_EVERY` s on the
Savitzky–Golay weights computed once per window length (:mod:`.centred_window`). Nothing is
approximated: the float forms are the same expressions as the array forms they stand for, and
the 3 × 3 inverse of the update is written out (:func:`inv3`), equal to rounding.

Not from a library: the Savitzky–Golay weights are scipy's; the update is filterpy's
``KalmanFilter.update`` in the same operations; only the measurement matrix and the leaky angle
integrator are written here.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from filterpy.kalman import KalmanFilter

from ...errors import ParameterTypeError, check_choice, check_range, check_vector
from ...frames import GRAVITY_N, G, body_to_euler_rates, rigid_point_operator
from .centred_window import (CentredWindow, derivative_gain_error, derivative_increment_gain, derivative_noise_gain,
                             window_samples)
from ..noise_meter import WhiteNoiseMeter
from ..samples import (MAX_RATE, MAX_SPECIFIC_FORCE, MAX_TILT, MAX_YAW, angles_beyond_limit, force_beyond_limit,
                       rate_beyond_limit, step_changed)

log = logging.getLogger(__name__)

ANGLE_CHOICES = ("gyro_hp", "input")
DIFF_SIZINGS = ("auto", "fixed")
#: Windows [s] the ``auto`` sizing chooses from (module docstring, "Window sized from the data").
WINDOW_CHOICES = tuple(0.5 * k for k in range(2, 21))
#: Interval of the ``auto`` sizing [s]; the first comes after this much filtered time.
SIZING_EVERY = 60.0
#: Weights of the two errors the window trades, as measured (module docstring): the offset error
#: the noise causes is 0.3 r_x (polar_supply, Hs 3 m, Tp 10 s, IMU far, windows 1.5-3 s) and the
#: one the window's loss causes is 2.7 ε(W, ω_j) (research36, Hs 6 m, Tp 14 s, IMU far, 3 s; more
#: than ε at ω_j because the loss grows as ω⁴ and Δα carries the motion's upper band too).
NOISE_WEIGHT, LOSS_WEIGHT = 0.3, 2.7
#: Memory of the running mean squares of the gyro's second difference, of α and of Δα [s].
NOISE_TAU = 60.0
#: Order of the Savitzky–Golay fit. The derivative's gain error grows as (ωT)^(order): order 2
#: over 0.5 s loses 1 % of α at 0.2 Hz (0.13 m on a 13 m offset), order 4 over the default 1.5 s
#: loses 0.16 % at 0.2 Hz and 0.8 % at 0.3 Hz while averaging the gyro noise enough that it does
#: not shrink the offset (noise in α biases the estimate towards the sensor).
POLYORDER = 4
#: Least RMS angular acceleration |α| [rad/s²] from which the offset is estimated (module
#: docstring, "No rotation"): about 4 times the RMS |α| that the default MEMS gyro's white noise
#: (5e-5 rad/s/√Hz) gives through the default 1.5 s derivative (2.3e-4 rad/s² per axis, 4e-4
#: for the vector, at any sample rate), and under 1/50 of that of a 36 m vessel in a 1.5 m sea
#: (0.058 rad/s², :mod:`marinefmu.papers.paper002`).
MIN_ANG_ACC = 1e-3
#: Memory of the running mean square of |α| that is compared with :data:`MIN_ANG_ACC` [s] ...
EXCITATION_TAU = 30.0
#: ... which is judged once it holds this long [s] of filtered samples (the mean is corrected
#: for its start; a single sample at a zero crossing of α would say nothing).
EXCITATION_MIN = 1.0


@dataclass(frozen=True)
class CentreOfRotationParams:
    """Parameters of :class:`CentreOfRotation` (FMU names in brackets).

    Parameters
    ----------
    angles : str
        ``"gyro_hp"`` high-pass integrated gyro rates (paper section 3.2, default) or
        ``"input"`` roll/pitch/yaw given to :meth:`CentreOfRotation.step`. [``angles``]
    hp_cutoff : float
        Cutoff of the angle high-pass [Hz], (0, 1]. [``hp_cutoff``]
    diff_window : float
        Length of the Savitzky–Golay differentiation window [s], (0, 10]; the estimator runs
        half of it behind the newest sample. With ``diff_sizing = "auto"`` the window it starts
        with. [``diff_window``]
    diff_sizing : str
        ``"auto"`` (default): the window is sized from the gyro's noise and the rotation as the
        estimator runs (module docstring); ``"fixed"``: ``diff_window`` throughout. [``diff_sizing``]
    centripetal : bool
        Include ω × (ω × o) in the lever-arm term (False: the paper's α × r only). [``centripetal``]
    acc_sigma : float
        Standard deviation of one specific-force sample in the measurement model [m/s²],
        (0, 10]: sensor noise plus g times the angle error. [``acc_sigma``]
    acc_rw : float
        Random-walk density of the CR acceleration states [m/s²/√s], (0, 100]. [``acc_rw``]
    offset_rw : float
        Random-walk density of the offset states [m/√s], (0, 10]. [``offset_rw``]
    offset_sigma0 : float
        Initial standard deviation of the offset [m], (0, 1000]. [``offset_sigma0``]
    settle_time : float
        Time after which the offset is averaged [s], [0, 1e6]. [``settle_time``]
    sensor : tuple of float
        Sensor position relative to the COG, body frame [m], to report the CR relative to the
        COG. [``sensor.{x,y,z}``]
    """

    angles: str = "gyro_hp"
    hp_cutoff: float = 0.005
    diff_window: float = 1.5
    diff_sizing: str = "auto"
    centripetal: bool = True
    acc_sigma: float = 0.02
    acc_rw: float = 0.05
    offset_rw: float = 1e-3
    offset_sigma0: float = 10.0
    settle_time: float = 120.0
    sensor: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        check_choice("angles", self.angles, ANGLE_CHOICES)
        check_range("hp_cutoff", self.hp_cutoff, lo=0.0, hi=1.0, lo_open=True, unit="Hz")
        check_range("diff_window", self.diff_window, lo=0.0, hi=10.0, lo_open=True, unit="s")
        check_choice("diff_sizing", self.diff_sizing, DIFF_SIZINGS)
        if not isinstance(self.centripetal, (bool, np.bool_)):
            raise ParameterTypeError(f"centripetal must be True or False, got {self.centripetal!r}")
        check_range("acc_sigma", self.acc_sigma, lo=0.0, hi=10.0, lo_open=True, unit="m/s2")
        check_range("acc_rw", self.acc_rw, lo=0.0, hi=100.0, lo_open=True, unit="m/s2/sqrt(s)")
        check_range("offset_rw", self.offset_rw, lo=0.0, hi=10.0, lo_open=True, unit="m/sqrt(s)")
        check_range("offset_sigma0", self.offset_sigma0, lo=0.0, hi=1000.0, lo_open=True, unit="m")
        check_range("settle_time", self.settle_time, lo=0.0, hi=1e6, unit="s")
        check_vector("sensor", self.sensor, unit="m")


# ---- stateless kernel -----------------------------------------------------------------------
def lever_matrix(omega: Any, alpha: Any, centripetal: bool = True) -> np.ndarray:
    """M with M·o = α × o (+ ω × (ω × o) if ``centripetal``), body frame.

    Parameters
    ----------
    omega : array_like
        (3,) body angular rate [rad/s].
    alpha : array_like
        (3,) body angular acceleration [rad/s²].
    centripetal : bool
        Include the centripetal part [ω×]² (the paper's eq. 10 omits it).
    """
    w = list(omega) if centripetal else [0.0, 0.0, 0.0]
    return rigid_point_operator(w, list(alpha))[6:9]


def measurement_matrix(rot: np.ndarray, omega: Any, alpha: Any, centripetal: bool = True) -> np.ndarray:
    """(3, 6) H of eq. 11 in NED/FRD: z = f_b + R_nbᵀ g_n = H [a_CR; o].

    Parameters
    ----------
    rot : numpy.ndarray
        (3, 3) R_nb.
    omega, alpha : array_like
        (3,) body angular rate [rad/s] and acceleration [rad/s²].
    centripetal : bool
        See :func:`lever_matrix`.
    """
    return np.hstack((rot.T, -lever_matrix(omega, alpha, centripetal)))


def predicted_specific_force(rot: np.ndarray, acc_cr: Any, offset: Any, omega: Any, alpha: Any,
                             centripetal: bool = True) -> np.ndarray:
    """Specific force at a sensor whose CR is at ``offset`` [m, b]: R_nbᵀ (a_CR − g_n) − M o [m/s², b].

    Parameters
    ----------
    rot : numpy.ndarray
        (3, 3) R_nb.
    acc_cr : array_like
        (3,) acceleration of the CR [m/s², NED].
    offset : array_like
        (3,) CR relative to the sensor [m, b].
    omega, alpha : array_like
        (3,) body angular rate [rad/s] and acceleration [rad/s²].
    centripetal : bool
        See :func:`lever_matrix`.
    """
    s = np.concatenate((np.asarray(acc_cr, dtype=float), np.asarray(offset, dtype=float)))
    return measurement_matrix(rot, omega, alpha, centripetal) @ s - rot.T @ GRAVITY_N


def eq11_specific_force(euler: Any, euler_ddot: Any, acc_n: Any, r: Any, g: float = G) -> np.ndarray:
    """Paper 002's eq. 11 exactly as printed, in the paper's frames (x bow, y port, z up).

    Parameters
    ----------
    euler : array_like
        Paper roll, pitch, yaw [rad] (eqs. 7-9).
    euler_ddot : array_like
        φ̈, θ̈, ψ̈ [rad/s²] (ψ̈ is unused: eq. 11 drops it).
    acc_n : array_like
        (ax_n, ay_n, az_n): acceleration of the CR in the paper's earth frame [m/s²].
    r : array_like
        (r_x, r_y, r_z): offset of the sensor from the CR, paper body frame [m].
    g : float
        Gravity [m/s²].

    Returns
    -------
    numpy.ndarray
        (ax_sensor, ay_sensor, az_sensor) [m/s²], paper body frame.
    """
    f, t, p = euler
    fdd, tdd, _ = euler_ddot
    ax, ay, az = acc_n
    rx, ry, rz = r
    sf, cf, st, ct, sp, cp = math.sin(f), math.cos(f), math.sin(t), math.cos(t), math.sin(p), math.cos(p)
    return np.array([
        ax * ct * cp + ay * ct * sp - az * st - g * st + rz * tdd,
        ax * (sf * st * cp - cf * sp) + ay * (sf * st * sp + cf * cp) + az * sf * ct + g * sf * ct - rz * fdd,
        ax * (cf * st * cp + sf * sp) + ay * (cf * st * sp - sf * cp) + az * cf * ct + g * cf * ct + ry * fdd - rx * tdd,
    ])


def offset_floor(acc_cr: np.ndarray, rot: np.ndarray, omega: np.ndarray, alpha: np.ndarray,
                 centripetal: bool = True) -> np.ndarray:
    """Offset error that the sample correlation of the CR acceleration with the rotation alone
    causes over a record [m, b]: the floor of any estimator built on their independence.

    With exact data, z_k = R_kᵀ a_CR,k − M_k o. The filter's random-walk model of a_CR (eq. 1)
    with a small measurement noise makes it, in effect, a least-squares fit of the *increments*
    Δz_k on −ΔM_k, so its offset settles at o − (Σ ΔMᵀΔM)⁻¹ Σ ΔMᵀ Δ(Rᵀ a_CR): this function
    returns that error term. It vanishes only as the sample correlation averages out (slowly:
    with the line spectra of a simulated sea, not even as 1/√T).

    Parameters
    ----------
    acc_cr : numpy.ndarray
        (N, 3) true acceleration of the CR [m/s², NED].
    rot : numpy.ndarray
        (N, 3, 3) true R_nb.
    omega, alpha : numpy.ndarray
        (N, 3) true body angular rate [rad/s] and acceleration [rad/s²].
    centripetal : bool
        See :func:`lever_matrix`.

    Returns
    -------
    numpy.ndarray
        (3,) estimate minus true offset [m, b].
    """
    m = np.diff(np.array([lever_matrix(w, a, centripetal) for w, a in zip(omega, alpha)]), axis=0)
    b = np.diff(np.einsum("kji,kj->ki", rot, acc_cr), axis=0)
    return -np.linalg.lstsq(m.reshape(-1, 3), b.reshape(-1), rcond=None)[0]


def leaky_angle_step(euler: list[float], rate: list[float], dt: float, cutoff: float) -> list[float]:
    """One step of the high-pass angle integrator (paper section 3.2): Θ̇ = T(Θ)ω − ω_c Θ,
    exact for the Euler rate held over the step.

    Parameters
    ----------
    euler : list of float
        [φ, θ, ψ] at the start of the step [rad].
    rate : list of float
        Body angular rate over the step [rad/s].
    dt : float
        Step [s].
    cutoff : float
        High-pass cutoff [Hz].
    """
    wc = 2.0 * math.pi * cutoff
    decay = math.exp(-wc * dt)
    gain = -math.expm1(-wc * dt) / wc
    return [decay * e + gain * d for e, d in zip(euler, body_to_euler_rates(euler, rate))]


_EYE6 = np.eye(6)


def inv3(m: np.ndarray, diag: float = 0.0) -> np.ndarray:
    """Inverse of the (3, 3) matrix ``m`` + ``diag`` · I by its adjugate over its determinant
    (for the innovation covariance H P Hᵀ + R, symmetric positive definite; ``numpy.linalg.inv``
    costs several times more in call overhead at this size)."""
    (a, b, c), (d, e, f), (g, h, i) = m.tolist()
    a, e, i = a + diag, e + diag, i + diag
    c0, c1, c2 = e * i - f * h, f * g - d * i, d * h - e * g
    r = 1.0 / (a * c0 + b * c1 + c * c2)
    return np.array(((c0 * r, (c * h - b * i) * r, (b * f - c * e) * r),
                     (c1 * r, (a * i - c * g) * r, (c * d - a * f) * r),
                     (c2 * r, (b * g - a * h) * r, (a * e - b * d) * r)))


def joseph_update(x: np.ndarray, P: np.ndarray, H: np.ndarray, z: np.ndarray,
                  r_var: float) -> tuple[np.ndarray, np.ndarray]:
    r"""Kalman measurement update with the Joseph-form covariance (paper 002, eq. 5) for the
    measurement noise R = ``r_var`` · I:

    .. math::
        K = P H^T (H P H^T + R)^{-1},\quad x^+ = x + K (z - H x),\quad
        P^+ = (I - K H) P (I - K H)^T + K R K^T

    The operations of filterpy's ``KalmanFilter.update`` in the same order and shapes, without
    its bookkeeping copies (the adds of R's zeros are left out: they change nothing), and with
    the 3 × 3 inverse written out (:func:`inv3`; ``numpy.linalg.inv`` for other sizes): the same
    result to rounding.

    Parameters
    ----------
    x : numpy.ndarray
        (n, 1) state.
    P : numpy.ndarray
        (n, n) covariance (not changed).
    H : numpy.ndarray
        (m, n) measurement matrix.
    z : numpy.ndarray
        (m, 1) measurement.
    r_var : float
        Variance of each measurement.

    Returns
    -------
    tuple of numpy.ndarray
        New x (n, 1) and P (n, n).
    """
    y = z - np.dot(H, x)
    pht = np.dot(P, H.T)
    s = np.dot(H, pht)
    if s.shape == (3, 3):
        si = inv3(s, r_var)
    else:
        s.flat[::s.shape[0] + 1] += r_var
        si = np.linalg.inv(s)
    k = np.dot(pht, si)
    x = x + np.dot(k, y)
    ikh = (_EYE6 if P.shape[0] == 6 else np.eye(P.shape[0])) - np.dot(k, H)
    return x, np.dot(np.dot(ikh, P), ikh.T) + np.dot(k * r_var, k.T)


# ---- stateful estimator ---------------------------------------------------------------------
@dataclass(frozen=True)
class CentreOfRotationResult:
    """Output of one :meth:`CentreOfRotation.step` (all at ``delay`` before the newest sample).

    Attributes
    ----------
    offset, offset_std, offset_mean : tuple of float
        CR relative to the sensor, its standard deviation, and its running mean after
        ``settle_time`` (the current estimate before) [m, b].
    cr : tuple of float
        CR relative to the COG from the mean offset: ``sensor + offset_mean`` [m, b].
    acc_cr : tuple of float
        Specific force a sensor at the CR would read [m/s², b].
    acc_cr_n : tuple of float
        Acceleration of the CR [m/s², NED] (the filter's a_CR states).
    euler : tuple of float
        Roll, pitch, yaw used [rad].
    ang_acc : tuple of float
        Angular acceleration used [rad/s², b].
    delay : float
        How far the estimate lags the newest sample [s].
    valid : bool
        Window full, the sample good, and enough rotation to observe the offset
        (:data:`MIN_ANG_ACC`).
    settled : bool
        ``settle_time`` has passed, so ``offset_mean`` is an average.
    warning : str or None
        Why the sample was rejected, if it was.
    """

    offset: tuple[float, float, float]
    offset_std: tuple[float, float, float]
    offset_mean: tuple[float, float, float]
    cr: tuple[float, float, float]
    acc_cr: tuple[float, float, float]
    acc_cr_n: tuple[float, float, float]
    euler: tuple[float, float, float]
    ang_acc: tuple[float, float, float]
    delay: float
    valid: bool
    settled: bool
    warning: str | None = None


def _bad_sample(acc: Any, gyro: Any, euler: Any) -> str | None:
    acc, gyro = np.asarray(acc, dtype=float), np.asarray(gyro, dtype=float)
    if not (np.all(np.isfinite(acc)) and np.all(np.isfinite(gyro))):
        return "non-finite acc or gyro sample"
    if euler is not None:
        euler = np.asarray(euler, dtype=float)
        if not np.all(np.isfinite(euler)):
            return "non-finite roll, pitch or yaw input"
        if reason := angles_beyond_limit(euler):
            return f"{reason} (input)"
    return rate_beyond_limit(gyro) or force_beyond_limit(acc)


#: Squared specific force [m²/s⁴] below which :func:`force_beyond_limit` cannot fire, whatever the
#: rounding of its norm.
_FORCE_SQ_PLAIN = (MAX_SPECIFIC_FORCE * (1.0 - 1e-9)) ** 2


def _plainly_good(acc: list[float], gyro: list[float], euler: list[float] | None) -> bool:
    """True if :func:`_bad_sample` would pass the sample, by float comparisons only (the per-step
    test); False sends the sample to :func:`_bad_sample` for the verdict and its reason. A
    non-finite value makes the sum non-finite; a finite sum that overflows goes to the full check."""
    a0, a1, a2 = acc
    g0, g1, g2 = gyro
    total = a0 + a1 + a2 + g0 + g1 + g2
    if euler is not None:
        e0, e1, e2 = euler
        total += e0 + e1 + e2
        if max(abs(e0), abs(e1)) > MAX_TILT or abs(e2) > MAX_YAW:
            return False
    return (math.isfinite(total) and max(abs(g0), abs(g1), abs(g2)) <= MAX_RATE
            and a0 * a0 + a1 * a1 + a2 * a2 < _FORCE_SQ_PLAIN)


class CentreOfRotation:
    """Kalman estimate of the CR offset from a strapdown IMU (module docstring).

    Parameters
    ----------
    params : CentreOfRotationParams, optional
        Validated parameters (defaults if omitted).

    Examples
    --------
    >>> est = CentreOfRotation(CentreOfRotationParams(diff_window=0.04))
    >>> r = est.step([0.0, 0.0, -9.80665], [0.0, 0.0, 0.0], 0.01)
    >>> r.valid, r.delay     # filling the differentiation window (its shortest, 7 samples)
    (False, 0.03)
    """

    def __init__(self, params: CentreOfRotationParams | None = None) -> None:
        self.params = params or CentreOfRotationParams()
        self.reset()

    def reset(self) -> None:
        """Back to the initial state."""
        p = self.params
        self.dt: float | None = None
        self.window: CentredWindow | None = None
        self.euler = [0.0, 0.0, 0.0]
        # the last good (acc, gyro, angles or None) as lists of floats
        self.last: tuple[list[float], list[float], list[float] | None] | None = None
        self.filtered_time = 0.0
        self.mean_sum = [0.0, 0.0, 0.0]
        self.mean_count = 0
        # running mean square of |α| [rad²/s⁴], its start-corrected weight, the time it holds [s],
        # and whether the offset is held for want of rotation (module docstring, "No rotation")
        self.alpha_ms = 0.0
        self.alpha_weight = 0.0
        self.alpha_time = 0.0
        self.unobservable = False
        # auto window sizing: the gyro's noise from its second difference; per axis the running
        # mean squares of α [(rad/s²)²] and of its
        # step-to-step change Δα with their weight, the last α (None after a break); the window
        # [s] in use, the filtered time at the next sizing [s], and centre samples still to skip
        self.gyro_meter = WhiteNoiseMeter(NOISE_TAU)
        self.ms_alpha = [0.0, 0.0, 0.0]
        self.ms_dalpha = [0.0, 0.0, 0.0]
        self.alpha_stats_weight = 0.0
        self.prev_alpha: list[float] | None = None
        self.window_s = p.diff_window
        self.next_sizing = SIZING_EVERY
        self.skip = 0
        # filterpy's KalmanFilter holds the state s = [a_CR; o] (x, (6, 1)), P, Q (set with the
        # step, _start), R and H (written in full every filtered step); the update is
        # joseph_update, the same operations as kf.update; z is a work array
        self.kf = KalmanFilter(dim_x=6, dim_z=3)
        self.kf.P = np.diag([1.0] * 3 + [p.offset_sigma0 ** 2] * 3)
        self.r_var = p.acc_sigma ** 2
        self.kf.R = np.eye(3) * self.r_var
        self._z = np.zeros((3, 1))
        self._result = self._output(self.kf.x[:, 0].tolist(), [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], False, None)

    def _start(self, dt: float) -> None:
        p = self.params
        self.dt = dt
        capacity = None
        if p.diff_sizing == "auto":
            capacity = max(window_samples(w, dt, POLYORDER) for w in WINDOW_CHOICES + (self.window_s,))
        self.window = CentredWindow(9, window_samples(self.window_s, dt, POLYORDER), dt, POLYORDER, capacity)
        self.skip = 0
        self.kf.Q = np.diag([p.acc_rw ** 2 * dt] * 3 + [p.offset_rw ** 2 * dt] * 3)

    def step(self, acc: Any, gyro: Any, dt: float, euler: Any = None) -> CentreOfRotationResult:
        """Process one sample.

        Parameters
        ----------
        acc : array_like
            (3,) specific force at the sensor at the end of the step [m/s², b].
        gyro : array_like
            (3,) angular rate at the end of the step [rad/s, b].
        dt : float
            Step [s] (> 0, constant; a change restarts the differentiation window).
        euler : array_like, optional
            Roll, pitch, yaw [rad] for ``angles="input"`` (ignored otherwise).

        Returns
        -------
        CentreOfRotationResult
            Refers to ``delay`` s before this sample. A non-finite or absurd sample is replaced
            by the last good one (hold): ``valid`` is False and ``warning`` says why.
        """
        p = self.params
        a0, a1, a2 = acc
        g0, g1, g2 = gyro
        acc = [float(a0), float(a1), float(a2)]
        gyro = [float(g0), float(g1), float(g2)]
        ang = None
        if p.angles == "input":
            try:
                e0, e1, e2 = euler
                ang = [float(e0), float(e1), float(e2)]
            except (TypeError, ValueError):
                ang = [math.nan, math.nan, math.nan]
        warning = None if _plainly_good(acc, gyro, ang) else _bad_sample(acc, gyro, ang)
        if warning is not None:
            log.warning("centre of rotation: %s; holding the last good sample", warning)
            if self.last is None:
                return self._invalid(warning)
            acc, gyro, ang = self.last
        if self.dt is not None and step_changed(self.dt, dt):
            warning = f"step size changed from {self.dt} s to {dt} s; differentiation window restarted"
            log.warning("centre of rotation: %s", warning)
            self.dt = None
        prev = self.last
        self.last = (acc, gyro, ang)
        if self.dt is None:
            self._start(dt)
        if ang is None:
            rate = gyro if prev is None else [0.5 * (g + q) for g, q in zip(gyro, prev[1])]
            self.euler = ang = leaky_angle_step(self.euler, rate, dt, p.hp_cutoff)
        if p.diff_sizing == "auto":
            if warning is None:
                self.gyro_meter.push(np.array(gyro), dt)
            else:
                self.gyro_meter.break_chain()
        centre = self.window.push(gyro + acc + ang)
        if centre is None:
            return self._invalid(warning)
        if self.skip > 0:
            # the window grew: this centre sample was filtered before the change
            self.skip -= 1
            return self._invalid(warning)
        raw, smooth, deriv = centre
        raw = raw.tolist()
        wx, wy, wz = smooth[0:3].tolist() if p.centripetal else (0.0, 0.0, 0.0)
        alpha = deriv[0:3].tolist()
        f_b, angles = raw[3:6], raw[6:9]
        observable = self._excitation(alpha, dt)
        if p.diff_sizing == "auto":
            self._alpha_statistics(alpha if warning is None else None, dt)
        # R_nb (frames.rot_nb) and H = [R_nbᵀ, −M] (measurement_matrix), written out in floats
        cf, sf = math.cos(angles[0]), math.sin(angles[0])
        ct, st = math.cos(angles[1]), math.sin(angles[1])
        cp, sp = math.cos(angles[2]), math.sin(angles[2])
        ax, ay, az = alpha
        if observable:
            m = ((-wy * wy - wz * wz, wx * wy - az, wx * wz + ay),
                 (wx * wy + az, -wx * wx - wz * wz, wy * wz - ax),
                 (wx * wz - ay, wy * wz + ax, -wx * wx - wy * wy))
        else:
            # no rotation: the offset is held (module docstring, "No rotation"); without its
            # covariance with a_CR the a_CR innovations do not move it either
            m = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        m0, m1, m2 = m
        r20, r21, r22 = -st, ct * sf, ct * cf
        kf = self.kf
        H = kf.H
        H[:] = ((cp * ct, sp * ct, r20, -m0[0], -m0[1], -m0[2]),
                (cp * st * sf - sp * cf, sp * st * sf + cp * cf, r21, -m1[0], -m1[1], -m1[2]),
                (cp * st * cf + sp * sf, sp * st * cf - cp * sf, r22, -m2[0], -m2[1], -m2[2]))
        # z = f_b + R_nbᵀ g_n: g_n = (0, 0, g) picks R_nb's last row
        z = self._z
        z[:, 0] = (f_b[0] + r20 * G, f_b[1] + r21 * G, f_b[2] + r22 * G)
        P = kf.P
        P += kf.Q                                             # predict: F = I (eq. 1)
        if not observable:
            P[0:3, 3:6] = P[3:6, 0:3] = 0.0
        kf.x, kf.P = joseph_update(kf.x, P, H, z, self.r_var)
        self.filtered_time += dt
        s = kf.x[:, 0].tolist()
        if self.filtered_time >= p.settle_time - 1e-9:
            ms = self.mean_sum
            ms[0] += s[3]
            ms[1] += s[4]
            ms[2] += s[5]
            self.mean_count += 1
        # what a sensor at the CR would read: f_b + M o
        o0, o1, o2 = s[3:6]
        acc_cr = [f_b[0] + (m0[0] * o0 + m0[1] * o1 + m0[2] * o2),
                  f_b[1] + (m1[0] * o0 + m1[1] * o1 + m1[2] * o2),
                  f_b[2] + (m2[0] * o0 + m2[1] * o1 + m2[2] * o2)]
        self._result = self._output(s, acc_cr, alpha, angles, warning is None and observable, warning)
        if p.diff_sizing == "auto" and self.filtered_time >= self.next_sizing - 1e-9:
            self.next_sizing += SIZING_EVERY
            self._size_window(dt)
        return self._result

    def _alpha_statistics(self, alpha: list[float] | None, dt: float) -> None:
        """Running mean squares per axis of α and of its change since the last filtered sample
        [(rad/s²)²], start-corrected weight; a held sample (None) breaks the chain."""
        prev, self.prev_alpha = self.prev_alpha, alpha
        if alpha is None or prev is None:
            return
        beta = dt / NOISE_TAU
        ms, md = self.ms_alpha, self.ms_dalpha
        for i in range(3):
            a = alpha[i]
            d = a - prev[i]
            ms[i] += beta * (a * a - ms[i])
            md[i] += beta * (d * d - md[i])
        self.alpha_stats_weight += beta * (1.0 - self.alpha_stats_weight)

    def _size_window(self, dt: float) -> None:
        """Set the window of :data:`WINDOW_CHOICES` minimising the weighted r and ε (module
        docstring); no change while the rotation is too weak to say (harbour) or unmeasured."""
        if self.unobservable or self.alpha_stats_weight <= 0.0 or self.gyro_meter.weight <= 0.0:
            return
        sigma2 = self.gyro_meter.variance                             # gyro white noise per sample [(rad/s)²]
        n_now = self.window.n
        var_a = np.array(self.ms_alpha) / self.alpha_stats_weight - sigma2 * derivative_noise_gain(n_now, dt, POLYORDER)
        var_da = np.array(self.ms_dalpha) / self.alpha_stats_weight - sigma2 * derivative_increment_gain(n_now, dt, POLYORDER)
        if not (np.all(np.isfinite(var_da)) and var_a.sum() > 0.0 and var_da.sum() > 0.0):
            return
        omega_j = math.sqrt(var_da.sum() / var_a.sum()) / dt          # σ(α̇)/σ(α) [rad/s]
        pairs = np.maximum(np.array([var_da[1] + var_da[2], var_da[0] + var_da[2], var_da[0] + var_da[1]]), 1e-300)
        best_cost, best = math.inf, self.window_s
        for w in WINDOW_CHOICES:
            n = window_samples(w, dt, POLYORDER)
            cost = (NOISE_WEIGHT * float(np.max(2.0 * sigma2 * derivative_increment_gain(n, dt, POLYORDER) / pairs))
                    + LOSS_WEIGHT * derivative_gain_error(n, dt, POLYORDER, omega_j))
            if cost < best_cost - 1e-12:
                best_cost, best = cost, w
        n_new = window_samples(best, dt, POLYORDER)
        self.window_s = best
        if n_new == n_now:
            return
        log.info("centre of rotation: differentiation window %.2f s → %.2f s (gyro noise %.2g rad/s/√Hz, "
                 "RMS α̇ %s rad/s³, α at %.3f Hz)", (n_now - 1) * dt, (n_new - 1) * dt, math.sqrt(sigma2 * dt),
                 np.array2string(np.sqrt(np.maximum(var_da, 0.0)) / dt, precision=2), omega_j / (2 * math.pi))
        self.skip = max(0, (n_new - n_now) // 2)
        self.prev_alpha = None
        self.window.resize(n_new)

    def _excitation(self, alpha: list[float], dt: float) -> bool:
        """Update the running mean square of |α| [rad/s²] and say whether the rotation is enough
        to observe the offset (:data:`MIN_ANG_ACC`); log when it stops being enough."""
        beta = dt / EXCITATION_TAU
        self.alpha_ms += beta * (alpha[0] * alpha[0] + alpha[1] * alpha[1] + alpha[2] * alpha[2] - self.alpha_ms)
        self.alpha_weight += beta * (1.0 - self.alpha_weight)
        self.alpha_time += dt
        if self.alpha_time < EXCITATION_MIN - 1e-9:
            return True
        rms = math.sqrt(self.alpha_ms / self.alpha_weight)
        if rms < MIN_ANG_ACC and not self.unobservable:
            log.warning("centre of rotation: no rotation to observe the offset by (RMS angular acceleration "
                        "%.2g rad/s² over the last %g s < %g): offset held, valid = false", rms, EXCITATION_TAU,
                        MIN_ANG_ACC)
        elif rms >= MIN_ANG_ACC and self.unobservable:
            log.info("centre of rotation: rotation again (RMS angular acceleration %.2g rad/s²): offset estimated",
                     rms)
        self.unobservable = rms < MIN_ANG_ACC
        return not self.unobservable

    def _invalid(self, warning: str | None) -> CentreOfRotationResult:
        return replace(self._result, delay=self.delay, valid=False, warning=warning)

    @property
    def delay(self) -> float:
        """Lag of the estimate behind the newest sample [s] (half the differentiation window)."""
        return self.window.delay if self.window is not None else 0.0

    def _output(self, s: list[float], acc_cr: list[float], alpha: list[float], angles: list[float], valid: bool,
                warning: str | None) -> CentreOfRotationResult:
        """The result from the state ``s`` (6 floats) and this step's signals."""
        offset = tuple(s[3:6])
        P = self.kf.P
        std = (math.sqrt(P[3, 3]), math.sqrt(P[4, 4]), math.sqrt(P[5, 5]))
        n = self.mean_count
        mean = tuple(v / n for v in self.mean_sum) if n else offset
        sensor = self.params.sensor
        return CentreOfRotationResult(
            offset, std, mean, (sensor[0] + mean[0], sensor[1] + mean[1], sensor[2] + mean[2]), tuple(acc_cr),
            tuple(s[0:3]), tuple(angles), tuple(alpha), self.delay, valid, n > 0, warning,
        )

    # ---- FMU state ---------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable internal state."""
        last = None if self.last is None else [None if v is None else list(v) for v in self.last]
        return {
            "dt": self.dt, "window": None if self.window is None else self.window.get_state(),
            "euler": list(self.euler), "last": last, "filtered_time": self.filtered_time,
            "mean_sum": list(self.mean_sum), "mean_count": self.mean_count,
            "kf_x": self.kf.x.tolist(), "kf_P": self.kf.P.tolist(),
            "alpha_ms": self.alpha_ms, "alpha_weight": self.alpha_weight, "alpha_time": self.alpha_time,
            "unobservable": self.unobservable,
            "gyro_meter": self.gyro_meter.get_state(), "ms_alpha": list(self.ms_alpha), "ms_dalpha": list(self.ms_dalpha),
            "alpha_stats_weight": self.alpha_stats_weight,
            "prev_alpha": None if self.prev_alpha is None else list(self.prev_alpha),
            "window_s": self.window_s, "next_sizing": self.next_sizing, "skip": self.skip,
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        floats = lambda v: [float(a) for a in v]  # noqa: E731
        self.reset()
        self.window_s = float(s["window_s"])
        if s["dt"] is not None:
            self._start(float(s["dt"]))
            self.window.set_state(s["window"])
        self.euler = floats(s["euler"])
        self.last = None if s["last"] is None else tuple(None if v is None else floats(v) for v in s["last"])
        self.filtered_time = float(s["filtered_time"])
        self.mean_sum, self.mean_count = floats(s["mean_sum"]), int(s["mean_count"])
        self.kf.x = np.array(s["kf_x"], dtype=float).reshape(6, 1)
        self.kf.P = np.array(s["kf_P"], dtype=float).reshape(6, 6)
        self.alpha_ms, self.alpha_weight = float(s["alpha_ms"]), float(s["alpha_weight"])
        self.alpha_time, self.unobservable = float(s["alpha_time"]), bool(s["unobservable"])
        self.gyro_meter.set_state(s["gyro_meter"])
        self.ms_alpha, self.ms_dalpha = floats(s["ms_alpha"]), floats(s["ms_dalpha"])
        self.alpha_stats_weight = float(s["alpha_stats_weight"])
        self.prev_alpha = None if s["prev_alpha"] is None else floats(s["prev_alpha"])
        self.next_sizing, self.skip = float(s["next_sizing"]), int(s["skip"])

def estimate_centre_of_rotation(acc: np.ndarray, gyro: np.ndarray, dt: float,
                                params: CentreOfRotationParams | None = None,
                                euler: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Run :class:`CentreOfRotation` over whole records.

    Parameters
    ----------
    acc, gyro : numpy.ndarray
        (N, 3) specific force [m/s², b] and angular rate [rad/s, b] at t_k = (k + 1)·dt.
    dt : float
        Sample interval [s].
    params : CentreOfRotationParams, optional
        Defaults to :class:`CentreOfRotationParams` ().
    euler : numpy.ndarray, optional
        (N, 3) roll, pitch, yaw [rad] for ``angles="input"``.

    Returns
    -------
    dict of numpy.ndarray
        ``offset``, ``offset_std``, ``offset_mean``, ``cr``, ``acc_cr``, ``acc_cr_n``, ``euler``,
        ``ang_acc`` (N, 3); ``valid``, ``settled`` (N,) bool; ``delay`` (N,) [s]. Row k refers
        to the time t_k − delay[k] (the delay follows the window, which ``diff_sizing = "auto"``
        resizes).
    """
    acc = np.asarray(acc, dtype=float)
    gyro = np.asarray(gyro, dtype=float)
    est = CentreOfRotation(params)
    n = len(acc)
    vec_fields = ("offset", "offset_std", "offset_mean", "cr", "acc_cr", "acc_cr_n", "euler", "ang_acc")
    out: dict[str, Any] = {f: np.empty((n, 3)) for f in vec_fields}
    out["valid"] = np.empty(n, dtype=bool)
    out["settled"] = np.empty(n, dtype=bool)
    out["delay"] = np.empty(n)
    for k in range(n):
        r = est.step(acc[k], gyro[k], dt, None if euler is None else euler[k])
        for f in vec_fields:
            out[f][k] = getattr(r, f)
        out["valid"][k], out["settled"][k], out["delay"][k] = r.valid, r.settled, r.delay
    return out
