"""GNSS-aided band observer of one NED axis: the wave model of a GNSS dropout coast (beyond
papers 001 and 003).

Why. The coast of :mod:`.wave_coast` used to run the band observer of paper 003 on the
acceleration alone and add a straight line fitted to the GNSS anchors z − d_w. That observer's
wave displacement d_w was then only as good as the accelerometer makes it, all the time: on the
paper-001 set-up its east error was 3.5 cm RMS (8 cm max) on a 57 cm sway *before* any gap,
mostly from g × the antenna-attitude error at 0.1-0.3 rad/s, which the accelerometer cannot
tell from sway. GNSS sees that displacement, but a line through the anchors could not give it
back to the wave states. Applying the fixes to the band observer with its acceleration-only
steady-state covariance did not work either (worse: the gain was wrong once positions are
measured). The states need one covariance that knows both measurement types.

Model. One Kalman filter with the state

    x = [band elements …, offset, drift position p_d, drift velocity v_d (, tilt ε, rate δ
         (, wave-tilt elements …))]

* the band elements and the offset are the band observer's model
  (:func:`~.band_bank.build_band_bank`: damped resonators weighted by the measured spectrum, a
  random-walk offset) in its decorrelated ``"increment"`` form: the measurement is the mean
  acceleration of a step y = C x + v, and the prediction x⁺ = Ā x + J y (Simon 2006, 7.1;
  :mod:`.oscillator_bank`);
* the drift (p_d, v_d) is a constant-velocity model driven by white acceleration of density
  q_d (filterpy ``Q_continuous_white_noise``). It carries what the accelerometer does not see
  (a vessel on station or drifting steadily has no acceleration of its own below the waves):
  it has no row in C;
* the acceleration of a step updates the band and the offset (R of the band model); a GNSS
  position of the axis, z = Σ heave_j + p_d + e (σ :data:`FIX_SIGMA`), updates everything,
  so the position fixes anchor the wave states too.

The covariance is propagated in full (not a steady-state gain): the fixes come at another rate
than the acceleration and stop in a gap, where the filter turns, step by step, into the
acceleration-only observer. With no fix ever, and started on the band model's steady-state
covariance, it *is* that observer (a test checks the states to 1e-9).

Written out rather than with filterpy's ``KalmanFilter``: every measurement here is a scalar,
for which the plain update K = P hᵀ/s, P ← P − s K Kᵀ costs O(n²), and filterpy's Joseph-form
update O(n³) (n ≈ 60-220): the fusion of the 340 s dropout record below took about 6.5 s with
filterpy's filter and 5 s written out (4 s with the line coast before). A test runs the same
sequence through a filterpy ``KalmanFilter`` and compares.

When the band observer's spectrum changes the element set (every
:data:`~.wave_coast.PEAK_INTERVAL` s), state and covariance are carried by
:func:`~.oscillator_bank.carry_map` (P ← T P Tᵀ); an element with no predecessor starts from the
new model's steady-state covariance, uncorrelated with the rest. Two alternatives were worse on
east (30 dropouts below): the new model's steady-state covariance for the whole band (what the
fixes told is lost when the change falls at the start of a gap), and that covariance less the
carried reduction the fixes made.

Measured without the tilt states below (``coast_tilt`` false) on the paper-001 set-up (1 Hz
RTK, a 30 s dropout, max error through the gap of the fused real-time output; the coast's
acceleration corrected with its own attitude (``coast_attitude_tau`` 150 s of :class:`~.gnss_fusion.GnssAccFusionParams`), spectrum window
:data:`~.wave_coast.SPECTRUM_WINDOW` 180 s, the step means of :meth:`WaveCoast.add
<.wave_coast.WaveCoast.add>`; ``make bench``, part ``dropout``, 2026-11-24; in brackets before
the step-mean fix of that day, then the fusion's attitude and a 120 s window):

* dropout at 300 s (the test's), seeds 1-10: east 6.7 / 4.1 / 7.7 / 7.4 / 5.8 / 8.0 / 6.0 /
  5.7 / 7.2 / 4.8 cm (7.5 / 3.6 / 9.6 / 8.1 / 6.0 / 7.5 / 6.4 / 5.5 / 9.5 / 4.4; 8.4 / 4.7 /
  8.4 / 9.4 / 6.2 / 5.7 / 7.5 / 6.1 / 9.0 / 5.7), against 8.4 / 3.8 / 11.2 / 12.0 / 6.0 / 7.9 /
  9.5 / 10.3 / 8.2 / 8.1 cm with the line through the anchors; north at most 5.7 cm, down at
  most 5.3 cm (6.5; 8.0; line: 5.7 and 6.0 cm);
* 60 dropouts, at 270, 300 and 320 s of seeds 1-10, at 400 s of seeds 11-20 and at 350 s of
  seeds 21-40: east at 10 cm or more in 4 (worst 15.4 cm, seed 27 at 350 s), mean N / E / D
  1.9 / 6.6 / 3.1 cm (3, 17.1 cm, 1.9 / 7.1 / 4.3 cm); the line: 12 of the first 30 (at most
  14.6 cm). The best linear estimator that knows the joint statistics of the sea and the
  sensors errs far less on the same dropouts (:mod:`marinefmu.papers.gap_bound`).

Tilt states (2026-11-24, :class:`Tilt`, ``coast_tilt`` of
:class:`~.gnss_fusion.GnssAccFusionParams`). The horizontal acceleration is off by g × the error of
the attitude that corrects it, ε: east by −g·ε_N, north by +g·ε_E (checked on the paper-001
record: the 20 s means of a_used − a_true equal g·ε to 0.5 mm/s², with ε 1-4 mrad and the
accelerometer bias under 1 mm/s²). Until then a loose random-walk offset
(:data:`~.wave_coast.HORIZONTAL_OFFSET_NOISE`, ten times the heave observer's) stood in for
g·ε, and took a few percent of the sway at the wave peak with it (|1 − H| 3 % at 0.77 rad/s).
Now the north and east filters carry ε and the gyro-bias error δ that turns it,

    ε̇ = δ + w,  δ Gauss-Markov (the gyro's bias instability and correlation time),
    w white (the gyro's white noise, its angle random walk; ARW below),

with ``gain``·ε in the acceleration row (and −J·gain in Ā, the increment form's feed-through),
measured at every fix by the antenna attitude's error against the coast's attitude (σ from the
antenna geometry, :func:`~.antenna_attitude.antenna_attitude_std`: 1.9 / 0.75 mrad about N / E on
the paper-001 set-up, as measured). The coast's PI pulls move ε and δ by known amounts
(:meth:`AidedBand.shift_tilt`). The offset keeps the heave observer's noise (1e-4), the
accelerometer bias alone; at the first band model it restarts at 0 ± 2 mm/s², because the
observer's own offset had taken g·ε (started on it, ε was estimated 1.5 mrad off on seed 27;
restarted, 0.24 / 0.15 mrad RMS about N / E over 190 s, with the 1.3 → 4.2 mrad growth of ε_N
through the gap followed to 0.5 mrad). On a synthetic tilt swing the gap error falls from
9.1-9.3 to 4.8-5.6 cm (test). Over the 60 dropouts (``make bench``, part ``dropout``,
2026-11-24): east at 10 cm or more in 2 instead of 4 (seed 27 at 350 s 11.8 cm instead of
15.4, seed 36 10.8 instead of 8.0), mean N / E / D 2.0 / 6.6 / 3.1 cm (1.9 / 6.6 / 3.1).
Scans: with an offset noise of 3e-4 also 2 (12.2 cm worst, mean east 6.6 cm);
``gyro_bias_sigma`` 1e-4, 3; ``coast_attitude_tau`` 50 s, 3 (13.1 cm). With the tilt states the
band observers' spectrum counts too: with the heave observer's own settings (a growing window,
integrated variances; :mod:`.wave_coast`) 1 of the 60 (10.7 cm, seed 27), mean N / E / D
2.0 / 6.3 / 3.0 cm; with the element weights smoothed over neighbours
(:data:`~.wave_coast.BAND_SMOOTHING`) none (worst 9.7 cm), mean 2.0 / 6.1 / 2.9 cm, but 1 of the
same 60 later in a run (10.4 cm, seed 2 at 1200 s) (``make bench``, part ``dropout``,
2026-11-24).

ARW (session 32, 2026-11-24): the coast's attitude integrates the gyro's white noise too, a
random walk of ε of density ``noise`` (:class:`Tilt`, the fusion's ``gyro_noise``), which
the tilt states used to leave out (Q on ε zero). With it, on a synthetic tilt that walks at
5e-4 rad/s/√Hz, the tilt estimate errs what its covariance says (RMS / σ 0.74-1.01 over ten
seeds, against 4.0-8.7 without) and the gap error falls from 14-54 to 9-14 cm (test). On the
paper-001 set-up (scans): over 200 fresh 30 s dropouts east reaches 10 cm in 1 instead of 3,
mean 5.78 cm instead of 5.87, 95th percentile 8.1 cm instead of 8.3; with a gyro of 1e-5
rad/s bias instability and the MEMS white noise seed 27 at 350 s errs 10.1 cm instead of
12.2, with a tactical-grade gyro 8.3 instead of 8.5 cm. On the 60 early bench dropouts the
mean east falls 6.06 → 5.90 cm, but seed 27 at 350 s rises 9.7 → 10.7 cm: the tail moves,
as with every change here.

Wave tilt (session 33, 2026-11-24, :meth:`AidedBand.follow_angle`, :meth:`AidedBand.wave_tilt`;
:mod:`.wave_coast`, "The wave tilt"): the correcting attitude's own tilt, the vessel's wave
roll or pitch less ε, measured at every band step through a band model of the wave tilt that
sits after the tilt states. It is a second measurement of ε that goes on in a gap. On the
synthetic swing with the MEMS gyro's angle random walk the gap error falls from 6.3 to 4.6 cm
on average (test); on the paper-001 set-up see :mod:`.wave_coast`.

What is left on east is at the wave frequency: through seed 27's gap the error swung ±9 cm
at the 8 s peak period on a ±1.5 m sway (±4 cm with the true attitude; before the spectrum
settings). What tells the sway
in a gap beyond the acceleration is the roll the gyro measures
(:mod:`marinefmu.papers.gap_bound`); this filter does not use it. Split by input (the filter
replayed with one input real and the others true, 2026-11-24, README): the true tilt that the
tilt states must follow through the gap is the largest part on seeds 3 and 10 (2.6 cm RMS),
and with every input true the tilt states cost 1.3 → 3.0 cm RMS on seed 27: in a gap they
follow ε with a bandwidth of about 0.37 rad/s, so what the band model misses at the wave peak
partly lands in ε. Measured and not taken
before the tilt states: lower offset noise, an offset-rate state, another offset noise in gaps
only, a smoothed spectrum, and the fixes' attitude as a measurement of the offset itself
(``docs/paper001_dropout.md``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.common import Q_continuous_white_noise

from ..heave.oscillator_bank import BankModel, carry_map


@dataclass(frozen=True)
class Tilt:
    """The tilt error of the attitude that corrects the axis's acceleration, as two states.

    ε [rad] is the component of that attitude's error (n frame, true = exp(ε)·used) whose
    g-multiple lands on this axis: the axis's acceleration is off by ``gain``·ε (east −g·ε_N,
    north +g·ε_E; :class:`~.wave_coast.WaveCoast`). It grows with the gyro-bias error
    δ [rad/s] and the gyro's white noise, ε̇ = δ + w, δ a Gauss-Markov process of standard
    deviation ``bias_sigma`` and correlation time ``bias_tau``, w white of density ``noise``
    (the angle random walk; the gyro's datasheet). Each GNSS fix's antenna attitude measures ε
    (:meth:`AidedBand.attitude_fix`).
    """

    gain: float                       # [m/s²/rad]
    bias_sigma: float                 # [rad/s]
    bias_tau: float                   # [s]
    noise: float = 0.0                # white-noise density of the gyro [rad/s/√Hz]
    prior: float = 5e-3               # standard deviation of ε at a start [rad]
    offset_prior: float = 2e-3        # standard deviation of the offset at the first model [m/s²]

#: Standard deviation of a GNSS position of the accelerometer point, per axis [m]. Four RTK
#: antennas (1 cm) average to 0.5 cm, and the lever arm turned with the propagated attitude adds
#: its share; of 0.5, 1, 2 and 5 cm, 2 cm coasted best (max east error through the dropout of
#: seeds 1-3: 9.2 / 5.6 / 8.5, 8.9 / 5.1 / 8.5, 8.4 / 4.8 / 8.4, 8.4 / 4.5 / 8.7 cm).
FIX_SIGMA = 0.02
#: Prior standard deviations of the drift position [m] and velocity [m/s] at a (re)start.
DRIFT_PRIOR = (10.0, 1.0)
#: Standard deviation of the correcting attitude's own tilt as a measurement of the wave-tilt
#: band less ε [rad] (:meth:`AidedBand.wave_tilt`). The angle itself is exact to 1e-6 rad RMS
#: (the split θ_used = θ − ε, checked about N on the paper-001 record); this allows for the
#: band model's misfit of a narrow roll spectrum. Scans on three of the hardest 30 s dropouts
#: (max east error, seeds 27 / 120 / 54, 2026-11-24): 1e-4 11.3 / 8.1 / 10.3 cm, 1e-3 10.1 / 9.2 / 10.3 cm,
#: 3e-3 10.3 / 9.6 / 10.7 cm (damping 0.1; without the band 10.7 / 10.1 / 10.9 cm).
ANGLE_SIGMA = 1e-3


def restart(x: np.ndarray, p: np.ndarray, idx, cov: np.ndarray, value: np.ndarray | float = 0.0) -> None:
    """Restart the states ``idx`` of (x, P) in place at ``value`` with covariance ``cov``,
    uncorrelated with the rest."""
    idx = np.asarray(idx, dtype=int)
    p[idx, :] = 0.0
    p[:, idx] = 0.0
    p[np.ix_(idx, idx)] = cov
    x[idx] = value


def drift_noise(window: float, sigma: float = FIX_SIGMA, fix_interval: float = 1.0) -> float:
    """Acceleration density q_d [m²/s³] of the drift model that remembers about ``window`` s.

    A constant-velocity Kalman filter with position noise of density r = σ²·T (fixes of σ
    every T s) settles to the bandwidth ω_n = (q_d/r)^(1/4); q_d = σ²T(2π/window)⁴ makes that
    one cycle per ``window``, the span the line through the anchors used to fit.

    Examples
    --------
    >>> f"{drift_noise(120.0):.2e}"
    '3.01e-09'
    """
    return sigma**2 * fix_interval * (2.0 * math.pi / window) ** 4


def blocks_times(blocks: np.ndarray, m: np.ndarray) -> np.ndarray:
    """diag(blocks) @ m for a block-diagonal matrix given by its (k, s, s) ``blocks`` and an
    (k·s, c) ``m``, element by element (:meth:`AidedBand._predict`)."""
    k, s, _ = blocks.shape
    return np.matmul(blocks, m.reshape(k, s, -1)).reshape(k * s, -1)


class AidedBand:
    """Band elements, offset and drift of one axis in one Kalman filter (module docstring).

    Parameters
    ----------
    q_drift : float
        Acceleration density of the drift model [m²/s³] (:func:`drift_noise`), > 0.
    dt : float
        Step of the acceleration samples [s] (that of the band observer's model).

    Examples
    --------
    >>> f = AidedBand(drift_noise(120.0), 0.05)
    >>> f.fix(1.5, 0.0)           # no band model yet: the drift alone takes the fix
    >>> round(f.position(0.0), 3)
    1.5
    """

    def __init__(self, q_drift: float, dt: float, tilt: Tilt | None = None) -> None:
        self.q_drift = float(q_drift)
        self.dt = float(dt)
        self.tilt = tilt
        self.n_extra = 2 if tilt is None else 4     # drift (and tilt) states after the band
        self.model: BankModel | None = None
        self.angle: BankModel | None = None         # the wave tilt's band (wave_tilt), after them
        self.weak_tilt: float | None = None         # or the variance of a wave tilt too weak for one [rad²]
        self.fixes = 0                      # fixes since the last drift restart
        self._configure()
        self.x = np.zeros(self.n_extra)     # state (module docstring)
        prior = list(np.square(DRIFT_PRIOR))
        if tilt is not None:
            prior += [tilt.prior ** 2, tilt.bias_sigma ** 2]
        self.P = np.diag(prior)

    # ---- model -------------------------------------------------------------------------------
    @property
    def n_band(self) -> int:
        """Band elements' and offset states (0 without a model)."""
        return 0 if self.model is None else self.model.n

    @property
    def n_angle(self) -> int:
        """States of the wave tilt's band (0 without one), the last of the state."""
        return 0 if self.angle is None else self.angle.n - 1

    def _configure(self) -> None:
        """Transition F, feed-through J, process noise Q and acceleration row C of the current
        model plus the drift (and the tilt states, and the wave tilt's band)."""
        m, n, t = self.model, self.n_band, self.tilt
        size = n + self.n_extra + self.n_angle
        d = n                               # drift position, velocity at d, d + 1
        self.F = np.eye(size)
        self.F[d, d + 1] = self.dt
        self.Q = np.zeros((size, size))
        self.Q[d:d + 2, d:d + 2] = Q_continuous_white_noise(2, self.dt, self.q_drift)
        self.J = np.zeros(size)
        self.C = np.zeros(size)
        if m is not None:
            self.F[:n, :n] = m.A_bar
            self.J[:n] = m.J
            self.Q[:n, :n] = m.Q
            self.C[:n] = m.C
        if t is not None:                   # ε at d + 2, δ at d + 3
            phi = math.exp(-self.dt / t.bias_tau)
            self.F[d + 2, d + 3] = t.bias_tau * (1.0 - phi)
            self.F[d + 3, d + 3] = phi
            self.Q[d + 3, d + 3] = t.bias_sigma ** 2 * (1.0 - phi * phi)
            self.Q[d + 2, d + 2] = t.noise ** 2 * self.dt      # the angle random walk
            self.C[d + 2] = t.gain
            # decorrelated increment form: Ā = A − J C over the tilt's column too
            self.F[:n, d + 2] = -self.J[:n] * t.gain
        if self.angle is not None:          # the wave tilt's elements, without their offset
            a, s = n + self.n_extra, self.angle.block
            self.F[a:, a:] = self.angle.A[:-1, :-1]
            self.Q[a:, a:] = self.angle.Q[:-1, :-1]
            self._angle_blocks = np.stack([self.F[a + i:a + i + s, a + i:a + i + s]
                                           for i in range(0, self.n_angle, s)])
        self.rows = np.zeros((2, size))     # position and velocity of the axis
        if m is not None:
            self.rows[:, :n] = m.heave_rows
        self.rows[0, d] = self.rows[1, d + 1] = 1.0

    def follow(self, model: BankModel, band_state: np.ndarray) -> None:
        """Adopt the band observer's (new) model, built for this filter's step.

        The first model starts the band at ``band_state`` (the observer's own, replayed over its
        window) with the model's steady-state covariance; a later one carries state and
        covariance over (module docstring).
        """
        old, n_new, e = self.model, model.n, self.n_extra + self.n_angle
        t = np.zeros((n_new + e, self.n_band + e))
        t[-e:, -e:] = np.eye(e)
        if old is not None:
            t[:n_new, :old.n] = carry_map(old.omega, model.omega, model.block)
        x, p = self._carry(t, 0, n_new, model, band_state if old is None else None)
        if old is None and self.tilt is not None:
            # the observer's offset holds the tilt's g·ε as well: start it at 0 with the
            # accelerometer-bias prior and let the tilt states take the rest (Tilt)
            o = [n_new - 1]
            restart(x, p, o, np.diag([self.tilt.offset_prior ** 2]))
        self.model = model
        self._configure()
        self.x, self.P = x, p

    def follow_angle(self, model: BankModel, band_state: np.ndarray) -> None:
        """Adopt the (new) model of the wave tilt about this axis's tilt axis: the band of an
        observer of the tilt's second difference (:class:`~.wave_coast.WaveCoast`), its offset
        left out. As :meth:`follow`: the first model starts at that observer's ``band_state``
        with the model's steady-state covariance, a later one carries state and covariance."""
        if self.tilt is None:
            raise ValueError("a wave-tilt measurement needs the tilt states (tilt)")
        old, b = self.angle, self.n_band + self.n_extra
        t = np.zeros((b + model.n - 1, b + self.n_angle))
        t[:b, :b] = np.eye(b)
        if old is not None:
            t[b:, b:] = carry_map(old.omega, model.omega, model.block)[:-1, :-1]
        x, p = self._carry(t, b, model.n - 1, model, band_state if old is None else None)
        self.angle, self.weak_tilt = model, None
        self._configure()
        self.x, self.P = x, p

    def _carry(self, t: np.ndarray, at: int, n: int, model: BankModel,
               band_state: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """State and covariance mapped by ``t`` to a new element set of ``model`` whose first
        ``n`` states sit at ``at``: set to ``band_state`` (its first ``n``) on a first model, and
        elements with no predecessor restarted on the model's steady-state covariance."""
        x, p = t @ self.x, t @ self.P @ t.T
        if band_state is not None:
            x[at:at + n] = np.asarray(band_state, dtype=float)[:n]
        fresh = np.flatnonzero(~t[at:at + n].any(axis=1))
        restart(x, p, at + fresh, model.P[np.ix_(fresh, fresh)], x[at + fresh])
        return x, p

    def weak_angle(self, variance: float) -> None:
        """The wave tilt about this axis's tilt axis is too weak to model (its variance
        ``variance`` [rad²] under :data:`ANGLE_SIGMA`²): drop its band, if any, and let
        :meth:`wave_tilt` measure ε alone, the tilt's variance added to the noise."""
        if self.tilt is None:
            raise ValueError("a wave-tilt measurement needs the tilt states (tilt)")
        b = self.n_band + self.n_extra
        self.x, self.P = self.x[:b], self.P[:b, :b]
        self.angle, self.weak_tilt = None, float(variance)
        self._configure()

    # ---- measurements ------------------------------------------------------------------------
    def accelerate(self, y: float) -> None:
        """One step with ``y`` [m/s²], the mean acceleration over the step that ends now (the
        increment model's measurement): the update, then the prediction to now (without a band
        model the drift is only predicted).

        ``y`` must be the mean over *this* step (:meth:`~.wave_coast.WaveCoast.add` gives the
        trapezoid mean of the accelerometer's point samples). Until 2026-11-24 this method
        averaged its argument, a block mean of five 100 Hz samples, with the previous one, as
        the heave observer does with point samples: the band states then lagged 20 ms more
        (measured on a sine: 31.4 ms against the model's own 11.4 ms; 1.6 % of the sway at
        0.8 rad/s), half of the coast's error with perfect sensors (``docs/paper001_dropout.md``).
        """
        if self.model is None:
            self._predict(0.0)
            return
        self._update(y, self.C, self.model.R)
        self._predict(y)

    def fix(self, z: float, lead: float, sigma: float = FIX_SIGMA) -> None:
        """Update with a GNSS position ``z`` [m] of the axis taken ``lead`` s after the band
        states' time (the end of the last band step); ``sigma`` its standard deviation [m]."""
        self._update(z, self._row(lead), sigma**2)
        self.fixes += 1

    def attitude_fix(self, e: float, sigma: float, lead: float) -> None:
        """Update the tilt states with the attitude error ``e`` [rad] that a GNSS fix's antenna
        attitude measured with standard deviation ``sigma`` [rad], ``lead`` s after the band
        states' time (:class:`Tilt`)."""
        if self.tilt is None:
            return
        h = np.zeros(len(self.x))
        i = self.n_band + 2
        h[i], h[i + 1] = 1.0, lead
        self._update(e, h, sigma ** 2)

    def wave_tilt(self, angle: float, sigma: float = ANGLE_SIGMA) -> None:
        """Update with the correcting attitude's own tilt about this axis's tilt axis now (the
        end of the last band step), ``angle`` [rad, NED]: the vessel's wave tilt, the sum of
        the wave-tilt band's elements, less ε (:class:`~.wave_coast.WaveCoast`); ``sigma`` its
        standard deviation [rad]; with a wave tilt too weak for a band (:meth:`weak_angle`) ε
        alone, the tilt's variance added. Before either: nothing."""
        if self.angle is None and self.weak_tilt is None:
            return
        h = np.zeros(len(self.x))
        h[self.n_band + 2] = -1.0
        if self.angle is not None:
            h[self.n_band + self.n_extra:] = self.angle.heave_rows[0, :-1]
        self._update(angle, h, sigma ** 2 + (self.weak_tilt or 0.0))

    def shift_tilt(self, d_eps: float, d_rate: float) -> None:
        """The attitude was corrected: its error moved by ``d_eps`` [rad] and the gyro-bias
        error by ``d_rate`` [rad/s] (known, so the covariance stays)."""
        if self.tilt is None:
            return
        i = self.n_band + 2
        self.x[i] += d_eps
        self.x[i + 1] += d_rate

    def position(self, lead: float) -> float:
        """Position of the axis [m] ``lead`` s after the band states' time (moved on by the rate)."""
        return float(self._row(lead) @ self.x)

    def std(self, lead: float) -> tuple[float, float]:
        """Standard deviations of :meth:`position` [m] and of the axis velocity [m/s] from the
        covariance."""
        h = self._row(lead)
        v = self.rows[1]
        return math.sqrt(max(0.0, float(h @ self.P @ h))), math.sqrt(max(0.0, float(v @ self.P @ v)))

    def _row(self, lead: float) -> np.ndarray:
        return self.rows[0] + lead * self.rows[1]

    def _update(self, z: float, h: np.ndarray, r: float) -> None:
        """Kalman update with a scalar measurement z = h x + v, Var v = r."""
        ph = self.P @ h
        s = float(h @ ph) + r
        k = ph / s
        self.x = self.x + k * (z - float(h @ self.x))
        self.P = self.P - np.outer(k, ph)

    def _predict(self, y: float) -> None:
        """x ← F x + J y, P ← F P Fᵀ + Q.

        With a wave-tilt band F is block-diagonal, [F₁ 0; 0 F₂], and F₂ is itself a chain of
        independent elements (``angle.block`` states each), so the product is taken by parts
        and F₂'s by element (:func:`blocks_times`): O(n₁³ + n₁²n₂ + n₂²·block) instead of
        O((n₁ + n₂)³): over a 390 s paper-001 record (n₁ 95-113, n₂ 78-198) the predictions
        took 2.3 s instead of 12.2 s (a profile, 2026-11-24)."""
        self.x = self.F @ self.x + self.J * y
        if self.angle is None:
            p = self.F @ self.P @ self.F.T + self.Q
        else:
            b = self.n_band + self.n_extra
            f1, blocks, pm = self.F[:b, :b], self._angle_blocks, self.P
            p = np.empty_like(pm)
            p[:b, :b] = f1 @ pm[:b, :b] @ f1.T
            p[:b, b:] = blocks_times(blocks, (f1 @ pm[:b, b:]).T).T
            p[b:, :b] = p[:b, b:].T
            p[b:, b:] = blocks_times(blocks, blocks_times(blocks, pm[b:, b:]).T).T
            p += self.Q
        self.P = 0.5 * (p + p.T)

    def restart_drift(self) -> None:
        """Forget the drift and the tilt (the fusion re-initialised on a fix: a real reposition,
        and the attitude restarts on the fix's)."""
        d = self.n_band
        restart(self.x, self.P, [d, d + 1], np.diag(np.square(DRIFT_PRIOR)))
        if self.tilt is not None:           # the attitude restarts on the fix as well
            restart(self.x, self.P, [d + 2], np.diag([self.tilt.prior ** 2]))
        self.fixes = 0

    # ---- state -------------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable state (the model is the band observer's, restored with it)."""
        return {"x": self.x.tolist(), "P": self.P.tolist(), "fixes": self.fixes, "weak_tilt": self.weak_tilt}

    def set_state(self, s: dict, model: BankModel | None, angle: BankModel | None = None) -> None:
        """Restore a state from :meth:`get_state` with the band observer's restored ``model``
        (and the wave-tilt observer's ``angle``, if the state had one)."""
        self.model = model
        self.angle = angle if len(s["x"]) > self.n_extra + (0 if model is None else model.n) else None
        self.weak_tilt = s["weak_tilt"]
        self._configure()
        self.x = np.array(s["x"], dtype=float)
        self.P = np.array(s["P"], dtype=float)
        self.fixes = int(s["fixes"])
