"""The ``model="band"`` observer of :mod:`marinefmu.estimators.heave` (beyond paper 003): a comb of damped
band-pass resonators spanning the wave band, each weighted by the measured spectrum, so that the
Kalman filter's model of heave has the sea's spectrum and no heave below the band.

Why. The paper's undamped modes at the spectral peaks model a sea as a few lines; driven by
white acceleration noise, each mode also claims a flat heave spectrum q_j/ω_j⁴ below its
frequency. On a broad long-period sea (Tp 9-14 s) the filter then lets accelerometer bias and
noise below the band into heave and distorts the gain between and beside the modes
(docs/decisions/heave-models.md). The filter is only the optimal (Wiener)
estimator when its model has the signal's spectrum.

Element j at ω_j (a geometric grid of ``count`` frequencies in [ω_min, ω_max]) is ``stages``
damped oscillators in cascade, the first driven by white noise w of density q_j, each next one
by the velocity of the one before:

.. math::
    \\ddot p_1 = −ω_j^2 p_1 − 2ζω_j \\dot p_1 + w,\\qquad
    \\ddot p_i = −ω_j^2 p_i − 2ζω_j \\dot p_i + ω_j \\dot p_{i−1},\\qquad z_j = p_{\\text{stages}}

so heave z_j = ω_j^{s−1} s^{s−1} / (s² + 2ζω_j s + ω_j²)^s · w: a band-pass whose heave
spectrum falls as ω^{2(s−1)} below ω_j (flat for s = 1, the paper's oscillator) and whose
acceleration has no white part. q_j is set so the element's stationary heave variance (the
continuous Lyapunov equation, ``scipy.linalg.solve_continuous_lyapunov``) equals the measured
heave spectrum S_z(ω_j) = S_ä(ω_j)/ω_j⁴ times the element's width; elements below ``floor``
times the highest S_z are left out (the accelerometer's noise floor is not sea). Each element is
discretised exactly (Van Loan's matrix exponential, ``scipy.linalg.expm``). The measurement
models and the steady-state gain are those of :mod:`.oscillator_bank`.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.linalg import block_diag, expm, solve_continuous_lyapunov
from scipy.ndimage import convolve1d

from .oscillator_bank import BankModel, steady_state_filter
from .spectrum import Spectrum, band_integral

#: Ways of reading a band element's variance from the spectrum (:func:`band_elements`).
BAND_VARIANCES = ("integral", "point")


def resonator(omega: float, damping: float, stages: int) -> tuple[np.ndarray, np.ndarray]:
    """Continuous model of one band element (module docstring).

    Parameters
    ----------
    omega : float
        Centre frequency ω_j [rad/s].
    damping : float
        Damping ratio ζ of each stage.
    stages : int
        Number of cascaded oscillators s ≥ 1.

    Returns
    -------
    tuple of numpy.ndarray
        (2s, 2s) system matrix and (2s, 1) noise input; states [p_1, ṗ_1, …, p_s, ṗ_s].
    """
    n = 2 * stages
    a = np.zeros((n, n))
    for i in range(stages):
        a[2 * i, 2 * i + 1] = 1.0
        a[2 * i + 1, 2 * i] = -omega**2
        a[2 * i + 1, 2 * i + 1] = -2.0 * damping * omega
        if i > 0:
            a[2 * i + 1, 2 * i - 1] = omega
    g = np.zeros((n, 1))
    g[1, 0] = 1.0
    return a, g


def discretise(a: np.ndarray, g: np.ndarray, density: float, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact discrete transition and process-noise covariance of ẋ = a x + g w, w white of
    ``density`` (Van Loan 1978, by ``scipy.linalg.expm``)."""
    n = len(a)
    m = np.zeros((2 * n, 2 * n))
    m[:n, :n] = -a
    m[:n, n:] = density * (g @ g.T)
    m[n:, n:] = a.T
    e = expm(m * dt)
    phi = e[n:, n:].T
    q = phi @ e[:n, n:]
    return phi, 0.5 * (q + q.T)


def band_grid(omega_min: float, omega_max: float, count: int) -> np.ndarray:
    """(count,) geometric grid of element frequencies [rad/s] (constant relative spacing, as a
    constant damping ratio gives each element a bandwidth proportional to its frequency)."""
    return np.geomspace(omega_min, omega_max, count)


def band_elements(spectrum: Spectrum, grid: np.ndarray, floor: float,
                  variance: str = "integral", smoothing: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Elements of the band and their heave variances from an acceleration spectrum.

    Element j covers the band between the geometric midpoints of its neighbours in ``grid``
    (the end elements as far out as in). ``variance="integral"`` (default): its variance is the
    heave spectrum S_z(ω) = S_ä(ω)/ω⁴ integrated over that band, each periodogram bin spread
    evenly over its width. ``"point"``: S_z interpolated at ω_j times the grid's spacing there,
    one or two bins of a periodogram whose values scatter ±100 %
    (:data:`~marinefmu.estimators.heave.common.WINDOW_MAX`, docs/decisions/heave-window.md).

    Parameters
    ----------
    spectrum : Spectrum
        From :func:`~.spectrum.acceleration_spectrum`.
    grid : numpy.ndarray
        (M,) candidate frequencies [rad/s], ascending, geometric, M ≥ 2 (:func:`band_grid`).
    floor : float
        Elements whose mean heave density over their band (``"point"``: at ω_j) is below
        ``floor`` times the highest are left out.
    variance : str
        ``"integral"`` or ``"point"`` (above).
    smoothing : int
        Half-width h ≥ 0 of a smoothing of the elements' heave densities over their neighbours
        (:func:`smooth_densities`; 0: none), before the floor is applied.

    Returns
    -------
    tuple of numpy.ndarray
        Frequencies [rad/s] and heave variances [m²] of the elements kept (possibly none).
    """
    if variance == "point":
        s_z = np.interp(grid, spectrum.omega, spectrum.acc_density) / grid**4
        s_z = smooth_densities(s_z, np.gradient(grid), smoothing)
        keep = (s_z > 0.0) & (s_z >= floor * s_z.max())
        return grid[keep], (s_z * np.gradient(grid))[keep]
    mid = np.sqrt(grid[1:] * grid[:-1])
    lo = np.concatenate([[grid[0] ** 2 / mid[0]], mid])
    hi = np.concatenate([mid, [grid[-1] ** 2 / mid[-1]]])
    var = band_integral(spectrum.omega, spectrum.acc_density / spectrum.omega**4, lo, hi)
    density = smooth_densities(var / (hi - lo), hi - lo, smoothing)
    var = density * (hi - lo)
    keep = (density > 0.0) & (density >= floor * density.max())
    return grid[keep], var[keep]


def smooth_densities(density: np.ndarray, width: np.ndarray, half_width: int) -> np.ndarray:
    """Element heave densities smoothed over their neighbours in the log domain, the band's
    variance kept.

    Why. The elements' weights should be the sea's spectrum, but a few minutes of record give
    one realisation of it: a Hann periodogram's bins scatter ±100 %, and an element's band of
    2-4 bins (7 % wide at 36 elements) still ±50 % (docs/decisions/gnss-fusion-coast.md). An
    element weighted far below its neighbours leaves the acceleration at its frequency to them,
    whose ω² turn it into displacement of the wrong size. The ensemble spectrum is smooth on
    that scale, so averaging neighbours trades a little resolution for a steadier weight. The
    average is of log densities (a geometric mean: a steep band edge, where the density falls
    by decades from one element to the next, does not spill into the elements beyond it, as an
    arithmetic mean or a wider periodogram taper does), with binomial weights (1-2-1 for
    ``half_width`` 1), the end values repeated at the ends (:func:`scipy.ndimage.convolve1d`,
    ``mode="nearest"``); the result is scaled so that Σ density·width is unchanged (a
    geometric mean of scattered values is biased low).

    Parameters
    ----------
    density : numpy.ndarray
        (M,) heave densities of the elements [m²/(rad/s)], ≥ 0, ascending in frequency.
    width : numpy.ndarray
        (M,) the elements' band widths [rad/s], > 0.
    half_width : int
        h ≥ 0: 2h + 1 binomial weights (0: ``density`` returned as it is).

    Examples
    --------
    >>> d = smooth_densities(np.array([1.0, 4.0, 1.0]), np.ones(3), 1)
    >>> [round(float(v), 3) for v in d], round(float(d.sum()), 6)
    ([1.757, 2.485, 1.757], 6.0)
    """
    density = np.asarray(density, dtype=float)
    if half_width <= 0 or len(density) < 2 or density.max() <= 0.0:
        return density
    weights = np.array([math.comb(2 * half_width, k) for k in range(2 * half_width + 1)], dtype=float)
    weights /= weights.sum()
    log_d = np.log(np.maximum(density, density.max() * 1e-12))
    smooth = np.exp(convolve1d(log_d, weights, mode="nearest"))
    return smooth * float(np.sum(density * width) / np.sum(smooth * width))


def build_band_bank(omega: np.ndarray, variance: np.ndarray, dt: float, damping: float, stages: int,
                    offset_noise: float, acc_noise: float, measurement: str = "increment") -> BankModel:
    """The band observer's model and steady-state filter.

    Parameters
    ----------
    omega, variance : numpy.ndarray
        (m,) element frequencies [rad/s] and stationary heave variances [m²].
    dt : float
        Step [s].
    damping, stages
        See :func:`resonator`.
    offset_noise : float
        Random-walk density of the offset [m/s²/√s].
    acc_noise : float
        Accelerometer white-noise density [m/s²/√Hz].
    measurement : str
        ``"increment"`` or ``"paper"`` (:mod:`.oscillator_bank`).
    """
    omega = np.asarray(omega, dtype=float)
    blocks_a, blocks_q, rows_c = [], [], []
    for w, v in zip(omega, variance):
        a_c, g = resonator(float(w), damping, stages)
        unit = solve_continuous_lyapunov(a_c, -(g @ g.T))[-2, -2]     # heave variance per unit q
        a_d, q_d = discretise(a_c, g, float(v) / unit, dt)
        blocks_a.append(a_d)
        blocks_q.append(q_d)
        rows_c.append(a_c[-1])                                          # the element's acceleration
    a = block_diag(*blocks_a, np.eye(1))
    q = block_diag(*blocks_q, np.zeros((1, 1)))
    q[-1, -1] = offset_noise**2 * dt
    c = np.concatenate([*rows_c, [1.0]])
    return steady_state_filter(omega, 2 * stages, a, q, c, dt, acc_noise, measurement)

