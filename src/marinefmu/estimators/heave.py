"""Adaptive heave observer with transfer to a remote point (paper 003, Auestad, Gravdahl &
Fossen, "Heave motion estimation on a craft using a strapdown inertial measurement unit").

Heave (positive down, NED, relative to the mean position) is estimated from the vertical
acceleration with no model of the craft, in the paper's four steps (the default estimator,
``model="wiener"``, shares steps 1 and 4 and replaces 2-3 by a causal Wiener filter designed
from the spectrum: :mod:`.wiener_heave`; :func:`~.highpass_heave.heave_estimator` builds
whichever ``model`` names):

1. **Spectrum** of the vertical acceleration over the last ``window`` seconds and the position
   spectrum A(ω) = Ä(ω)/ω² (eq. 2), :func:`~.wave_peaks.acceleration_spectrum`. Beyond the
   paper, the window then grows with the data up to ``window_max`` seconds (``window_max =
   window`` is the paper's fixed window): a longer record gives the band model a finer and
   steadier spectrum (measured in :data:`WINDOW_MAX`).
2. **Peaks** of A(ω) every ``peak_interval`` seconds (paper: T = 15 s) inside
   [``omega_min``, ``omega_max``], at most ``max_modes``, :func:`~.wave_peaks.find_modes`.
3. **Observer**: ``model="peaks"`` is the paper's, a Kalman filter over undamped oscillator
   modes at the peak frequencies plus a random-walk offset (eqs. 3-9), :mod:`.oscillator_bank`;
   exact (rotation) discretisation by default, the Euler form of eq. 9 selectable.
   ``model="band"`` (beyond the paper) replaces the modes by a comb of damped band-pass
   elements spanning [``band_min``, ``omega_max``], weighted by the measured spectrum
   (:mod:`.band_bank`): the filter's model then has the sea's spectrum and no heave below the
   band, which the paper's modes lack (measured on VesselMotion, real-time RMS error at
   Hs 4 m / Tp 14 s: 13 cm with the modes, ~3 cm with the band; README). Either way the gain is
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
accelerations times the tilt for heave (measured: 34 cm instead of 3.6 cm RMS error at Hs 4 m,
Tp 14 s, where that product has energy below the band); ``vertical="paper"`` is eq. 6 as printed:
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

import logging
import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..errors import ParameterError, check_choice, check_int, check_range, check_vector
from ..frames import G
from .fixed_lag import FixedLagOutputs
from .band_bank import BAND_VARIANCES, band_elements, band_grid, build_band_bank
from .oscillator_bank import DISCRETISATIONS, MEASUREMENTS, BankModel, build_bank, carry_map
from .samples import angles_beyond_limit, force_beyond_limit
from .wave_peaks import acceleration_spectrum, find_modes

log = logging.getLogger(__name__)


class _Silent:
    """Stands in for the logger of a ``quiet`` observer."""

    def warning(self, *args: Any, **kwargs: Any) -> None:
        """Drop the message."""

VERTICAL_CHOICES = ("ned", "tilt", "paper")
MODEL_CHOICES = ("band", "peaks", "highpass", "wiener")
TRANSFER_CHOICES = ("exact", "paper")
#: Default lowest band element ``band_min`` [rad/s] (:class:`HeaveObserverParams`). Measured
#: 2026-11-23, real-time heave RMS error at the IMU [cm], default MEMS noise, truth angles;
#: band_min 0.25 (the earlier default, = omega_min) → 0.30 → 0.35 → 0.40:
#:
#: * VesselMotion JONSWAP seas of the accuracy tests (30 min after 2 min, seed 3):
#:   Hs 4 / Tp 14 3.64 → 3.26 → 3.02 → 3.81; Hs 1 / Tp 14 1.98 → 1.76 → 1.62;
#:   Hs 4 / Tp 12 (no test's sea) 2.83 → – → 2.43; Hs 2.5 / Tp 9 and the Tp 6 seas unchanged;
#: * smsfusion's OrcaFlex record (Tp about 14 s, but 14 % of its heave variance below
#:   0.35 rad/s): 3.29 → 3.29 → 6.32 (true angles, :mod:`~marinefmu.peer_orcaflex`).
#:
#: All but the Hs 4 / Tp 12 and 0.40 figures (a scan) are re-measured by ``marinefmu bench
#: --parts heave`` (:func:`~marinefmu.examples.paper003.band_min_study`). 0.35 is best on the JONSWAP seas,
#: whose spectrum has almost nothing below 0.75 ω_peak, and doubles the error on the broader
#: OrcaFlex sea; 0.30 is better than 0.25 on the JONSWAP seas and equal on OrcaFlex.
#: Not taken: dropping the lowest elements by their share of the band's variance (1-10 %:
#: Hs 4 / Tp 14 3.34-3.44 with band_min 0.25), four stages per element (3.80), offset noise
#: 3e-5 / 5e-5 (4.57 / 4.02).
BAND_MIN = 0.3
#: Default longest spectrum window ``window_max`` [s] (:class:`HeaveObserverParams`). Measured
#: 2026-11-23 (a scan; ``marinefmu bench --parts heave`` re-measures the Hs 4 seas and the
#: OrcaFlex record, :func:`~marinefmu.examples.paper003.window_max_study`), real-time heave RMS
#: error at the IMU [cm], the checks' seas (30 min after 2 min, seed 3), before → growing
#: window and band variances integrated (:func:`~.band_bank.band_elements`):
#: Hs 1 / Tp 6 0.29 → 0.27; Hs 4 / Tp 6 0.52 → 0.49; Hs 2.5 / Tp 9 1.19 → 1.03;
#: Hs 4 / Tp 12 2.63 → 2.31; Hs 1 / Tp 14 1.76 → 1.59; Hs 2.5 / Tp 14 2.65 → 2.40;
#: Hs 4 / Tp 14 3.26 → 2.96 (the growing window alone 3.06, the integral alone 3.24); the OrcaFlex
#: record 3.28 → 3.32. Why 1200 s (600 s until 2026-11-23): 20 minutes is the usual length of
#: a sea-state record (a sea stays stationary for 20-30 minutes), and the Wiener filter
#: (``model="wiener"``), whose design reads the spectrum bin by bin, gains from it on the long
#: seas. Measured 2026-11-23 (a scan, 30 min after 2 min), ``window_max`` 600 / 1200 / 1800 s,
#: seed 3: Hs 4 / Tp 12 2.107 / 2.076 / 2.074; Hs 2.5 / Tp 14 2.287 / 2.215 / 2.212; Hs 4 /
#: Tp 14 2.772 / 2.693 / 2.687; Hs 2.5 / Tp 9 0.874 / 0.876 / 0.870; Hs 1 / Tp 6 0.223 / 0.220 /
#: 0.219; seed 1, the same seas: 2.145 / 2.116 / 2.116; 2.237 / 2.188 / 2.185; 2.706 / 2.651 /
#: 2.645; 0.895 / 0.891 / 0.887; 0.224 / 0.222 / 0.221. The band observer (seed 3, 600 / 1200 s):
#: Hs 4 / Tp 12 2.307 / 2.297, Hs 4 / Tp 14 2.957 / 2.941, Hs 2.5 / Tp 9 1.033 / 1.033; with an
#: oracle spectrum (the truth's acceleration over the whole 32 min run) it does no better
#: (2.95 cm on Hs 4 / Tp 14). The price: the buffer (at 100 Hz 1 MB for the Wiener filter,
#: 3.8 MB for the band observer) and the band observer's larger spectra (115 → 130 µs a step at
#: 100 Hz, a scan; the Wiener filter's ~80 µs unchanged). Runs shorter than 10 minutes reach
#: neither length. Not taken: narrower band elements (``elements`` 60, ``damping`` 0.07:
#: 2.76 cm on Hs 4 / Tp 14, 2.10 on Hs 4 / Tp 12, but the OrcaFlex record's 120-360 s of
#: spectrum make them 4.09 cm; ``elements`` 60 alone 2.94 cm).
WINDOW_MAX = 1200.0


@dataclass(frozen=True)
class HeaveObserverParams:
    """Parameters of :class:`HeaveObserver` (FMU names in brackets).

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
        (:class:`~.wiener_heave.WienerHeave`, not this class: the most accurate, README);
        ``"band"`` or ``"peaks"`` (the paper's modes), the observers of this module
        (module docstring); or ``"highpass"``, the classical high-pass double integration
        (:class:`~.highpass_heave.HighpassHeave`, a baseline, not this class). Build any of
        them with :func:`~.highpass_heave.heave_estimator`. [``model``]
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
        noise and bias, as heave, grow as 1/ω⁴ (on Hs 4 m / Tp 14 s they put 2.7 cm of heave
        error below 0.2 rad/s, 0.6 cm without them). Why not higher: the sea below it is left
        out. For swell longer than about 16 s lower it (0.25 serves Tp ≤ 20 s). Measured in
        :data:`BAND_MIN`. [``band_min``]
    damping : float
        Damping ratio of each band element's stages, (0, 1]. [``damping``]
    stages : int
        Cascaded oscillators per band element, 1..4 (heave spectrum ∝ ω^{2(stages−1)} below
        an element). [``stages``]
    band_variance : str
        ``"integral"`` (default: the heave spectrum integrated over each element's band) or
        ``"point"`` (read at the element's frequency, as until 2026-11-23),
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


def read_sample(acc: Any, roll: float, pitch: float) -> tuple[np.ndarray, float, float, str | None]:
    """One IMU sample as the heave estimators take it: (f_b (3,) [m/s²], roll, pitch [rad],
    the reason it is bad or None). ``acc`` is f_z or (3,) f_b; another shape is a bad sample."""
    f = np.asarray(acc, dtype=float).reshape(-1)
    if f.shape == (1,):
        f = np.array([0.0, 0.0, f[0]])
    elif f.shape != (3,):
        f = np.full(3, math.nan)
    roll, pitch = float(roll), float(pitch)
    return f, roll, pitch, _bad_sample(f, roll, pitch)


def read_and_start(estimator: Any, acc: Any, roll: float, pitch: float,
                   dt: float) -> tuple[np.ndarray, float, float, str | None]:
    """:func:`read_sample`, and the start of a sample-by-sample heave filter (its ``dt``,
    ``reset()`` and ``_start(dt)``, as :class:`~.highpass_heave.HighpassHeave` and
    :class:`~.wiener_heave.WienerHeave` have them): at the first step, or afresh when the step
    size changes (that reason then replaces the sample's)."""
    f, roll, pitch, warning = read_sample(acc, roll, pitch)
    if estimator.dt is not None and abs(dt - estimator.dt) > 1e-9 * estimator.dt:
        warning = f"step size changed from {estimator.dt} s to {dt} s; filter restarted"
        estimator.reset()
    if estimator.dt is None:
        estimator._start(dt)
    return f, roll, pitch, warning


def _bad_sample(acc: np.ndarray, roll: float, pitch: float) -> str | None:
    if not (np.all(np.isfinite(acc)) and math.isfinite(roll) and math.isfinite(pitch)):
        return "non-finite acceleration or angle sample"
    return angles_beyond_limit((roll, pitch)) or force_beyond_limit(acc)


# ---- stateful observer ----------------------------------------------------------------------
@dataclass(frozen=True)
class HeaveResult:
    """Output of one :meth:`HeaveObserver.step`.

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


class HeaveObserver:
    """Heave at the IMU and at a point from vertical acceleration and roll/pitch (module docstring).

    Parameters
    ----------
    params : HeaveObserverParams, optional
        Validated parameters with ``model`` "band" or "peaks" (the defaults with ``model="band"``
        if omitted).
    quiet : bool
        Log nothing (for use inside another estimator that reports for itself, such as
        :class:`~.wave_coast.WaveCoast`, where an axis without waves is normal).

    Examples
    --------
    >>> obs = HeaveObserver(HeaveObserverParams(model="band", window=60.0))
    >>> r = obs.step(-9.80665, 0.0, 0.0, 0.1)
    >>> r.valid, r.modes      # no spectrum before the first window is full
    (False, 0)
    """

    def __init__(self, params: HeaveObserverParams | None = None, *, quiet: bool = False) -> None:
        self.params = params or HeaveObserverParams(model="band")
        if self.params.model in ("highpass", "wiener"):
            raise ParameterError(f"model = {self.params.model!r} is not an observer model: use "
                                 "estimators.highpass_heave.heave_estimator(params)")
        self.log: Any = _Silent() if quiet else log
        self.reset()

    def reset(self) -> None:
        """Back to the initial state."""
        self.dt: float | None = None
        self.buf: np.ndarray | None = None     # ring of window_max samples × (a_v, roll, pitch, good)
        self.k = 0                              # samples seen
        self.next_detect = 0
        self.model: BankModel | None = None
        self._variance: np.ndarray | None = None   # band elements' heave variances [m²]
        self.xp = np.zeros(1)                   # prior for the next measurement
        self.x = np.zeros(1)                    # estimate at the newest sample's time
        self.prev: tuple[float | None, np.ndarray] | None = None   # last sample: a_v, aux
        self.angles: list[tuple[float, float]] = []
        self.last_angles = (0.0, 0.0)
        self.peak_period = 0.0
        self.smoother: FixedLagOutputs | None = None
        self._delayed: tuple[np.ndarray, np.ndarray] | None = None
        self._aux = np.zeros(4)
        self._result = HeaveResult(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0.0, (), False, False)

    def _start(self, dt: float) -> None:
        p = self.params
        self.dt = dt
        n = int(round(p.window / dt))
        self.buf = np.zeros((max(n, int(round(p.window_max / dt))), 4))
        self.next_detect = n
        self.smoother = FixedLagOutputs(int(round(p.smoother_lag / dt)), 2, 4)

    @property
    def band_variance(self) -> float | None:
        """Heave variance of the band model, the sum of its elements' [m²] (``model="band"``
        with a model; else None)."""
        return None if self._variance is None else float(np.sum(self._variance))

    @property
    def delay(self) -> float:
        """Lag of the delayed outputs [s] (the increment model's states refer to the start of
        each step, one step more)."""
        if self.smoother is None:
            return 0.0
        return (self.smoother.lag + (self.params.measurement == "increment")) * self.dt

    def step(self, acc: Any, roll: float, pitch: float, dt: float) -> HeaveResult:
        """Process one sample.

        Parameters
        ----------
        acc : float or array_like
            f_z, or (3,) f_b: specific force at the IMU [m/s², body] (``vertical="ned"``
            needs all three).
        roll, pitch : float
            φ, θ at the IMU's time [rad].
        dt : float
            Step [s] (> 0, constant; a change restarts the observer).

        Returns
        -------
        HeaveResult
            A bad sample is not used (the observer coasts); ``valid`` is False and ``warning``
            says why.
        """
        p = self.params
        f, roll, pitch, warning = read_sample(acc, roll, pitch)
        if warning is not None:
            self.log.warning("heave observer: %s; coasting on the model", warning)
        restarted = None
        if self.dt is not None and abs(dt - self.dt) > 1e-9 * self.dt:
            restarted = f"step size changed from {self.dt} s to {dt} s; observer restarted"
            self.log.warning("heave observer: %s", restarted)
            self.reset()
        if self.dt is None:
            self._start(dt)
        good = warning is None
        if good:
            a_v = vertical_acceleration(f, roll, pitch, p.vertical)
            self.last_angles = (roll, pitch)
            self.angles = (self.angles + [(roll, pitch)])[-3:]
        else:
            a_v = None
            roll, pitch = self.last_angles
        self.k += 1
        aux = np.array([roll, pitch, *backward_rate(self.angles, self.dt)])
        warning = warning or restarted
        if self.model is None:
            self._buffer(a_v, roll, pitch)
            if self.k >= self.next_detect and self._detect():
                self._replay()
                return self._finish(good and restarted is None, warning)
            return replace(self._result, valid=False, warning=warning)
        self._process(a_v, aux)
        self._buffer(a_v, roll, pitch)
        if self.k >= self.next_detect:
            self._detect()
        return self._finish(good and restarted is None, warning)

    def track_spectrum(self, acc: Any, roll: float, pitch: float) -> None:
        """Take one sample (as :meth:`step`, same step size) once the model exists, for the
        spectrum and the model only: it is buffered and the spectrum and model are redone when
        due, without the Kalman step, whose state then goes stale (``x``, ``xp`` and the
        outputs are not updated). A bad sample repeats the previous one in the buffer.

        For an estimator that runs the model in a filter of its own
        (:class:`~.wave_coast.WaveCoast`): the observer's step is then work done twice.
        """
        if self.model is None:
            raise RuntimeError("track_spectrum needs the first model: call step until model is set")
        f, roll, pitch, warning = read_sample(acc, roll, pitch)
        self.k += 1
        if warning is None:
            row = (vertical_acceleration(f, roll, pitch, self.params.vertical), roll, pitch, 1.0)
        else:
            self.log.warning("heave observer: %s; repeating the previous sample in the spectrum", warning)
            row = (float(self.buf[(self.k - 2) % len(self.buf), 0]), *self.last_angles, 0.0)
        self.buf[(self.k - 1) % len(self.buf)] = row
        if self.k >= self.next_detect:
            self._detect()

    # ---- internals ---------------------------------------------------------------------------
    def _buffer(self, a_v: float | None, roll: float, pitch: float) -> None:
        """Store a sample for the spectrum; a bad one is replaced by the model's acceleration
        (or the previous sample before the model exists)."""
        if a_v is None:
            if self.model is not None:
                fill = float(self.model.C @ self.xp)             # the predicted measurement
            else:
                fill = float(self.buf[(self.k - 2) % len(self.buf), 0]) if self.k > 1 else 0.0
            row = (fill, roll, pitch, 0.0)
        else:
            row = (a_v, roll, pitch, 1.0)
        self.buf[(self.k - 1) % len(self.buf)] = row

    def _window(self) -> np.ndarray:
        """The samples buffered so far (at most ``window_max`` s of them), oldest first."""
        return np.roll(self.buf, -(self.k % len(self.buf)), axis=0)[-min(self.k, len(self.buf)):]

    def _detect(self) -> bool:
        """Steps 1-2 on the buffer and, if the band has energy, a new model with the state carried."""
        p = self.params
        self.next_detect = self.k + max(1, int(round(p.peak_interval / self.dt)))
        spectrum = acceleration_spectrum(self._window()[:, 0], self.dt)
        modes = find_modes(spectrum, p.omega_min, p.omega_max, p.max_modes, p.min_separation, p.min_relative)
        if p.model == "band":
            omega, variance = band_elements(spectrum, band_grid(max(p.omega_min, p.band_min), p.omega_max,
                                                                p.elements), p.spectrum_floor,
                                              p.band_variance, p.band_smoothing)
        else:
            omega, variance = modes.omega, None
        if len(modes) == 0 or len(omega) == 0:
            self.log.warning("heave observer: no spectral peak in [%g, %g] rad/s; modes unchanged", p.omega_min, p.omega_max)
            return False
        self.peak_period = 2.0 * math.pi / float(modes.omega[np.argmax(modes.amplitude)])
        new = self._build(omega, variance)
        if self.model is not None:
            t = carry_map(self.model.omega, new.omega, new.block)
            self.xp, self.x = t @ self.xp, t @ self.x
        self._use(new)
        self._variance = variance
        return True

    def _use(self, model: BankModel) -> None:
        """Make ``model`` the observer's (the smoother freezes the pending times)."""
        self.model = model
        self.smoother.set_model(model.heave_rows, model.P, model.closed_loop, model.C, model.S)

    def response(self, omega: Any) -> np.ndarray | None:
        """Heave response H(ω) of the current model (:meth:`.BankModel.heave_response`): the
        estimate of a noise-free sinusoidal heave at ω [rad/s] is H(ω) times the truth.
        None before the first spectrum."""
        if self.model is None or self.dt is None:
            return None
        return self.model.heave_response(np.asarray(omega, dtype=float), self.dt)

    def _build(self, omega: np.ndarray, variance: np.ndarray | None) -> BankModel:
        """The observer model for mode frequencies ``omega`` (and, for the band, element variances)."""
        p = self.params
        if p.model == "band":
            return build_band_bank(omega, variance, self.dt, p.damping, p.stages, p.offset_noise, p.acc_noise,
                                   p.measurement)
        return build_bank(omega, self.dt, p.mode_noise, p.offset_noise, p.acc_noise, p.discretisation,
                          p.measurement)

    def _replay(self) -> None:
        """Run the new observer over the buffered window (first detection only)."""
        win = self._window()
        self.xp = np.zeros(self.model.n)
        if self.params.vertical == "paper":
            self.xp[-1] = -G * math.cos(win[0, 1]) * math.cos(win[0, 2])
        self.x = self.xp.copy()
        self.prev = None
        hist: list[tuple[float, float]] = []
        for a_v, roll, pitch, good in win:
            hist = (hist + [(roll, pitch)])[-3:]
            self._process(a_v if good else None, np.array([roll, pitch, *backward_rate(hist, self.dt)]))

    def _process(self, a_v: float | None, aux: np.ndarray) -> None:
        """One Kalman step (steady-state gain) with the smoother; a missing measurement coasts.

        ``"paper"``: the measurement is this sample, the prior refers to its time.
        ``"increment"``: the measurement is the mean of the previous and this sample, the prior
        refers to the previous sample's time.
        """
        m, sm = self.model, self.smoother
        if m.measurement == "paper":
            y, state_aux = a_v, aux
        else:
            if self.prev is None:                       # first sample: nothing to difference
                self.prev = (a_v, aux)
                return
            prev_a, state_aux = self.prev
            y = None if a_v is None or prev_a is None else 0.5 * (prev_a + a_v)
            self.prev = (a_v, aux)
        sm.push(self.xp, state_aux)
        if y is None:
            post, phi = self.xp, m.A
            nxt = m.A @ post
        else:
            innovation = y - float(m.C @ self.xp)
            post = self.xp + m.K * innovation
            sm.correct(innovation)
            nxt = m.A_bar @ post + m.J * y
            phi = None   # the steady closed loop
        self._delayed = sm.pop()
        sm.propagate(phi)
        self.x = post if m.measurement == "paper" else nxt
        self.xp = nxt
        self._aux = aux

    def _finish(self, good: bool, warning: str | None) -> HeaveResult:
        p, m = self.params, self.model
        roll, pitch, rr, pr = self._aux
        rows = m.heave_rows @ self.x
        heave, rate = float(rows[0]), float(rows[1])
        ph, pr_ = point_heave(heave, rate, p.point, roll, pitch, rr, pr, p.transfer)
        if self._delayed is not None:
            (dh, dr), (droll, dpitch, drr, dpr) = self._delayed
            dph, _ = point_heave(float(dh), float(dr), p.point, droll, dpitch, drr, dpr, p.transfer)
            delayed = (float(dh), float(dr), dph, True)
        else:
            delayed = (0.0, 0.0, 0.0, False)
        self._result = HeaveResult(
            heave, rate, ph, pr_, delayed[0], delayed[1], delayed[2], self.delay, float(self.x[-1]),
            len(m.omega), self.peak_period, tuple(float(w) for w in m.omega), good, delayed[3], warning,
        )
        return self._result

    # ---- FMU state ---------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable internal state (the bank is rebuilt from its frequencies)."""
        def arr(v: Any) -> Any:
            return None if v is None else np.asarray(v).tolist()
        return {
            "dt": self.dt, "buf": arr(self.buf), "k": self.k, "next_detect": self.next_detect,
            "omega": None if self.model is None else self.model.omega.tolist(), "variance": arr(self._variance),
            "xp": arr(self.xp), "x": arr(self.x),
            "prev": None if self.prev is None else [self.prev[0], self.prev[1].tolist()],
            "angles": [list(a) for a in self.angles], "last_angles": list(self.last_angles),
            "peak_period": self.peak_period, "aux": self._aux.tolist(),
            "delayed": None if self._delayed is None else [v.tolist() for v in self._delayed],
            "smoother": None if self.smoother is None else self.smoother.get_state(), "result": self._result.__dict__,
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.reset()
        if s["dt"] is None:
            return
        self._start(float(s["dt"]))
        self.buf = np.array(s["buf"], dtype=float)
        self.k, self.next_detect = int(s["k"]), int(s["next_detect"])
        self._variance = None if s["variance"] is None else np.array(s["variance"], dtype=float)
        if s["omega"] is not None:
            self._use(self._build(np.array(s["omega"], dtype=float), self._variance))
        self.xp, self.x = np.array(s["xp"], dtype=float), np.array(s["x"], dtype=float)
        self.prev = None if s["prev"] is None else (s["prev"][0], np.array(s["prev"][1]))
        self.angles = [tuple(a) for a in s["angles"]]
        self.last_angles = tuple(s["last_angles"])
        self.peak_period = float(s["peak_period"])
        self._aux = np.array(s["aux"], dtype=float)
        self._delayed = None if s["delayed"] is None else tuple(np.array(v) for v in s["delayed"])
        self.smoother.set_state(s["smoother"])
        self._result = HeaveResult(**{**s["result"], "omega": tuple(s["result"]["omega"])})
