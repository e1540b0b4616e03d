"""A sliding window that returns, for every new sample, the sample at the window's centre, its
Savitzky–Golay smoothed value and its Savitzky–Golay time derivative.

Used by the centre-of-rotation estimator (paper 002) to get the angular acceleration α_b by
filtered differentiation of the gyro rates without a phase error: the derivative of a centred
(linear-phase, symmetric) Savitzky–Golay filter has no delay at its centre, so every other
signal is taken at the same centre sample, and the whole estimator runs ``delay`` =
(n − 1)/2 samples behind the newest one. A causal low-pass differentiator would instead shift
α_b against the accelerations by its group delay (tens of milliseconds even at 2 Hz) and bias
the lever-arm regression.

The window can be resized as it runs (:meth:`CentredWindow.resize`, for a window sized from
the data): it keeps ``capacity`` samples and fits the newest ``n`` of them.

The filter weights come from :func:`scipy.signal.savgol_coeffs` (least-squares polynomial fit of
order ``polyorder`` over the window, evaluated at its centre). :func:`derivative_noise_gain` and
:func:`derivative_gain_error` give the two sides of choosing its length: the white noise a
derivative passes, and the part of a sinusoid's derivative it loses.

Cost per push: the write of one sample and one (2, n) × (n, channels) product giving the
smoothed value and the derivative together. The weights are computed once per (window length,
order, step) and kept (:func:`_savgol_weights`), so a resize and the kernels below do not fit
them again: the same numbers, computed once.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.signal import savgol_coeffs

from ...errors import check_int, check_range

#: Fewest samples in a window (a quadratic fit over 5 points still averages noise).
MIN_SAMPLES = 5


@lru_cache(maxsize=256)
def _savgol_weights(n: int, polyorder: int, deriv: int, dt: float) -> np.ndarray:
    """``savgol_coeffs(n, polyorder, deriv, delta=dt, use="dot")``, read-only, computed once per
    argument set (the window sizing asks for the same windows every time it runs)."""
    w = savgol_coeffs(n, polyorder, deriv=deriv, delta=dt, use="dot")
    w.flags.writeable = False
    return w


def window_samples(window: float, dt: float, polyorder: int = 2) -> int:
    """Odd number of samples closest to ``window`` / ``dt`` [s / s], at least
    max(:data:`MIN_SAMPLES`, polyorder + 2) (a fit needs more points than coefficients)."""
    n = 2 * int(round(0.5 * window / dt)) + 1
    least = max(MIN_SAMPLES, polyorder + 2)
    return max(n, least + 1 - least % 2)


def derivative_noise_gain(n: int, dt: float, polyorder: int) -> float:
    """Σ d_k² [1/s²] of the Savitzky–Golay derivative weights d over ``n`` samples of ``dt`` [s]:
    white noise of variance σ² per sample comes out of the derivative with variance σ² Σ d_k²
    (a gyro of white-noise density N [rad/s/√Hz] sampled at dt has σ² = N²/dt)."""
    d = _savgol_weights(n, polyorder, 1, dt)
    return float(d @ d)


def derivative_increment_gain(n: int, dt: float, polyorder: int) -> float:
    """Σ (d_k − d_{k−1})² [1/s²] over the weights padded with a zero at each end: white noise
    of variance σ² per sample gives the step-to-step change of the derivative the variance
    σ² Σ (Δd)². Dominated by the window's ends, where the weights jump to and from zero
    (they fall as 1/n² against Σ d² as 1/n³, so the change of the noise falls as n⁻⁴)."""
    d = _savgol_weights(n, polyorder, 1, dt)
    dd = np.diff(np.concatenate(([0.0], d, [0.0])))
    return float(dd @ dd)


def derivative_gain_error(n: int, dt: float, polyorder: int, omega: float) -> float:
    """1 − |H(ω)|/ω [-]: the fraction of the derivative of a sinusoid of ``omega`` [rad/s] that
    the Savitzky–Golay derivative over ``n`` samples of ``dt`` [s] loses. H(ω) = i Σ_k d_k
    sin(ω (k − c) dt) for the antisymmetric weights d about the centre c. For a window short
    against the period the loss grows as (ω n dt)^polyorder at even orders (order 4 over 1.5 s:
    0.16 % at 0.2 Hz, 0.76 % at 0.3 Hz; over 3 s: 2.3 % at 0.2 Hz); 0 for ω = 0."""
    if omega <= 0.0:
        return 0.0
    d = _savgol_weights(n, polyorder, 1, dt)
    t = (np.arange(n) - n // 2) * dt
    return float(1.0 - abs(d @ np.sin(omega * t)) / omega)


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
    capacity : int, optional
        Samples kept (≥ ``n``; default ``n``): the longest window :meth:`resize` can set.

    Examples
    --------
    >>> w = CentredWindow(1, 5, 0.1)
    >>> out = [w.push([0.1 * k * 2.0]) for k in range(5)]   # x = 2 t
    >>> raw, smooth, deriv = out[-1]
    >>> round(float(deriv[0]), 12), round(float(raw[0]), 12)
    (2.0, 0.4)
    """

    def __init__(self, channels: int, n: int, dt: float, polyorder: int = 2, capacity: int | None = None) -> None:
        check_range("dt", dt, lo=0.0, lo_open=True, unit="s")
        self.dt, self.polyorder = dt, polyorder
        capacity = n if capacity is None else capacity
        check_int("window capacity", capacity, lo=n)
        self.capacity = capacity
        # mirrored ring: every sample is written at head and head + capacity, so the newest
        # ``capacity`` samples are always one contiguous slice and a push costs the same for
        # any capacity (no shift of the whole buffer)
        self._ring = np.zeros((2 * capacity, channels))
        self._head = capacity - 1    # the slot of the newest sample
        self.count = 0
        self.resize(n)

    def resize(self, n: int) -> None:
        """Fit the newest ``n`` samples from now on (odd, ≥ :data:`MIN_SAMPLES`, ≤ the capacity).

        The centre moves to (n − 1)/2 samples behind the newest; the caller decides what to do
        with the samples the move skips or repeats."""
        check_int("window samples", n, lo=MIN_SAMPLES, hi=self.buffer.shape[0])
        if n % 2 == 0:
            raise ValueError(f"window samples = {n} must be odd")
        check_int("polyorder", self.polyorder, lo=0, hi=n - 2)
        self.n = n
        # use="dot": weights for the oldest..newest sample, evaluated at the centre (pos = n // 2)
        self._smooth = _savgol_weights(n, self.polyorder, 0, 1.0)
        self._deriv = _savgol_weights(n, self.polyorder, 1, self.dt)
        # both weight rows in one (2, n) matrix: one product per push gives both fits
        self._weights = np.vstack((self._smooth, self._deriv))

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
        c, ring = self.capacity, self._ring
        h = self._head = (self._head + 1) % c
        row = ring[h]
        row[:] = sample
        ring[h + c] = row
        self.count += 1
        n = self.n
        if self.count < n:
            return None
        seg = ring[h + c + 1 - n:h + c + 1]
        fits = np.dot(self._weights, seg)
        return seg[n // 2].copy(), fits[0], fits[1]

    @property
    def buffer(self) -> np.ndarray:
        """(capacity, channels) the samples kept, oldest first (zeros before the first ones)."""
        h, c = self._head, self.capacity
        return self._ring[h + 1:h + 1 + c]

    def get_state(self) -> dict:
        """JSON-serialisable buffer and window length."""
        return {"buffer": self.buffer.tolist(), "count": self.count, "n": self.n}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        c = self.capacity
        buffer = np.array(s["buffer"], dtype=float).reshape((c, self._ring.shape[1]))
        self._ring[:c] = self._ring[c:] = buffer
        self._head = c - 1
        self.count = int(s["count"])
        if int(s.get("n", self.n)) != self.n:
            self.resize(int(s["n"]))
