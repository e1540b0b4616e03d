"""Wave spectra and seeded random-phase realisations of a sea state.

Spectra follow DNV-RP-C205 (2021), section 3.5.5: Pierson–Moskowitz (eq. 3.5.5.1) and
JONSWAP (eq. 3.5.5.4, σ = 0.07 below and 0.09 above the peak). The JONSWAP normalising
factor is computed numerically so that m0 = Hs²/16 holds exactly; DNV's ``1 − 0.287 ln γ``
is an approximation good to ~1 %.

Directional spreading is the cos-2s form (Longuet-Higgins 1963),
D(θ) = Γ(s+1) / (2√π Γ(s+½)) · cos^{2s}(θ/2), |θ| ≤ π.

A realisation is a sum of ``n_components`` regular waves (single summation: each component
carries one frequency and one direction, which avoids phase locking of a double sum). Each
frequency is drawn uniformly inside its bin so the record does not repeat every 2π/Δω.
Amplitudes are a_i = √(2 S(ω_i) Δω), phases uniform on [0, 2π).

Direction convention: ``heading`` is the direction the waves travel *towards*, measured
from the vessel's bow (body x) towards starboard (body y) [rad]: 0 following seas,
π/2 waves travelling to starboard (beam seas from port), π head seas.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import integrate, special

from ..errors import ParameterError, check_choice, check_int, check_range
from ..frames import G

SPECTRA = ("jonswap", "pierson-moskowitz")


def pierson_moskowitz(omega: np.ndarray, hs: float, tp: float) -> np.ndarray:
    """Pierson–Moskowitz spectrum S(ω) [m²·s/rad] (DNV-RP-C205 eq. 3.5.5.1).

    .. math:: S(ω) = \\frac{5}{16} H_s^2 ω_p^4 ω^{-5} \\exp\\left(-\\frac54 (ω/ω_p)^{-4}\\right)

    Parameters
    ----------
    omega : array_like
        Wave frequency ω [rad/s]; ω ≤ 0 gives 0.
    hs : float
        Significant wave height [m].
    tp : float
        Peak period [s], ω_p = 2π/Tp.
    """
    w = np.asarray(omega, dtype=float)
    wp = 2.0 * math.pi / tp
    out = np.zeros_like(w)
    pos = w > 0
    wr = wp / w[pos]
    out[pos] = 5.0 / 16.0 * hs**2 * wp**4 * w[pos] ** -5 * np.exp(-1.25 * wr**4)
    return out


def _peak_enhancement(omega: np.ndarray, tp: float, gamma: float) -> np.ndarray:
    wp = 2.0 * math.pi / tp
    w = np.asarray(omega, dtype=float)
    sigma = np.where(w <= wp, 0.07, 0.09)
    return gamma ** np.exp(-0.5 * ((w - wp) / (sigma * wp)) ** 2)


def _jonswap_norm(tp: float, gamma: float) -> float:
    """Factor A_γ such that A_γ·S_PM·γ^r integrates to m0 = Hs²/16 (hs=1)."""
    def shape(w: float) -> float:
        return float(pierson_moskowitz(np.array([w]), 1.0, tp)[0] * _peak_enhancement(np.array([w]), tp, gamma)[0])

    wp = 2.0 * math.pi / tp
    pts = [0.0, 0.5 * wp, wp, 1.5 * wp, 3 * wp, 10 * wp]
    m0 = sum(integrate.quad(shape, a, b, limit=200)[0] for a, b in zip(pts[:-1], pts[1:]))
    m0 += integrate.quad(shape, 10 * wp, np.inf, limit=200)[0]
    return (1.0 / 16.0) / m0


def jonswap(omega: np.ndarray, hs: float, tp: float, gamma: float = 3.3) -> np.ndarray:
    """JONSWAP spectrum S(ω) [m²·s/rad] (DNV-RP-C205 eq. 3.5.5.4), normalised to m0 = Hs²/16.

    .. math:: S_J(ω) = A_γ S_{PM}(ω) γ^{\\exp\\left(-\\frac{(ω-ω_p)^2}{2σ^2ω_p^2}\\right)}

    Parameters
    ----------
    omega : array_like
        Wave frequency ω [rad/s].
    hs, tp : float
        Significant wave height [m] and peak period [s].
    gamma : float
        Peak enhancement factor γ [-], 1 ≤ γ ≤ 10 (γ = 1 is Pierson–Moskowitz).
    """
    check_range("gamma", gamma, lo=1.0, hi=10.0)
    return _jonswap_norm(tp, gamma) * pierson_moskowitz(omega, hs, tp) * _peak_enhancement(omega, tp, gamma)


def spreading_pdf(theta: np.ndarray, s: float) -> np.ndarray:
    """cos-2s directional spreading D(θ) [1/rad], θ relative to the mean direction, |θ| ≤ π."""
    th = np.asarray(theta, dtype=float)
    c = special.gamma(s + 1.0) / (2.0 * math.sqrt(math.pi) * special.gamma(s + 0.5))
    return np.where(np.abs(th) <= math.pi, c * np.abs(np.cos(th / 2.0)) ** (2.0 * s), 0.0)


def spectral_moment(omega: np.ndarray, s: np.ndarray, n: int) -> float:
    """n-th spectral moment m_n = ∫ ωⁿ S(ω) dω (trapezoid rule) [m²·(rad/s)ⁿ]."""
    return float(np.trapezoid(np.asarray(omega) ** n * np.asarray(s), omega))


@dataclass(frozen=True)
class SeaState:
    """A validated sea state and its realisation settings.

    Parameters
    ----------
    hs : float
        Significant wave height Hs [m], 0 < Hs ≤ 30.
    tp : float
        Peak period Tp [s], 1 ≤ Tp ≤ 40.
    gamma : float
        JONSWAP peak enhancement γ [-], 1 ≤ γ ≤ 10.
    spectrum : str
        ``"jonswap"`` or ``"pierson-moskowitz"``.
    heading : float
        Mean direction the waves travel towards, relative to the bow [rad] (π = head seas).
    spreading : float
        Exponent s of cos-2s spreading [-]; 0 = long-crested, else 1 ≤ s ≤ 100.
    seed : int
        Seed of the random phases, frequencies and directions (≥ 0).
    n_components : int
        Number of regular wave components, 10 … 5000.
    omega_min, omega_max : float
        Frequency range [rad/s]; 0 selects the default 0.5 ω_p … 5 ω_p (> 99.7 % of m0).
    """

    hs: float = 2.5
    tp: float = 9.0
    gamma: float = 3.3
    spectrum: str = "jonswap"
    heading: float = math.pi
    spreading: float = 0.0
    seed: int = 1
    n_components: int = 200
    omega_min: float = 0.0
    omega_max: float = 0.0

    def __post_init__(self) -> None:
        check_range("sea.hs", self.hs, lo=0.0, hi=30.0, lo_open=True, unit="m")
        check_range("sea.tp", self.tp, lo=1.0, hi=40.0, unit="s")
        check_range("sea.gamma", self.gamma, lo=1.0, hi=10.0)
        check_choice("sea.spectrum", self.spectrum, SPECTRA)
        check_range("sea.heading", self.heading, lo=-2 * math.pi, hi=2 * math.pi, unit="rad")
        s = check_range("sea.spreading", self.spreading, lo=0.0, hi=100.0)
        if 0.0 < s < 1.0:
            check_range("sea.spreading", s, lo=1.0, hi=100.0)
        check_int("sea.seed", self.seed, lo=0, hi=2**31 - 1)
        check_int("sea.components", self.n_components, lo=10, hi=5000)
        check_range("sea.omega_min", self.omega_min, lo=0.0, hi=20.0, unit="rad/s")
        check_range("sea.omega_max", self.omega_max, lo=0.0, hi=40.0, unit="rad/s")
        lo, hi = self.omega_range
        if hi <= lo:
            raise ParameterError(f"sea.omega_max = {hi} is out of range: must be > sea.omega_min = {lo} [rad/s]")

    @property
    def omega_peak(self) -> float:
        """Peak frequency ω_p = 2π/Tp [rad/s]."""
        return 2.0 * math.pi / self.tp

    @property
    def omega_range(self) -> tuple[float, float]:
        """Realised frequency range [rad/s] after applying the defaults."""
        lo = self.omega_min if self.omega_min > 0 else 0.5 * self.omega_peak
        hi = self.omega_max if self.omega_max > 0 else 5.0 * self.omega_peak
        return lo, hi

    def density(self, omega: np.ndarray) -> np.ndarray:
        """Wave spectrum S(ω) [m²·s/rad] of this sea state."""
        if self.spectrum == "pierson-moskowitz":
            return pierson_moskowitz(omega, self.hs, self.tp)
        return jonswap(omega, self.hs, self.tp, self.gamma)


@dataclass(frozen=True)
class WaveField:
    """A realised sea: N regular components (one frequency and direction each).

    Attributes
    ----------
    omega : numpy.ndarray
        (N,) wave frequencies ω_i [rad/s].
    amplitude : numpy.ndarray
        (N,) amplitudes a_i [m].
    phase : numpy.ndarray
        (N,) phases ε_i [rad].
    direction : numpy.ndarray
        (N,) travel directions β_i relative to the bow [rad].
    d_omega : float
        Bin width Δω [rad/s].
    """

    omega: np.ndarray
    amplitude: np.ndarray
    phase: np.ndarray
    direction: np.ndarray
    d_omega: float

    @property
    def wavenumber(self) -> np.ndarray:
        """Deep-water wave numbers k_i = ω_i²/g [rad/m]."""
        return self.omega**2 / G

    def encounter_frequency(self, speed: float) -> np.ndarray:
        """Encounter frequencies ω_e = ω − k U cos β [rad/s] for forward speed U [m/s] (deep water)."""
        return self.omega - self.wavenumber * speed * np.cos(self.direction)

    @property
    def hs_nominal(self) -> float:
        """Hs = 4√m0 of the discrete realisation, m0 = Σ a_i²/2 [m]."""
        return 4.0 * math.sqrt(0.5 * float(np.sum(self.amplitude**2)))

    def elevation(self, t: np.ndarray, speed: float = 0.0, chunk: int = 4096) -> np.ndarray:
        """Wave elevation η(t) at the origin of the frame moving with the vessel [m, positive up]."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        we = self.encounter_frequency(speed)
        out = np.empty_like(t)
        for i in range(0, t.size, chunk):
            arg = np.outer(t[i : i + chunk], we) + self.phase
            out[i : i + chunk] = np.cos(arg) @ self.amplitude
        return out


def realise(sea: SeaState, stream: int = 0) -> WaveField:
    """Draw the seeded realisation of ``sea``.

    The seed feeds a :class:`numpy.random.SeedSequence` spawned into independent streams for
    frequency jitter, phases and directions, so changing one never shifts the others.
    ``stream`` selects another, statistically independent realisation of the same sea state
    (the vessel's independent-rotation mode drives the rotations with ``stream=1``).
    """
    jitter_rng, phase_rng, dir_rng = (
        np.random.default_rng(s) for s in np.random.SeedSequence(sea.seed).spawn(3 * (stream + 1))[3 * stream:]
    )
    lo, hi = sea.omega_range
    n = sea.n_components
    dw = (hi - lo) / n
    omega = lo + dw * (np.arange(n) + jitter_rng.uniform(0.0, 1.0, n))
    amplitude = np.sqrt(2.0 * sea.density(omega) * dw)
    phase = phase_rng.uniform(0.0, 2.0 * math.pi, n)
    if sea.spreading > 0:
        grid = np.linspace(-math.pi, math.pi, 4001)
        cdf = integrate.cumulative_trapezoid(spreading_pdf(grid, sea.spreading), grid, initial=0.0)
        cdf /= cdf[-1]
        direction = sea.heading + np.interp(dir_rng.uniform(0.0, 1.0, n), cdf, grid)
    else:
        direction = np.full(n, float(sea.heading))
    return WaveField(omega=omega, amplitude=amplitude, phase=phase, direction=direction, d_omega=dw)
