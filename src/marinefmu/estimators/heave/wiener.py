"""The ``model="wiener"`` heave estimator (beyond paper 003): the causal Wiener FIR filter
from vertical acceleration to heave, designed from the measured spectrum.

Why. The band observer (:mod:`.band_bank`) is the Wiener filter of its *model*; its
resonators spread each element's variance over a skirt, most harmfully below the sea's low
edge, where the model then claims heave that is not there and the filter lets accelerometer
noise through: on a long-period sea most of its error lies there, and the best causal filter
(:func:`~marinefmu.papers.paper003.causal_bound`) errs markedly less
(docs/decisions/heave-wiener.md). Here the filter is designed from the spectrum itself, with
no model shape in between.

Design, at every ``peak_interval`` after the first ``window`` (the window grows to
``window_max`` as in :class:`~.bank.OscillatorBankHeave`):

1. The acceleration spectrum S_ä of the window (:func:`~.spectrum.acceleration_spectrum`)
   less the sensor's noise S_n(ω) = N²/π + q²/(πω²) (``acc_noise`` N, white; ``offset_noise``
   q, the bias as a random walk; one-sided densities per rad/s), averaged over
   ±:data:`SMOOTHING`/2 of the frequency (⟨·⟩), gives the sea's heave spectrum
   S_z(ω) = max(⟨S_ä − S_n⟩, 0)/ω⁴ on [``omega_min``, ``omega_max``], zero elsewhere
   (:func:`sea_heave_density`). No ``band_min``: the subtraction finds the sea's low edge.
2. The taps act on block means ā of the acceleration over :data:`BLOCK` s, every
   :data:`BLOCK` s back over :data:`MEMORY` s (or as far as the data go). Their Wiener-Hopf equations R w = r are
   Toeplitz (``scipy.linalg.solve_toeplitz``, Levinson): R, the autocorrelation of ā under
   the model (sea plus noise; white noise only at lag 0, as blocks do not overlap), and r, the
   cross-correlation of the wanted output with ā, r(τ) = Σ S_z |B| Δω cos(ω(τ − ℓ) − ∠B) with
   B(ω) = −ω² times the block mean's response (for the rate, ω S_z and ∠B − π/2), for heave and
   heave rate now (ℓ = 0) and ``smoother_lag`` s ago (the delayed outputs, ℓ = the lag: the
   same R, two more right-hand sides). R also holds the measured acceleration above
   ``omega_max`` (up to the block mean's first null), which is not heave to estimate, so the
   filter does not amplify it. :func:`wiener_taps`.
3. Every step, the four outputs are the weights applied to the block means ending at the
   newest sample (a full-rate FIR of MEMORY/Δt taps, each block's weight spread over its
   samples, computed as differences of a running sum: L + 1 reads instead of L·M multiplies)
   of the acceleration less the window's mean (with the bias steps found, the ``offset``
   output; the weights sum to zero, so it changes no output).

Cost per step: every step, the ring writes and the L + 1 reads of the running sum (step 3)
and the point transfer; every :data:`STEP_CHECK` s the bias-step search; every
``peak_interval`` the design. The design's correlation sums Σ c(ω) e^{jωτ} over the frequency
grid and the L lags are one inverse FFT per right-hand side on the grid folded modulo its
period in ωτ (:func:`correlation_sums`), not (K, L) tables of cosines and sines: the grid is
uniform and its step times the tap spacing is 2π/N, so the two are the same sum, equal to the
rounding of the tables' own phases.

Bias steps. The output has no gain at zero frequency, so a constant bias never reaches it, but a
bias *step* in mid-run would stay in the spectrum window as a 1/ω² density, taken for sea at low
frequency for as long as the window holds it (``window_max``, 20 minutes by default), and the
heave would be decimetres wrong meanwhile (docs/decisions/heave-wiener.md). So every
:data:`STEP_CHECK` s the window is
searched for a step (:func:`~.bias_step.find_bias_step`: the kink it puts into the integrated
acceleration); one found is taken out of the window and of the filter's input from its first
sample on, and of every sample to come (the ``offset`` output includes it), and its size is
estimated again at every check for :data:`STEP_REFINE_AGE` s as the record after it grows. The
heave is then the heave of the run without the step (test). A warning is logged for each step.

No sea (a vessel in harbour, a constant input): a design that finds no density above the
sensor's noise keeps the filter it has, and before the first one there is none, so ``valid``
stays false. That is logged once when it starts, not at every design (every ``peak_interval``
for as long as the vessel lies still).

Bad samples (NaN, Inf, absurd values, :func:`~.common.read_sample`) enter the filter as the
window's mean (zero acceleration: the estimate decays to zero over the memory rather than
drifting), ``valid`` is false and a warning is logged. A change of step size restarts.
Not a library filter: scipy designs FIR filters from magnitude specifications
(``firwin2``, ``remez``), not least-squares Wiener filters from cross-spectra; the solve is
scipy's.
"""
from __future__ import annotations

import logging
import math
from dataclasses import replace
from fractions import Fraction
from typing import Any

import numpy as np
from scipy.linalg import solve_toeplitz

from .common import HeaveObserverParams, HeaveResult, SilentLog, backward_rate, point_heave, read_and_start, \
    vertical_acceleration
from .bias_step import BiasStep, find_bias_step
from .spectrum import Spectrum, acceleration_spectrum, band_integral, find_modes

log = logging.getLogger(__name__)

#: Tap spacing of the Wiener filter: the length of the acceleration block means it weighs [s].
BLOCK = 0.4
#: How far back the Wiener filter looks [s] (the causal bound changes by < 2 % from 120 to
#: 240 s, :func:`~marinefmu.papers.paper003.causal_bound`).
MEMORY = 180.0
#: Width of the moving average over the acceleration spectrum, relative to the frequency
#: (at least one bin): it steadies the periodogram's scatter without blurring the sea's
#: spectrum, and a width relative to the frequency did better than a fixed one on the
#: long-period seas (docs/decisions/heave-wiener.md).
SMOOTHING = 0.1
#: Interval of the search for a bias step in the buffered window (:mod:`.bias_step`) [s].
STEP_CHECK = 1.0
#: A step found is estimated again at every check until it is this old [s] …
STEP_REFINE_AGE = 600.0
#: … and the difference taken out when it reaches this [m/s²].
STEP_REFINE_MIN = 1e-4


def excess_acceleration(spectrum: Spectrum, acc_noise: float, offset_noise: float,
                        smoothing: float = SMOOTHING) -> np.ndarray:
    """The acceleration density above the sensor's noise, max(⟨S_ä − S_n⟩, 0)
    [(m/s²)²/(rad/s)], at the spectrum's frequencies (arguments as :func:`sea_heave_density`)."""
    omega = spectrum.omega
    noise = (acc_noise**2 + offset_noise**2 / omega**2) / math.pi
    half = np.maximum(0.5 * smoothing * omega, 0.5 * (omega[1] - omega[0]))
    excess = band_integral(omega, spectrum.acc_density - noise, omega - half, omega + half) / (2.0 * half)
    return np.maximum(excess, 0.0)


def sea_heave_density(spectrum: Spectrum, acc_noise: float, offset_noise: float, omega_min: float,
                      omega_max: float, smoothing: float = SMOOTHING) -> np.ndarray:
    """Step 1: the sea's heave spectrum S_z [m²/(rad/s)] at the spectrum's frequencies.

    Parameters
    ----------
    spectrum : Spectrum
        From :func:`~.spectrum.acceleration_spectrum` (one-sided density per rad/s).
    acc_noise : float
        Accelerometer white-noise density N [m/s²/√Hz].
    offset_noise : float
        Bias random-walk density q [m/s²/√s].
    omega_min, omega_max : float
        Band of the sea [rad/s].
    smoothing : float
        Width of the moving average over the excess density, relative to the frequency (at
        least one bin; :data:`SMOOTHING`).
    """
    omega = spectrum.omega
    sea = excess_acceleration(spectrum, acc_noise, offset_noise, smoothing) / omega**4
    sea[(omega < omega_min) | (omega > omega_max)] = 0.0
    return sea


def block_mean_response(w: np.ndarray, block: int, dt: float) -> np.ndarray:
    """Frequency response of the mean of ``block`` consecutive samples ``dt`` [s] apart, newest
    at lag 0: (1/M) Σ_m e^{−jωmΔt} = e^{−jω(M−1)Δt/2} sin(MωΔt/2) / (M sin(ωΔt/2)) (the
    geometric sum in closed form, without its cancellation at small ωΔt), at ``w`` [rad/s] > 0
    below 2π/Δt."""
    x = 0.5 * w * dt
    return np.exp(-1j * (block - 1) * x) * (np.sin(block * x) / (block * np.sin(x)))


def correlation_sums(coef: np.ndarray, w: np.ndarray, taps: int, spacing: float) -> np.ndarray:
    """Σ_k c_k e^{jω_k τ_j} for the lags τ_j = j·``spacing``, j = 0 … ``taps`` − 1, of rows of
    coefficients ``coef`` (R, K) at uniform frequencies ``w`` (K,) [rad/s].

    With ω_k = ω_0 + kΔω and ΔωT = 2πp/N for integers p, N (T the spacing), the sum is
    e^{jω_0τ_j} Σ_m V_m e^{2πjmj/N} with V_m the sum of the c_k with pk ≡ m (mod N): one
    inverse FFT of N points per row instead of a (K, L) table of cosines and sines. That holds
    for the grids :func:`wiener_taps` makes (Δω = π/(2·memory): p = 1, N = 4L; or the window's
    bin 2π/(nΔt): p = M, N = n), to within the rounding of ω_k τ_j that the table itself
    has; on any other grid the table is used.
    """
    d_omega = float(w[1] - w[0]) if len(w) > 1 else 0.0
    theta = d_omega * spacing / (2.0 * math.pi)
    tau = np.arange(taps) * spacing
    ratio = Fraction(theta).limit_denominator(1 << 18) if theta > 0.0 else Fraction(0)
    p, n = ratio.numerator, ratio.denominator
    # the phase error of the folded sum, k·j·|Δθ|, within the table's own: a few ulp of max ωτ
    if p > 0 and len(w) * taps * abs(2.0 * math.pi * (theta - p / n)) <= 8.0 * np.finfo(float).eps * w[-1] * tau[-1]:
        idx = (p * np.arange(len(w))) % n
        folded = np.zeros((len(coef), n), dtype=complex)
        for r in range(len(coef)):
            folded[r] = np.bincount(idx, coef[r].real, n) + 1j * np.bincount(idx, coef[r].imag, n)
        spectrum = np.fft.ifft(folded, axis=1) * n
        return np.exp(1j * w[0] * tau) * spectrum[:, np.arange(taps) % n]
    wt = np.outer(w, tau)
    return coef @ (np.cos(wt) + 1j * np.sin(wt))


def wiener_taps(omega: np.ndarray, heave_density: np.ndarray, dt: float, block: int, taps: int, lag: float,
                acc_noise: float, offset_noise: float, unwanted: np.ndarray | None = None) -> np.ndarray:
    """Step 2: the weights of the four outputs on the block means.

    Parameters
    ----------
    omega, heave_density : numpy.ndarray
        (K,) uniform frequencies [rad/s] and the sea's heave spectrum on them [m²/(rad/s)]
        (:func:`sea_heave_density`); interpolated onto a grid fine enough that the modelled
        correlations repeat only after four times the memory (a short window's bins, 2π/T
        apart, would make them repeat after T, within the memory, and the design singular).
    dt : float
        Sample interval [s].
    block : int
        Samples per block mean M.
    taps : int
        Number of blocks L.
    lag : float
        Delay of the delayed outputs [s].
    acc_noise, offset_noise : float
        As :func:`sea_heave_density`.
    unwanted : numpy.ndarray, optional
        (K,) acceleration density on ``omega`` that is not heave to estimate [(m/s²)²/(rad/s)]:
        the measured excess above ``omega_max`` (short waves a buoy follows, vibration). It
        enters the autocorrelation only, up to 2π/(M·Δt), the block mean's first null (beyond
        it the block mean passes ≤ 5 % of the power), so the filter does not amplify it:
        without it, a wind sea reaching just above ``omega_max`` meets a gain of two orders of
        magnitude there and its heave is wrong by twice its standard deviation (a test covers
        this case).

    Returns
    -------
    numpy.ndarray
        (4, L) weights of the block means of acceleration [m/s²], newest block first (block j
        is the samples j·M … j·M + M − 1 steps old), of heave [m], heave rate [m/s], and both
        ``lag`` s ago.
    """
    memory = taps * block * dt
    top = float(np.max(omega[heave_density > 0.0], initial=omega[0]))
    if unwanted is not None:
        first_null = 2.0 * math.pi / (block * dt)
        top = max(top, min(float(np.max(omega[unwanted > 0.0], initial=omega[0])), first_null))
    d_omega = min(omega[1] - omega[0], math.pi / (2.0 * memory))    # correlations periodic in 4× the memory
    w = np.arange(omega[0], top + d_omega, d_omega)
    s_z = np.interp(w, omega, heave_density)
    extra = np.zeros_like(w) if unwanted is None else np.interp(w, omega, unwanted)
    mean_response = block_mean_response(w, block, dt)
    b = -(w**2) * mean_response
    acc_density = np.abs(mean_response) ** 2 * (s_z * w**4 + extra + offset_noise**2 / (math.pi * w**2))
    # Σ_ω c(ω) e^{jωτ} for R (c real) and for each r (c = weight·e^{−j(β − shift)}):
    # Re Σ c e^{jωτ} = Σ Re c cos ωτ − Im c sin ωτ, i.e. Σ weight cos(ωτ − β + shift)
    coefficients = [acc_density * d_omega]
    for delay in (0.0, lag):
        beta = w * delay + np.angle(b)
        for weight, shift in ((s_z * np.abs(b) * d_omega, 0.0), (s_z * w * np.abs(b) * d_omega, 0.5 * math.pi)):
            coefficients.append(weight * np.cos(beta - shift) - 1j * (weight * np.sin(beta - shift)))
    sums = correlation_sums(np.array(coefficients), w, taps, block * dt)
    auto = sums[0].real
    auto[0] += acc_noise**2 / (block * dt)
    cross = list(sums[1:].real)
    solved = solve_toeplitz(auto, np.column_stack([*cross, np.ones(taps)]))
    weights, ones = solved[:, :4], solved[:, 4]                         # R⁻¹r (L, 4), R⁻¹1
    weights -= np.outer(ones, weights.sum(axis=0) / ones.sum())         # no gain at zero frequency
    return weights.T


class WienerAxis:
    """The causal Wiener filter of steps 1-3 (module docstring) on one scalar acceleration: the
    displacement and velocity along that axis now and ``smoother_lag`` s ago, with the bias-step
    search. :class:`WienerHeave` runs it on the vertical acceleration; the MotionReferenceUnit
    runs one per axis of the level frame.

    Parameters
    ----------
    params : HeaveObserverParams
        Uses ``window``, ``window_max``, ``peak_interval``, ``omega_min``, ``omega_max``,
        ``acc_noise``, ``offset_noise``, ``smoother_lag``, ``max_modes``, ``min_separation``
        and ``min_relative`` (as :class:`WienerHeave`).
    log : logging.Logger or SilentLog
        Where warnings go.
    label : str
        Names the axis in those warnings.
    reject_below : bool
        Whether the measured acceleration below ``omega_min`` enters the design as acceleration
        that is not motion to estimate (``unwanted`` of :func:`wiener_taps`), as that above
        ``omega_max`` always does. For a horizontal axis: there the attitude's slow tilt error ε
        puts g·ε into the acceleration, which a filter designed without it passes as metres of
        displacement below the sea's band. The vertical sees ε only at second order, and its
        low-frequency excess is the sea's own low edge.
    find_steps : bool
        Whether to search the window for bias steps (module docstring). Off where the design
        rejects the band below ``omega_min`` (``reject_below``): a step's 1/ω² density then
        meets no gain, and on a horizontal axis the tilt error's slow wander is found as steps
        that are not there.
    """

    def __init__(self, params: HeaveObserverParams, log: Any, label: str = "wiener heave",
                 reject_below: bool = False, find_steps: bool = True) -> None:
        self.params = params
        self.log = log
        self.label = label
        self.reject_below = reject_below
        self.find_steps = find_steps
        self.reset()

    def reset(self) -> None:
        """Back to the initial state."""
        self.dt: float | None = None
        self.k = 0
        self.next_detect = 0
        self.spectrum_buf = np.zeros(0)      # ring of window_max samples of a_v
        self.sum_buf = np.zeros((0, 0))      # running sum of a_v by block phase, twice over (:meth:`nodes`)
        self.taps: np.ndarray | None = None  # (4, L) weights of block sums, newest block first
        self.tap_sums = np.zeros(4)          # the taps' sums over the samples
        self.total = 0.0                     # the running sum at the newest sample
        self.mean = 0.0
        self.level = 0.0                     # bias steps found and taken out of the buffers [m/s²]
        self.step_at: int | None = None      # sample index of the last step found (refined as it ages)
        self.peak_period = 0.0
        self.peaks: tuple[float, ...] = ()   # frequencies of the sea's spectral peaks [rad/s]
        self.no_sea = False                  # the last design found no sea (logged once: module docstring)

    def start(self, dt: float, first_design: float | None = None, interval: float | None = None) -> None:
        """Size the buffers for the step ``dt`` [s]; the first design after ``first_design`` s
        of samples (``window`` if None; later to spread several axes' designs over time), the
        next every ``interval`` s (``peak_interval`` if None)."""
        p = self.params
        self.dt = dt
        self.interval_steps = max(1, int(round((p.peak_interval if interval is None else interval) / dt)))
        self.block = max(1, int(round(BLOCK / dt)))
        self.blocks = max(2, int(round(MEMORY / (self.block * dt))))
        self.n_fir = self.block * self.blocks
        self.slots = self.blocks + 1        # a phase's samples the ring keeps: the L + 1 nodes
        self.lag_steps = int(round(p.smoother_lag / dt))
        self.spectrum_buf = np.zeros(max(int(round(p.window / dt)), int(round(p.window_max / dt))))
        self.sum_buf = np.zeros((self.block, 2 * self.slots))
        self.next_detect = int(round((p.window if first_design is None else first_design) / dt))
        self.check_every = max(1, int(round(STEP_CHECK / dt)))

    @property
    def delay(self) -> float:
        """Lag of the delayed outputs [s]."""
        return 0.0 if self.dt is None else self.lag_steps * self.dt

    def _window(self) -> np.ndarray:
        """The buffered accelerations (at most ``window_max`` s), oldest first."""
        n = len(self.spectrum_buf)
        return np.roll(self.spectrum_buf, -(self.k % n))[-min(self.k, n):]

    def _design(self) -> None:
        """Steps 1-2 on the window: new taps and mean."""
        p = self.params
        self.next_detect = self.k + self.interval_steps
        win = self._window()
        self.sum_buf -= self.total          # keep the running sum near zero: its differences are unchanged
        self.total = 0.0
        spectrum = acceleration_spectrum(win, self.dt)
        excess = excess_acceleration(spectrum, p.acc_noise, p.offset_noise, SMOOTHING)
        sea = np.where((spectrum.omega >= p.omega_min) & (spectrum.omega <= p.omega_max), excess / spectrum.omega**4,
                       0.0)
        if not np.any(sea > 0.0):
            if not self.no_sea:
                self.log.warning("%s: no sea above the accelerometer noise in [%g, %g] rad/s; %s", self.label,
                                 p.omega_min, p.omega_max, "no filter yet, valid = false" if self.taps is None
                                 else "filter unchanged")
            self.no_sea = True
            return
        self.no_sea = False
        self.peak_period = 2.0 * math.pi / float(spectrum.omega[np.argmax(sea)])
        found = find_modes(replace(spectrum, position_amplitude=np.sqrt(sea)), p.omega_min, p.omega_max,
                           p.max_modes, p.min_separation, p.min_relative)
        self.peaks = tuple(float(w) for w in found.omega)
        blocks = min(self.blocks, self.k // self.block)           # no further back than the data
        above = np.where(spectrum.omega > p.omega_max, excess, 0.0)
        if self.reject_below:
            above = np.where(spectrum.omega < p.omega_min, excess, above)
        self.taps = np.ascontiguousarray(wiener_taps(spectrum.omega, sea, self.dt, self.block, blocks, self.delay,
                                                     p.acc_noise, p.offset_noise, above) / self.block)  # as restored
        self.tap_sums = self.taps.sum(axis=1) * self.block
        self.mean = float(win.mean())

    def _check_bias_step(self) -> None:
        """Look for a bias step in the window (:func:`~.bias_step.find_bias_step`) and take it
        out; else estimate the last one's size again on the longer record since it (its first
        estimate, made early, errs by about √2 σ_v / its age) and take out the difference."""
        win = self._window()
        first = self.k - len(win)
        found = find_bias_step(win, self.dt)
        if found is not None:
            self._relevel(found, first)
            self.step_at = first + found.index
            self.log.warning("%s: a bias step of %+.4f m/s² at t = %.1f s (%.0f s ago, z = %.1f) found "
                             "and taken out", self.label, found.size, self.step_at * self.dt,
                             (self.k - self.step_at) * self.dt, found.z)
        elif self.step_at is not None:
            if self.step_at <= first or (self.k - self.step_at) * self.dt > STEP_REFINE_AGE:
                self.step_at = None
                return
            again = find_bias_step(win, self.dt, at=self.step_at - first)
            if again is not None and abs(again.size) >= STEP_REFINE_MIN:
                self._relevel(again, first)

    def _relevel(self, found: BiasStep, first: int) -> None:
        """Take a bias step out of the buffers, from its first sample on (``first``: the
        absolute index of the window's oldest sample), and out of every sample to come."""
        start, size = first + found.index, found.size
        n = len(self.spectrum_buf)
        self.spectrum_buf[np.arange(max(start, self.k - n), self.k) % n] -= size
        stored = np.arange(max(start, self.k - self.n_fir - 1), self.k)     # those a node can still read
        phase, slot = stored % self.block, stored // self.block % self.slots
        for offset in (0, self.slots):
            self.sum_buf[phase, slot + offset] -= size * (stored - start + 1)
        self.total -= size * (self.k - start)
        self.level += size

    def response(self, omega: Any) -> np.ndarray | None:
        """Heave response H(e^{jωΔt}) of the current filter: the real-time heave estimate of a
        noise-free sinusoidal heave at ω [rad/s] is H(ω) times the truth (the filter sees −ω²
        times the heave). None before the first design."""
        if self.taps is None:
            return None
        w = np.asarray(omega, dtype=float)
        flat = w.reshape(-1, 1)
        blocks = np.exp(-1j * flat * (np.arange(self.taps.shape[1]) * self.block * self.dt)) @ self.taps[0]
        within = np.exp(-1j * flat * (np.arange(self.block) * self.dt)).sum(axis=1)
        return (-(w**2) * (blocks * within).reshape(w.shape))

    def push(self, a: float | None) -> np.ndarray | None:
        """One sample of the axis's acceleration ``a`` [m/s²] (None: a bad sample, which enters
        as the window's mean): step 3's outputs, displacement [m] and velocity [m/s] now and
        ``delay`` s ago, as a (4,) array; None before the first design. Every step: the ring
        writes and L + 1 reads of the running sum; every :data:`STEP_CHECK` s the bias-step
        search; every ``peak_interval`` the design."""
        self.record(a)
        if self.taps is None:
            return None
        return self.output()

    def record(self, a: float | None) -> None:
        """:meth:`push` without its outputs: the sample into the buffers (:meth:`accept`, the
        ring writes, :meth:`advance`), and the bias-step search and the design when they are
        due."""
        a_v = self.accept(a)
        self.spectrum_buf[self.k % len(self.spectrum_buf)] = a_v
        phase, slot = self.ring_position()
        self.sum_buf[phase, slot] = self.sum_buf[phase, slot + self.slots] = self.total
        self.advance()

    def ring_position(self) -> tuple[int, int]:
        """Where the sample about to be recorded (the k-th) goes in :attr:`sum_buf`: its phase
        in the block (row) and its block's slot (column, and the slot plus ``slots``)."""
        return self.k % self.block, self.k // self.block % self.slots

    def accept(self, a: float | None) -> float:
        """The sample ``a`` [m/s²] as the buffers take it, a_v = a − level (the window's mean
        for a bad one, None), added to the running sum; the ring writes follow."""
        a_v = self.mean if a is None else a - self.level
        self.total += a_v
        return a_v

    def advance(self) -> bool:
        """After a sample's ring writes: the sample count, and the bias-step search and the
        design when they are due; whether a design ran (the taps and mean may have changed)."""
        self.k += 1
        if self.find_steps and self.k % self.check_every == 0:
            self._check_bias_step()
        if self.k >= self.next_detect:
            self._design()
            return True
        return False

    def nodes(self, buf: np.ndarray, blocks: int) -> np.ndarray:
        """The running sums at the newest sample and every block before it, ``blocks`` + 1 of
        them, oldest first, from ``buf`` (this axis's ``sum_buf``, or a stack of such buffers
        along a first axis); a block's sum is the difference of two neighbours.

        The ring is laid out by block phase: row p holds the running sum at the samples k with
        k mod ``block`` = p, one column per block, each written twice (``slots`` apart), so
        that the nodes of any sample are one contiguous slice of one row: L + 1 neighbouring
        numbers to read rather than L + 1 cache lines ``block`` samples apart."""
        newest = self.k - 1
        slot = newest // self.block % self.slots + self.slots
        return buf[..., newest % self.block, slot - blocks:slot + 1]

    def output(self) -> np.ndarray:
        """Step 3's outputs of the current filter after :meth:`record` (as :meth:`push`)."""
        nodes = self.nodes(self.sum_buf, self.taps.shape[1])[::-1]          # newest first, as the taps
        return self.taps @ (nodes[:-1] - nodes[1:]) - self.mean * self.tap_sums

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        def arr(v: Any) -> Any:
            return None if v is None else np.asarray(v).tolist()
        return {"dt": self.dt, "k": self.k, "next_detect": self.next_detect,
                "interval_steps": None if self.dt is None else self.interval_steps, "spectrum_buf": arr(self.spectrum_buf),
                "sum_buf": arr(self.sum_buf), "total": self.total, "taps": arr(self.taps),
                "mean": self.mean, "level": self.level, "step_at": self.step_at, "peak_period": self.peak_period,
                "peaks": list(self.peaks), "no_sea": self.no_sea}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.reset()
        if s["dt"] is None:
            return
        self.start(float(s["dt"]))
        self.k, self.next_detect = int(s["k"]), int(s["next_detect"])
        # the design interval its owner started it with (a unit spreads several axes' designs)
        self.interval_steps = int(s.get("interval_steps") or self.interval_steps)
        self.spectrum_buf = np.array(s["spectrum_buf"], dtype=float)
        self.sum_buf = np.array(s["sum_buf"], dtype=float).reshape(self.block, 2 * self.slots)
        self.total = float(s["total"])
        if s["taps"] is not None:
            self.taps = np.array(s["taps"], dtype=float)
            self.tap_sums = self.taps.sum(axis=1) * self.block
        self.mean, self.level, self.peak_period = float(s["mean"]), float(s["level"]), float(s["peak_period"])
        self.step_at = None if s["step_at"] is None else int(s["step_at"])
        self.peaks = tuple(float(w) for w in s["peaks"])
        self.no_sea = bool(s["no_sea"])


class WienerGroup:
    """Several :class:`WienerAxis` filters stepped together, their outputs by one product.

    Each axis keeps its own buffers, spectrum, design and bias-step search; the group moves their
    running sums into one array, an axis's ring (:meth:`WienerAxis.nodes`) a slab of it (each
    axis's ``sum_buf`` a view of its slab, so the axes' own in-place updates land there), writes
    a step's sums with one store per copy, and holds their taps zero-padded to the longest
    memory and turned to act on the nodes oldest first, so that step 3 of all of them is one
    batched (A × 4 × L)·(A × L) product on contiguous rows, instead of one product and a dozen
    small numpy calls per axis. It restacks the taps only after a design. The outputs equal
    each axis's :meth:`WienerAxis.push` to rounding (the sums are formed in another order; the
    padding multiplies finite sums by zero).

    Parameters
    ----------
    axes : sequence of WienerAxis
        Filters with the same step and memory (the same ``dt``, ``block`` and ``blocks``) and
        sample count, pushed every step. (The spectrum rings stay apart: at a step of 1 µs each
        is gigabytes of untouched zeros, which a stacked copy would have to write.) Call :meth:`bind` after their ``start`` or ``set_state``, which
        give them new buffers.
    """

    def __init__(self, axes: list[WienerAxis]) -> None:
        self.axes = list(axes)
        self.sums = np.zeros((len(self.axes), 0))
        self._stale = True                                 # the stack below is not the axes' taps
        self._taps = np.zeros((len(self.axes), 4, 0))
        self._node_taps = np.zeros((len(self.axes), 4, 1))
        self._offsets = np.zeros((len(self.axes), 4))     # mean × the taps' sums, per axis

    def __setstate__(self, state: dict) -> None:
        """Unpickled or deep-copied: each axis's ``sum_buf`` a view of its slab again (a copy
        copies a view's data apart from its base; the axes' updates would then miss the slab
        the outputs are read from)."""
        self.__dict__.update(state)
        if self.sums.ndim == 3:                            # bound
            self._link_axes()

    def _link_axes(self) -> None:
        """Each axis's ``sum_buf`` a view of its slab of :attr:`sums`."""
        for row, axis in zip(self.sums, self.axes):
            axis.sum_buf = row

    def bind(self) -> None:
        """Move the axes' running sums into one array (after their ``start`` or ``set_state``)."""
        first = self.axes[0]
        if any(a.dt != first.dt or a.block != first.block or a.blocks != first.blocks or a.k != first.k
               for a in self.axes):
            raise ValueError("WienerGroup: the axes must share dt, block, blocks and the sample count")
        self.sums = np.zeros((len(self.axes), *first.sum_buf.shape))
        for row, axis in zip(self.sums, self.axes):
            if axis.k:             # restored or running: carry its sums (fresh ones are zeros, left untouched)
                row[:] = axis.sum_buf
        self._link_axes()
        self._stale = True

    def push(self, values: list[float | None]) -> np.ndarray | None:
        """One sample per axis (as :meth:`WienerAxis.push`): the (A, 4) outputs, a row per axis,
        or None while any axis has no design yet."""
        axes = self.axes
        first = axes[0]
        k = first.k
        phase, slot = first.ring_position()
        totals = []                                     # WienerAxis.record for all axes
        for axis, a in zip(axes, values):
            axis.spectrum_buf[k % len(axis.spectrum_buf)] = axis.accept(a)
            totals.append(axis.total)
        sums = self.sums
        sums[:, phase, slot] = totals
        sums[:, phase, slot + first.slots] = totals
        for axis in axes:
            if axis.advance():                          # only a design changes the taps and the mean
                self._stale = True
        if self._stale:
            if any(a.taps is None for a in axes):
                return None
            self._stack_taps()
        nodes = axes[0].nodes(self.sums, self._taps.shape[2])      # (A, L + 1), each row contiguous
        return np.matmul(self._node_taps, nodes[:, :, None])[:, :, 0] - self._offsets

    def _stack_taps(self) -> None:
        """The axes' current taps, zero-padded to the longest, their differences and their mean
        terms.

        A block's sum is the difference of two neighbouring nodes n_j, so the taps h_j act on
        the nodes as d_j = h_j − h_{j−1} (h_{−1} = h_L = 0): Σ_j h_j (n_j − n_{j+1}) =
        Σ_j d_j n_j, one product on the L + 1 nodes and no subtraction of L columns. The
        d_j sum to zero, so the nodes' common part (the running sum's level) cancels as it
        did in the differences, to the same rounding."""
        longest = max(a.taps.shape[1] for a in self.axes)
        self._taps = np.zeros((len(self.axes), 4, longest))
        for row, axis in zip(self._taps, self.axes):
            row[:, :axis.taps.shape[1]] = axis.taps
        padded = np.zeros((len(self.axes), 4, longest + 2))
        padded[:, :, 1:-1] = self._taps
        # (A, 4, L + 1): d_j = h_j − h_{j−1}, oldest node first as :meth:`WienerAxis.nodes` gives them
        self._node_taps = np.ascontiguousarray(np.diff(padded, axis=2)[:, :, ::-1])
        self._offsets = np.array([a.mean * a.tap_sums for a in self.axes])
        self._stale = False


class WienerHeave(WienerAxis):
    """Heave at the IMU and at a point by the spectrum's causal Wiener filter (module docstring):
    :class:`WienerAxis` on the vertical acceleration, and step 4.

    Parameters
    ----------
    params : HeaveObserverParams, optional
        Uses ``window``, ``window_max``, ``peak_interval``, ``omega_min``, ``omega_max``,
        ``acc_noise``, ``offset_noise``, ``smoother_lag``, ``vertical``, ``transfer`` and
        ``point``; ``max_modes``, ``min_separation`` and ``min_relative`` for the peaks of the
        sea's heave spectrum reported as ``modes`` and ``omega`` (the filter has no modes;
        :func:`~.spectrum.find_modes` on √S_z: swell and wind sea). ``model`` is ignored.
    quiet : bool
        Log nothing.

    Examples
    --------
    >>> wh = WienerHeave(HeaveObserverParams(model="wiener", window=60.0))
    >>> r = wh.step((0.0, 0.0, -9.80665), 0.0, 0.0, 0.1)
    >>> r.valid      # no spectrum before the first window is full
    False
    """

    def __init__(self, params: HeaveObserverParams | None = None, *, quiet: bool = False) -> None:
        super().__init__(params or HeaveObserverParams(model="wiener"), SilentLog() if quiet else log)

    def reset(self) -> None:
        """Back to the initial state."""
        super().reset()
        self.angle_buf: list[tuple[float, float]] = []   # ring of (roll, pitch) for the delayed point

    def start(self, dt: float, first_design: float | None = None, interval: float | None = None) -> None:
        super().start(dt, first_design, interval)
        self.angle_buf = [(0.0, 0.0)] * (self.lag_steps + 3)

    def _angles(self, age: int, count: int) -> list[tuple[float, float]]:
        """``count`` (roll, pitch) samples [rad], oldest first, ending ``age`` samples before the
        newest stored one."""
        buf = self.angle_buf
        n = len(buf)
        end = self.k - 1 - age
        return [buf[(end - j) % n] for j in range(count - 1, -1, -1)]

    def step(self, acc: Any, roll: float, pitch: float, dt: float) -> HeaveResult:
        """Process one sample (arguments as :meth:`.OscillatorBankHeave.step`)."""
        p = self.params
        f, roll, pitch, warning = read_and_start(self, acc, roll, pitch, dt)
        a_v = None
        if warning is None:
            a_v = vertical_acceleration(f, roll, pitch, p.vertical)
        else:
            self.log.warning("%s: %s; the window's mean acceleration used", self.label, warning)
            roll, pitch = self._angles(0, 1)[0] if self.k else (0.0, 0.0)      # the last good ones
        self.angle_buf[self.k % len(self.angle_buf)] = (roll, pitch)
        out = self.push(a_v)
        if out is None:
            return HeaveResult(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, self.delay, 0.0, 0, 0.0, (), False, False,
                               warning)
        heave, rate, d_heave, d_rate = out.tolist()
        rates = backward_rate(self._angles(0, min(3, self.k)), self.dt)
        ph, pr = point_heave(heave, rate, p.point, roll, pitch, *rates, p.transfer)
        old = self._angles(self.lag_steps, 3)
        d_point, _ = point_heave(d_heave, d_rate, p.point, *old[-1], *backward_rate(old, self.dt), p.transfer)
        delayed_valid = self.k * self.dt >= p.window + self.delay
        return HeaveResult(heave, rate, ph, pr, d_heave, d_rate, d_point, self.delay,
                           self.level + self.mean, len(self.peaks), self.peak_period, self.peaks, warning is None,
                           delayed_valid, warning)

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {**super().get_state(), "angle_buf": [list(a) for a in self.angle_buf]}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        super().set_state(s)
        if s["dt"] is not None:
            self.angle_buf = [(float(r), float(p)) for r, p in s["angle_buf"]]
