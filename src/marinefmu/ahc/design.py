"""Design of the heave-compensation controller with python-control.

Linear models (``control.tf``):

- winch, speed command → wire length: P(s) = 1 / (s (τ s + 1)) (first-order servo; second
  order: ω_n² / (s (s² + 2ζω_n s + ω_n²)));
- load on the wire, wire length → load motion: W(s) = ω_w² / (s² + 2ζ_w ω_w s + ω_w²),
  ω_w = √(k/m), ζ_w = c / (2√(k m)).

Tuning (loop shaping of the length loop, documented so it can be repeated): PI feedback
C(s) = k_p + k_i/s with the integral corner a decade below the crossover, k_i = k_p ω_c / 10,
and k_p set so that |C P| = 1 at the crossover ω_c. ω_c is the largest value that keeps the
phase margin ≥ ``phase_margin`` and stays below half the wire-load mode (the loop must not
shake the load on its wire), searched on a grid. ``control.stability_margins`` gives the margins
of the chosen loop, ``control.feedback`` its closed loop, whose poles must all lie in the left
half-plane: a design that fails is refused with the cause named.

Feedforward: k_ff = 1 (full compensation of the estimated heave rate) by :func:`design`; with
an identified estimator, :func:`fit_feedforward` picks the k_ff that minimises the predicted
residual.

**The estimator in the loop** (:func:`identify_response`): the transfers from the true
crane-tip heave x to the heave ĥ and heave rate r̂ the controller receives are identified from
a co-simulation record, H_h = S_xĥ/S_xx and H_r = S_ẋr̂/S_ẋẋ (Welch cross-spectra,
``scipy.signal.csd``), each fitted as gain·e^{−jω·delay} over the band that holds the heave,
with each estimate's noise (the part not linearly related to the truth).

**Residual** (:func:`residual_response`): the load hangs at tip + L (+ stretch) and follows
it through the wire, W(s). The controller (``u = −k_ff r̂ + C(L_ref − L)``, L_ref = L₀ − k_ff ĥ)
acts, in a Jacobi co-simulation with base step h, on inputs one step old and its command is
held over the next step: a delay D = 1.5 h on every signal it passes on, inside the length
loop too; the winch holds the tip's position over a step (h/2). So

    load / tip = W (e^{−sh/2} − k_ff (A s H_r + B H_h)),
    A = e^{−sD} P/(1 + P C e^{−sD}),  B = e^{−sD} P C/(1 + P C e^{−sD}),

with H_h, H_r the estimator's heave and heave-rate responses (1 for the truth). The delays
matter: with them the model predicts the residual of a co-simulation of the built-in scenario
``ahc`` (tested to 15 %), without them it misses it by a large factor. The predicted
residual (:func:`predicted_residual`) weighs |…|² with the tip's heave spectrum and adds the
estimates' noise at every heave frequency.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .controller import AhcControllerParams
from .winch import AhcWinchParams
from ..errors import ParameterError, check_range
from ..frames import HEAVE_CUTOFF


@dataclass(frozen=True)
class EstimatorResponse:
    """An identified estimator: true crane-tip heave x → the heave ĥ and heave rate r̂ the
    controller receives.

    Attributes
    ----------
    omega : numpy.ndarray
        Frequencies [rad/s].
    spectrum : numpy.ndarray
        One-sided PSD of the true heave S_xx [m²/(rad/s)].
    heave, rate : numpy.ndarray
        Complex H_h = S_xĥ/S_xx and H_r = S_ẋr̂/S_ẋẋ: each estimate over what it estimates
        (1 for a perfect estimator), as measured (ẋ by central difference of x).
    heave_noise, rate_noise : numpy.ndarray
        PSD of the part of each estimate not linearly related to what it estimates (its
        noise), S_ĥĥ − |S_xĥ|²/S_xx [m²/(rad/s)] and S_r̂r̂ − |S_ẋr̂|²/S_ẋẋ [m²/s²/(rad/s)]
        (each against its own reference: rescaling one by ω² within a Welch bin errs by
        percents, more than the noise).
    coherence : numpy.ndarray
        Magnitude-squared coherence of x and ĥ, [0, 1].
    heave_model, rate_model : tuple of float
        (gain, delay [s]) of H ≈ gain·e^{−jω·delay} fitted over :meth:`band` (weighted by
        the spectrum: gain the weighted mean of |H|, delay the weighted slope of its phase):
        the measured responses vary from bin to bin with the estimation noise, the models are
        what the design uses.
    """

    omega: np.ndarray
    spectrum: np.ndarray
    heave: np.ndarray
    rate: np.ndarray
    heave_noise: np.ndarray
    rate_noise: np.ndarray
    coherence: np.ndarray
    heave_model: tuple[float, float] = (1.0, 0.0)
    rate_model: tuple[float, float] = (1.0, 0.0)

    def band(self, share: float = 0.99) -> np.ndarray:
        """Boolean mask of the frequencies that hold the central ``share`` of the heave's
        variance (where the identification means something)."""
        c = np.cumsum(self.spectrum)
        c = c / c[-1]
        tail = 0.5 * (1.0 - share)
        return (c >= tail) & (c <= 1.0 - tail)

    @staticmethod
    def evaluate(model: tuple[float, float], omega: np.ndarray) -> np.ndarray:
        """A (gain, delay) model at ``omega`` [rad/s]."""
        return model[0] * np.exp(-1j * np.asarray(omega, dtype=float) * model[1])


def _fit(h: np.ndarray, w: np.ndarray, weight: np.ndarray) -> tuple[float, float]:
    """(gain, delay) of gain·e^{−jω·delay} ≈ ``h`` (weighted mean of |h|, weighted slope of
    its unwrapped phase through the origin)."""
    phase = np.unwrap(np.angle(h))
    return (float(np.sum(weight * np.abs(h)) / np.sum(weight)),
            float(-np.sum(weight * w * phase) / np.sum(weight * w ** 2)))


def identify_response(truth: np.ndarray, heave: np.ndarray, rate: np.ndarray, dt: float, segment: float = 100.0
                      ) -> EstimatorResponse:
    """The estimator's responses and noise from a true heave record and the estimates
    (module docstring; Welch spectra, ``scipy.signal.csd``).

    Parameters
    ----------
    truth, heave, rate : numpy.ndarray
        (N,) true heave [m], and the heave [m] and heave rate [m/s] estimates as the
        controller receives them, same times.
    dt : float
        Sample interval [s].
    segment : float
        Welch segment [s] (resolution 2π/segment rad/s), at most half the record.

    Raises
    ------
    ParameterError
        For records of different lengths, non-finite samples, or a record shorter than two
        segments.
    """
    from scipy import signal

    x, y, r = (np.asarray(v, dtype=float) for v in (truth, heave, rate))
    if not (x.shape == y.shape == r.shape and x.ndim == 1):
        raise ParameterError(f"truth, heave and rate must be 1-D of one length, got {x.shape}, {y.shape}, {r.shape}")
    if not all(np.all(np.isfinite(v)) for v in (x, y, r)):
        raise ParameterError("truth or estimates hold NaN/Inf: identify on the estimator's valid span")
    check_range("segment", segment, lo=0.0, hi=0.5 * len(x) * dt, lo_open=True, unit="s (half the record)")
    n = int(round(segment / dt))
    fs = 1.0 / dt
    x, y, r = x - x.mean(), y - y.mean(), r - r.mean()

    def csd(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return signal.csd(a, b, fs=fs, nperseg=n)

    f, pxx = csd(x, x)
    pxx = np.real(pxx)
    keep = (f > 0) & (pxx > 0)
    w = 2 * math.pi * f[keep]
    scale = 1.0 / (2 * math.pi)
    pxx = pxx[keep]
    xd = np.gradient(x, dt)        # the true rate (central difference: error (ωΔt)²/6 ≈ 1e-5 in the band)
    pxy, pvr, pvv, pyy, prr = (csd(a, b)[1][keep] for a, b in ((x, y), (xd, r), (xd, xd), (y, y), (r, r)))
    pvv, pyy, prr = np.real(pvv), np.real(pyy), np.real(prr)
    resp = EstimatorResponse(w, pxx * scale, pxy / pxx, pvr / pvv, np.maximum(pyy - np.abs(pxy) ** 2 / pxx, 0.0) * scale,
                             np.maximum(prr - np.abs(pvr) ** 2 / pvv, 0.0) * scale, np.abs(pxy) ** 2 / (pxx * pyy))
    m = resp.band()
    weight = resp.spectrum[m]
    return replace(resp, heave_model=_fit(resp.heave[m], w[m], weight), rate_model=_fit(resp.rate[m], w[m], weight))


def _freq(sys, s: np.ndarray) -> np.ndarray:
    """Frequency response of a ``control`` system at the points ``s``."""
    return np.array([complex(sys(z)) for z in s])


def _paths(s: np.ndarray, winch: AhcWinchParams, ctrl: AhcControllerParams, step: float) -> tuple[np.ndarray, np.ndarray]:
    """(A, B): the wire length is L = −k_ff (A·r̂ + B·ĥ), with the controller's delay
    D = 1.5·``step`` (module docstring): A = e^{−sD} P/(1 + P C e^{−sD}),
    B = e^{−sD} P C/(1 + P C e^{−sD}) (rate feedforward and the closed length loop)."""
    p = _freq(winch_tf(winch), s)
    c = ctrl.k_p + ctrl.k_i / s
    lag = np.exp(-1.5 * step * s)
    d = lag / (1.0 + p * c * lag)
    return d * p, d * p * c


def residual_response(omega: np.ndarray, winch: AhcWinchParams, ctrl: AhcControllerParams,
                      estimator: tuple[np.ndarray, np.ndarray] | None = None, step: float = 0.0) -> np.ndarray:
    """Load heave / tip heave at ``omega`` [rad/s] (module docstring), complex:
    W (e^{−s·step/2} − k_ff (A s H_r + B H_h)).

    ``estimator`` is (H_h, H_r) at ``omega`` (None: the truth, both 1); ``step`` the
    co-simulation's base step [s] (0: continuous)."""
    s = 1j * np.asarray(omega, dtype=float)
    a, b = _paths(s, winch, ctrl, step)
    hh, hr = (1.0, 1.0) if estimator is None else estimator
    return _freq(load_tf(winch), s) * (np.exp(-0.5 * step * s) - ctrl.k_ff * (a * s * hr + b * hh))


def _noise(resp: EstimatorResponse, m: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """PSD of the noise of v = A r̂ + B ĥ, taking the two estimates' noises as fully
    correlated (an upper bound: (|A|√N_r + |B|√N_h)²)."""
    return (np.abs(a) * np.sqrt(resp.rate_noise[m]) + np.abs(b) * np.sqrt(resp.heave_noise[m])) ** 2


def _noise_power(resp: EstimatorResponse, winch: AhcWinchParams, ctrl: AhcControllerParams, step: float) -> float:
    """Σ |W|² S_v,noise over every frequency of heave (ω ≥ :data:`~marinefmu.frames.HEAVE_CUTOFF`),
    per unit k_ff²: the estimates' noise reaches the load wherever it is, not only where the
    sea is."""

    m = resp.omega >= HEAVE_CUTOFF
    s = 1j * resp.omega[m]
    a, b = _paths(s, winch, ctrl, step)
    return float(np.sum(np.abs(_freq(load_tf(winch), s)) ** 2 * _noise(resp, m, a, b)))


def predicted_residual(resp: EstimatorResponse, winch: AhcWinchParams, ctrl: AhcControllerParams, step: float = 0.0,
                       estimator: bool = True) -> float:
    """Predicted load heave / tip heave [-]: the models' part Σ S_xx |:func:`residual_response`|²
    over the identified band plus the estimates' noise k_ff² Σ |W|² S_v,noise over every
    heave frequency, over Σ S_xx; ``estimator=False`` for a truth-fed loop. Checked against a
    co-simulation of the scenario ``ahc`` with the designed gains (tested to 15 %)."""
    m = resp.band()
    w = resp.omega[m]
    models = (resp.evaluate(resp.heave_model, w), resp.evaluate(resp.rate_model, w)) if estimator else None
    total = np.sum(resp.spectrum[m] * np.abs(residual_response(w, winch, ctrl, models, step)) ** 2)
    if estimator:
        total += ctrl.k_ff ** 2 * _noise_power(resp, winch, ctrl, step)
    return float(np.sqrt(total / np.sum(resp.spectrum[m])))


def fit_feedforward(resp: EstimatorResponse, winch: AhcWinchParams, ctrl: AhcControllerParams, step: float = 0.0
                    ) -> AhcControllerParams:
    """``ctrl`` with the k_ff in [0, 2] that minimises :func:`predicted_residual` (closed
    form: with F = A s H_r + B H_h from the models and W the wire load,
    k = Re Σ S|W|² conj(F) e^{−s·step/2} / (Σ S|W|²|F|² + Σ |W|² S_v,noise))."""
    m = resp.band()
    w = resp.omega[m]
    s = 1j * w
    a, b = _paths(s, winch, ctrl, step)
    f = a * s * resp.evaluate(resp.rate_model, w) + b * resp.evaluate(resp.heave_model, w)
    load = np.abs(_freq(load_tf(winch), s)) ** 2
    k = float(np.real(np.sum(resp.spectrum[m] * load * np.conj(f) * np.exp(-0.5 * step * s)))
              / (np.sum(resp.spectrum[m] * load * np.abs(f) ** 2) + _noise_power(resp, winch, ctrl, step)))
    return replace(ctrl, k_ff=min(2.0, max(0.0, k)))


@dataclass(frozen=True)
class AhcDesign:
    """A tuned controller and what the linear analysis says of it.

    Attributes
    ----------
    controller : AhcControllerParams
        The gains (k_ff, k_p, k_i) with the winch's nominal length.
    crossover : float
        Crossover frequency of the length loop [rad/s].
    phase_margin, gain_margin : float
        Margins of the length loop [deg], [-] (inf when the phase never reaches -180°).
    closed_loop_poles : numpy.ndarray
        Poles of the length loop closed with C.
    """

    controller: AhcControllerParams
    crossover: float
    phase_margin: float
    gain_margin: float
    closed_loop_poles: np.ndarray


def winch_tf(p: AhcWinchParams):
    """Speed command → wire length [m per m/s], ``control.TransferFunction``."""
    import control

    if p.order == 1:
        return control.tf([1.0], [p.tau, 1.0, 0.0])
    w = p.omega_n
    return control.tf([w * w], [1.0, 2.0 * p.zeta * w, w * w, 0.0])


def load_tf(p: AhcWinchParams):
    """Wire length → load position (tip still), ``control.TransferFunction``."""
    import control

    w = math.sqrt(p.stiffness / p.mass)
    zeta = p.damping / (2.0 * math.sqrt(p.stiffness * p.mass))
    return control.tf([w * w], [1.0, 2.0 * zeta * w, w * w])


def _loop(plant, kp: float, wc: float):
    import control

    return control.tf([kp, kp * wc / 10.0], [1.0, 0.0]) * plant


def check_phase_margin(phase_margin: float) -> float:
    """``phase_margin`` [deg] if in (0, 90), else :class:`~.errors.ParameterError` naming it."""
    return check_range("phase_margin", phase_margin, lo=0.0, hi=90.0, lo_open=True, hi_open=True, unit="deg")


def design(winch: AhcWinchParams | None = None, phase_margin: float = 60.0) -> AhcDesign:
    """Tune the PI length loop for ``winch`` (module docstring).

    Raises
    ------
    ParameterError
        For a phase margin outside (0, 90) deg, or when no crossover gives a stable loop with
        the margin (the cause named).
    """
    import control

    winch = winch or AhcWinchParams()
    check_phase_margin(phase_margin)
    plant = winch_tf(winch)
    w_load = math.sqrt(winch.stiffness / winch.mass)
    best = None
    for wc in np.geomspace(0.01, 0.5 * w_load, 400):
        kp = 1.0 / abs(complex(control.evalfr(_loop(plant, 1.0, wc), 1j * wc)))
        gm, pm = control.stability_margins(_loop(plant, kp, wc))[:2]
        if pm >= phase_margin:
            best = (wc, kp, gm, pm)
    if best is None:
        raise ParameterError(f"no crossover below half the wire-load mode ({0.5 * w_load:.3g} rad/s) gives a phase "
                             f"margin of {phase_margin} deg: a slower winch (tau) or a stiffer wire is needed")
    wc, kp, gm, pm = best
    closed = control.feedback(_loop(plant, kp, wc), 1)
    poles = np.asarray(control.poles(closed))
    if np.any(poles.real >= 0.0):
        raise ParameterError(f"the designed loop is unstable: closed-loop poles {np.round(poles, 4)} in the right half-plane")
    ctrl = AhcControllerParams(length0=winch.length0, k_ff=1.0, k_p=float(kp), k_i=float(kp * wc / 10.0))
    return AhcDesign(ctrl, float(wc), float(pm), float(gm), poles)
