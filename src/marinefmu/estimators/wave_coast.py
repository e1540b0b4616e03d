"""Wave-model coasting through GNSS dropouts (beyond paper 001).

Why: an inertial coast cannot hold centimetres for 30 s with a MEMS gyro. The gyro bias wander
(VesselMotion's default: 5e-5 rad/s Gauss-Markov, 50 s) tilts a perfectly initialised
attitude by ~0.5-1 mrad within 30 s, and g·ε integrated twice is metres (measured on the paper
001 set-up: 1-6 m after 30 s, README). A floating vessel whose mean position is steady or moves
steadily (moored, dynamically positioned, drifting) has no acceleration of its own below the
wave band, so there the accelerometer's low-frequency content is error, not motion.

Method, per NED axis:

1. a band observer — :class:`~.heave.HeaveObserver` with ``model="band"``, the heave observer of
   paper 003, run on one axis of the attitude-corrected acceleration a_n at the accelerometer,
   decimated to about :data:`RATE` Hz by block means — gives the wave-frequency displacement
   d_w(t) and its rate, with no content below the sea's band (its offset state takes the rest);
2. at every accepted GNSS fix z (the accelerometer point), z − d_w is an *anchor* of the
   low-frequency position;
3. a straight line fitted to the anchors of the last ``window`` seconds (numpy ``polyfit``)
   extrapolates the low-frequency position, and the coast position is line(t) + d_w(t).

Its error is the band observer's wave-frequency error plus the line's extrapolation error: a
vessel that manoeuvres during the gap breaks the assumption (use ``coast="inertial"`` in
:class:`~.gnss_fusion.FusionParams` then). :class:`~.gnss_fusion.GnssAccFusion` feeds the
coast position to its Kalman filter as a pseudo-fix every 0.1 s while GNSS is missing.

The horizontal observers use ``offset_noise`` :data:`HORIZONTAL_OFFSET_NOISE`, ten times the
heave default: the horizontal a_n carries g × the attitude error of the antenna fixes (about
5 mm/s² RMS at 0.1-0.25 rad/s with 1 cm fixes on an 8 m baseline), which a weaker offset
leaves to the lowest band elements as displacement (measured: 25 cm RMS east instead of
3-5 cm).
"""
from __future__ import annotations

import math
from collections import deque

import numpy as np

from ..frames import G
from .heave import HeaveObserver, HeaveObserverParams

#: Target rate of the band observers [Hz] (block means of the accelerometer samples).
RATE = 20.0
#: Offset-state random-walk density of the north and east observers [m/s²/√s] (module docstring).
HORIZONTAL_OFFSET_NOISE = 1e-3
#: Fewest anchors for a line.
MIN_ANCHORS = 3
#: Time between the band observers' spectrum updates [s]. The sea state changes over tens of
#: minutes; the heave observer's 15 s (paper 003) here cost 60 % of the fusion's time (three
#: 217-state steady-state filters rebuilt with ``dlqe``) for no better coast: the 30 s dropout
#: of the paper-001 set-up erred at most 7.0 / 4.9 / 11.5 cm east over seeds 1-3 with 15 s,
#: 8.4 / 3.8 / 11.2 cm with 60 s, and the fusion ran 2.3 times faster.
PEAK_INTERVAL = 60.0


class WaveCoast:
    """Low-frequency line plus wave-frequency band displacement, per NED axis (module docstring).

    Parameters
    ----------
    window : float
        Anchors older than this [s] are dropped from the line fit, > 0.

    Examples
    --------
    >>> c = WaveCoast(120.0)
    >>> c.add(np.zeros(3), 0.01)
    >>> c.position() is None        # no band observer output and no anchors yet
    True
    """

    def __init__(self, window: float) -> None:
        self.window = float(window)
        self.reset()

    def reset(self) -> None:
        """Forget everything (observers, block, anchors)."""
        horizontal = HeaveObserverParams(offset_noise=HORIZONTAL_OFFSET_NOISE, smoother_lag=0.0,
                                         peak_interval=PEAK_INTERVAL)
        self.observers = [HeaveObserver(horizontal, quiet=True), HeaveObserver(horizontal, quiet=True),
                          HeaveObserver(HeaveObserverParams(smoother_lag=0.0, peak_interval=PEAK_INTERVAL), quiet=True)]
        self.dt: float | None = None
        self.block = 1                      # accelerometer samples per observer step
        self.k = 0                          # accelerometer samples seen (time = k·dt)
        self.acc_sum = np.zeros(3)          # a_n summed over the current block
        self.in_block = 0
        self.disp: np.ndarray | None = None  # d_w at the end of the last block [m], NED
        self.rate = np.zeros(3)              # its rate [m/s]
        self.k_disp = 0                      # sample count at the end of the last block
        self.anchors: deque[tuple[int, tuple[float, float, float]]] = deque()

    def add(self, acc_n: np.ndarray, dt: float) -> None:
        """Take one attitude-corrected acceleration sample a_n [m/s², NED, gravity removed]
        over a step of ``dt`` s (a change of ``dt`` restarts the coaster)."""
        if self.dt is not None and abs(dt - self.dt) > 1e-9 * self.dt:
            self.reset()
        if self.dt is None:
            self.dt = float(dt)
            self.block = max(1, int(round(1.0 / (RATE * dt))))
        self.k += 1
        self.acc_sum += acc_n
        self.in_block += 1
        if self.in_block < self.block:
            return
        mean = self.acc_sum / self.block
        self.acc_sum[:] = 0.0
        self.in_block = 0
        # each observer sees its axis as a level vertical: a_v = f_z + g with f_z = a − g
        res = [obs.step(float(a) - G, 0.0, 0.0, self.block * self.dt) for obs, a in zip(self.observers, mean)]
        if self.k * self.dt < self.observers[0].params.window:
            return                              # no spectrum yet
        # an axis whose spectrum had no band energy (no waves along it) has no wave motion
        self.disp = np.array([r.heave if r.valid else 0.0 for r in res])
        self.rate = np.array([r.heave_rate if r.valid else 0.0 for r in res])
        self.k_disp = self.k

    def displacement(self) -> np.ndarray | None:
        """d_w now [m, NED] (the last block's value moved on by its rate), or None before the
        band observers have their first spectrum."""
        if self.disp is None:
            return None
        return self.disp + self.rate * ((self.k - self.k_disp) * self.dt)

    def anchor(self, z: np.ndarray) -> None:
        """Record an accepted GNSS position of the accelerometer point z [m, NED]."""
        d = self.displacement()
        if d is None:
            return
        self.anchors.append((self.k, tuple((np.asarray(z, dtype=float) - d).tolist())))
        oldest = self.k - self.window / self.dt
        while self.anchors and self.anchors[0][0] < oldest:
            self.anchors.popleft()

    def clear_anchors(self) -> None:
        """Drop the anchors (the filter re-initialised: a real reposition)."""
        self.anchors.clear()

    def position(self) -> np.ndarray | None:
        """Coast position of the accelerometer point now [m, NED], or None if the band
        observers are not ready or fewer than :data:`MIN_ANCHORS` anchors span the window."""
        d = self.displacement()
        if d is None or len(self.anchors) < MIN_ANCHORS:
            return None
        t = np.array([a[0] for a in self.anchors], dtype=float) - self.k
        y = np.array([a[1] for a in self.anchors])
        level = np.polyfit(t, y, 1)[1]           # per axis, at t = 0 (now)
        return level + d

    # ---- state ------------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {
            "dt": self.dt, "block": self.block, "k": self.k, "acc_sum": self.acc_sum.tolist(),
            "in_block": self.in_block, "disp": None if self.disp is None else self.disp.tolist(),
            "rate": self.rate.tolist(), "k_disp": self.k_disp,
            "anchors": [[k, list(a)] for k, a in self.anchors],
            "observers": [o.get_state() for o in self.observers],
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.reset()
        self.dt = None if s["dt"] is None else float(s["dt"])
        self.block, self.k, self.in_block, self.k_disp = int(s["block"]), int(s["k"]), int(s["in_block"]), int(s["k_disp"])
        self.acc_sum = np.array(s["acc_sum"], dtype=float)
        self.disp = None if s["disp"] is None else np.array(s["disp"], dtype=float)
        self.rate = np.array(s["rate"], dtype=float)
        self.anchors = deque((int(k), tuple(a)) for k, a in s["anchors"])
        for o, st in zip(self.observers, s["observers"]):
            o.set_state(st)


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
