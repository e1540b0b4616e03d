"""Design of the heave-compensation controller with python-control (issue 9).

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

Feedforward: k_ff = 1 (full compensation of the estimated heave rate).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .ahc.controller import ControllerParams
from .ahc.winch import WinchParams
from .errors import ParameterError, check_range


@dataclass(frozen=True)
class AhcDesign:
    """A tuned controller and what the linear analysis says of it.

    Attributes
    ----------
    controller : ControllerParams
        The gains (k_ff, k_p, k_i) with the winch's nominal length.
    crossover : float
        Crossover frequency of the length loop [rad/s].
    phase_margin, gain_margin : float
        Margins of the length loop [deg], [-] (inf when the phase never reaches -180°).
    closed_loop_poles : numpy.ndarray
        Poles of the length loop closed with C.
    """

    controller: ControllerParams
    crossover: float
    phase_margin: float
    gain_margin: float
    closed_loop_poles: np.ndarray


def winch_tf(p: WinchParams):
    """Speed command → wire length [m per m/s], ``control.TransferFunction``."""
    import control

    if p.order == 1:
        return control.tf([1.0], [p.tau, 1.0, 0.0])
    w = p.omega_n
    return control.tf([w * w], [1.0, 2.0 * p.zeta * w, w * w, 0.0])


def load_tf(p: WinchParams):
    """Wire length → load position (tip still), ``control.TransferFunction``."""
    import control

    w = math.sqrt(p.stiffness / p.mass)
    zeta = p.damping / (2.0 * math.sqrt(p.stiffness * p.mass))
    return control.tf([w * w], [1.0, 2.0 * zeta * w, w * w])


def _loop(plant, kp: float, wc: float):
    import control

    return control.tf([kp, kp * wc / 10.0], [1.0, 0.0]) * plant


def design(winch: WinchParams | None = None, phase_margin: float = 60.0) -> AhcDesign:
    """Tune the PI length loop for ``winch`` (module docstring).

    Raises
    ------
    ParameterError
        For a phase margin outside (0, 90) deg, or when no crossover gives a stable loop with
        the margin (the cause named).
    """
    import control

    winch = winch or WinchParams()
    check_range("phase_margin", phase_margin, lo=0.0, hi=90.0, lo_open=True, hi_open=True, unit="deg")
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
    ctrl = ControllerParams(length0=winch.length0, k_ff=1.0, k_p=float(kp), k_i=float(kp * wc / 10.0))
    return AhcDesign(ctrl, float(wc), float(pm), float(gm), poles)
