"""Wave-model coasting through GNSS dropouts (beyond paper 001).

Why: an inertial coast cannot hold centimetres for 30 s with a MEMS gyro. The gyro bias wander
(VesselMotion's default: 5e-5 rad/s Gauss-Markov, 50 s) tilts a perfectly initialised
attitude by ~0.5-1 mrad within 30 s, and g·ε integrated twice is metres (:func:`coast_floor`).
A floating vessel whose mean position is steady or moves steadily (moored, dynamically
positioned, drifting) has no acceleration of its own below the wave band, so there the
accelerometer's low-frequency content is error, not motion.

Method, per NED axis:

1. a band observer — :class:`~marinefmu.estimators.heave.bank.OscillatorBankHeave` with
   ``model="band"``, the heave observer of paper 003 with a :data:`SPECTRUM_WINDOW` s spectrum
   window, run on one axis of the attitude-corrected acceleration a_n at the accelerometer,
   decimated to about :data:`RATE` Hz by block means — measures the sea's spectrum along the
   axis and builds the model of its wave-frequency motion (band elements and an offset);
2. :class:`~.aided_band.AidedBand` runs that model in one Kalman filter with a
   constant-velocity drift, updated by the acceleration at every band step and by every
   accepted GNSS fix z of the accelerometer point, so the fixes anchor the wave states as well
   as the drift;
3. in a gap the filter goes on with the acceleration alone: the coast position is its
   Σ elements + drift.

The fixes in step 2 remove the g × antenna-attitude error that the band observer's wave
displacement carries at 0.1-0.3 rad/s, which a straight line fitted to the anchors cannot
(:mod:`.aided_band`). The error left is the band observer's acceleration-only response
through the gap, whose offset must follow g × the attitude error of the corrected
acceleration (:mod:`.aided_band`). A vessel that manoeuvres during the gap breaks the drift
assumption: use ``coast="inertial"`` in :class:`~.filter.GnssAccFusionParams` then.
:class:`~.filter.GnssAccFusion` feeds the coast position to its Kalman filter as a pseudo-fix
every 0.1 s while GNSS is missing.

With tilt states (``tilt``; the default of :class:`~.filter.GnssAccFusion`) the north and
east filters carry the tilt error of the correcting attitude explicitly
(:class:`~.aided_band.Tilt`), measured by each fix's antenna attitude
(:meth:`WaveCoast.attitude_fix`), and all three observers keep the heave observer's offset
noise. Without them the horizontal observers use ``offset_noise``
:data:`HORIZONTAL_OFFSET_NOISE`, ten times the heave default: the horizontal a_n carries g ×
the attitude error of the antenna fixes (about 5 mm/s² RMS at 0.1-0.25 rad/s with 1 cm fixes
on an 8 m baseline) and, in a gap, g × the gyro-propagated tilt drift, which a weaker offset
leaves to the lowest band elements as displacement (docs/decisions/gnss-fusion-coast.md).

The wave tilt (``tilt_band``, the default of :class:`~.filter.GnssAccFusion`). In a gap the
tilt states have only the acceleration to tell the tilt error ε of the correcting attitude
from sway, and what they miss makes the tail of the dropout errors. The correcting attitude's
own tilt about N and E (:func:`~marinefmu.frames.nav_tilt`) is the vessel's wave roll and pitch
less ε, θ_used = θ − ε to second order, and a floating vessel's wave tilt has, like its sway,
nothing below the wave band. So the north and east filters also carry a band model of the wave
tilt about E / N and measure θ_used at every band step
(:meth:`~.aided_band.AidedBand.wave_tilt`, σ :data:`~.aided_band.ANGLE_SIGMA`): in a gap the
gyro's tilt, which turns with the bias, is then a second source of ε besides the acceleration.
The band's spectrum comes from a fourth and fifth
:class:`~marinefmu.estimators.heave.bank.OscillatorBankHeave` fed the tilt's second difference
at the band rate (its spectrum S_θ̈ = ω⁴S_θ, so its "heave" band is the tilt's), with the same
window and floor and damping :data:`ANGLE_DAMPING`; the band drops the observer's offset. A tilt
whose band variance is under ANGLE_SIGMA² gets no band: ε is measured alone, the tilt's
variance added to the noise (:meth:`~.aided_band.AidedBand.weak_angle`), as a band fitted to
noise costs time and helps nothing (in the paper-001 beam sea the tilt about E is 0.03 mrad).
The measurements behind the wave tilt are in docs/decisions/gnss-fusion-coast.md.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ...frames import G
from .aided_band import ANGLE_SIGMA, AidedBand, Tilt, drift_noise
from .antenna_attitude import matrix_rotvec
from ..numerics import one_blas_thread
from ..heave.bank import OscillatorBankHeave
from ..heave.common import HeaveObserverParams
from ..samples import step_changed

#: Target rate of the band observers [Hz] (block means of the accelerometer samples).
RATE = 20.0
#: Offset-state random-walk density of the north and east observers [m/s²/√s] (module docstring).
HORIZONTAL_OFFSET_NOISE = 1e-3
#: Fewest fixes before the coast gives a position.
MIN_FIXES = 3
#: First spectrum window of the band observers [s] (with tilt states it then grows, below): the
#: coast gives positions from this long into a run. A longer window resolves the sea's
#: spectrum, and so the band elements' weights, more finely: 180 s coasted better than the
#: heave observer's 120 s, and 240 s no better (docs/decisions/gnss-fusion-coast.md).
SPECTRUM_WINDOW = 180.0
#: Time between the band observers' spectrum updates [s]. The sea state changes over tens of
#: minutes; the heave observer's 15 s (paper 003) here costs more than half the fusion's time
#: (three 217-state steady-state filters rebuilt with ``dlqe``) for no better coast
#: (docs/decisions/gnss-fusion-coast.md).
PEAK_INTERVAL = 60.0
#: Lowest band element of the band observers [rad/s]: the heave observer's ``omega_min``, the
#: setting the coast was tuned with; the heave observer's own default ``band_min`` (0.3, for
#: long seas) changes nothing that counts here (docs/decisions/gnss-fusion-coast.md).
BAND_MIN = 0.25
#: The band observers' spectrum. With tilt states (the default) they take the heave observer's
#: own settings: the window grows from :data:`SPECTRUM_WINDOW` with the data up to its
#: ``window_max`` (:data:`~marinefmu.estimators.heave.common.WINDOW_MAX`) and the element
#: variances are integrated over their bands, which with the tilt states coasts better. Without
#: tilt states they keep a fixed window (``window_max`` = window) and variances read at the
#: element's frequency (``band_variance = "point"``): with the loose offset, integrated
#: variances moved the dropout errors by noise only (docs/decisions/gnss-fusion-coast.md).

#: Half-width of the smoothing of the band observers' element densities over their neighbours
#: (with tilt states; :func:`~marinefmu.estimators.heave.band_bank.smooth_densities`; the heave
#: observer's default is 0). The dropouts come minutes into a run, when the spectrum window
#: holds one realisation of a few minutes, whose element weights scatter ±50 % about the sea's;
#: a log-domain 1-2-1 average steadies them, a small gain on the mean error and none on the
#: tail. The heave observer keeps 0: its window grows to 20 minutes, and there smoothing moves
#: the band model's error by under 1 % (docs/decisions/gnss-fusion-coast.md).
BAND_SMOOTHING = 1
#: Damping ratio of the wave-tilt band's elements (``tilt_band``): the roll is a narrow
#: resonance, which narrower elements than the heave observer's 0.1 follow better
#: (docs/decisions/gnss-fusion-coast.md).
ANGLE_DAMPING = 0.05


def nav_tilt(rot: np.ndarray) -> tuple[float, float]:
    """:func:`marinefmu.frames.nav_tilt`, the tilt of R_nb about N and E [rad], with its
    rotation vector in floats (:func:`~.antenna_attitude.matrix_rotvec`, equal to scipy's):
    once per band step."""
    yaw = math.atan2(rot[1, 0], rot[0, 0])
    c, s = math.cos(yaw), math.sin(yaw)
    return matrix_rotvec(rot @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]]))[:2]


def observe(obs: OscillatorBankHeave, value: float, dt: float) -> None:
    """One sample ``value`` of an axis to its band observer, which sees the axis as a level
    vertical (a_v = f_z + g with f_z = value − g): stepped until its first model, then only
    its spectrum tracked (the coast's filters run the model)."""
    if obs.model is None:
        obs.step(value - G, 0.0, 0.0, dt)
    else:
        obs.track_spectrum(value - G, 0.0, 0.0)


class WaveCoast:
    """Wave-frequency motion plus drift per NED axis, aided by GNSS (module docstring).

    Parameters
    ----------
    window : float
        Memory of the drift model [s] (:func:`~.aided_band.drift_noise`), > 0.
    spectrum_window : float
        First spectrum window of the band observers [s] (:data:`SPECTRUM_WINDOW`); no position
        before it has passed, ≥ 4π/``omega_min`` of the heave observer (50.3 s).
    tilt : tuple of float, optional
        (σ [rad/s], τ [s]) of the gyro-bias error, and optionally the gyro's white-noise
        density [rad/s/√Hz] (default 0), for tilt states in the north and east filters
        (module docstring, :class:`~.aided_band.Tilt`); None: none, and a loose horizontal
        offset.
    tilt_band : bool
        With ``tilt``: the north and east filters also model the vessel's wave tilt about
        E / N as a band (an observer of its second difference gives the spectrum) and measure
        it at every band step by the correcting attitude's own tilt, which :meth:`add` then
        needs (module docstring, "The wave tilt").

    Examples
    --------
    >>> c = WaveCoast(120.0)
    >>> c.add(np.zeros(3), 0.01)
    >>> c.position() is None        # no band model and no fixes yet
    True
    """

    def __init__(self, window: float, spectrum_window: float = SPECTRUM_WINDOW,
                 tilt: tuple[float, ...] | None = None, tilt_band: bool = False) -> None:
        if tilt_band and tilt is None:
            raise ValueError("tilt_band needs the tilt states (tilt)")
        self.window = float(window)
        self.spectrum_window = float(spectrum_window)
        self.tilt = tilt
        self.tilt_band = bool(tilt_band)
        self.reset()

    def reset(self) -> None:
        """Forget everything (observers, block, filters)."""
        # spectrum: with tilt states the heave observer's own settings and smoothed element
        # weights (BAND_SMOOTHING), without them a fixed window and point variances
        spectrum = ({"band_smoothing": BAND_SMOOTHING} if self.tilt is not None
                    else {"window_max": self.spectrum_window, "band_variance": "point"})
        vertical = HeaveObserverParams(model="band", smoother_lag=0.0, peak_interval=PEAK_INTERVAL,
                                       window=self.spectrum_window, band_min=BAND_MIN, **spectrum)
        # with tilt states the offset takes only the accelerometer bias, as on the vertical
        horizontal = vertical if self.tilt is not None else replace(vertical, offset_noise=HORIZONTAL_OFFSET_NOISE)
        self.observers = [OscillatorBankHeave(horizontal, quiet=True), OscillatorBankHeave(horizontal, quiet=True),
                          OscillatorBankHeave(vertical, quiet=True)]
        # the wave tilt about E (north filter) and N (east filter), from its second difference
        angle = replace(vertical, damping=ANGLE_DAMPING)
        self.angle_observers = ([OscillatorBankHeave(angle, quiet=True), OscillatorBankHeave(angle, quiet=True)]
                                if self.tilt_band else [])
        self.angles: list[np.ndarray] = []  # the attitude's tilt at the last three band steps [rad]
        self.angle_models: list = [None, None]   # the wave-tilt models taken, about N and E
        self.dt: float | None = None
        self.block = 1                      # accelerometer samples per observer step
        self.k = 0                          # accelerometer samples seen (time = k·dt)
        self.acc_sum = np.zeros(3)          # a_n summed over the current block
        self.step_sum = np.zeros(3)         # step means of a_n (trapezoid) summed over the block
        self.last: np.ndarray | None = None  # previous a_n sample
        self.in_block = 0
        self.bands: list[AidedBand] = []    # per axis, from the first sample on
        self.k_band = 0                     # sample count at the end of the last block
        self.k_fix: int | None = None       # sample count of the last fix

    def add(self, acc_n: np.ndarray, dt: float, attitude: np.ndarray | None = None) -> None:
        """Take one attitude-corrected acceleration sample a_n [m/s², NED, gravity removed]
        over a step of ``dt`` s (a change of ``dt`` restarts the coaster), and with
        ``tilt_band`` the attitude R_nb that corrected it (needed then)."""
        if self.dt is not None and step_changed(self.dt, dt):
            self.reset()
        if self.dt is None:
            self._start(dt)
        self.k += 1
        acc_n = np.asarray(acc_n, dtype=float)
        self.acc_sum += acc_n
        # the band filters measure the mean of a_n over their step: the samples are points, so
        # each sample's step contributes the mean of it and the one before (trapezoid)
        self.step_sum += acc_n if self.last is None else 0.5 * (self.last + acc_n)
        self.last = acc_n.copy()
        self.in_block += 1
        if self.in_block < self.block:
            return
        mean, step_mean = self.acc_sum / self.block, self.step_sum / self.block
        self.acc_sum[:] = 0.0
        self.step_sum[:] = 0.0
        self.in_block = 0
        with one_blas_thread():                 # the filters' products are small (numerics.one_blas_thread)
            for obs, band, a, y in zip(self.observers, self.bands, mean, step_mean):
                observe(obs, float(a), self.block * self.dt)
                if obs.model is not None and obs.model is not band.model:
                    first = band.model is None
                    band.follow(obs.model, obs.xp)
                    if first:               # the observer's state has taken this block already
                        continue
                band.accelerate(float(y))
            if self.tilt_band:
                self._wave_tilt(attitude)
        self.k_band = self.k

    def _wave_tilt(self, attitude: np.ndarray | None) -> None:
        """The band step's wave-tilt part (``tilt_band``): the correcting attitude's tilt now,
        its second difference to the wave-tilt observers, and the tilt to the north (about E)
        and east (about N) filters (module docstring)."""
        if attitude is None:
            raise ValueError("WaveCoast.add needs the attitude with tilt_band")
        theta = nav_tilt(np.asarray(attitude, dtype=float))
        if not (math.isfinite(theta[0]) and math.isfinite(theta[1])):
            return          # not expected: the fusion holds its last good attitude on a bad sample
        self.angles = (self.angles + [np.array(theta)])[-3:]
        if len(self.angles) < 3:
            return
        h = self.block * self.dt
        second = (self.angles[2] - 2.0 * self.angles[1] + self.angles[0]) / (h * h)
        for obs, band, i in zip(self.angle_observers, self.bands, (1, 0)):
            observe(obs, float(second[i]), h)
            if band.model is None or obs.model is None:
                continue
            if obs.model is not self.angle_models[i]:     # a new spectrum
                self.angle_models[i] = obs.model
                if obs.band_variance < ANGLE_SIGMA ** 2:
                    band.weak_angle(obs.band_variance)
                else:
                    band.follow_angle(obs.model, obs.xp)
            band.wave_tilt(float(theta[i]))

    def _start(self, dt: float) -> None:
        self.dt = float(dt)
        self.block = max(1, int(round(1.0 / (RATE * dt))))
        tilts: list[Tilt | None] = [None, None, None]
        if self.tilt is not None:
            # north a_n is off by +g·ε_E, east by −g·ε_N (class docstring)
            tilts = [Tilt(G, *self.tilt), Tilt(-G, *self.tilt), None]
        self.bands = [AidedBand(drift_noise(self.window), self.block * self.dt, t) for t in tilts]

    @property
    def ready(self) -> bool:
        """The band observers have had their first spectrum (an axis without band energy has
        no wave model and only the drift)."""
        return self.dt is not None and self.k * self.dt >= self.spectrum_window

    def _lead(self) -> float:
        """Time since the end of the last block [s]."""
        return (self.k - self.k_band) * self.dt

    def anchor(self, z: np.ndarray) -> None:
        """Update with an accepted GNSS position of the accelerometer point z [m, NED]
        (ignored before the first spectrum: the drift would take the waves)."""
        if not self.ready:
            return
        lead = self._lead()
        for band, zi in zip(self.bands, np.asarray(z, dtype=float)):
            band.fix(float(zi), lead)
        self.k_fix = self.k

    def attitude_fix(self, e_n: np.ndarray, sigma_n: np.ndarray) -> None:
        """Update the tilt states with the error of the correcting attitude that a fix's antenna
        attitude measured, e_n [rad, NED rotation vector, true = exp(e_n)·used], of standard
        deviations ``sigma_n`` [rad, NED] (:func:`~.antenna_attitude.antenna_attitude_std`)."""
        if not self.ready or self.tilt is None:
            return
        lead = self._lead()
        self.bands[0].attitude_fix(float(e_n[1]), float(sigma_n[1]), lead)
        self.bands[1].attitude_fix(float(e_n[0]), float(sigma_n[0]), lead)

    def shift_tilt(self, d_eps: np.ndarray, d_rate: np.ndarray) -> None:
        """The correcting attitude was pulled: its error moved by ``d_eps`` [rad, NED] and the
        gyro-bias error by ``d_rate`` [rad/s, NED]."""
        if self.tilt is None:
            return
        self.bands[0].shift_tilt(float(d_eps[1]), float(d_rate[1]))
        self.bands[1].shift_tilt(float(d_eps[0]), float(d_rate[0]))

    def forget_position(self) -> None:
        """Forget the drift (the fusion re-initialised: a real reposition)."""
        for band in self.bands:
            band.restart_drift()
        self.k_fix = None

    def position(self) -> np.ndarray | None:
        """Coast position of the accelerometer point now [m, NED], or None before the first
        spectrum or before :data:`MIN_FIXES` fixes. However long ago the last fix was: the
        error grows slowly (decimetres after a 5-min gap on the paper-001 set-up), where an
        inertial coast is off by kilometres."""
        if not self.ready or self.k_fix is None or min(b.fixes for b in self.bands) < MIN_FIXES:
            return None
        lead = self._lead()
        return np.array([b.position(lead) for b in self.bands])

    def position_std(self) -> np.ndarray:
        """Standard deviation [m] of :meth:`position` per NED axis, from each axis filter's
        covariance (it grows through a gap)."""
        lead = self._lead()
        return np.array([b.std(lead)[0] for b in self.bands])

    def velocity_std(self) -> np.ndarray:
        """Standard deviation [m/s] of the coast's velocity per NED axis (covariance)."""
        lead = self._lead()
        return np.array([b.std(lead)[1] for b in self.bands])

    # ---- state ------------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {
            "dt": self.dt, "block": self.block, "k": self.k, "acc_sum": self.acc_sum.tolist(),
            "step_sum": self.step_sum.tolist(),
            "last": None if self.last is None else self.last.tolist(),
            "in_block": self.in_block, "k_band": self.k_band, "k_fix": self.k_fix,
            "observers": [o.get_state() for o in self.observers],
            "bands": [b.get_state() for b in self.bands],
            "angle_observers": [o.get_state() for o in self.angle_observers],
            "angles": [a.tolist() for a in self.angles],
            # whether each wave-tilt observer's model has been taken (about N, about E); a taken
            # one is the observer's current model (_wave_tilt takes a new one as it comes)
            "angle_taken": [m is not None for m in self.angle_models],
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.reset()
        if s["dt"] is None:
            return
        self._start(float(s["dt"]))
        self.block, self.k, self.in_block, self.k_band = int(s["block"]), int(s["k"]), int(s["in_block"]), int(s["k_band"])
        self.k_fix = None if s["k_fix"] is None else int(s["k_fix"])
        self.acc_sum = np.array(s["acc_sum"], dtype=float)
        self.step_sum = np.array(s["step_sum"], dtype=float)
        self.last = None if s["last"] is None else np.array(s["last"], dtype=float)
        for o, st in zip([*self.observers, *self.angle_observers], s["observers"] + s["angle_observers"]):
            o.set_state(st)
        angle_models = [o.model for o in self.angle_observers] + [None] * 3
        for b, o, a, st in zip(self.bands, self.observers, angle_models, s["bands"]):
            b.set_state(st, o.model, a)
        # the models taken (a weak tilt's too, though it has no band), restored as objects
        observed = [o.model for o in self.angle_observers[::-1]] or [None, None]
        self.angle_models = [m if taken else None for m, taken in zip(observed, s["angle_taken"])]
        self.angles = [np.array(a, dtype=float) for a in s["angles"]]


def coast_floor(sigma_b: float, tau: float, duration: float, dt: float = 0.1, runs: int = 400,
                seed: int = 0, g: float = G) -> float:
    """RMS horizontal position error [m] of a perfectly initialised inertial coast after
    ``duration`` s, from the gyro bias wander alone (Monte Carlo, seeded).

    The bias is Gauss-Markov (σ ``sigma_b`` [rad/s], correlation ``tau`` [s]) and known
    exactly at the start, so only its change b(t) − b(0) acts: ε̇ = Δb, ä = g·ε. This is the
    floor below which no inertial coast can go, whatever the filter.
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration / dt))
    phi = math.exp(-dt / tau)
    b0 = rng.normal(0.0, sigma_b, runs)
    b, eps, vel, pos = b0.copy(), np.zeros(runs), np.zeros(runs), np.zeros(runs)
    for _ in range(n):
        b = phi * b + rng.normal(0.0, sigma_b * math.sqrt(1.0 - phi * phi), runs)
        eps += (b - b0) * dt
        vel += g * eps * dt
        pos += vel * dt
    return float(np.sqrt(np.mean(pos ** 2)))
