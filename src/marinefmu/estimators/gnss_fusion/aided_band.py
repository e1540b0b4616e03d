"""GNSS-aided band observer of one NED axis: the wave model of a GNSS dropout coast (beyond
papers 001 and 003).

Why. The band observer of paper 003, run on the acceleration alone, gives a wave displacement
d_w only as good as the accelerometer makes it, all the time: on the paper-001 set-up its error
is mostly g × the antenna-attitude error at 0.1-0.3 rad/s, which the accelerometer cannot tell
from sway. GNSS sees that displacement, but a straight line fitted to the GNSS anchors z − d_w
cannot give it back to the wave states, and applying the fixes to the band observer with its
acceleration-only steady-state covariance makes the gain wrong once positions are measured.
The states need one covariance that knows both measurement types
(docs/decisions/gnss-fusion-coast.md).

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
update O(n³) (n ≈ 60-220). A test runs the same sequence through a filterpy ``KalmanFilter``
and compares.

Cost per step: at every band step (20 Hz) each axis's covariance is predicted in O(n²·block)
as its block-diagonal part and the increment form's rank-one feed-through
(:meth:`AidedBand._predict`) and each scalar update is one in-place rank-one downdate; the
dense O(n³) product runs only should the transition not have that structure (checked when
the model is configured). Both equal the dense recursion to rounding (a test compares them).

When the band observer's spectrum changes the element set (every
:data:`~.wave_coast.PEAK_INTERVAL` s), state and covariance are carried by
:func:`~.oscillator_bank.carry_map` (P ← T P Tᵀ); an element with no predecessor starts from the
new model's steady-state covariance, uncorrelated with the rest. Two alternatives coasted worse
on east: the new model's steady-state covariance for the whole band (what the fixes told is
lost when the change falls at the start of a gap), and that covariance less the carried
reduction the fixes made.

Tilt states (:class:`Tilt`, ``coast_tilt`` of :class:`~.filter.GnssAccFusionParams`). The
horizontal acceleration is off by g × the error of the attitude that corrects it, ε: east by
−g·ε_N, north by +g·ε_E (checked on the paper-001 record). Without tilt states a loose
random-walk offset (:data:`~.wave_coast.HORIZONTAL_OFFSET_NOISE`, ten times the heave
observer's) stands in for g·ε, and takes a few percent of the sway at the wave peak with it.
With them the north and east filters carry ε and the gyro-bias error δ that turns it,

    ε̇ = δ + w,  δ Gauss-Markov (the gyro's bias instability and correlation time),
    w white (the gyro's white noise, its angle random walk, of density ``noise``),

with ``gain``·ε in the acceleration row (and −J·gain in Ā, the increment form's feed-through),
measured at every fix by the antenna attitude's error against the coast's attitude (σ from the
antenna geometry, :func:`~.antenna_attitude.antenna_attitude_std`). The coast's PI pulls move ε
and δ by known amounts (:meth:`AidedBand.shift_tilt`). The offset keeps the heave observer's
noise (1e-4), the accelerometer bias alone; at the first band model it restarts at
0 ± 2 mm/s², because the observer's own offset holds g·ε as well, and kept, it would hide ε
from the tilt states. The angle random walk in Q makes the tilt estimate err what its
covariance says (a test checks this on a synthetic tilt that walks). The band observers'
spectrum counts with the tilt states: they take the heave observer's own spectrum settings
(:mod:`.wave_coast`).

Wave tilt (:meth:`AidedBand.follow_angle`, :meth:`AidedBand.wave_tilt`; :mod:`.wave_coast`,
"The wave tilt"): the correcting attitude's own tilt, the vessel's wave roll or pitch less ε,
measured at every band step through a band model of the wave tilt that sits after the tilt
states. It is a second measurement of ε that goes on in a gap (a test shows the gain on a
synthetic swing with the MEMS gyro's angle random walk).

What is left on east is at the wave frequency. What tells the sway in a gap beyond the
acceleration is the roll the gyro measures (:mod:`marinefmu.papers.gap_bound`); this filter
does not use it. The measurements behind each choice, and what was tried and not kept, are in
docs/decisions/gnss-fusion-coast.md.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from filterpy.common import Q_continuous_white_noise
from scipy.linalg.blas import dgemm

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
#: its share; 2 cm, above that, coasted best of 0.5-5 cm (docs/decisions/gnss-fusion-coast.md).
FIX_SIGMA = 0.02
#: Prior standard deviations of the drift position [m] and velocity [m/s] at a (re)start.
DRIFT_PRIOR = (10.0, 1.0)
#: Standard deviation of the correcting attitude's own tilt as a measurement of the wave-tilt
#: band less ε [rad] (:meth:`AidedBand.wave_tilt`). The angle itself is nearly exact (the
#: split θ_used = θ − ε); this allows for the band model's misfit of a narrow roll spectrum
#: (docs/decisions/gnss-fusion-coast.md).
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


def rank_one_down(m: np.ndarray, a: np.ndarray, b: np.ndarray) -> None:
    """m ← m − a bᵀ in place, ``m`` a C-ordered block of rows.

    BLAS dgemm of inner dimension one on the Fortran view mᵀ (one pass, no temporary), not
    dger: OpenBLAS runs a rank-one update of some 170² on two threads, milliseconds a call
    when the other core is busy, where its gemm stays on one thread below 65536·4 products."""
    if m.size == 0:
        return
    if not m.flags.c_contiguous:            # dgemm would work on a copy
        m -= np.outer(a, b)
        return
    dgemm(-1.0, b[:, None], a[None, :], beta=1.0, c=m.T, overwrite_c=True)


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
            a = n + self.n_extra
            self.F[a:, a:] = self.angle.A[:-1, :-1]
            self.Q[a:, a:] = self.angle.Q[:-1, :-1]
        self._segments = self._block_segments()
        self._work: np.ndarray | None = None    # the prediction's work array (n × n)
        nz = np.flatnonzero(self.J)
        self._j_rows = int(nz[-1]) + 1 if len(nz) else 0    # J is zero below this row
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
        if len(fresh):                      # model.P is solved on first use (BankModel)
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
        trapezoid mean of the accelerometer's point samples). Averaging a block mean again with
        the previous one, as the heave observer does with point samples, would make the band
        states lag by a further fraction of a step, a large share of the coast's error with
        perfect sensors (docs/decisions/gnss-fusion-coast.md).
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
        if not self.P.flags.c_contiguous:
            self.P = np.ascontiguousarray(self.P)
        rank_one_down(self.P, k, ph)

    def _block_segments(self) -> list[tuple[int, int, np.ndarray]] | None:
        """The block-diagonal part D = F + J Cᵀ of the transition (:meth:`_predict`) as
        contiguous segments (first row, end row, (k, s, s) blocks): the band elements (blocks
        of ``model.block``), the offset with the drift and tilt states (one block), the wave
        tilt's elements (blocks of ``angle.block``). None if D has an entry outside them (then
        the product is taken densely)."""
        d = self.F + np.outer(self.J, self.C)
        size = len(d)
        cuts: list[tuple[int, int, int]] = []           # (first row, end row, block size)
        tail = 0
        if self.model is not None:
            tail = self.n_band - 1
            cuts.append((0, tail, self.model.block))
        b = self.n_band + self.n_extra
        cuts.append((tail, b, b - tail))
        if self.angle is not None:
            cuts.append((b, size, self.angle.block))
        mask = np.ones((size, size), dtype=bool)
        segments = []
        for a0, a1, s in cuts:
            if a1 == a0:
                continue
            if (a1 - a0) % s:
                return None
            for i in range(a0, a1, s):
                mask[i:i + s, i:i + s] = False
            segments.append((a0, a1, np.stack([d[i:i + s, i:i + s] for i in range(a0, a1, s)])))
        return segments if not np.any(d[mask]) else None

    def _scratch(self) -> np.ndarray:
        """An n × n work array for :meth:`_predict` and :meth:`_update` (kept between steps)."""
        size = len(self.x)
        if self._work is None or len(self._work) != size:
            self._work = np.empty((size, size))
        return self._work

    def _block_times(self, m: np.ndarray, out: np.ndarray) -> np.ndarray:
        """D @ ``m`` into ``out`` (D of :meth:`_block_segments`)."""
        for a0, a1, blocks in self._segments:
            k, s, _ = blocks.shape
            np.matmul(blocks, m[a0:a1].reshape(k, s, -1), out=out[a0:a1].reshape(k, s, -1))
        return out

    def _predict(self, y: float) -> None:
        """x ← F x + J y, P ← F P Fᵀ + Q.

        F is a block-diagonal D (the band's and the wave tilt's elements, ``block`` states
        each, and the offset, drift and tilt states) less the rank-one feed-through of the
        increment form, F = D − J Cᵀ (Ā = A − J C, :mod:`.oscillator_bank`; the tilt's column
        −J·gain). So, with w = P C, u = D w and s = Cᵀ w,

            F P Fᵀ = D P Dᵀ − v Jᵀ − J vᵀ,   v = u − (s/2) J,

        with D P Dᵀ = D (D P)ᵀ taken element by element: O(n²·block) instead of the dense
        O(n³) (n up to about 170 on the paper-001 set-up), equal to rounding (a test compares
        it with the dense product). Should D have an entry outside its blocks, the product is
        the dense one."""
        self.x = self.F @ self.x + self.J * y
        if self._segments is None:
            p = self.F @ self.P @ self.F.T + self.Q
            self.P = 0.5 * (p + p.T)
            return
        pm = self.P if self.P.flags.c_contiguous else np.ascontiguousarray(self.P)
        a = self._scratch()
        w = pm @ self.C
        v = self._block_times(w, np.empty_like(w))
        v -= (0.5 * float(self.C @ w)) * self.J
        self._block_times(pm, a)                            # D P
        np.copyto(pm, a.T)                                  # (D P)ᵀ (P is not needed again)
        self._block_times(pm, a)                            # D P Dᵀ = D (D P)ᵀ
        # a ← a − 2 J vᵀ in place (the rows where J is not zero), whose symmetric part is the
        # rank-two term
        j = self._j_rows
        rank_one_down(a[:j], 2.0 * self.J[:j], v)
        np.add(a, a.T, out=pm)
        pm *= 0.5
        pm += self.Q
        self.P = pm

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
