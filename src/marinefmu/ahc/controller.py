"""Active-heave-compensation controller (issue 9): feedforward from the estimated crane-tip
heave plus PI feedback on the wire length.

The load hangs at z_load = z_tip + L + e (NED, down positive; e the wire's stretch). To keep it
still the wire must follow L_ref = L₀ − k_ff·(ĥ − h_ref), ĥ the crane tip's heave estimate
(HeaveObserver ``point.heave``: zero-mean, down positive; h_ref = ``heave_ref`` removes a mean,
e.g. of a true position), so the speed command is

    u = −k_ff·dĥ/dt + k_p (L_ref − L) + k_i ∫ (L_ref − L) dt

with dĥ/dt the estimated heave rate (``point.heave_rate``) as feedforward and PI feedback on the
measured wire length L (the winch's ``length``). ``k_ff`` = 1 is full compensation, 0 none.
The gains come from :mod:`marinefmu.ahc_design` or by hand. A bad input (NaN, Inf, absurd)
holds the last good one and sets ``valid`` false; the integrator is clamped to ±``max_integral``
(anti-windup: while the winch saturates the error cannot grow without bound).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import check_range
from ..estimators.samples import bad_scalar


@dataclass(frozen=True)
class ControllerParams:
    """Parameters of :class:`AhcController` (FMU names in brackets).

    Parameters
    ----------
    length0 : float
        Nominal wire length L₀ [m], ≥ 0. [``length0``]
    k_ff : float
        Feedforward gain, [0, 2] (1: full compensation). [``k_ff``]
    k_p : float
        Proportional gain on the length error [1/s], ≥ 0. [``k_p``]
    k_i : float
        Integral gain [1/s²], ≥ 0. [``k_i``]
    max_integral : float
        Clamp of the integrated length error [m·s], > 0. [``max_integral``]
    heave_ref : float
        The tip's mean down position in the heave input [m], removed before use: 0 for a
        zero-mean heave estimate (HeaveObserver), the point's static z for a true position
        (VesselMotion ``truth.point.d``). [``heave_ref``]
    """

    length0: float = 20.0
    k_ff: float = 1.0
    k_p: float = 1.0
    k_i: float = 0.05
    max_integral: float = 10.0
    heave_ref: float = 0.0

    def __post_init__(self) -> None:
        check_range("length0", self.length0, lo=0.0, hi=1e4, unit="m")
        check_range("k_ff", self.k_ff, lo=0.0, hi=2.0)
        check_range("k_p", self.k_p, lo=0.0, hi=1e3, unit="1/s")
        check_range("k_i", self.k_i, lo=0.0, hi=1e3, unit="1/s2")
        check_range("max_integral", self.max_integral, lo=0.0, lo_open=True, hi=1e6, unit="m*s")
        check_range("heave_ref", self.heave_ref, lo=-1e3, hi=1e3, unit="m")


@dataclass(frozen=True)
class ControllerOutput:
    """Speed command [m/s], the length reference [m], and whether the inputs were usable."""

    command: float
    length_ref: float
    valid: bool
    warning: str | None = None


class AhcController:
    """The controller (module docstring), one step at a time."""

    def __init__(self, params: ControllerParams | None = None) -> None:
        self.params = params or ControllerParams()
        self.integral = 0.0
        self.inputs = (0.0, 0.0, self.params.length0)   # last good heave, heave rate, length

    def step(self, heave: float, heave_rate: float, length: float, dt: float) -> ControllerOutput:
        """The command for the next ``dt`` s from the tip's heave [m] and heave rate [m/s]
        estimates and the wire length [m]."""
        p = self.params
        warning = bad_scalar((("heave", heave, 1e3), ("heave rate", heave_rate, 1e3), ("length", length, 1e5)))
        if warning is None:
            self.inputs = (float(heave), float(heave_rate), float(length))
        heave, heave_rate, length = self.inputs
        ref = p.length0 - p.k_ff * (heave - p.heave_ref)
        err = ref - length
        self.integral = max(-p.max_integral, min(p.max_integral, self.integral + err * dt))
        u = -p.k_ff * heave_rate + p.k_p * err + p.k_i * self.integral
        return ControllerOutput(u, ref, warning is None, warning)

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"integral": self.integral, "inputs": list(self.inputs)}

    def set_state(self, s: dict) -> None:
        """Restore from :meth:`get_state`."""
        self.integral = float(s["integral"])
        self.inputs = tuple(float(v) for v in s["inputs"])
