"""Adaptive heave observer with transfer to a remote point (paper 003, Auestad, Gravdahl &
Fossen, "Heave motion estimation on a craft using a strapdown inertial measurement unit").

Heave (positive down, NED, relative to the mean position) is estimated from the vertical
acceleration with no model of the craft, in the paper's four steps (the default estimator,
``model="wiener"``, shares steps 1 and 4 and replaces 2-3 by a causal Wiener filter designed
from the spectrum: :mod:`~marinefmu.estimators.heave.wiener`;
:class:`~marinefmu.estimators.heave.observer.HeaveObserver` runs whichever ``model`` names):

1. **Spectrum** of the vertical acceleration over the last ``window`` seconds and the position
   spectrum A(ω) = Ä(ω)/ω² (eq. 2), :func:`~.spectrum.acceleration_spectrum`. Beyond the
   paper, the window then grows with the data up to ``window_max`` seconds (``window_max =
   window`` is the paper's fixed window): a longer record gives the band model a finer and
   steadier spectrum (:data:`WINDOW_MAX`).
2. **Peaks** of A(ω) every ``peak_interval`` seconds (paper: T = 15 s) inside
   [``omega_min``, ``omega_max``], at most ``max_modes``, :func:`~.spectrum.find_modes`.
3. **Observer**: ``model="peaks"`` is the paper's, a Kalman filter over undamped oscillator
   modes at the peak frequencies plus a random-walk offset (eqs. 3-9), :mod:`.oscillator_bank`;
   exact (rotation) discretisation by default, the Euler form of eq. 9 selectable.
   ``model="band"`` (beyond the paper) replaces the modes by a comb of damped band-pass
   elements spanning [``band_min``, ``omega_max``], weighted by the measured spectrum
   (:mod:`.band_bank`): the filter's model then has the sea's spectrum and no heave below the
   band, which the paper's modes lack, so on a broad long-period sea it errs several times
   less (docs/decisions/heave-models.md). Either way the gain is
   the steady-state gain of the model (``dlqe``), recomputed at each spectrum.
   When the mode set changes, the state is carried over (:func:`~.oscillator_bank.carry_map`)
   so heave has no transient. The first time modes are found, the filter is run over the
   buffered window (the paper initialises from the FFT's amplitudes and phases instead), so it
   starts converged.
4. **Transfer** to the point at lever arm r from the IMU (body frame):
   ``transfer="exact"`` (default) D_p = D + [R_nb r]_d − r_z, the exact rigid-body relation
   generalising eqs. 10-11 to a 3-D lever arm; ``transfer="paper"`` is eqs. 10-11 as printed,
   D_p = cosθ cosφ (z − r_x tanθ) (a point on the IMU's centreline and baseline).

**Vertical acceleration** (the measurement, eq. 6). ``vertical="ned"`` (default) uses the whole
specific force, a_d = [R_nb f_b]_d + g (exact; needs acc.x, acc.y); ``vertical="tilt"`` (needs
only acc.z): a_d = f_z / (cosθ cosφ) + g, which removes gravity exactly but takes the horizontal
accelerations times the tilt for heave, a product with energy below the wave band that the
observer turns into heave error (docs/decisions/heave-models.md); ``vertical="paper"`` is eq. 6 as printed:
the body-axis f_z itself, whose gravity part −g cosθ cosφ the offset state absorbs
(x_off(0) = −g cosθ cosφ, eq. 7) and whose output is heave along the body z axis.

**Heave rate at the point** needs the angle rates; they come from the roll and pitch inputs by a
second-order backward difference (no lag, error O((ωΔt)²)).

**Delayed heave**: a fixed-lag smoother over ``smoother_lag`` seconds
(:class:`~.fixed_lag.FixedLagOutputs`), output with its delay.

Bad samples (non-finite or absurd acceleration or angles) are not used: the observer coasts on
its model (prediction without update), the spectrum buffer takes the predicted acceleration,
``valid`` goes false and the step reports a warning.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...errors import check_choice, check_int, check_range, check_vector
from ...frames import G
from .band_bank import BAND_VARIANCES
from .oscillator_bank import DISCRETISATIONS, MEASUREMENTS
from ..samples import FORCE_PASS2, MAX_TILT, angles_beyond_limit, force_beyond_limit, step_changed


class SilentLog:
    """Stands in for the logger of a ``quiet`` observer."""

    def warning(self, *args: Any, **kwargs: Any) -> None:
        """Drop the message."""

VERTICAL_CHOICES = ("ned", "tilt", "paper")
MODEL_CHOICES = ("band", "peaks", "highpass", "wiener")
TRANSFER_CHOICES = ("exact", "paper")
#: Default lowest band element ``band_min`` [rad/s] (:class:`HeaveObserverParams`). It trades
#: narrow JONSWAP seas, whose spectrum has almost nothing below 0.75 ω_peak and which gain from
#: a higher edge (less accelerometer noise passed as heave), against broader long-period seas,
#: which lose the heave below it (docs/decisions/heave-band-min.md; ``marinefmu bench --parts
#: heave`` measures it, :func:`~marinefmu.papers.paper003.band_min_study`).
BAND_MIN = 0.3
#: Default longest spectrum window ``window_max`` [s] (:class:`HeaveObserverParams`): 20 minutes,
#: the usual length of a sea-state record (a sea stays stationary for 20-30 minutes). A longer
#: window gives the band model and the Wiener filter, whose design reads the spectrum bin by
#: bin, a finer and steadier spectrum; the price is the buffer (at 100 Hz about 1 MB for the
#: Wiener filter, 3.8 MB for the band observer) (docs/decisions/heave-window.md; ``marinefmu
#: bench --parts heave`` measures it, :func:`~marinefmu.papers.paper003.window_max_study`).
WINDOW_MAX = 1200.0


@dataclass(frozen=True)
class HeaveObserverParams:
    """Parameters of :class:`~marinefmu.estimators.heave.observer.HeaveObserver` (FMU names in
    brackets).

    Parameters
    ----------
    window : float
        Length of the first spectrum window [s] (the observer is valid after it), at least two
        periods of ``omega_min`` (4π/omega_min) and at most 3600. [``window``]
    window_max : float
        Longest spectrum window [s], [window, 3600]: after the first spectrum the window takes
        every sample so far up to this length (module docstring, :data:`WINDOW_MAX`); equal to
        ``window`` for the paper's fixed sliding window. [``window_max``]
    peak_interval : float
        Time between peak detections [s], (0, 3600] (paper: T = 15 s). [``peak_interval``]
    model : str
        ``"wiener"`` (default), the causal Wiener filter designed from the spectrum
        (:class:`~.wiener.WienerHeave`, the most accurate of the four);
        ``"band"`` or ``"peaks"`` (the paper's modes), the observers of the module docstring
        (:class:`~.bank.OscillatorBankHeave`); or ``"highpass"``, the classical high-pass
        double integration (:class:`~.highpass.HighpassHeave`, a baseline). Build any of
        them with :class:`~marinefmu.estimators.heave.observer.HeaveObserver`. [``model``]
    max_modes : int
        Most oscillator modes, 1..20 (``model="peaks"``). [``max_modes``]
    omega_min, omega_max : float
        Band searched for peaks [rad/s], 0 < omega_min < omega_max ≤ 20. [``omega_min``, ``omega_max``]
    min_separation : float
        Peaks closer than this to a higher one are dropped [rad/s], (0, 2]. [``min_separation``]
    min_relative : float
        Peaks lower than this fraction of the highest are dropped, [0, 1). [``min_relative``]
    elements : int
        Grid size of the band model, 2..100 (geometric in [max(omega_min, band_min), omega_max]).
        [``elements``]
    band_min : float
        Lowest band element [rad/s], (0, omega_max) (``model="band"``; the peak search keeps
        ``omega_min``). Why not lower: the observer overshoots just below its lowest element
        (|H| ≈ 3-4 at 0.15-0.2 rad/s with elements from 0.25 rad/s), where the accelerometer's
        noise and bias, as heave, grow as 1/ω⁴. Why not higher: the sea below it is left
        out. For swell longer than about 16 s lower it (0.25 serves Tp ≤ 20 s).
        :data:`BAND_MIN`. [``band_min``]
    damping : float
        Damping ratio of each band element's stages, (0, 1]. [``damping``]
    stages : int
        Cascaded oscillators per band element, 1..4 (heave spectrum ∝ ω^{2(stages−1)} below
        an element). [``stages``]
    band_variance : str
        ``"integral"`` (default: the heave spectrum integrated over each element's band) or
        ``"point"`` (read at the element's frequency),
        :func:`~.band_bank.band_elements`. [``band_variance``]
    band_smoothing : int
        Half-width of the smoothing of the band elements' heave densities over their
        neighbours, 0..5 elements (0: none, the default;
        :func:`~.band_bank.smooth_densities`). [``band_smoothing``]
    spectrum_floor : float
        Band elements whose heave density is below this fraction of the highest are left out,
        [0, 1). [``spectrum_floor``]
    acc_noise : float
        Accelerometer white-noise density N [m/s²/√Hz], (0, 1]: R = N²/Δt. [``acc_noise``]
    mode_noise : float
        Mode process-noise density per rad/s of mode frequency [m²/s²], (0, 1e3]:
        q_j = mode_noise·ω_j (paper section 2.3; ``model="peaks"``). [``mode_noise``]
    offset_noise : float
        Random-walk density of the offset state [m/s²/√s], (0, 10] (eq. 7). [``offset_noise``]
    discretisation : str
        ``"exact"`` (rotation matrix) or ``"euler"`` (eq. 9); ``model="peaks"`` only, band
        elements are always exact. [``discretisation``]
    measurement : str
        ``"increment"`` (the mean acceleration over a step, default) or ``"paper"`` (eq. 9,
        y = Cx), :mod:`.oscillator_bank`. [``measurement``]
    vertical : str
        ``"tilt"``, ``"ned"`` or ``"paper"`` (module docstring). [``vertical``]
    transfer : str
        ``"exact"`` or ``"paper"`` (eqs. 10-11). [``transfer``]
    point : tuple of float
        Monitoring point relative to the IMU, body frame [m]. [``point.{x,y,z}``]
    smoother_lag : float
        Delay of the delayed heave [s], [0, 120]. [``smoother_lag``]
    highpass_cutoff : float
        Corner of the classical filter [rad/s], (0, omega_max) (``model="highpass"``).
        [``highpass_cutoff``]
    highpass_order : int
        Butterworth order of the classical filter, 2..8 (``model="highpass"``). [``highpass_order``]
    """

    window: float = 120.0
    window_max: float = WINDOW_MAX
    peak_interval: float = 15.0
    model: str = "wiener"
    max_modes: int = 6
    omega_min: float = 0.25
    omega_max: float = 6.0
    min_separation: float = 0.06
    min_relative: float = 0.05
    elements: int = 36
    band_min: float = BAND_MIN
    damping: float = 0.1
    stages: int = 3
    band_variance: str = "integral"
    band_smoothing: int = 0
    spectrum_floor: float = 1e-3
    acc_noise: float = 7e-4
    mode_noise: float = 1e-2
    offset_noise: float = 1e-4
    discretisation: str = "exact"
    measurement: str = "increment"
    vertical: str = "ned"
    transfer: str = "exact"
    point: tuple[float, float, float] = (0.0, 0.0, 0.0)
    smoother_lag: float = 5.0
    highpass_cutoff: float = 0.1
    highpass_order: int = 4

    def __post_init__(self) -> None:
        check_range("omega_min", self.omega_min, lo=0.0, hi=20.0, lo_open=True, unit="rad/s")
        check_range("omega_max", self.omega_max, lo=self.omega_min, hi=20.0, lo_open=True, unit="rad/s")
        shortest = 4.0 * math.pi / self.omega_min
        check_range("window", self.window, lo=shortest, hi=3600.0, unit="s (two periods of omega_min)")
        check_range("window_max", self.window_max, lo=self.window, hi=3600.0, unit="s (at least window)")
        check_range("peak_interval", self.peak_interval, lo=0.0, hi=3600.0, lo_open=True, unit="s")
        check_choice("model", self.model, MODEL_CHOICES)
        check_int("max_modes", self.max_modes, lo=1, hi=20)
        check_int("elements", self.elements, lo=2, hi=100)
        check_range("band_min", self.band_min, lo=0.0, hi=self.omega_max, lo_open=True, hi_open=True, unit="rad/s")
        check_range("damping", self.damping, lo=0.0, hi=1.0, lo_open=True)
        check_int("stages", self.stages, lo=1, hi=4)
        check_choice("band_variance", self.band_variance, BAND_VARIANCES)
        check_int("band_smoothing", self.band_smoothing, lo=0, hi=5)
        check_range("spectrum_floor", self.spectrum_floor, lo=0.0, hi=1.0, hi_open=True)
        check_range("min_separation", self.min_separation, lo=0.0, hi=2.0, lo_open=True, unit="rad/s")
        check_range("min_relative", self.min_relative, lo=0.0, hi=1.0, hi_open=True)
        check_range("acc_noise", self.acc_noise, lo=0.0, hi=1.0, lo_open=True, unit="m/s2/sqrt(Hz)")
        check_range("mode_noise", self.mode_noise, lo=0.0, hi=1e3, lo_open=True, unit="m2/s2")
        check_range("offset_noise", self.offset_noise, lo=0.0, hi=10.0, lo_open=True, unit="m/s2/sqrt(s)")
        check_choice("discretisation", self.discretisation, DISCRETISATIONS)
        check_choice("measurement", self.measurement, MEASUREMENTS)
        check_choice("vertical", self.vertical, VERTICAL_CHOICES)
        check_choice("transfer", self.transfer, TRANSFER_CHOICES)
        check_vector("point", self.point, unit="m")
        check_range("smoother_lag", self.smoother_lag, lo=0.0, hi=120.0, unit="s")
        check_range("highpass_cutoff", self.highpass_cutoff, lo=0.0, hi=self.omega_max, lo_open=True, hi_open=True,
                    unit="rad/s")
        check_int("highpass_order", self.highpass_order, lo=2, hi=8)


# ---- stateless kernels ----------------------------------------------------------------------
def vertical_acceleration(acc: Any, roll: float, pitch: float, vertical: str = "ned") -> float:
    """The observer's measurement from one specific-force sample (eq. 6 and its improvements).

    Parameters
    ----------
    acc : array_like
        (3,) specific force f_b [m/s², body]; ``"tilt"`` and ``"paper"`` use only f_z.
    roll, pitch : float
        φ, θ [rad].
    vertical : str
        ``"tilt"``: f_z/(cosθ cosφ) + g; ``"ned"``: [R_nb f_b]_d + g (exact); ``"paper"``: f_z.

    Returns
    -------
    float
        [m/s²], positive down (for ``"paper"``: along body z, including gravity).
    """
    fx, fy, fz = acc
    if vertical == "paper":
        return float(fz)
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    if vertical == "tilt":
        return float(fz) / (cp * cr) + G
    return -sp * float(fx) + cp * sr * float(fy) + cp * cr * float(fz) + G


def point_heave(heave: float, rate: float, point: Any, roll: float, pitch: float, roll_rate: float,
                pitch_rate: float, transfer: str = "exact") -> tuple[float, float]:
    """Step 4: heave and heave rate at a point from those at the IMU.

    Parameters
    ----------
    heave, rate : float
        At the IMU [m], [m/s], positive down.
    point : array_like
        (3,) r, the point relative to the IMU [m, body].
    roll, pitch : float
        φ, θ [rad].
    roll_rate, pitch_rate : float
        φ̇, θ̇ [rad/s].
    transfer : str
        ``"exact"``: D_p = D + [R_nb r]_d − r_z (yaw does not enter); ``"paper"``: eqs. 10-11,
        D_p = cosθ cosφ (D − r_x tanθ), and its time derivative.

    Returns
    -------
    tuple of float
        Heave [m] and heave rate [m/s] at the point, positive down.
    """
    rx, ry, rz = point
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    if transfer == "paper":
        bow = heave - rx * sp / cp
        bow_rate = rate - rx * pitch_rate / cp**2
        c = cp * cr
        c_rate = -sp * cr * pitch_rate - cp * sr * roll_rate
        return c * bow, c_rate * bow + c * bow_rate
    arm_d = -sp * rx + cp * sr * ry + cp * cr * rz
    arm_rate = (-cp * rx - sp * sr * ry - sp * cr * rz) * pitch_rate + (cp * cr * ry - cp * sr * rz) * roll_rate
    return heave + arm_d - rz, rate + arm_rate


def backward_rate(history: list[tuple[float, float]], dt: float) -> tuple[float, float]:
    """Second-order backward difference (3x_k − 4x_{k−1} + x_{k−2})/(2Δt) of (roll, pitch);
    first order with two samples, zero with one."""
    if len(history) >= 3:
        (a0, b0), (a1, b1), (a2, b2) = history[-1], history[-2], history[-3]
        return (3 * a0 - 4 * a1 + a2) / (2 * dt), (3 * b0 - 4 * b1 + b2) / (2 * dt)
    if len(history) == 2:
        return (history[-1][0] - history[-2][0]) / dt, (history[-1][1] - history[-2][1]) / dt
    return 0.0, 0.0


def central_rate(prev: tuple[float, float], nxt: tuple[float, float], dt: float) -> tuple[float, float]:
    """Central difference (x_{k+1} − x_{k−1})/(2Δt) of (roll, pitch) [rad/s]."""
    return (nxt[0] - prev[0]) / (2 * dt), (nxt[1] - prev[1]) / (2 * dt)


def read_sample(acc: Any, roll: float, pitch: float) -> tuple[Any, float, float, str | None]:
    """One IMU sample as the heave estimators take it: (f_b (3,) [m/s²], roll, pitch [rad],
    the reason it is bad or None). ``acc`` is f_z or (3,) f_b; another shape is a bad sample.
    A float f_z (taken as (0, 0, f_z)) or a (3,) sequence or array whose values are finite and
    well inside the limits is checked on Python floats and returned as a tuple of them (NaN
    fails every comparison, so it takes the full check); anything else as an array, after the
    full check."""
    roll, pitch = float(roll), float(pitch)
    three = (type(acc) in (tuple, list) and len(acc) == 3) or (isinstance(acc, np.ndarray) and acc.shape == (3,))
    if three or isinstance(acc, float):   # np.float64 is a float
        fx, fy, fz = (float(acc[0]), float(acc[1]), float(acc[2])) if three else (0.0, 0.0, float(acc))
        if abs(roll) <= MAX_TILT and abs(pitch) <= MAX_TILT and fx * fx + fy * fy + fz * fz <= FORCE_PASS2:
            return (fx, fy, fz), roll, pitch, None
        f = np.array((fx, fy, fz))
    else:
        f = np.asarray(acc, dtype=float).reshape(-1)
        if f.shape == (1,):
            f = np.array([0.0, 0.0, f[0]])
        elif f.shape != (3,):
            f = np.full(3, math.nan)
    return f, roll, pitch, _bad_sample(f, roll, pitch)


def read_and_start(estimator: Any, acc: Any, roll: float, pitch: float,
                   dt: float) -> tuple[Any, float, float, str | None]:
    """:func:`read_sample`, and the start of a sample-by-sample heave filter (its ``dt``,
    ``reset()`` and ``start(dt)``, as :class:`~.highpass.HighpassHeave` and
    :class:`~.wiener.WienerHeave` have them): at the first step, or afresh when the step
    size changes (that reason then replaces the sample's)."""
    f, roll, pitch, warning = read_sample(acc, roll, pitch)
    if estimator.dt is not None and step_changed(estimator.dt, dt):
        warning = f"step size changed from {estimator.dt} s to {dt} s; filter restarted"
        estimator.reset()
    if estimator.dt is None:
        estimator.start(dt)
    return f, roll, pitch, warning


def _bad_sample(acc: np.ndarray, roll: float, pitch: float) -> str | None:
    if not (np.all(np.isfinite(acc)) and math.isfinite(roll) and math.isfinite(pitch)):
        return "non-finite acceleration or angle sample"
    return angles_beyond_limit((roll, pitch)) or force_beyond_limit(acc)


# ---- stateful observer ----------------------------------------------------------------------
@dataclass(frozen=True)
class HeaveResult:
    """Output of one :meth:`~marinefmu.estimators.heave.observer.HeaveObserver.step`.

    Attributes
    ----------
    heave, heave_rate : float
        At the IMU [m], [m/s], positive down (``vertical="paper"``: along body z).
    point_heave, point_heave_rate : float
        At the monitoring point [m], [m/s], positive down.
    delayed_heave, delayed_heave_rate, delayed_point_heave : float
        Fixed-lag smoothed heave, rate at the IMU and heave at the point, for the time
        ``delay`` s before this sample [m], [m/s].
    delay : float
        Lag of the delayed outputs [s].
    offset : float
        Offset state [m/s²] (accelerometer bias along the vertical; ``vertical="paper"``: plus
        −g cosθ cosφ).
    modes : int
        Number of oscillator modes (0 before the first spectrum; ``model="wiener"``: of peaks
        of the sea's heave spectrum, the filter has no modes).
    peak_period : float
        Period of the highest peak of A(ω) [s] (0 before the first spectrum).
    omega : tuple of float
        Mode frequencies [rad/s] (``model="wiener"``: the peaks').
    valid : bool
        Modes found and the sample good.
    delayed_valid : bool
        The delayed outputs refer to a time the observer has run through.
    warning : str or None
        Why the sample was not used, if it was not.
    """

    heave: float
    heave_rate: float
    point_heave: float
    point_heave_rate: float
    delayed_heave: float
    delayed_heave_rate: float
    delayed_point_heave: float
    delay: float
    offset: float
    modes: int
    peak_period: float
    omega: tuple[float, ...]
    valid: bool
    delayed_valid: bool
    warning: str | None = None
