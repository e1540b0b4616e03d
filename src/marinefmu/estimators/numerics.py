"""Numerics shared by several estimators: direct integration of acceleration and the high-pass
sections built on it, and BLAS on one thread for small per-step matrices.

**Direct integration** (the baselines of paper 001, section 2.1; the heave observer's
``model="highpass"`` baseline runs :func:`highpass_sections` sample by sample).

Time domain (eqs. 1-6): cumulative integration twice, with the trapezoid rule (eq. 5) or the
paper's three-point rule (eq. 6) — as written, eq. 6 averages a(i−1), 4a(i), a(i+1) over one
step, which integrates over [t_i − Δt/2, t_i + Δt/2] and so leads the true integral by half a
sample; :func:`integrate_time` offers it as ``"simpson_eq6"`` and uses scipy's composite
Simpson rule (``scipy.integrate.cumulative_simpson``) for ``"simpson"``. Both drift: noise η
gives a velocity error η t and a displacement error η t²/2 (eqs. 3-4).

Frequency domain (eqs. 7-12): V(k) = A(k)/(jω_k), S(k) = −A(k)/ω_k², with the bins outside a
band [f_lo, f_hi] set to zero (the paper: "high-frequency and low-frequency noise components
are eliminated"). No drift, but the mean position and velocity are lost and the record is
treated as periodic. Note the paper's eqs. 8, 11, 12 print the inverse DFT with the forward
sign; numpy's ``irfft`` is the correct inverse.

**One BLAS thread** (:func:`one_blas_thread`, threadpoolctl) for the reconstruction's
decomposition and the GNSS coast's covariance.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import integrate, signal
from threadpoolctl import ThreadpoolController

from ..errors import ParameterError, ShapeError, check_choice, check_int, check_range

TIME_METHODS = ("trapezoid", "simpson", "simpson_eq6")


def _as_samples(a: np.ndarray) -> np.ndarray:
    arr = np.asarray(a, dtype=float)
    if arr.ndim not in (1, 2) or len(arr) < 3:
        raise ShapeError(f"acc must have shape (N,) or (N, k) with N >= 3, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ParameterError("acc contains NaN or Inf: remove or interpolate the bad samples first")
    return arr


def _cumulative(x: np.ndarray, dt: float, method: str, x0: np.ndarray | float) -> np.ndarray:
    if method == "trapezoid":  # eq. 5
        out = integrate.cumulative_trapezoid(x, dx=dt, axis=0, initial=0.0)
    elif method == "simpson":
        out = integrate.cumulative_simpson(x, dx=dt, axis=0, initial=0.0)
    else:  # eq. 6 as printed; the last step has no a(i+1): trapezoid there
        mid = (x[:-2] + 4.0 * x[1:-1] + x[2:]) / 6.0 * dt
        last = 0.5 * (x[-2] + x[-1]) * dt
        out = np.concatenate((np.zeros((1,) + x.shape[1:]), np.cumsum(np.concatenate((mid, last[None])), axis=0)))
    return out + x0


def integrate_time(acc: np.ndarray, dt: float, method: str = "trapezoid", v0: float | np.ndarray = 0.0,
                   s0: float | np.ndarray = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and displacement by double time-domain integration (paper 001, eqs. 1, 5, 6).

    Parameters
    ----------
    acc : numpy.ndarray
        (N,) or (N, k) acceleration [m/s²], uniformly sampled, N ≥ 3.
    dt : float
        Sample interval [s], > 0.
    method : {"trapezoid", "simpson", "simpson_eq6"}
        Eq. 5; composite Simpson (scipy); eq. 6 as printed in the paper (half-sample lead).
    v0, s0 : float or numpy.ndarray
        Initial velocity [m/s] and displacement [m].

    Returns
    -------
    (velocity, displacement) : tuple of numpy.ndarray
        Same shape as ``acc``.
    """
    check_choice("method", method, TIME_METHODS)
    check_range("dt", dt, lo=0.0, lo_open=True, unit="s")
    a = _as_samples(acc)
    v = _cumulative(a, dt, method, v0)
    return v, _cumulative(v, dt, method, s0)


def integrate_frequency(acc: np.ndarray, dt: float, band: tuple[float, float] | None = None
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and displacement by frequency-domain integration (paper 001, eqs. 7-12).

    Parameters
    ----------
    acc : numpy.ndarray
        (N,) or (N, k) acceleration [m/s²], uniformly sampled, N ≥ 3.
    dt : float
        Sample interval [s], > 0.
    band : (f_lo, f_hi), optional
        Kept band [Hz], 0 < f_lo < f_hi ≤ Nyquist; default (1/(N·dt), Nyquist): every bin but
        the mean (ω = 0 has no integral).

    Returns
    -------
    (velocity, displacement) : tuple of numpy.ndarray
        Same shape as ``acc``, zero-mean.
    """
    check_range("dt", dt, lo=0.0, lo_open=True, unit="s")
    a = _as_samples(acc)
    n = len(a)
    nyq = 0.5 / dt
    f_lo, f_hi = band if band is not None else (1.0 / (n * dt), nyq)
    check_range("band[0]", f_lo, lo=0.0, hi=nyq, lo_open=True, unit="Hz")
    check_range("band[1]", f_hi, lo=f_lo, hi=nyq, lo_open=True, unit="Hz")
    f = np.fft.rfftfreq(n, dt)
    keep = (f >= f_lo - 1e-12) & (f <= f_hi + 1e-12) & (f > 0)
    jw = np.zeros(len(f), dtype=complex)
    jw[keep] = 1.0 / (2j * math.pi * f[keep])
    shape = (-1,) + (1,) * (a.ndim - 1)
    spec = np.fft.rfft(a, axis=0)
    vel = np.fft.irfft(spec * jw.reshape(shape), n=n, axis=0)  # eq. 9, 11
    disp = np.fft.irfft(spec * (jw ** 2).reshape(shape), n=n, axis=0)  # eq. 10, 12
    return vel, disp


def highpass_sections(cutoff: float, dt: float, order: int = 4, rate: bool = False) -> np.ndarray:
    """Second-order sections of the classical heave filter H(s) = s^{order−2}/B(s) (or, with
    ``rate``, the heave-rate filter s^{order−1}/B(s)), B the ``order``-th order Butterworth
    polynomial with corner ``cutoff``, each section made discrete by the bilinear transform.

    Sections (not one polynomial) because the poles sit within ω_cΔt ≈ 1e-3 of z = 1: in one
    polynomial of order 4 rounding moves them by ~ε^{1/4} ≈ 1e-4, as far as they are from the
    unit circle. Each conjugate pair (and a real pole) is its own section with s² (s) on top,
    except the last pair, which carries 1 (rate: s): the double integration.

    Parameters
    ----------
    cutoff : float
        High-pass corner ω_c [rad/s], (0, π/dt).
    dt : float
        Sample interval [s], > 0.
    order : int
        Butterworth order, 2..8.
    rate : bool
        The heave-rate filter instead of the heave filter.

    Returns
    -------
    numpy.ndarray
        (n_sections, 6) in ``scipy.signal.sosfilt`` layout [b0, b1, b2, 1, a1, a2].
    """
    check_range("dt", dt, lo=0.0, lo_open=True, unit="s")
    check_range("cutoff", cutoff, lo=0.0, hi=math.pi / dt, lo_open=True, hi_open=True, unit="rad/s")
    check_int("order", order, lo=2, hi=8)
    _, poles, _ = signal.butter(order, cutoff, btype="highpass", analog=True, output="zpk")
    pairs = [p for p in poles if p.imag > 1e-12 * cutoff]
    groups = [np.array([p, np.conj(p)]) for p in pairs] + [np.array([p]) for p in poles if abs(p.imag) <= 1e-12 * cutoff]
    sections = []
    for i, group in enumerate(groups):
        zeros = len(group) - (0 if i else 2 - int(rate))        # the first pair integrates
        z, p, k = signal.bilinear_zpk(np.zeros(zeros), group, 1.0, fs=1.0 / dt)
        b, a = signal.zpk2tf(z, p, k)
        b = np.concatenate([np.zeros(len(a) - len(b)), b])
        sections.append(np.concatenate([np.pad(np.real(b), (0, 3 - len(b))), np.pad(np.real(a), (0, 3 - len(a)))]))
    return np.array(sections)


def highpass_double_integration(acc: np.ndarray, dt: float, cutoff: float, order: int = 4) -> np.ndarray:
    """Causal heave from acceleration by high-pass filtered double integration, the classical
    design of motion reference units (the baseline of paper 003's checks).

    The continuous filter is 1/s² (double integration) times an ``order``-th order Butterworth
    high pass at ``cutoff``, H(s) = s^{order−2}/B(s), proper and stable for order ≥ 2, made
    discrete by the bilinear transform in second-order sections (:func:`highpass_sections`)
    and run by ``scipy.signal.sosfilt`` from rest. It has no drift, but its phase lead and gain
    loss near the cutoff are errors on long waves. The same filter runs sample by sample in
    :class:`~marinefmu.estimators.heave.highpass.HighpassHeave` (the HeaveObserver FMU's
    ``model = "highpass"``).

    Parameters
    ----------
    acc : numpy.ndarray
        (N,) vertical acceleration [m/s²], gravity removed, uniformly sampled.
    dt : float
        Sample interval [s].
    cutoff : float
        High-pass corner ω_c [rad/s], below the wave band, (0, π/dt).
    order : int
        Butterworth order, 2..8.

    Returns
    -------
    numpy.ndarray
        (N,) heave [m], same sign convention as ``acc``.
    """
    return signal.sosfilt(highpass_sections(cutoff, dt, order), np.asarray(acc, dtype=float))

_BLAS: ThreadpoolController | None = None


def one_blas_thread():
    """Context manager that runs BLAS/LAPACK on one thread (threadpoolctl), restoring the
    previous setting on exit.

    Used where an estimator multiplies small dense matrices every step or block: the
    decomposition of :mod:`~marinefmu.estimators.reconstruction.decomposition` and the
    covariance of :mod:`~marinefmu.estimators.gnss_fusion.aided_band`. The decomposition's
    matrices are small (≈ 500 × 500 SVDs, 1000 × 120 least squares) and the coast's
    covariances 60-220 states (above OpenBLAS's 64³ threading threshold): on them OpenBLAS's
    thread synchronisation costs more than a second thread gains, and far more when another
    process holds the other core (docs/decisions/reconstruction-blas-threads.md)."""
    global _BLAS
    if _BLAS is None:
        _BLAS = ThreadpoolController()
    return _BLAS.limit(limits=1, user_api="blas")
