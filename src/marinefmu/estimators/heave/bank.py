"""Paper 003's heave observer (:class:`OscillatorBankHeave`, ``model="peaks"`` and the
``model="band"`` comb): the spectrum, its peaks or band weights, a steady-state Kalman filter over
the oscillator bank, the transfer to a point and the fixed-lag smoother. The method and its
equations are set out in :mod:`.common`.

A spectrum with no peak or band energy (a vessel in harbour, a constant input) keeps the model
the observer has, and before the first one there is none, so ``valid`` stays false; that is
logged once when it starts, not at every ``peak_interval`` for as long as the vessel lies still.
"""
from __future__ import annotations

import logging
import math
from dataclasses import replace
from typing import Any

import numpy as np

from ...errors import ParameterError
from .band_bank import band_elements, band_grid, build_band_bank
from ...frames import G
from .common import (HeaveObserverParams, HeaveResult, SilentLog, backward_rate, point_heave, read_sample,
                     vertical_acceleration)
from .fixed_lag import FixedLagOutputs
from .oscillator_bank import BankModel, build_bank, carry_map
from .spectrum import acceleration_spectrum, find_modes
from ..samples import step_changed

log = logging.getLogger(__name__)

class OscillatorBankHeave:
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
    >>> obs = OscillatorBankHeave(HeaveObserverParams(model="band", window=60.0))
    >>> r = obs.step(-9.80665, 0.0, 0.0, 0.1)
    >>> r.valid, r.modes      # no spectrum before the first window is full
    (False, 0)
    """

    def __init__(self, params: HeaveObserverParams | None = None, *, quiet: bool = False) -> None:
        self.params = params or HeaveObserverParams(model="band")
        if self.params.model in ("highpass", "wiener"):
            raise ParameterError(f"model = {self.params.model!r} is not an observer model: use "
                                 "HeaveObserver(params)")
        self.log: Any = SilentLog() if quiet else log
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
        self.no_sea = False                     # the last spectrum had no peak (logged once: module docstring)
        self.smoother: FixedLagOutputs | None = None
        self._smoothed: BankModel | None = None    # the model the smoother was last set to
        self._delayed: tuple[np.ndarray, np.ndarray] | None = None
        self._aux = np.zeros(4)
        self._result = HeaveResult(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0.0, (), False, False)

    def start(self, dt: float) -> None:
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
        if self.dt is not None and step_changed(self.dt, dt):
            restarted = f"step size changed from {self.dt} s to {dt} s; observer restarted"
            self.log.warning("heave observer: %s", restarted)
            self.reset()
        if self.dt is None:
            self.start(dt)
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
            if warning is None:   # the initial result (frozen, not valid) is the answer as it stands
                return self._result
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
            if not self.no_sea:
                self.log.warning("heave observer: no spectral peak in [%g, %g] rad/s; %s", p.omega_min, p.omega_max,
                                 "no modes yet, valid = false" if self.model is None else "modes unchanged")
            self.no_sea = True
            return False
        self.no_sea = False
        self.peak_period = 2.0 * math.pi / float(modes.omega[np.argmax(modes.amplitude)])
        new = self._build(omega, variance)
        if self.model is not None:
            t = carry_map(self.model.omega, new.omega, new.block)
            self.xp, self.x = t @ self.xp, t @ self.x
        self._use(new)
        self._variance = variance
        return True

    def _use(self, model: BankModel) -> None:
        """Make ``model`` the observer's; the smoother takes it before the next Kalman step
        (:meth:`_bind_smoother`)."""
        self.model = model

    def _bind_smoother(self) -> None:
        """Give the smoother the current model, if it has not had it (it then freezes the
        pending times). Deferred from :meth:`_use` to the next Kalman step, state save or
        restore, with nothing between that reads the smoother, so the outputs are those of an
        immediate set: an observer that only tracks the spectrum (:meth:`track_spectrum`) then
        never needs its model's Riccati solution (:class:`.BankModel`)."""
        if self._smoothed is not self.model:
            m = self.model
            self.smoother.set_model(m.heave_rows, m.P, m.closed_loop, m.C, m.S)
            self._smoothed = m

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
        self._bind_smoother()
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
        if self.model is not None:
            self._bind_smoother()
        return {
            "dt": self.dt, "buf": arr(self.buf), "k": self.k, "next_detect": self.next_detect,
            "omega": None if self.model is None else self.model.omega.tolist(), "variance": arr(self._variance),
            "xp": arr(self.xp), "x": arr(self.x),
            "prev": None if self.prev is None else [self.prev[0], self.prev[1].tolist()],
            "angles": [list(a) for a in self.angles], "last_angles": list(self.last_angles),
            "peak_period": self.peak_period, "no_sea": self.no_sea, "aux": self._aux.tolist(),
            "delayed": None if self._delayed is None else [v.tolist() for v in self._delayed],
            "smoother": None if self.smoother is None else self.smoother.get_state(), "result": self._result.__dict__,
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.reset()
        if s["dt"] is None:
            return
        self.start(float(s["dt"]))
        self.buf = np.array(s["buf"], dtype=float)
        self.k, self.next_detect = int(s["k"]), int(s["next_detect"])
        self._variance = None if s["variance"] is None else np.array(s["variance"], dtype=float)
        if s["omega"] is not None:
            self._use(self._build(np.array(s["omega"], dtype=float), self._variance))
            self._bind_smoother()
        self.xp, self.x = np.array(s["xp"], dtype=float), np.array(s["x"], dtype=float)
        self.prev = None if s["prev"] is None else (s["prev"][0], np.array(s["prev"][1]))
        self.angles = [tuple(a) for a in s["angles"]]
        self.last_angles = tuple(s["last_angles"])
        self.peak_period = float(s["peak_period"])
        self.no_sea = bool(s["no_sea"])
        self._aux = np.array(s["aux"], dtype=float)
        self._delayed = None if s["delayed"] is None else tuple(np.array(v) for v in s["delayed"])
        self.smoother.set_state(s["smoother"])
        self._result = HeaveResult(**{**s["result"], "omega": tuple(s["result"]["omega"])})
