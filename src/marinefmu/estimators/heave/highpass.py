"""The classical heave estimator, sample by sample: high-pass filtered double integration of
the vertical acceleration, transferred to a remote point (the baseline the observer models are
compared with).

Motion reference units long estimated heave this way: the vertical acceleration (gravity
removed, :func:`~.common.vertical_acceleration`) through 1/s² times an ``order``-th order
Butterworth high pass at ω_c, H(s) = s^{order−2}/B(s), and the heave rate through
s^{order−1}/B(s); both discrete by the bilinear transform in second-order sections
(:func:`~marinefmu.estimators.numerics.highpass_sections`; the same filter as the offline
:func:`~marinefmu.estimators.numerics.highpass_double_integration`). It needs no spectrum and starts at once,
but it leads and loses gain on long waves (phase lead ≈ a₁ω_c/ω rad above the corner, a₁ = 2.61
for order 4) and amplifies low-frequency noise by 1/ω_c²: the cutoff trades the two.

Each section runs in transposed direct form II (the ``scipy.signal.sosfilt`` recursion,
hand-written for one sample: a call to sosfilt per sample costs ten times more).

The transfer to the point and the bad-sample handling are the observer's
(:func:`~.common.point_heave`, the last good sample held: the filter coasts on it, ``valid``
false). ``valid`` also stays false for 4 time constants of the slowest pole, 4/(ζ_min ω_c),
while the start from rest decays. The outputs have the observer's shape
(:class:`~.common.HeaveResult`; no delayed outputs, no modes).
"""
from __future__ import annotations

import logging
from typing import Any

import numpy as np
from scipy import signal

from .common import HeaveObserverParams, HeaveResult, SilentLog, backward_rate, point_heave, \
    read_and_start, vertical_acceleration
from ..numerics import highpass_sections

log = logging.getLogger(__name__)


class HighpassHeave:
    """Classical heave at the IMU and at a point (module docstring).

    Parameters
    ----------
    params : HeaveObserverParams, optional
        Uses ``highpass_cutoff``, ``highpass_order``, ``vertical``, ``transfer`` and ``point``
        (``model`` is ignored).
    quiet : bool
        Log nothing.

    Examples
    --------
    >>> hp = HighpassHeave(HeaveObserverParams(model="highpass", highpass_cutoff=0.1))
    >>> r = hp.step((0.0, 0.0, -9.80665), 0.0, 0.0, 0.01)
    >>> r.heave, r.valid      # at rest, and not yet settled
    (0.0, False)
    """

    def __init__(self, params: HeaveObserverParams | None = None, *, quiet: bool = False) -> None:
        self.params = params or HeaveObserverParams(model="highpass")
        self.log: Any = SilentLog() if quiet else log
        poles = signal.butter(self.params.highpass_order, 1.0, btype="highpass", analog=True, output="zpk")[1]
        #: Time the start from rest needs to decay [s]: 4 time constants of the slowest pole.
        self.settle_time = 4.0 / (float(np.min(-poles.real)) * self.params.highpass_cutoff)
        self.reset()

    def reset(self) -> None:
        """Back to rest."""
        self.dt: float | None = None
        self.k = 0
        self.sections: tuple[np.ndarray, np.ndarray] | None = None   # heave, rate SOS
        self._coefs: list[list[tuple[float, ...]]] = [[], []]        # the same as float tuples
        self.states: list[list[list[float]]] = [[], []]              # per section [z0, z1]
        self.last = (None, 0.0, 0.0)              # last good a_v, roll, pitch
        self.angles: list[tuple[float, float]] = []

    def start(self, dt: float) -> None:
        p = self.params
        self.dt = dt
        self.sections = (highpass_sections(p.highpass_cutoff, dt, p.highpass_order),
                         highpass_sections(p.highpass_cutoff, dt, p.highpass_order, rate=True))
        self._coefs = [[tuple(float(c) for c in row) for row in sos] for sos in self.sections]
        self.states = [[[0.0, 0.0] for _ in sos] for sos in self.sections]

    def response(self, omega: Any) -> np.ndarray | None:
        """Heave response H(e^{jωΔt}) of the discrete filter to a sinusoidal heave at ω [rad/s]
        (the estimate is H times the truth; the filter sees −ω² times the heave and applies
        s^{order−2}/B(s)). None before the first step."""
        if self.dt is None:
            return None
        w = np.asarray(omega, dtype=float)
        _, h = signal.sosfreqz(self.sections[0], worN=np.atleast_1d(w) * self.dt)
        return (-(w ** 2) * h.reshape(w.shape))

    def step(self, acc: Any, roll: float, pitch: float, dt: float) -> HeaveResult:
        """Process one sample (arguments as :meth:`.OscillatorBankHeave.step`)."""
        p = self.params
        f, roll, pitch, warning = read_and_start(self, acc, roll, pitch, dt)
        if warning is None:
            a_v = vertical_acceleration(f, roll, pitch, p.vertical)
            self.last = (a_v, roll, pitch)
            self.angles = (self.angles + [(roll, pitch)])[-3:]
        else:
            self.log.warning("classical heave: %s; holding the last good sample", warning)
        a_v, roll, pitch = self.last
        self.k += 1
        heave = _run(self._coefs[0], self.states[0], a_v or 0.0)
        rate = _run(self._coefs[1], self.states[1], a_v or 0.0)
        ph, pr = point_heave(heave, rate, p.point, roll, pitch, *backward_rate(self.angles, self.dt), p.transfer)
        valid = warning is None and self.k * self.dt >= self.settle_time
        return HeaveResult(heave, rate, ph, pr, 0.0, 0.0, 0.0, 0.0, 0.0, 0, 0.0, (), valid, False, warning)

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"dt": self.dt, "k": self.k, "states": self.states, "last": list(self.last),
                "angles": [list(a) for a in self.angles]}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.reset()
        if s["dt"] is None:
            return
        self.start(float(s["dt"]))
        self.k = int(s["k"])
        self.states = [[[float(z0), float(z1)] for z0, z1 in v] for v in s["states"]]
        self.last = tuple(s["last"])
        self.angles = [tuple(a) for a in s["angles"]]


def _run(sos: list[tuple[float, ...]], state: list[list[float]], x: float) -> float:
    """One sample through second-order sections in transposed direct form II (the recursion
    of ``scipy.signal.sosfilt``); ``state`` (per section [z0, z1]) is updated in place."""
    for (b0, b1, b2, _, a1, a2), z in zip(sos, state):
        y = b0 * x + z[0]
        z[0] = b1 * x - a1 * y + z[1]
        z[1] = b2 * x - a2 * y
        x = y
    return x
