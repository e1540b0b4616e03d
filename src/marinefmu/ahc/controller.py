"""Active-heave-compensation controller: feedforward from the estimated crane-tip
heave plus PI feedback on the wire length.

The load hangs at z_load = z_tip + L + e (NED, down positive; e the wire's stretch). To keep it
still the wire must follow L_ref = L₀ − k_ff·(ĥ − h_ref), ĥ the crane tip's heave estimate
(HeaveObserver ``point.heave``: zero-mean, down positive; h_ref = ``heave_ref`` removes a mean,
e.g. of a true position), so the speed command is

    u = −k_ff·dĥ/dt + k_p (L_ref − L) + k_i ∫ (L_ref − L) dt

with dĥ/dt the estimated heave rate (``point.heave_rate``) as feedforward and PI feedback on the
measured wire length L (the winch's ``length``). ``k_ff`` = 1 is full compensation, 0 none.
The gains come from :mod:`marinefmu.ahc.design` or by hand. A bad input (NaN, Inf, absurd)
holds the last good one and sets ``valid`` false; the integrator is clamped to ±``max_integral``
and the command is clipped to ±``max_command`` (set it to the winch's ``max_speed``), with
conditional integration: while the command is clipped, the error that would drive it further
into the clip is not integrated (anti-windup: without it a saturated winch winds the integral
up and the loop falls into a limit cycle of metres; measured). ``command_limited`` reports the
clip.

**Engagement.** The feedforward is weighted by w ∈ [0, 1] (both terms above take k_ff·w),
which ramps towards 1 at 1/``engage_time`` per second while the ``heave_valid`` input is true
(e.g. HeaveObserver ``valid``: its estimate has converged) and back towards 0 at the same rate
while it is false: compensation fades in when the estimator is ready, instead of stepping the
length reference by the heave of the moment, and a few rejected samples barely move it.
``valid`` is false while w < 1 (the loop does not yet compensate fully).
"""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import check_range
from ..estimators.samples import bad_scalar


@dataclass(frozen=True)
class AhcControllerParams:
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
    max_command : float
        Clip of the speed command [m/s], > 0: the winch's speed limit. [``max_command``]
    heave_ref : float
        The tip's mean down position in the heave input [m], removed before use: 0 for a
        zero-mean heave estimate (HeaveObserver), the point's static z for a true position
        (VesselMotion ``truth.point.d``). [``heave_ref``]
    engage_time : float
        Time for the feedforward to fade in (and out) [s], [0, 600]; 0 switches at once.
        [``engage_time``]
    """

    length0: float = 20.0
    k_ff: float = 1.0
    k_p: float = 1.0
    k_i: float = 0.05
    max_integral: float = 10.0
    max_command: float = 2.0
    heave_ref: float = 0.0
    engage_time: float = 10.0

    def __post_init__(self) -> None:
        check_range("length0", self.length0, lo=0.0, hi=1e4, unit="m")
        check_range("k_ff", self.k_ff, lo=0.0, hi=2.0)
        check_range("k_p", self.k_p, lo=0.0, hi=1e3, unit="1/s")
        check_range("k_i", self.k_i, lo=0.0, hi=1e3, unit="1/s2")
        check_range("max_integral", self.max_integral, lo=0.0, lo_open=True, hi=1e6, unit="m*s")
        check_range("max_command", self.max_command, lo=0.0, lo_open=True, hi=100.0, unit="m/s")
        check_range("heave_ref", self.heave_ref, lo=-1e3, hi=1e3, unit="m")
        check_range("engage_time", self.engage_time, lo=0.0, hi=600.0, unit="s")


@dataclass(frozen=True)
class ControllerOutput:
    """Speed command [m/s], the length reference [m], the feedforward's engagement w [-],
    whether the command was clipped, and whether the loop compensates fully with usable inputs."""

    command: float
    length_ref: float
    engagement: float
    command_limited: bool
    valid: bool
    warning: str | None = None


class AhcController:
    """The controller (module docstring), one step at a time."""

    def __init__(self, params: AhcControllerParams | None = None) -> None:
        self.params = params or AhcControllerParams()
        self.reset()

    def reset(self) -> None:
        """Back to the initial state: no integral, disengaged, inputs at rest at ``length0``."""
        self.integral = 0.0
        self.engagement = 0.0
        self.inputs = (0.0, 0.0, self.params.length0)   # last good heave, heave rate, length

    def step(self, heave: float, heave_rate: float, length: float, dt: float, heave_valid: bool = True
             ) -> ControllerOutput:
        """The command for the next ``dt`` s from the tip's heave [m] and heave rate [m/s]
        estimates, the wire length [m] and whether the estimate is usable."""
        p = self.params
        warning = bad_scalar((("heave", heave, 1e3), ("heave rate", heave_rate, 1e3), ("length", length, 1e5)))
        if warning is None:
            self.inputs = (float(heave), float(heave_rate), float(length))
        heave, heave_rate, length = self.inputs
        ramp = dt / p.engage_time if p.engage_time > 0 else 1.0
        self.engagement = min(1.0, self.engagement + ramp) if heave_valid else max(0.0, self.engagement - ramp)
        k_ff = p.k_ff * self.engagement
        ref = p.length0 - k_ff * (heave - p.heave_ref)
        err = ref - length
        integral = max(-p.max_integral, min(p.max_integral, self.integral + err * dt))
        u = -k_ff * heave_rate + p.k_p * err + p.k_i * integral
        limited = abs(u) > p.max_command
        if not (limited and err * u > 0.0):              # conditional integration (anti-windup)
            self.integral = integral
        u = max(-p.max_command, min(p.max_command, u))
        return ControllerOutput(u, ref, self.engagement, limited, warning is None and self.engagement == 1.0, warning)

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"integral": self.integral, "engagement": self.engagement, "inputs": list(self.inputs)}

    def set_state(self, s: dict) -> None:
        """Restore from :meth:`get_state`."""
        self.integral = float(s["integral"])
        self.engagement = float(s["engagement"])
        self.inputs = tuple(float(v) for v in s["inputs"])
