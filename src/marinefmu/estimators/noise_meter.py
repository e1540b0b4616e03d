"""A sensor's white noise measured from its own samples, as an estimator runs.

The second difference d_k = x_k − 2x_{k−1} + x_{k−2} of white noise of variance σ² per sample
has variance 6σ²; a signal smooth at the sample rate adds only its second derivative times
Δt² (for a vessel's rate at 100 Hz, below 2·10⁻⁵ rad/s even for a 5° roll at 1.3 rad/s). So
σ² = mean(d²)/6, the mean running over the axes, exponential with a time constant τ and
corrected for its start by its weight 1 − (1 − β)^k (β = Δt/τ). A second difference spans
consecutive good samples only: a rejected (held) sample breaks the chain.

Used by the AttitudeEstimator (the gyro's noise density, ``aid_sizing = "auto"``) and the
CentreOfRotation (the gyro noise in α, ``diff_sizing = "auto"``). Hand-written: a running
second-difference variance has no library equivalent in scipy or filterpy.
"""
from __future__ import annotations

import math

import numpy as np


class WhiteNoiseMeter:
    """Running white-noise variance per sample from the second difference of good samples.

    Parameters
    ----------
    tau : float
        Time constant of the running mean [s].

    Examples
    --------
    >>> m = WhiteNoiseMeter(10.0)
    >>> rng = np.random.default_rng(0)
    >>> for _ in range(20_000):
    ...     m.push(rng.normal(0.0, 0.1, 3), 0.01)
    >>> round(m.variance ** 0.5, 2)      # σ = 0.1 per sample
    0.1
    """

    def __init__(self, tau: float) -> None:
        self.tau = tau
        self.hist: list[np.ndarray] = []
        self.ms = 0.0
        self.weight = 0.0
        self.time = 0.0

    def push(self, x: np.ndarray, dt: float) -> None:
        """Add a good sample (n axes) taken ``dt`` [s] after the previous one."""
        hist = self.hist
        if len(hist) < 2:
            hist.append(x)
            return
        d = x - 2.0 * hist[1] + hist[0]
        hist[0], hist[1] = hist[1], x
        beta = dt / self.tau
        self.ms += beta * (float(d @ d) / d.size - self.ms)
        self.weight += beta * (1.0 - self.weight)
        self.time += dt

    def break_chain(self) -> None:
        """A rejected sample: the next second difference starts after it."""
        self.hist.clear()

    @property
    def variance(self) -> float:
        """White-noise variance per sample and axis [unit²]; 0 before the first difference."""
        return self.ms / self.weight / 6.0 if self.weight > 0.0 else 0.0

    def density(self, dt: float) -> float:
        """White-noise density √(σ² dt) [unit/√Hz] of samples ``dt`` [s] apart; 0 before the
        first difference."""
        return math.sqrt(self.ms / self.weight * dt / 6.0) if self.weight > 0.0 else 0.0

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"hist": [h.tolist() for h in self.hist], "ms": self.ms, "weight": self.weight, "time": self.time}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.hist = [np.array(h) for h in s["hist"]]
        self.ms, self.weight, self.time = float(s["ms"]), float(s["weight"]), float(s["time"])
