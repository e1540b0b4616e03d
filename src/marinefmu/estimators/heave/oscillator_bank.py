"""Step 3 of paper 003: the observer model, a bank of undamped oscillator modes plus a
random-walk offset (eqs. 3-9), its steady-state Kalman gain, and the map that carries the state
across a change of the mode set.

State x = [z_1, ż_1, …, z_m, ż_m, x_off] (eq. 9); the measurement is the vertical acceleration

.. math:: y = \\sum_j \\ddot z_j + x_{off} = \\sum_j (−ω_j^2 z_j) + x_{off} + ξ \\qquad \\text{(eqs. 5-6)}

(the paper's C in eq. 9 prints +ω_j², its eq. 5 −ω_j²; the sign of eq. 5 is the physics).

**Transition.** ``"exact"`` (default): each mode is a rotation in (z, ż/ω),

.. math:: A_j = \\begin{bmatrix} \\cos ωΔt & \\sin(ωΔt)/ω \\\\ −ω\\sin ωΔt & \\cos ωΔt \\end{bmatrix}

which keeps the oscillator's energy. ``"euler"`` is eq. 9 as printed, A_j = [[1, Δt], [−ω²Δt, 1]]
(det = 1 + ω²Δt² > 1: the modes grow by that factor each step unless the gain pulls them back).

**Process noise.** Each mode is driven by white acceleration noise of density
q_j = ``mode_noise``·ω_j: the paper multiplies the Q elements of a mode by its frequency (section
2.3). Its discrete covariance is the closed-form integral ∫₀^Δt e^{Aτ}GGᵀe^{Aᵀτ}dτ q_j with
G = [0, 1]ᵀ, the same for both transitions. The offset is a random walk of density
``offset_noise`` (eq. 7). The measurement noise is R = N²/Δt for a white accelerometer noise of
density N (band-limited to the sample rate, as :mod:`marinefmu.sea.sensors` generates it).

**Measurement.** ``"paper"`` is eq. 6/9: y_k = C x_k with C = [−ω_1², 0, …, 1], the
acceleration of the modes' *model* (−ω_j² z_j). A sea has a continuous spectrum, so most of its
energy is not at a mode frequency, and this model scales such energy by 1/ω_j² instead of
1/ω² and shifts its phase: tens of percent heave error on a JONSWAP sea. ``"increment"``
(default) measures what an accelerometer sees, the true acceleration averaged over the step,
y_k = Σ_j (ż_j,k+1 − ż_j,k)/Δt + x_off + v_k, which contains the modes' process noise. That
correlation is removed by the standard transformation (Simon, *Optimal State Estimation*,
2006, section 7.1): with N = Cov(w_k, e_k) and R' the variance of e_k, x_{k+1} = Āx_k + J y_k
+ w̄_k with J = N/R', Ā = A − J C and Cov(w̄) = Q − N Nᵀ/R', after which the ordinary Kalman
filter (and ``dlqe``) applies. The observer then double-integrates the measured acceleration
wherever the modes' spectrum dominates the noise, and the undamped modes only hold the
integration from drifting.

**Gain.** Between mode changes the model is LTI, so the Kalman gain converges; it is computed
once per mode set by python-control's ``dlqe`` (discrete algebraic Riccati equation). ``dlqe``
returns the predictor gain L = A P⁻Cᵀ S⁻¹ and the prior covariance P⁻; the filter uses the
update gain K = P⁻Cᵀ S⁻¹ (L = A K; a test shows K and P⁻ equal those of a filterpy
``KalmanFilter`` run to convergence).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import control
import numpy as np

DISCRETISATIONS = ("exact", "euler")


def mode_transition(omega: float, dt: float, discretisation: str = "exact") -> np.ndarray:
    """(2, 2) A_j of one mode over ``dt`` [s] at ``omega`` [rad/s] (eq. 9 or its exact form)."""
    if discretisation == "euler":
        return np.array([[1.0, dt], [-omega**2 * dt, 1.0]])
    c, s = math.cos(omega * dt), math.sin(omega * dt)
    return np.array([[c, s / omega], [-omega * s, c]])


def mode_noise_covariance(omega: float, dt: float, density: float) -> np.ndarray:
    """(2, 2) discrete covariance of an oscillator driven by white acceleration noise.

    Parameters
    ----------
    omega : float
        Mode frequency [rad/s].
    dt : float
        Step [s].
    density : float
        Acceleration noise density q [m²/s³].
    """
    s2 = math.sin(2.0 * omega * dt) / (2.0 * omega)
    q11 = density / (2.0 * omega**2) * (dt - s2)
    q12 = density * math.sin(omega * dt) ** 2 / (2.0 * omega**2)
    q22 = density / 2.0 * (dt + s2)
    return np.array([[q11, q12], [q12, q22]])


MEASUREMENTS = ("increment", "paper")


@dataclass(frozen=True)
class BankModel:
    r"""Discrete model of the mode bank (eqs. 8-9) with its steady-state Kalman filter.

    The filter, for either measurement model (module docstring), is

    .. math::
        x^+_k = x^-_k + K (y_k − C x^-_k),\qquad x^-_{k+1} = \bar A x^+_k + J y_k

    with J = 0, Ā = A for ``"paper"``.

    Attributes
    ----------
    omega : numpy.ndarray
        (m,) mode frequencies [rad/s].
    block : int
        States per mode: 2 for an oscillator (z, ż), 2·stages for a band element whose last
        two states are its heave and heave rate.
    measurement : str
        ``"increment"`` or ``"paper"``.
    A, Q : numpy.ndarray
        (n, n) transition and process-noise covariance, n = 2m + 1.
    A_bar, J : numpy.ndarray
        (n, n) transition and (n,) measurement feed-through of the decorrelated model.
    C : numpy.ndarray
        (n,) measurement row.
    R : float
        Variance of the measurement noise (the decorrelated model's) [(m/s²)²].
    K : numpy.ndarray
        (n,) steady-state update gain P Cᵀ / S.
    P : numpy.ndarray
        (n, n) steady-state prior covariance.
    S : float
        Innovation variance C P Cᵀ + R.

    Notes
    -----
    K, P and S come from the discrete algebraic Riccati equation of (Ā, Q, C, R) (python-control
    ``dlqe``), solved on first use and kept. An estimator that runs the model in a Kalman filter
    of its own and only tracks the spectrum with the observer
    (:class:`~marinefmu.estimators.gnss_fusion.wave_coast.WaveCoast`) needs P for its first
    model and for elements new to a later one only; the solution of a 217-state band costs
    about 0.3 s, and the coast's five observers build a model every minute.
    """

    omega: np.ndarray
    block: int
    measurement: str
    A: np.ndarray
    Q: np.ndarray
    A_bar: np.ndarray
    J: np.ndarray
    C: np.ndarray
    R: float

    @property
    def n(self) -> int:
        """State dimension 2m + 1."""
        return len(self.C)

    @cached_property
    def P(self) -> np.ndarray:
        """(n, n) steady-state prior covariance (class docstring), symmetrised."""
        _, p, _ = control.dlqe(self.A_bar, np.eye(self.n), self.C[None, :], self.Q, np.array([[self.R]]))
        return 0.5 * (np.asarray(p) + np.asarray(p).T)

    @cached_property
    def S(self) -> float:
        """Innovation variance C P Cᵀ + R."""
        return float(self.C @ self.P @ self.C + self.R)

    @cached_property
    def K(self) -> np.ndarray:
        """(n,) steady-state update gain P Cᵀ / S."""
        return self.P @ self.C / self.S

    @cached_property
    def heave_rows(self) -> np.ndarray:
        """(2, n) rows that sum the modes' positions and velocities: [Σz_j; Σż_j]."""
        rows = np.zeros((2, self.n))
        rows[0, self.block - 2:-1:self.block] = 1.0
        rows[1, self.block - 1:-1:self.block] = 1.0
        return rows

    @cached_property
    def closed_loop(self) -> np.ndarray:
        """Ā(I − K C): transition of the prior error from one step to the next."""
        return self.A_bar @ (np.eye(self.n) - np.outer(self.K, self.C))

    def heave_response(self, omega: np.ndarray, dt: float) -> np.ndarray:
        """Frequency response of the steady-state observer from true to estimated heave.

        For a noise-free sinusoidal heave z(t) = e^{jωt}, sampled every ``dt`` s as the observer
        receives it (the sample a_k = −ω² e^{jωt_k}; ``"increment"`` measures the mean of two
        bounding samples), the estimate settles to H(ω) e^{jωt_k}. H = 1 is a perfect observer;
        |H − 1| is the relative heave error of that frequency even with a perfect accelerometer:
        at high signal-to-noise the filter double-integrates, and the model's prior below and
        between its modes fixes the two integration constants, which acts as a high-pass.

        Parameters
        ----------
        omega : numpy.ndarray
            Frequencies [rad/s].
        dt : float
            Step the model was built for [s].

        Returns
        -------
        numpy.ndarray
            Complex H(ω), same shape as ``omega``.

        Notes
        -----
        ``"increment"``: x_k = Φ x_{k−1} + b y_k with Φ = Ā(I − KC), b = ĀK + J and
        y_k = (a_{k−1} + a_k)/2, so X = (I − Φ e^{−jωΔt})⁻¹ b Y. ``"paper"``: x_k = (I − KC)A x_{k−1}
        + K a_k. Closed form of the recursion the observer runs (a test compares it with the
        observer's own steps).
        """
        w = np.atleast_1d(np.asarray(omega, dtype=float))
        eye = np.eye(self.n)
        if self.measurement == "paper":
            phi, b = (eye - np.outer(self.K, self.C)) @ self.A, self.K
        else:
            phi, b = self.closed_loop, self.A_bar @ self.K + self.J
        out = np.empty(w.shape, dtype=complex)
        for i, wi in enumerate(w):
            back = np.exp(-1j * wi * dt)
            y = -wi**2 * ((1.0 + back) / 2.0 if self.measurement == "increment" else 1.0)
            out[i] = self.heave_rows[0] @ np.linalg.solve(eye - phi * back, b * y)
        return out.reshape(np.shape(omega))


def bank_matrices(omega: np.ndarray, dt: float, mode_noise: float, offset_noise: float,
                  discretisation: str = "exact") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A, Q and the paper's measurement row C of eq. 9 for the modes ``omega`` [rad/s].

    Parameters
    ----------
    omega : numpy.ndarray
        (m,) mode frequencies [rad/s], > 0.
    dt : float
        Step [s].
    mode_noise : float
        Acceleration noise density per rad/s of mode frequency [m²/s²]: q_j = mode_noise·ω_j.
    offset_noise : float
        Random-walk density of the offset [m/s²/√s].
    discretisation : str
        ``"exact"`` or ``"euler"`` (eq. 9).
    """
    m = len(omega)
    n = 2 * m + 1
    a, q, c = np.zeros((n, n)), np.zeros((n, n)), np.zeros(n)
    for j, w in enumerate(omega):
        sl = slice(2 * j, 2 * j + 2)
        a[sl, sl] = mode_transition(float(w), dt, discretisation)
        q[sl, sl] = mode_noise_covariance(float(w), dt, mode_noise * float(w))
        c[2 * j] = -float(w) ** 2
    a[-1, -1] = 1.0
    q[-1, -1] = offset_noise**2 * dt
    c[-1] = 1.0
    return a, q, c


def build_bank(omega: np.ndarray, dt: float, mode_noise: float, offset_noise: float, acc_noise: float,
               discretisation: str = "exact", measurement: str = "increment") -> BankModel:
    """The paper's mode bank with its steady-state gain (python-control ``dlqe``).

    Parameters
    ----------
    omega, dt, mode_noise, offset_noise, discretisation
        See :func:`bank_matrices`.
    acc_noise : float
        Accelerometer white-noise density N [m/s²/√Hz]: a sample has variance N²/dt, the
        mean of two N²/(2dt).
    measurement : str
        ``"increment"`` (mean acceleration over the step = velocity increment / dt) or
        ``"paper"`` (eq. 9: y = C x).
    """
    omega = np.asarray(omega, dtype=float)
    a, q, c = bank_matrices(omega, dt, mode_noise, offset_noise, discretisation)
    return steady_state_filter(omega, 2, a, q, c, dt, acc_noise, measurement)


def steady_state_filter(omega: np.ndarray, block: int, a: np.ndarray, q: np.ndarray, c: np.ndarray, dt: float,
                        acc_noise: float, measurement: str) -> BankModel:
    """The Kalman filter of a bank (modes of ``block`` states, then the offset) for either
    measurement model; its steady-state gain comes from ``dlqe`` on first use (:class:`BankModel`).

    Parameters
    ----------
    omega : numpy.ndarray
        (m,) mode frequencies [rad/s].
    block : int
        States per mode; the last two of each are its heave and heave rate.
    a, q : numpy.ndarray
        (n, n) discrete transition and process-noise covariance, n = block·m + 1.
    c : numpy.ndarray
        (n,) the paper's measurement row: the modes' acceleration plus the offset.
    dt : float
        Step [s].
    acc_noise : float
        Accelerometer white-noise density N [m/s²/√Hz].
    measurement : str
        ``"increment"`` or ``"paper"`` (module docstring).
    """
    n = len(c)
    if measurement == "paper":
        a_bar, j, r = a, np.zeros(n), acc_noise**2 / dt
    else:
        hv = np.zeros(n)
        hv[block - 1:-1:block] = 1.0
        c = hv @ (a - np.eye(n)) / dt
        c[-1] = 1.0
        cross = q @ hv / dt                                # Cov(w_k, e_k)
        r = acc_noise**2 / (2.0 * dt) + float(hv @ q @ hv) / dt**2
        j = cross / r
        a_bar = a - np.outer(j, c)
        q = q - np.outer(cross, cross) / r                 # decorrelated process noise
    return BankModel(omega, block, measurement, a, q, a_bar, j, c, r)


def carry_map(old: np.ndarray, new: np.ndarray, block: int = 2) -> np.ndarray:
    """(block·m_new + 1, block·m_old + 1) map of the state across a change of the mode set.

    Every old mode's states go to the nearest new mode in frequency (a persisting mode keeps
    its state; a vanished mode's state joins its nearest neighbour), the offset to the offset.
    So Σz_j, Σż_j and the offset, hence heave, heave rate and offset, are continuous across the
    change: no transient in the output. New modes with no old mode nearby start at zero.
    """
    t = np.zeros((block * len(new) + 1, block * len(old) + 1))
    eye = np.eye(block)
    for i, w in enumerate(old):
        j = int(np.argmin(np.abs(np.asarray(new) - w)))
        t[block * j:block * (j + 1), block * i:block * (i + 1)] += eye
    t[-1, -1] = 1.0
    return t
