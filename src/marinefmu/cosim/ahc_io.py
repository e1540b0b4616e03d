"""FMU variable tables of the AHC FMUs (issue 9) and the mapping from FMI values to their
parameter objects."""
from __future__ import annotations

from typing import Any

from ..ahc.controller import ControllerParams
from ..ahc.winch import WinchParams
from ..interface import Variable, real, resolve

_W = WinchParams()
WINCH_PARAMETERS: list[Variable] = [
    Variable("order", "integer", _W.order, "", "Winch speed servo: 1 first-order lag, 2 second order"),
    real("tau", _W.tau, "s", "First-order time constant, (0, 10]"),
    real("omega_n", _W.omega_n, "rad/s", "Second-order natural frequency, (0, 1000]"),
    real("zeta", _W.zeta, "", "Second-order damping ratio, (0, 10]"),
    real("max_speed", _W.max_speed, "m/s", "Winch speed limit, > 0"),
    real("max_acc", _W.max_acc, "m/s2", "Winch acceleration limit, > 0"),
    real("min_length", _W.min_length, "m", "Shortest wire paid out (stroke), >= 0"),
    real("max_length", _W.max_length, "m", "Longest wire paid out (stroke), > min_length"),
    real("length0", _W.length0, "m", "Initial wire length, within the stroke"),
    real("mass", _W.mass, "kg", "Load mass, > 0"),
    real("stiffness", _W.stiffness, "N/m", "Wire stiffness, > 0"),
    real("damping", _W.damping, "N*s/m", "Wire damping, >= 0"),
    real("max_substep", _W.max_substep, "s", "Longest integration substep, (0, 0.1]"),
]
WINCH_INPUTS: list[Variable] = [
    real("command", 0.0, "m/s", "Winch speed command (wire paid out per second)"),
    real("tip.n", 0.0, "m", "Crane tip position, north (the load hangs below it)"),
    real("tip.e", 0.0, "m", "Crane tip position, east"),
    real("tip.d", 0.0, "m", "Crane tip position, down (e.g. VesselMotion truth.point.d)"),
    real("tip_vel.d", 0.0, "m/s", "Crane tip velocity, down (e.g. VesselMotion truth.point_vel.d)"),
]
WINCH_OUTPUTS: list[Variable] = [
    real("length", _W.length0, "m", "Wire paid out"),
    real("speed", 0.0, "m/s", "Winch speed, dlength/dt"),
    real("acc", 0.0, "m/s2", "Winch acceleration"),
    real("load.n", 0.0, "m", "Load position, north (below the tip: pendulum motion not modelled)"),
    real("load.e", 0.0, "m", "Load position, east (below the tip)"),
    real("load.d", 0.0, "m", "Load position, down, NED"),
    real("load_vel.d", 0.0, "m/s", "Load velocity, down, NED"),
    real("tension", 0.0, "N", "Wire tension (>= 0: a wire cannot push)"),
]
WINCH_BOOLEANS: list[Variable] = [
    Variable("speed_limited", "boolean", False, "", "The command exceeded max_speed during the step"),
    Variable("acc_limited", "boolean", False, "", "The winch hit max_acc during the step"),
    Variable("stroke_limited", "boolean", False, "", "The wire sat at a stroke stop during the step"),
    Variable("slack", "boolean", False, "", "The wire went slack (tension 0) during the step"),
    Variable("valid", "boolean", False, "", "The step's inputs were usable (false: a NaN/Inf/absurd input was held)"),
]


def winch_params(values: dict[str, Any]) -> WinchParams:
    """WinchParams from FMI-named values."""
    return WinchParams(**resolve(WINCH_PARAMETERS, values, "AhcWinch"))   # FMI names = field names


_C = ControllerParams()
CONTROLLER_PARAMETERS: list[Variable] = [
    real("length0", _C.length0, "m", "Nominal wire length, >= 0"),
    real("k_ff", _C.k_ff, "", "Feedforward gain on the estimated tip heave and heave rate, [0, 2] (1: full compensation)"),
    real("k_p", _C.k_p, "1/s", "Proportional gain on the wire-length error, >= 0"),
    real("k_i", _C.k_i, "1/s2", "Integral gain on the wire-length error, >= 0"),
    real("max_integral", _C.max_integral, "m*s", "Clamp of the integrated length error (anti-windup), > 0"),
    real("max_command", _C.max_command, "m/s", "Clip of the speed command (the winch's max_speed), > 0; no integration into the clip"),
    real("heave_ref", _C.heave_ref, "m", "Mean down position in the heave input, removed (0 for a heave estimate; the point's z for truth)"),
    real("engage_time", _C.engage_time, "s", "Time for the feedforward to fade in while heave_valid (and out while not), [0, 600]"),
]
CONTROLLER_INPUTS: list[Variable] = [
    real("heave", 0.0, "m", "Estimated crane-tip heave, down (e.g. HeaveObserver point.heave)"),
    real("heave_rate", 0.0, "m/s", "Estimated crane-tip heave rate, down (e.g. HeaveObserver point.heave_rate)"),
    real("length", _C.length0, "m", "Measured wire length (AhcWinch length)"),
    Variable("heave_valid", "boolean", True, "", "The heave estimate is usable (e.g. HeaveObserver valid): the feedforward fades in"),
]
CONTROLLER_OUTPUTS: list[Variable] = [
    real("command", 0.0, "m/s", "Winch speed command"),
    real("length_ref", _C.length0, "m", "Wire-length reference, length0 - k_ff * engagement * (heave - heave_ref)"),
    real("engagement", 0.0, "", "Weight of the feedforward, 0 (off) .. 1 (full), ramped by heave_valid"),
]
CONTROLLER_BOOLEANS: list[Variable] = [
    Variable("command_limited", "boolean", False, "", "The command was clipped to max_command this step"),
    Variable("valid", "boolean", False, "", "Full compensation with usable inputs (false while engagement < 1 or a NaN/Inf/absurd input was held)"),
]


def controller_params(values: dict[str, Any]) -> ControllerParams:
    """ControllerParams from FMI-named values."""
    return ControllerParams(**resolve(CONTROLLER_PARAMETERS, values, "AhcController"))   # FMI names = field names
