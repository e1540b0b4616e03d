"""The MotionReferenceUnit: what a commercial motion reference unit outputs, from one IMU.

Per sample (:meth:`MotionReferenceUnit.step`):

1. **Attitude**: the AttitudeEstimator at its parameters (paper 000 eqs. 6-9 with the aided
   tilt correction; :mod:`marinefmu.estimators.attitude.estimator`) gives R_nb, roll, pitch and
   the gyro-integrated yaw ψ. Once the joint filter (step 3) has taken over, its horizontal
   position and velocity at the IMU are the attitude's aid reference (the estimator's "aid
   reference"; ``aid_reference``, on by default): the aid then tells the tilt's slow drift from
   the waves to centimetres rather than metres per second, and roll and pitch err 2-3 × less
   in waves. It is set on every good sample, also while the joint filter's rows still hold a
   bad one (the gap moves the reference by centimetres; without it the aid falls back to its
   own sizing, which left roll and pitch 5 × worse for the joint filter's memory after a
   single bad sample), and computed only on the steps before the attitude's aid updates
   (``AttitudeEstimator.aid_due``), which alone read it.
2. **Level frame** (:mod:`.level_frame`): R_hb = Rz(−ψ̄) R_nb, with ψ̄ the slow part of ψ, and
   the IMU's acceleration there, a_h = R_hb f_b + [0, 0, g] (the horizontal specific force after
   tilt compensation). The horizontal axes take it turned by a tilt whose wave-frequency part
   is the integrated gyro's (:class:`~.level_frame.GyroTilt`, ``tilt_tau``): a_x + g (θ − θ_c),
   a_y − g (φ − φ_c), with (φ_c, θ_c) the complementary filter's angles; the attitude's aid
   carries its error into the wave band, the gyro only its noise.
3. **Three axes**: surge, sway and heave of the IMU, each by paper 003's observer generalised
   from the vertical: the causal Wiener filter designed from that axis's own measured spectrum
   (:class:`~marinefmu.estimators.heave.wiener.WienerAxis`, the HeaveObserver's default
   filter; its docstring has steps 1-3), now and ``motion.smoother_lag`` s ago (the delayed
   outputs: the Wiener smoother for that lag). The horizontal axes take the vertical's design
   parameters but for the sensor's offset noise, which adds the gyro tilt's
   (:func:`horizontal_params`); their spectra and filters are their own, and their designs
   reject the acceleration below ``omega_min`` (the attitude's slow tilt error times g), so
   they have no bias-step search (:class:`~marinefmu.estimators.heave.wiener.WienerAxis`).
   **Joint filter** (``motion_model = "joint"``, the default; :mod:`.joint`): once it has two
   taught rows per weight (about 14 minutes at the defaults and 100 Hz), the real-time surge,
   sway and heave at the IMU and their rates come instead from one causal linear filter of all
   six IMU channels' past, fitted to the three axis filters' delayed outputs; the outputs move
   over to it in :data:`~.joint.BLEND` s. Its rows do not carry the attitude's tilt error and
   read every channel, so in a sea where one wave train drives all six motions it errs several
   times less than the axis filters in surge and sway (the MotionReferenceUnit docs page's
   Accuracy section has the figures). ``motion_model = "axis"`` keeps the axis
   filters' real-time outputs (paper 003's observer per axis). The delayed outputs are the
   axis filters' either way. The joint filter checks itself against the axis filters'
   real-time outputs (:meth:`~.joint.JointMotion.check`): where it departs from them (a
   heading change or a heel, which it was never taught) the unit gives the axis filters'
   outputs until the joint filter's memory has passed the departure, with a warning, and
   ``joint`` is false; after a gap the check waits until the axis filters have read past it
   (their longest span, ``axis_memory``: 180 s at the defaults).
4. **Monitoring points**: each adds its lever arm's motion about its mean, R r − ⟨R r⟩ with
   R = Rz(ψ_w) Ry(θ) Rx(φ), its rate Ṙ r from the gyro (Ṙ = R [ω]× less the slow yaw's turn)
   and its acceleration (:mod:`.level_frame`), the exact rigid-body transfer (paper 003
   eqs. 10-11 generalised to three axes and a 3-D lever arm).
   ψ_w, the yaw's wave-frequency part, comes from a fourth Wiener filter, on the Euler yaw
   rate ψ̇ (its "rate" output: the filter estimates ż from z̈ = ψ̇ with z = ∫ψ), designed like
   the others from ψ̇'s spectrum with the gyro's noise and bias as the sensor's
   (:func:`yaw_filter_params`) and the rate below ``omega_min`` rejected. The gyro-integrated
   yaw less its slow part (as the level frame's ψ − ψ̄) would keep the z gyro's bias wander
   over the low-pass's 30 s, about 0.13° on the default MEMS grade, 13 cm of sway at a point
   60 m forward of the IMU; the filter rejects the rate below ``omega_min``, where that wander
   lies.
5. **Heading** (optional): a valid heading input ψ_in turns the yaw output to north by a
   first-order correction, ψ_out = ψ + c, c ← c + (1 − e^{−Δt/τ}) wrap(ψ_in − ψ − c)
   (``heading_tau``; the first valid heading sets c). It does not enter the motion, which is
   in the level frame of the mean heading either way.

What runs when: every step, the attitude, the level frame's rows and a_h on Python floats
(:func:`~.level_frame.level_rows`), the joint filter's ring write and, once fitted, its one
gather and product, each filter's ring writes and the four filters' outputs
as one batched product (:class:`~marinefmu.estimators.heave.wiener.WienerGroup`), and the
points' arms: the nine entries of R − I and their slow mean on floats, those of Ṙ from the
gyro, one (1 × W)·(W × 9) product on a contiguous slice of their ring (stored twice for it) for
the accelerations, and one (4 × 12)·(12 × 3(P + 1)) product from them and the IMU's motion to every
location's (:func:`~.level_frame.location_map`); before every filter has a design, shared
read-only zeros;
every second, the heave filter's bias-step search;
first after ``motion.window`` s and then every :data:`DESIGN_ROUNDS` × ``motion.peak_interval``
s, each filter's Wiener design, the four a quarter of an interval apart (on average one
design per interval in all, as the HeaveObserver), so that no step designs more than one; every :data:`~.joint.REFIT` s the joint filter's refit
(a Cholesky solve of its normal equations).

Bad samples (NaN, Inf, absurd; the AttitudeEstimator's checks): the attitude coasts on the last
good sample, each axis takes the window's mean acceleration (its estimate decays rather than
drifts), the points keep the last good attitude, the gyro's tilt keeps its last difference from
the attitude (:meth:`~.level_frame.GyroTilt.hold`), ``valid`` and ``motion_valid`` are false and
the step's ``warning`` says why (also logged). The filters read the gap's stand-in samples for
a while after it: ``motion_valid`` stays false for :data:`RECOVERY` × the gap's length after
it, and ``delayed_valid`` for that plus the delay. A bad heading sample (while ``heading_valid``)
is not used: the yaw's correction coasts and ``valid`` is false for that step. While the attitude levels (the first
``attitude.level_time`` s) the axes take no acceleration either: the tilt is not yet known.
"""
from __future__ import annotations

import logging
import math
from dataclasses import replace
from typing import Any

import numpy as np

from ...frames import G, rot_nb_rows
from ..attitude.estimator import AttitudeEstimator, AttitudeResult
from ..heave.common import HeaveObserverParams, SilentLog
from ..heave.wiener import WienerAxis, WienerGroup
from ..samples import MAX_YAW, step_changed
from .joint import GATE, JointMotion, linear_channels
from .level_frame import GyroTilt, SlowLowPass, acceleration_weights, level_rows, location_map, turn_rate_rows, unwrap
from .params import ARM_TAU, COARSEST_MEASURED_STEP, YAW_TAU, MotionReferenceUnitParams, MruResult

log = logging.getLogger(__name__)

#: Each filter is designed again every DESIGN_ROUNDS × ``motion.peak_interval`` s (a quarter
#: interval after the previous filter), so that the four cost one HeaveObserver's designs: the window they read grows to 20 minutes, and over one minute the
#: design barely moves.
DESIGN_ROUNDS = 4
#: After a run of bad samples the motion stays invalid for RECOVERY × its length: the filters
#: read the gap's stand-ins (the window's mean acceleration, the joint filter's held sample)
#: until it has left their memory, and the attitude, which coasted through it on its last good
#: gyro sample, needs its aid to come back; the error they leave grows with the gap's length
#: (docs/decisions/mru-design.md has the measurements behind the factor).
RECOVERY = 120.0
#: The level frame's axes, in the order of the outputs' columns.
AXES = ("surge", "sway", "heave")
#: The identity's entries row by row.
IDENTITY_ROWS = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)


def yaw_filter_params(params: MotionReferenceUnitParams) -> HeaveObserverParams:
    """The wave-frequency yaw filter's parameters: the motion's, with the gyro's white noise and
    its bias's random walk in place of the accelerometer's (a Gauss-Markov bias of σ_b and τ_b
    looks like a random walk of density σ_b √(2/τ_b) above 1/τ_b, the band that matters here)."""
    a = params.attitude
    return replace(params.motion, acc_noise=a.gyro_noise,
                   offset_noise=min(10.0, a.gyro_bias_sigma * math.sqrt(2.0 / a.gyro_bias_tau)))


def horizontal_params(params: MotionReferenceUnitParams, gyro_noise: float | None = None,
                      gyro_bias_sigma: float | None = None) -> HeaveObserverParams:
    """The surge and sway filters' parameters: the motion's, with the gyro's error in the
    offset's random walk when the axes take the gyro's tilt (``tilt_tau`` > 0).

    ``gyro_noise``, ``gyro_bias_sigma``: the gyro's figures as the attitude has sized them
    (``gyro_noise_used``, ``gyro_bias_sigma_used``; the unit passes them before each surge and
    sway design); the attitude's parameters if None.

    The tilt's error in the wave band is then the integrated gyro's: g times it is an offset of
    the horizontal acceleration, which the filters' design takes as noise (the sensor's
    S_n = N²/π + q²/(πω²), :mod:`~marinefmu.estimators.heave.wiener`) rather than motion. The
    gyro's white noise N_g [rad/s/√Hz] integrates to a random walk of density g N_g; its bias,
    a Gauss-Markov process of σ_b and τ_b (the attitude's ``gyro_bias_sigma``,
    ``gyro_bias_tau``), to an acceleration of density g² 2σ_b²/(τ_b ω⁴) above 1/τ_b, taken as a
    random walk of the same density at ``omega_min``, where it counts most:

    .. math::
        q_h^2 = q^2 + g^2 \\left(N_g^2 + \\frac{2σ_b^2}{τ_b\\, ω_{min}^2}\\right).
    """
    if params.tilt_tau <= 0.0:
        return params.motion
    a, m = params.attitude, params.motion
    n_g = a.gyro_noise if gyro_noise is None else gyro_noise
    sigma_b = a.gyro_bias_sigma if gyro_bias_sigma is None else gyro_bias_sigma
    tilt_density = G * math.sqrt(n_g**2 + 2.0 * sigma_b**2 / (a.gyro_bias_tau * m.omega_min**2))
    return replace(m, offset_noise=math.hypot(m.offset_noise, tilt_density))


def zero_outputs(rows: int) -> tuple[np.ndarray, np.ndarray]:
    """Read-only zero (rows, 3) motion and (rows,) heave acceleration: the outputs before every
    filter has a design, shared by every such step (no arrays to build while nothing is known)."""
    zeros, zero_acc = np.zeros((rows, 3)), np.zeros(rows)
    zeros.flags.writeable = zero_acc.flags.writeable = False
    return zeros, zero_acc


def euler_yaw_rate(rates: tuple[float, float, float], att: AttitudeResult) -> float:
    """ψ̇ = (sin φ ω_y + cos φ ω_z) / cos θ [rad/s] from the body rate less the estimated bias
    ``rates`` [rad/s]."""
    return (math.sin(att.roll) * rates[1] + math.cos(att.roll) * rates[2]) / math.cos(att.pitch)


class MotionReferenceUnit:
    """Attitude and three-axis motion at the IMU and at monitoring points (module docstring).

    Parameters
    ----------
    params : MotionReferenceUnitParams, optional
        Validated parameters (the defaults if omitted).
    quiet : bool
        Log nothing from the motion filters.

    Examples
    --------
    >>> mru = MotionReferenceUnit(MotionReferenceUnitParams(points=((25.0, 0.0, -8.0),)))
    >>> r = mru.step((0.0, 0.0, 0.0), (0.0, 0.0, -9.80665), 0.01)
    >>> r.position.shape, r.motion_valid          # IMU and one point; not yet designed
    ((2, 3), False)
    """

    def __init__(self, params: MotionReferenceUnitParams | None = None, *, quiet: bool = False) -> None:
        self.params = params or MotionReferenceUnitParams()
        self.log: Any = SilentLog() if quiet else log
        self.arms = np.array(self.params.points, dtype=float).reshape(-1, 3)      # (P, 3) body [m]
        self.point_map = location_map(self.arms)        # (12, 3(P + 1)): the points' terms and the IMU's motion
        self.reset()

    def reset(self) -> None:
        """Back to the initial state."""
        p = self.params
        self.attitude = AttitudeEstimator(p.attitude)
        self.attitude.recover_from_gyro_gaps = False     # the angles wait for the motion after a gyro gap (step)
        horizontal = horizontal_params(p)
        self.axes = [WienerAxis(p.motion if name == "heave" else horizontal, self.log, f"mru {name}",
                                reject_below=name != "heave", find_steps=name == "heave") for name in AXES]
        self.yaw_axis = WienerAxis(yaw_filter_params(p), self.log, "mru yaw", reject_below=True, find_steps=False)
        self.group = WienerGroup([*self.axes, self.yaw_axis] if len(self.arms) else self.axes)
        self.yaw_ref = SlowLowPass(YAW_TAU)
        self.turn_mean = SlowLowPass(ARM_TAU, from_zero=True)    # ⟨R − I⟩, the arms' mean turn
        self.dt: float | None = None
        self.k = 0
        self.yaw: float | None = None                 # the unwrapped gyro yaw [rad]
        self.heading_offset: float | None = None      # c of the heading aid [rad]
        self.rot_rows = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)   # R_hb of the last good sample, row by row
        self.heave_acc = 0.0                          # the last good vertical acceleration [m/s²]
        self.turn_ring = np.zeros((0, 9))
        self.terms = np.zeros((4, 12))
        self.delay_s = 0.0
        self.no_motion = zero_outputs(len(self.arms) + 1)
        self.joint: JointMotion | None = None
        self.psi_bar = 0.0                            # ψ̄, the level frame's reference yaw [rad]
        self.gyro_tilt = GyroTilt(p.tilt_tau) if p.tilt_tau > 0.0 else None
        self.next_sizing = 0                          # the sample count of the next surge or sway design
        self.gap_steps = 0                            # bad samples in the current run of them
        self.recovered_at = 0                         # the sample count from which the motion is valid again
        self.compared_from = 0                        # the sample count from which the joint filter is checked
        self.angles_from = 0                          # the sample count from which the angles are valid again

    def start(self, dt: float) -> None:
        """Size the buffers for the step ``dt`` [s]."""
        m = self.params.motion
        self.dt = dt
        filters = (*self.axes, self.yaw_axis)
        for i, axis in enumerate(filters):            # heave, yaw, surge, sway a quarter interval apart
            axis.start(dt, m.window + m.peak_interval * (2, 3, 0, 1)[i] / 4.0,
                       interval=DESIGN_ROUNDS * m.peak_interval)
        self.weights = acceleration_weights(dt)
        self.lag_steps = self.axes[0].lag_steps
        self.axis_memory = self.axes[0].blocks * self.axes[0].block   # the axis filters' longest span [samples]
        self.group.bind()
        ring = max(self.lag_steps + 1, self.weights.shape[1])
        # (R_hb − I) − ⟨R_hb − I⟩ row by row (level_frame: every point's d is a product with it),
        # each sample twice, so that the last W are one slice; none without points (its length
        # grows as 1/dt: a 1 µs step would take gigabytes)
        self.turn_ring = np.zeros((2 * ring if len(self.arms) else 0, 9))
        # rows: position, rate, delayed position, acceleration; columns: the turn's nine entries
        # (its rate and acceleration from the fit), then the IMU's surge, sway and heave (of the
        # acceleration row only the heave: the other two stay zero)
        self.terms = np.zeros((4, 12))
        self.delay_s = self.axes[0].delay
        self.delayed_from = m.window + m.peak_interval * 3.0 / 4.0 + self.axes[0].delay
        if self.params.motion_model == "joint":
            self.joint = JointMotion(self.params.joint_memory, dt, self.lag_steps, m.window_max)

    @property
    def rot(self) -> np.ndarray:
        """R_hb of the last good sample [3 × 3]."""
        return np.array(self.rot_rows).reshape(3, 3)

    @property
    def delay(self) -> float:
        """Lag of the delayed outputs [s]."""
        return self.axes[0].delay

    def step(self, gyro: Any, acc: Any, dt: float, heading: float | None = None,
             heading_valid: bool = True) -> MruResult:
        """Process one IMU sample.

        Parameters
        ----------
        gyro : array_like
            (3,) angular rate [rad/s, body].
        acc : array_like
            (3,) specific force [m/s², body].
        dt : float
            Step [s], finite and > 0 (else ParameterError, the unit unchanged); a change
            restarts every filter, with a warning. A step above
            :data:`~.params.COARSEST_MEASURED_STEP` is warned of; one of
            ``params.longest_step`` (π/``motion.omega_max``) or more, where the filters' band
            is not sampled, gives the angles only: ``motion_valid`` stays false, with a
            warning.
        heading : float, optional
            True heading of the body x axis [rad, clockwise from north]; None for none.
        heading_valid : bool
            Whether ``heading`` holds a measurement.
        """
        restart = None
        if self.dt is None or not math.isfinite(dt) or step_changed(self.dt, dt):
            dt = self.params.check_step(dt)           # refused before anything changes
            if self.dt is not None:
                restart = f"step size changed from {self.dt} s to {dt} s; every filter restarted"
                self.log.warning("mru: %s", restart)
                self.reset()
            self.start(dt)
            if dt >= self.params.longest_step:        # the band is not sampled: no motion
                self.recovered_at = 1 << 62
                self.log.warning("mru: step %g s: the Nyquist frequency pi/dt is below omega_max = %g rad/s, the top "
                                 "of the motion filters' band; the motion is not estimated (motion.valid false); "
                                 "a step below %.4g s gives it", dt, self.params.motion.omega_max,
                                 self.params.longest_step)
            elif dt > COARSEST_MEASURED_STEP:
                self.log.warning("mru: step %g s is coarser than the %g s the unit's accuracy is measured at; "
                                 "expect larger errors", dt, COARSEST_MEASURED_STEP)
        att = self.attitude.step(gyro, acc, dt)
        good = att.valid and att.warning is None
        if att.warning is not None:                    # a bad sample: the motion recovers after the gap
            self.gap_steps += 1
            # a count (k + 1 after this sample); never earlier than set (a step that leaves the band unsampled)
            self.recovered_at = max(self.recovered_at, self.k + 2 + int(math.ceil(RECOVERY * self.gap_steps)))
            self.compared_from = self.k + 2 + self.axis_memory     # once the axis filters have read past it
            if not self.attitude.gyro_good and self._coast_matters(dt):   # the angles as the motion (below)
                self.angles_from = self.recovered_at
        elif self.gap_steps:
            self.gap_steps = 0
        points = len(self.arms)
        values: list[float | None]
        channels = None                                # the joint filter's sample (None: a bad one)
        if good:
            first = self.yaw is None
            self.yaw = att.yaw if first else unwrap(self.yaw, att.yaw)
            previous_psi_bar = self.psi_bar
            self.psi_bar = self.yaw_ref.push_one(self.yaw, dt)
            r = self.rot_rows = level_rows(self.psi_bar, att.q)
            f0, f1, f2 = float(acc[0]), float(acc[1]), float(acc[2])
            heave_acc = r[6] * f0 + r[7] * f1 + r[8] * f2 + G
            values = [r[0] * f0 + r[1] * f1 + r[2] * f2, r[3] * f0 + r[4] * f1 + r[5] * f2, heave_acc]
            tilt = self.gyro_tilt
            if self.joint is not None or points or tilt is not None:
                b = att.gyro_bias
                rates = (float(gyro[0]) - float(b[0]), float(gyro[1]) - float(b[1]), float(gyro[2]) - float(b[2]))
            if self.joint is not None or tilt is not None:
                euler = linear_channels(rates, att.roll, att.pitch, values)
                if self.joint is not None:
                    channels = euler
                if points:                             # the yaw filter serves the lever arms only
                    values.append(euler[2])
                if tilt is not None:                   # the horizontal axes' tilt: the gyro's in the wave band
                    d_roll, d_pitch = tilt.push(euler[0], euler[1], att.roll, att.pitch, dt)
                    # g [dθ, −dφ] in the heading frame, turned into the level frame by ψ − ψ̄
                    delta = self.yaw - self.psi_bar
                    cos_d, sin_d = math.cos(delta), math.sin(delta)
                    values[0] += G * (cos_d * d_pitch + sin_d * d_roll)
                    values[1] += G * (sin_d * d_pitch - cos_d * d_roll)
                    if self.axes[0].k + 1 >= self.next_sizing:     # a surge or sway design may be due
                        self._size_tilt_noise()
            elif points:
                values.append(euler_yaw_rate(rates, att))
        else:
            heave_acc = None
            values = [None] * (4 if points else 3)
            if self.gyro_tilt is not None:
                self.gyro_tilt.hold()
        out = self.group.push(values)                  # (axes, 4): position, rate, delayed position, rate
        ring = self.turn_ring
        n = len(ring) // 2
        if points:
            i = self.k % n
            if good:
                if out is not None:
                    yaw_wave = float(out[3, 1])
                else:                                  # some filter not yet designed: the yaw one may be
                    yaw_wave = None if self.yaw_axis.taps is None else float(self.yaw_axis.output()[1])
                rot = self.rot_rows if yaw_wave is None else rot_nb_rows(att.roll, att.pitch, yaw_wave)
                turn = [v - e for v, e in zip(rot, IDENTITY_ROWS)]              # R_hb − I
                ring[i::n] = [t - m for t, m in zip(turn, self.turn_mean.push(turn, dt))]
                slow_yaw_rate = 0.0 if first else (self.psi_bar - previous_psi_bar) / dt
                self.terms[1, :9] = turn_rate_rows(rot, rates, slow_yaw_rate)   # Ṙ, the slow yaw ψ̄'s rate left out
            elif self.k == 0:
                ring[i::n] = 0.0
            else:
                ring[i::n] = ring[(self.k - 1) % n]
                self.terms[1, :9] = 0.0                # the arms held: no turn rate
        self.k += 1
        heave_axis = self.axes[2]
        if heave_acc is not None:
            self.heave_acc = heave_acc - heave_axis.level - heave_axis.mean
        if heading is None and self.heading_offset is None:
            yaw_out, heading_used, heading_warning = att.yaw, False, None
        else:
            yaw_out, heading_used, heading_warning = self._heading(att.yaw, heading, heading_valid, dt)
        warning = restart or att.warning or heading_warning
        # after a gyro gap the attitude needs its aid reference to come back, which comes from
        # the joint filter, and that carries the coast error until it has read past the gap: the
        # angles wait for the motion's recovery
        angles_valid = att.valid and heading_warning is None and self.k >= self.angles_from
        if out is None:
            if self.joint is not None:
                self.joint.push(channels)
            zeros, zero_acc = self.no_motion
            return MruResult(att.roll, att.pitch, yaw_out, zeros, zeros, zero_acc, zeros, self.delay_s,
                             heave_axis.peak_period, angles_valid, False, False, heading_used, warning)
        delayed_ready = self.k * dt >= self.delayed_from     # before it the delayed outputs are zeros
        motion_valid = good and self.k >= self.recovered_at
        delayed_valid = motion_valid and delayed_ready and self.k >= self.recovered_at + self.lag_steps
        joint = self.joint
        now = None                                 # the joint filter's (2, 3) position and rate, once taught
        if joint is not None:
            # checked against the axis filters' outputs only once those have read past the last gap
            now = joint.step(channels, out, delayed_valid, motion_valid and self.k >= self.compared_from)
            if now is not None:
                if not joint.blended:
                    share = joint.share()
                    if share < 1.0:                # moving over from the axis filters' outputs
                        now = share * now + (1.0 - share) * out[:3, :2].T
                if joint.blended and self.params.aid_reference and self.attitude.aid_due(dt):
                    # the attitude reads it at its next aid only
                    self.attitude.aid_reference = self._aid_reference(now) if good else None
            elif joint.disagreed:                  # distrusted (JointMotion.check): no reference from it
                self.attitude.aid_reference = None
                self.log.warning("mru: the joint filter's motion departs from the axis filters' by more than %g x their "
                                 "usual difference (a heading change or a heel it was not taught?); the axis "
                                 "filters' outputs are used for at least %.0f s", GATE, (joint.distrusted_until - joint.k) * dt)
        if not points:                             # the IMU's row only: views of this step's own outputs
            if now is None:
                position, velocity = out[None, :3, 0], out[None, :3, 1]
            else:
                position, velocity = now[None, 0], now[None, 1]
            return MruResult(att.roll, att.pitch, yaw_out, position, velocity,
                             np.array([self.heave_acc]), out[None, :3, 2] if delayed_ready else self.no_motion[0],
                             self.delay_s, heave_axis.peak_period,
                             angles_valid, motion_valid, delayed_valid, heading_used, warning, now is not None)
        w = self.weights.shape[1]
        j = (self.k - 1) % n                   # the newest sample's row
        terms = self.terms
        terms[0, :9] = ring[j]
        if self.k >= w:                        # the acceleration row; oldest sample first
            np.matmul(self.weights, ring[j + n - w + 1:j + n + 1], out=terms[3:, :9])
        else:
            terms[3, :9] = 0.0
        terms[2, :9] = ring[(self.k - 1 - self.lag_steps) % n]
        terms[:3, 9:] = out[:3, :3].T
        if not delayed_ready:
            terms[2] = 0.0
        if now is not None:
            terms[:2, 9:] = now
        terms[3, 11] = self.heave_acc
        at = terms @ self.point_map            # (4, 3(P + 1)): every location's d + the IMU's motion
        motion = at[:3].reshape(3, points + 1, 3)
        return MruResult(att.roll, att.pitch, yaw_out, motion[0], motion[1], at[3, 2::3], motion[2], self.delay_s,
                         heave_axis.peak_period, angles_valid, motion_valid, delayed_valid, heading_used, warning,
                         now is not None)

    def _size_tilt_noise(self) -> None:
        """Before a surge or sway design: that filter's parameters from the gyro's noise as the
        attitude sizes it from the data now (``gyro_noise_used``, ``gyro_bias_sigma_used``;
        :func:`horizontal_params`), so that a quieter gyro than the default's is not designed
        for. Only on the steps whose push designs (a dataclass replace costs microseconds):
        called from ``next_sizing`` on, which it moves to the next design (on the step after a
        design, once the design has moved its axis's ``next_detect``)."""
        horizontal = self.axes[:2]
        for axis in horizontal:
            if axis.k + 1 >= axis.next_detect:
                att = self.attitude
                axis.params = horizontal_params(self.params, att.gyro_noise_used, att.gyro_bias_sigma_used)
        self.next_sizing = min(axis.next_detect for axis in horizontal)

    def _aid_reference(self, now: np.ndarray) -> tuple[float, float, float, float]:
        """The joint filter's horizontal position and velocity ``now`` (2, 3) [m, m/s, level
        frame h] turned into the attitude's frame n, Rz(ψ̄) [x, y]: the reference of its next
        aid (step 1)."""
        (px, py, _), (vx, vy, _) = now.tolist()
        c, s = math.cos(self.psi_bar), math.sin(self.psi_bar)
        return c * px - s * py, s * px + c * py, c * vx - s * vy, s * vx + c * vy

    def _coast_matters(self, dt: float) -> bool:
        """Whether the current gyro gap's coast error can exceed the attitude's own tilt
        uncertainty: its bound (:meth:`~marinefmu.estimators.attitude.gyro_coast.GyroCoast.bound`
        for the run of bad samples so far) against the tilt's standard deviation in the aid's
        covariance. In a 6 m sea a single bad sample at 100 Hz can leave 2·10⁻⁴ °, 0.1 s up to 0.02°."""
        P = self.attitude.kf.P
        coast = self.attitude.coast.bound(self.gap_steps * dt)
        return coast * coast > 0.5 * (P[4, 4] + P[5, 5])

    def _heading(self, yaw: float, heading: float | None, heading_valid: bool,
                 dt: float) -> tuple[float, bool, str | None]:
        """Step 5: the yaw output [rad], whether it is north-referenced, and why a heading
        sample was not used, if it was not."""
        warning = None
        if heading is not None and heading_valid:
            if math.isfinite(heading) and abs(heading) <= MAX_YAW:
                error = math.remainder(heading - yaw - (self.heading_offset or 0.0), 2.0 * math.pi)
                if self.heading_offset is None:
                    self.heading_offset = error
                else:
                    self.heading_offset += (1.0 - math.exp(-dt / self.params.heading_tau)) * error
            else:
                warning = f"heading sample {heading!r} not finite or beyond ±{MAX_YAW:g} rad; not used"
                self.log.warning("mru: %s", warning)
        if self.heading_offset is None:
            return yaw, False, warning
        return math.remainder(yaw + self.heading_offset, 2.0 * math.pi), True, warning

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"dt": self.dt, "k": self.k, "attitude": self.attitude.get_state(),
                "axes": [axis.get_state() for axis in self.axes], "yaw_axis": self.yaw_axis.get_state(),
                "yaw_ref": self.yaw_ref.get_state(),
                "turn_mean": self.turn_mean.get_state(), "yaw": self.yaw, "heading_offset": self.heading_offset,
                "rot": self.rot.tolist(), "heave_acc": self.heave_acc, "turn_ring": self.turn_ring.tolist(),
                "joint": None if self.joint is None else self.joint.get_state(), "psi_bar": self.psi_bar,
                "gyro_tilt": None if self.gyro_tilt is None else self.gyro_tilt.get_state(),
                "gap_steps": self.gap_steps, "recovered_at": self.recovered_at, "compared_from": self.compared_from,
                "angles_from": self.angles_from}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.reset()
        if s["dt"] is not None:
            self.start(float(s["dt"]))
        self.k = int(s["k"])
        self.attitude.set_state(s["attitude"])
        for axis, st in zip(self.axes, s["axes"]):
            axis.set_state(st)
        self.yaw_axis.set_state(s["yaw_axis"])
        self.group.bind()
        self.yaw_ref.set_state(s["yaw_ref"])
        self.turn_mean.set_state(s["turn_mean"])
        self.yaw, self.heading_offset = s["yaw"], s["heading_offset"]
        self.rot_rows = tuple(float(v) for v in np.ravel(s["rot"]))
        self.heave_acc = float(s["heave_acc"])
        self.turn_ring = np.array(s["turn_ring"], dtype=float).reshape(-1, 9)
        if self.joint is not None and s.get("joint") is not None:
            self.joint.set_state(s["joint"])
        self.psi_bar = float(s.get("psi_bar", 0.0))
        if self.gyro_tilt is not None:
            self.gyro_tilt.set_state(s.get("gyro_tilt"))
        self.gap_steps, self.recovered_at = int(s.get("gap_steps", 0)), int(s.get("recovered_at", 0))
        self.angles_from = int(s.get("angles_from", 0))
        self.compared_from = int(s.get("compared_from", 0))
