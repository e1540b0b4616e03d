"""Parameters and result of :class:`~marinefmu.estimators.mru.unit.MotionReferenceUnit`."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ...errors import ParameterError, check_choice, check_finite, check_range, check_vector
from ..attitude.estimator import AttitudeEstimatorParams
from ..heave.common import HeaveObserverParams

#: Most monitoring points.
MAX_POINTS = 4
#: Farthest monitoring point from the IMU [m]: beyond it a lever arm is taken for a unit error
#: (millimetres for metres) rather than a point on the vessel.
MAX_ARM = 200.0
#: Default delay of the delayed outputs [s]: by then the Wiener smoother has seen the
#: following half period of the longest benchmark sea twice over, and errs less than half as
#: much as the real-time estimate (``marinefmu bench --parts mru``).
DELAYED_LAG = 20.0
#: Time constant of the heading aid [s]: how fast the yaw output follows a heading input.
HEADING_TAU = 30.0
#: Time constant of each of the two cascaded first-order low-passes that give the level
#: frame's reference yaw [s] (:mod:`.level_frame`).
YAW_TAU = 30.0
#: Time constant of the two cascaded first-order low-passes that give a lever arm's mean [s].
ARM_TAU = 100.0
#: Coarsest step [s] at which the unit's accuracy is measured (10 Hz; the MotionReferenceUnit
#: docs page's sample rates): a coarser step runs, with a warning.
COARSEST_MEASURED_STEP = 0.1
#: The real-time motion's estimators (``motion_model``): the joint filter of all six channels
#: taught by the axis filters' delayed outputs (:mod:`.joint`), or the axis filters alone
#: (paper 003's observer generalised to three axes).
MOTION_MODELS = ("joint", "axis")
#: Default span of the joint filter's rows [s]: the sea's response at the peak period and the
#: attitude's coupling over several wave groups; 120 s moves the benchmark's errors by under 10 %.
JOINT_MEMORY = 60.0
#: Crossover of the horizontal axes' tilt between the attitude and the integrated gyro [s]
#: (:class:`~.level_frame.GyroTilt`): far below the wave band (a 5-20 s sea), so that the
#: wave-frequency tilt is the gyro's; 30-300 s move the benchmark by under 0.03 cm.
TILT_TAU = 100.0
#: Shortest non-zero ``tilt_tau`` [s]: below it the crossover reaches the waves (a 5 s wave
#: is at 1/(ωτ) = 8 % of a first-order crossover at 10 s).
TILT_TAU_MIN = 10.0


def default_motion() -> HeaveObserverParams:
    """The three axes' filter parameters: the HeaveObserver's defaults with the delayed lag
    :data:`DELAYED_LAG`."""
    return HeaveObserverParams(smoother_lag=DELAYED_LAG)


def check_arm(name: str, arm: Any) -> tuple[float, float, float]:
    """A monitoring point's lever arm from the IMU [m, body] as floats, if it is finite and
    within :data:`MAX_ARM` of the IMU; else a ParameterError naming it ``name``."""
    arm = check_vector(name, arm, unit="m")
    distance = math.sqrt(sum(a * a for a in arm))
    if distance > MAX_ARM:
        raise ParameterError(f"{name} must lie within {MAX_ARM:g} m of the IMU, got {distance:.1f} m "
                             f"({', '.join(f'{a:g}' for a in arm)})")
    return arm


@dataclass(frozen=True)
class MotionReferenceUnitParams:
    """Parameters of :class:`~marinefmu.estimators.mru.unit.MotionReferenceUnit` (FMU names in
    brackets).

    Parameters
    ----------
    attitude : AttitudeEstimatorParams
        The attitude estimator's (its defaults: drift-corrected, sized from the data).
    motion : HeaveObserverParams
        The filter of each level-frame axis (surge and sway with the gyro tilt's noise added to
        ``offset_noise`` when ``tilt_tau`` > 0; ``model`` must be ``"wiener"``; uses the fields
        :class:`~marinefmu.estimators.heave.wiener.WienerAxis` names); ``smoother_lag`` is the
        delay of the delayed outputs, [0, 120] s, :data:`DELAYED_LAG` by default.
        [``window``, ``window_max``, ``omega_min``, ``omega_max``, ``acc_noise``,
        ``delayed_lag``]
    points : tuple of (3,) tuples
        Up to :data:`MAX_POINTS` monitoring points, each a lever arm from the IMU to the point,
        body frame [m], each within :data:`MAX_ARM` of the IMU and finite.
        [``mp{1..4}.{x,y,z}``, ``mp{1..4}.enabled``]
    heading_tau : float
        Time constant of the heading aid [s], [1, 3600] (:data:`HEADING_TAU`). [``heading_tau``]
    motion_model : str
        The real-time motion at the IMU: ``"joint"`` (default), the joint filter of all six IMU
        channels taught by the axis filters' delayed outputs (:mod:`.joint`), once taught; or
        ``"axis"``, the axis filters alone (paper 003's observer per axis). [``motion_model``]
    joint_memory : float
        Span of the joint filter's rows [s], [10, 300] (:data:`JOINT_MEMORY`). [``joint_memory``]
    aid_reference : bool
        Once the joint filter has taken over, its horizontal motion at the IMU is the reference
        of the attitude's aid (default): roll and pitch err 2-3 × less in waves. Its error then
        follows the joint filter's, so that at a far point the heave error of the IMU and that
        of the lever arm add rather than cancel: a heave compensator, which passes every
        in-band error of the tip's heave to its load, may do better without it
        (``docs/decisions/mru-design.md``). Only with ``motion_model = "joint"``.
        [``aid_reference``]
    tilt_tau : float
        The horizontal axes' acceleration is turned with a tilt that follows the attitude below
        1/τ and the integrated gyro above it (:class:`~.level_frame.GyroTilt`), 0 or
        [:data:`TILT_TAU_MIN`, 3600] s (:data:`TILT_TAU`); 0 turns it with the attitude's own
        tilt. With it the surge and sway filters add the gyro tilt's noise to their design's
        ``offset_noise`` (:func:`~.unit.horizontal_params`). [``tilt_tau``]
    """

    attitude: AttitudeEstimatorParams = field(default_factory=AttitudeEstimatorParams)
    motion: HeaveObserverParams = field(default_factory=default_motion)
    points: tuple[tuple[float, float, float], ...] = ()
    heading_tau: float = HEADING_TAU
    motion_model: str = "joint"
    joint_memory: float = JOINT_MEMORY
    aid_reference: bool = True
    tilt_tau: float = TILT_TAU

    def __post_init__(self) -> None:
        if self.motion.model != "wiener":
            raise ParameterError(f"motion.model must be 'wiener' (the MotionReferenceUnit's axis filter), "
                                 f"got {self.motion.model!r}")
        if len(self.points) > MAX_POINTS:
            raise ParameterError(f"points: at most {MAX_POINTS} monitoring points, got {len(self.points)}")
        object.__setattr__(self, "points", tuple(check_arm(f"mp{i + 1}", arm) for i, arm in enumerate(self.points)))
        check_range("heading_tau", self.heading_tau, lo=1.0, hi=3600.0, unit="s")
        check_choice("motion_model", self.motion_model, MOTION_MODELS)
        check_range("joint_memory", self.joint_memory, lo=10.0, hi=300.0, unit="s")
        check_range("tilt_tau", self.tilt_tau, lo=0.0, hi=3600.0, unit="s")
        if 0.0 < self.tilt_tau < TILT_TAU_MIN:
            raise ParameterError(f"tilt_tau must be 0 (the attitude's own tilt) or in [{TILT_TAU_MIN:g}, 3600] s, "
                                 f"got {self.tilt_tau:g} s")
        if not isinstance(self.aid_reference, (bool, np.bool_)):
            raise ParameterError(f"aid_reference must be true or false, got {self.aid_reference!r}")

    def check_step(self, dt: float) -> float:
        """``dt`` [s] as a float if it is a step at all, else a ParameterError naming it: finite
        and > 0."""
        x = check_finite("dt", dt, "s")
        if not x > 0.0:
            raise ParameterError(f"dt = {dt!r} s is out of range: must be > 0 [s]")
        return x

    @property
    def longest_step(self) -> float:
        """π/``motion.omega_max`` [s]: at a step this long or longer the Nyquist frequency π/Δt
        is at or below the filters' band, whose designs read the measured spectrum up to
        ``omega_max`` (a sampled record has none above Nyquist); the unit then gives the angles
        but not the motion."""
        return math.pi / self.motion.omega_max


@dataclass(slots=True)
class MruResult:
    """Output of one :meth:`~marinefmu.estimators.mru.unit.MotionReferenceUnit.step`.

    Rows of the (P + 1, ·) arrays: the IMU, then the monitoring points in order. Columns of the
    (·, 3) arrays: surge, sway, heave, i.e. x forward, y starboard, z down of the vessel's level
    frame (heave positive down), about the point's mean position.

    Not frozen, unlike the parameters: a frozen dataclass sets each of its fourteen fields
    through ``object.__setattr__``, about 2 µs a step, more than the rest of the result's
    assembly. Before the motion is valid the arrays are shared read-only zeros.

    Attributes
    ----------
    roll, pitch, yaw : float
        ZYX Euler angles [rad]; yaw is north-referenced while a heading input aids it
        (``heading_used``), else the gyro-integrated yaw.
    position, velocity : numpy.ndarray
        (P + 1, 3) real-time surge, sway, heave [m] and their rates [m/s].
    heave_acc : numpy.ndarray
        (P + 1,) vertical acceleration [m/s², down], the bias estimate removed.
    delayed_position : numpy.ndarray
        (P + 1, 3) surge, sway, heave ``delay`` s before this sample [m]; zeros until the
        filters have run through that time (``delayed_valid`` first holds).
    delay : float
        Lag of the delayed outputs [s].
    wave_period : float
        Period of the peak of the heave spectrum [s] (0 before the first spectrum).
    valid : bool
        Roll, pitch and yaw: levelled, the IMU sample good and the heading sample, if one is
        given, good.
    motion_valid : bool
        The real-time motion: every axis's filter designed, the sample good and the last run of
        bad samples, if any, :data:`~.unit.RECOVERY` × its length behind.
    delayed_valid : bool
        The delayed outputs refer to a time the filters have run through, and the last run of
        bad samples is that and the delay behind.
    heading_used : bool
        The yaw output is north-referenced (a valid heading has been received).
    warning : str or None
        Why the sample was not used, if it was not.
    joint : bool
        The real-time motion at the IMU is the joint filter's (``motion_model = "joint"``, once
        taught, while it agrees with the axis filters), else the axis filters'.
    """

    roll: float
    pitch: float
    yaw: float
    position: np.ndarray
    velocity: np.ndarray
    heave_acc: np.ndarray
    delayed_position: np.ndarray
    delay: float
    wave_period: float
    valid: bool
    motion_valid: bool
    delayed_valid: bool
    heading_used: bool
    warning: str | None = None
    joint: bool = False
