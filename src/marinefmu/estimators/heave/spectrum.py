"""Steps 1-2 of paper 003 (Auestad, Gravdahl & Fossen): the spectrum of the vertical
acceleration over a window and the peaks of the position spectrum, which become the modes of
the heave observer (:mod:`.bank`).

**Step 1** (section 2.1): the one-sided amplitude spectrum Ä(ω) of the acceleration over the
window (mean removed, Hann taper, ``numpy.fft.rfft``) and the position spectrum

.. math:: A(ω) = Ä(ω) / ω^2,\\quad φ(ω) = \\ddot φ(ω) − π,\\quad ω > 0 \\qquad \\text{(eq. 2)}

**Step 2** (section 2.2): every local maximum of A(ω) is a mode. ``scipy.signal.find_peaks``
finds them inside [ω_min, ω_max] (which drops ω ≈ 0), its ``distance`` drops modes closer than
``min_separation`` to a higher neighbour (the paper's "sufficiently close to a neighbour"),
peaks lower than ``min_relative`` of the highest are dropped, and at most ``max_modes`` of the
highest are kept. Beyond the paper, each peak frequency is refined from the amplitude ratio of
its bin and the larger neighbour (exact for one Hann-windowed sinusoid), so a mode's frequency
is not quantised to the bin grid 2π/T.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.signal import find_peaks
from scipy.signal.windows import hann


@dataclass(frozen=True)
class Spectrum:
    """One-sided spectra of a window of vertical acceleration.

    Attributes
    ----------
    omega : numpy.ndarray
        (M,) frequencies [rad/s], ω_k = 2πk/(N·dt), k ≥ 1.
    acc_amplitude : numpy.ndarray
        (M,) amplitude Ä(ω) [m/s²] (a sinusoid of amplitude a on a bin reads a).
    position_amplitude : numpy.ndarray
        (M,) A(ω) = Ä(ω)/ω² [m] (eq. 2).
    position_phase : numpy.ndarray
        (M,) φ(ω) = φ̈(ω) − π [rad], phase at the window's last sample (eq. 2).
    acc_density : numpy.ndarray
        (M,) one-sided power spectral density of the acceleration [(m/s²)²/(rad/s)] (Hann
        periodogram: Σ acc_density·Δω is the window's variance).
    """

    omega: np.ndarray
    acc_amplitude: np.ndarray
    position_amplitude: np.ndarray
    position_phase: np.ndarray
    acc_density: np.ndarray

    @property
    def resolution(self) -> float:
        """Bin spacing [rad/s]."""
        return float(self.omega[1] - self.omega[0]) if len(self.omega) > 1 else math.inf


def acceleration_spectrum(acc: np.ndarray, dt: float) -> Spectrum:
    """Step 1: amplitude and phase spectra of a window of vertical acceleration (eq. 2).

    Parameters
    ----------
    acc : numpy.ndarray
        (N,) vertical acceleration [m/s²], oldest first, uniformly sampled.
    dt : float
        Sample interval [s].

    Returns
    -------
    Spectrum
        Bins k = 1 … N/2 (the mean, k = 0, is dropped).
    """
    x = np.asarray(acc, dtype=float)
    n = len(x)
    taper = hann(n, sym=False)
    spec = np.fft.rfft((x - x.mean()) * taper)[1:]
    omega = 2.0 * math.pi * np.arange(1, len(spec) + 1) / (n * dt)
    amp = 2.0 * np.abs(spec) / taper.sum()
    # phase referred to the last sample (t = (n−1)·dt from the window start)
    phase = np.angle(spec) + omega * (n - 1) * dt
    density = np.abs(spec) ** 2 * dt / (math.pi * float(np.sum(taper**2)))
    return Spectrum(omega, amp, amp / omega**2, np.angle(np.exp(1j * (phase - math.pi))), density)


def band_integral(omega: np.ndarray, density: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Integral of a density given at uniform bins ``omega`` over the bands [lo, hi], each bin's
    value spread evenly over its width (beyond the outer bins: nothing).

    Parameters
    ----------
    omega : numpy.ndarray
        (K,) uniform bin centres [rad/s].
    density : numpy.ndarray
        (K,) density per rad/s at them.
    lo, hi : numpy.ndarray
        Band edges [rad/s], lo ≤ hi, any shape.
    """
    d_omega = omega[1] - omega[0]
    edges = np.concatenate([omega - 0.5 * d_omega, [omega[-1] + 0.5 * d_omega]])
    cumulative = np.concatenate([[0.0], np.cumsum(density) * d_omega])
    return np.interp(hi, edges, cumulative) - np.interp(lo, edges, cumulative)


@dataclass(frozen=True)
class Modes:
    """Modes from the peak detection, ascending in frequency.

    Attributes
    ----------
    omega : numpy.ndarray
        (m,) refined peak frequencies [rad/s].
    amplitude : numpy.ndarray
        (m,) A(ω) at the peak bins [m].
    phase : numpy.ndarray
        (m,) position phase at the window's last sample [rad].
    """

    omega: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray

    def __len__(self) -> int:
        return len(self.omega)


def _refine(amp: np.ndarray, k: int, omega: np.ndarray) -> float:
    """Peak frequency of a Hann-windowed sinusoid from the bin k and its larger neighbour:
    offset δ = (2α − 1)/(α + 1) bins with α the amplitude ratio (Grandke 1983; exact for one
    sinusoid without leakage from others)."""
    if k == 0 or k == len(amp) - 1:
        return float(omega[k])
    side = 1 if amp[k + 1] >= amp[k - 1] else -1
    alpha = amp[k + side] / amp[k]
    delta = (2.0 * alpha - 1.0) / (alpha + 1.0)
    return float(omega[k] + side * min(0.5, max(0.0, delta)) * (omega[1] - omega[0]))


def find_modes(spectrum: Spectrum, omega_min: float, omega_max: float, max_modes: int,
               min_separation: float, min_relative: float) -> Modes:
    """Step 2: peaks of A(ω) that become observer modes.

    Parameters
    ----------
    spectrum : Spectrum
        From :func:`acceleration_spectrum`.
    omega_min, omega_max : float
        Band searched [rad/s] (ω ≈ 0 is outside it).
    max_modes : int
        Most modes kept (the highest peaks).
    min_separation : float
        A peak closer than this to a higher one is dropped [rad/s].
    min_relative : float
        Peaks lower than this fraction of the highest peak in the band are dropped.

    Returns
    -------
    Modes
        Possibly empty (no peak in the band).
    """
    w, amp = spectrum.omega, spectrum.position_amplitude
    band = np.flatnonzero((w >= omega_min) & (w <= omega_max))
    if len(band) < 3:
        return Modes(np.empty(0), np.empty(0), np.empty(0))
    lo, hi = band[0], band[-1] + 1
    distance = max(1, int(math.ceil(min_separation / spectrum.resolution)))
    peaks, _ = find_peaks(amp[lo:hi], distance=distance)
    peaks = peaks + lo
    if len(peaks) == 0:
        return Modes(np.empty(0), np.empty(0), np.empty(0))
    peaks = peaks[amp[peaks] >= min_relative * amp[peaks].max()]
    peaks = np.sort(peaks[np.argsort(amp[peaks])[::-1][:max_modes]])
    omega = np.array([_refine(spectrum.acc_amplitude, k, w) for k in peaks])
    return Modes(omega, amp[peaks], spectrum.position_phase[peaks])
