"""A sliding window that returns, for every new sample, the sample at the window's centre, its
Savitzky–Golay smoothed value and its Savitzky–Golay time derivative.

Used by the centre-of-rotation estimator (paper 002) to get the angular acceleration α_b by
filtered differentiation of the gyro rates without a phase error: the derivative of a centred
(linear-phase, symmetric) Savitzky–Golay filter has no delay at its centre, so every other
signal is taken at the same centre sample, and the whole estimator runs ``delay`` =
(n − 1)/2 samples behind the newest one. A causal low-pass differentiator would instead shift
α_b against the accelerations by its group delay (tens of milliseconds even at 2 Hz) and bias
the lever-arm regression.

The filter weights come from :func:`scipy.signal.savgol_coeffs` (least-squares polynomial fit of
order ``polyorder`` over the window, evaluated at its centre).
"""
from __future__ import annotations

import numpy as np
from scipy.signal import savgol_coeffs

from ...errors import check_int, check_range

#: Fewest samples in a window (a quadratic fit over 5 points still averages noise).
MIN_SAMPLES = 5


def window_samples(window: float, dt: float, polyorder: int = 2) -> int:
    """Odd number of samples closest to ``window`` / ``dt`` [s / s], at least
    max(:data:`MIN_SAMPLES`, polyorder + 2) (a fit needs more points than coefficients)."""
    n = 2 * int(round(0.5 * window / dt)) + 1
    least = max(MIN_SAMPLES, polyorder + 2)
    return max(n, least + 1 - least % 2)


class CentredWindow:
    """Sliding Savitzky–Golay window over ``channels`` signals.

    Parameters
    ----------
    channels : int
        Number of signals per sample.
    n : int
        Window length in samples (odd, ≥ :data:`MIN_SAMPLES`).
    dt : float
        Sample interval [s].
    polyorder : int
        Order of the local polynomial (2 keeps the derivative exact for quadratics).

    Examples
    --------
    >>> w = CentredWindow(1, 5, 0.1)
    >>> out = [w.push([0.1 * k * 2.0]) for k in range(5)]   # x = 2 t
    >>> raw, smooth, deriv = out[-1]
    >>> round(float(deriv[0]), 12), round(float(raw[0]), 12)
    (2.0, 0.4)
    """

    def __init__(self, channels: int, n: int, dt: float, polyorder: int = 2) -> None:
        check_int("window samples", n, lo=MIN_SAMPLES)
        if n % 2 == 0:
            raise ValueError(f"window samples = {n} must be odd")
        check_range("dt", dt, lo=0.0, lo_open=True, unit="s")
        check_int("polyorder", polyorder, lo=0, hi=n - 2)
        self.n, self.dt = n, dt
        # use="dot": weights for the oldest..newest sample, evaluated at the centre (pos = n // 2)
        self._smooth = savgol_coeffs(n, polyorder, deriv=0, use="dot")
        self._deriv = savgol_coeffs(n, polyorder, deriv=1, delta=dt, use="dot")
        self.buffer = np.zeros((n, channels))
        self.count = 0

    @property
    def delay(self) -> float:
        """Delay of the centre sample behind the newest one [s]."""
        return 0.5 * (self.n - 1) * self.dt

    @property
    def full(self) -> bool:
        """True once ``n`` samples have been pushed."""
        return self.count >= self.n

    def push(self, sample: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Add the newest sample; return (centre sample, smoothed, derivative [unit/s]) at the
        window centre, or None while the window is filling."""
        self.buffer[:-1] = self.buffer[1:]
        self.buffer[-1] = sample
        self.count += 1
        if self.count < self.n:
            return None
        return self.buffer[self.n // 2].copy(), self._smooth @ self.buffer, self._deriv @ self.buffer

    def get_state(self) -> dict:
        """JSON-serialisable buffer."""
        return {"buffer": self.buffer.tolist(), "count": self.count}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.buffer = np.array(s["buffer"], dtype=float).reshape(self.buffer.shape)
        self.count = int(s["count"])
