"""The vessel's level frame and the lever-arm terms of the monitoring points.

**Level frame h.** z down along gravity, x along the vessel's *mean* heading, y to starboard:
R_hb = Rz(ψ − ψ̄) Ry(θ) Rx(φ), with ψ̄ the yaw's slow part (:class:`SlowLowPass`, time
constant :data:`~.params.YAW_TAU`). A frame that turns with the wave-frequency yaw would mix the
surge and sway of a point by that yaw; one fixed to the mean heading does not, and the slow part
of a gyro-integrated yaw (its drift) cancels in ψ − ψ̄, so no heading sensor is needed. The
IMU's acceleration in h is a_h = R_hb f_b + [0, 0, g].

**A monitoring point** at lever arm r from the IMU (body frame) is at p_h + R_hb r in h. Its
motion about its mean position adds d = (R_hb r − r) − ⟨R_hb r − r⟩ to the IMU's, where ⟨·⟩
is the slow low-pass (:data:`~.params.ARM_TAU`), started at zero: the mean of R_hb r is not r
(a 2° roll and pitch shift a point 60 m away by 4 cm, the rectification of cos), and the
low-pass removes what the mean position holds while passing the wave-frequency part to within
(1/(ω τ))² (0.1 % at 0.3 rad/s). Both terms are linear in R_hb, so every point's d is one
product (:func:`turn_map`) with the nine entries of (R_hb − I) − ⟨R_hb − I⟩, the one series
the unit filters and stores.
**Velocity** adds ḋ = Ṙ r with the rigid body's own kinematics, Ṙ_nb = R_nb [ω]×: in the frame
of the wave-frequency yaw R = Rz(ψ_w) Ry(θ) Rx(φ) (``rot``; the yaw's slow part ψ_s is left
out), Ṙ = R [ω]× − ψ̇_s [ẑ]× R (:func:`turn_rate_rows`), ω the gyro's rate less its estimated
bias and ψ̇_s = ψ̇ − ψ̇_w the slow yaw rate. No angle is differentiated: the attitude's
corrections (its aid's steps) stay out of the rate, which carries only the gyro's own noise
times the arm. The rate of the slow mean ⟨R − I⟩ is left out (below 1/:data:`~.params.ARM_TAU`).
**Acceleration** adds d̈, the second derivative of a causal Savitzky-Golay fit (scipy's
``savgol_coeffs``) of degree :data:`DERIVATIVE_DEGREE` over the last :data:`DERIVATIVE_WINDOW`
s of d, evaluated at the newest sample (a wave of period ≥ 5 s is a quartic over 1 s to within
0.3 %).
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
from scipy.signal import savgol_coeffs

#: Length of the Savitzky-Golay fit for the lever arms' accelerations [s]: long enough to keep
#: the gyro-integrated angles' noise above 2 Hz out, short enough that a quartic follows a
#: wave (below).
DERIVATIVE_WINDOW = 1.0
#: Degree of that fit: over 1 s its endpoint first derivative errs by 0.03 / 0.27 / 1.5 % at
#: 0.8 / 1.3 / 2 rad/s (a cubic: 0.6 / 2.5 / 8.9 %).
DERIVATIVE_DEGREE = 4
#: 2π.
TWO_PI = 2.0 * math.pi


class SlowLowPass:
    """Two cascaded first-order low-passes with time constant ``tau`` [s] on a few numbers,
    y/x = 1/(1 + sτ)², exact discretisation (α = 1 − exp(−Δt/τ)); starts at the first sample.
    Hand-written, on Python floats: a per-sample two-pole recursion on a few numbers is cheaper
    inline than a call into ``scipy.signal.lfilter`` or a numpy array per step (the tests check
    it against ``lfilter``).

    Parameters
    ----------
    tau : float
        Time constant of each stage [s].
    from_zero : bool
        Start at zero rather than at the first sample.
    """

    def __init__(self, tau: float, from_zero: bool = False) -> None:
        self.tau = tau
        self.from_zero = from_zero
        self.stages: list[list[float]] | None = None   # the two stages' outputs
        self.dt, self.alpha = math.nan, 0.0         # the step the coefficient was computed for

    def push(self, x: Sequence[float], dt: float) -> list[float]:
        """The low-passed ``x`` (floats) after one step ``dt`` [s]."""
        if self.stages is None:
            start = [0.0] * len(x) if self.from_zero else [float(v) for v in x]
            self.stages = [start, start]
            if not self.from_zero:
                return start
        if dt != self.dt:
            self.dt, self.alpha = dt, 1.0 - math.exp(-dt / self.tau)
        alpha = self.alpha
        first, second = self.stages
        first = [s + alpha * (v - s) for s, v in zip(first, x)]
        second = [s + alpha * (f - s) for s, f in zip(second, first)]
        self.stages = [first, second]
        return second

    def push_one(self, x: float, dt: float) -> float:
        """:meth:`push` of one number, without its lists (the level frame's yaw, every step)."""
        if self.stages is None or dt != self.dt:
            return self.push([x], dt)[0]
        alpha = self.alpha
        (first,), (second,) = self.stages
        first += alpha * (x - first)
        second += alpha * (first - second)
        self.stages = [[first], [second]]
        return second

    def get_state(self) -> list | None:
        """JSON-serialisable state."""
        return None if self.stages is None else [list(v) for v in self.stages]

    def set_state(self, s: list | None) -> None:
        """Restore a state from :meth:`get_state`."""
        self.stages = None if s is None else [[float(v) for v in stage] for stage in s]


class GyroTilt:
    """Roll and pitch whose wave-frequency part is the gyro's alone: the complementary filter

    .. math::
        c^-_k = c_{k−1} + \\tfrac{Δt}{2}(u_{k−1} + u_k),\\qquad c_k = c^-_k + α\\,(a_k − c^-_k),
        \\qquad α = 1 − e^{−Δt/τ},

    per angle, u the Euler rate from the bias-corrected gyro [rad/s] and a the attitude's angle
    [rad]: c follows a below 1/τ and the integrated gyro above it (a first-order crossover).
    The trapezoidal rule: the rectangle's Δt u_k would lead the angle by half a sample, Δt/2 θ̇,
    0.009° on a 3° roll of 10 s at 100 Hz, more than the error taken out.
    :meth:`push` returns a − c, what the attitude's angle holds beyond the gyro at wave
    frequencies, which :class:`~.unit.MotionReferenceUnit` takes out of the horizontal
    level-frame acceleration (``tilt_tau``).

    **Why.** The attitude's aid corrects its tilt at every aid update from the horizontal
    specific force; in waves those corrections carry the aid's error into the wave band (the
    AttitudeEstimator's in-band tilt error on polar_supply Hs 3 m / Tp 10 s is 0.0065-0.0073°,
    the integrated gyro's alone 0.0055-0.0057°, 0.03-0.5 Hz), and g times that tilt error is
    an acceleration error the horizontal filters cannot tell from motion. The integrated gyro's
    in-band error is only its white noise's random walk, uncorrelated with the accelerations.
    Hand-written, on Python floats (two numbers a step; as :class:`SlowLowPass`).

    Parameters
    ----------
    tau : float
        Crossover time constant [s] (> 0).
    """

    def __init__(self, tau: float) -> None:
        self.tau = tau
        self.state: tuple[float, float, float, float] | None = None   # c (roll, pitch) [rad], u_{k−1} [rad/s]
        self.dt, self.alpha = math.nan, 0.0
        self.last = (0.0, 0.0)                      # the last (roll − c_roll, pitch − c_pitch) [rad]
        self.gap = False                            # a bad sample since the last push

    def push(self, roll_rate: float, pitch_rate: float, roll: float, pitch: float, dt: float) -> tuple[float, float]:
        """One good sample: the Euler rates [rad/s] and the attitude's angles [rad]; returns
        (roll − c_roll, pitch − c_pitch) [rad], the roll's wrapped to ±π. After a bad sample
        (:meth:`hold`) c restarts at the attitude less the last difference: the attitude coasted
        through the gap on its last gyro sample, which c did not see, and a − c would otherwise
        jump by what the attitude moved and take τ to recover."""
        if self.state is None:
            self.state = (roll, pitch, roll_rate, pitch_rate)
            self.last = (0.0, 0.0)
            return self.last
        if self.gap:
            self.gap = False
            d0, d1 = self.last
            self.state = (roll - d0, pitch - d1, roll_rate, pitch_rate)
            return self.last
        if dt != self.dt:
            self.dt, self.alpha = dt, 1.0 - math.exp(-dt / self.tau)
        alpha, h = self.alpha, 0.5 * dt
        c0, c1, u0, u1 = self.state
        c0 += h * (u0 + roll_rate)
        c1 += h * (u1 + pitch_rate)
        c0 += alpha * math.remainder(roll - c0, TWO_PI)
        c1 += alpha * (pitch - c1)
        self.state = (c0, c1, roll_rate, pitch_rate)
        self.last = (math.remainder(roll - c0, TWO_PI), pitch - c1)
        return self.last

    def hold(self) -> None:
        """A bad sample: nothing is integrated; the next :meth:`push` keeps the last difference."""
        if self.state is not None:
            self.gap = True

    def get_state(self) -> list | None:
        """JSON-serialisable state."""
        return None if self.state is None else [*self.state, *self.last, self.gap]

    def set_state(self, s: list | None) -> None:
        """Restore a state from :meth:`get_state`."""
        if s is None:
            self.state = None
            return
        self.state = tuple(float(v) for v in s[:4])
        self.last = (float(s[4]), float(s[5]))
        self.gap = bool(s[6])


def yaw_rotation(yaw: float) -> np.ndarray:
    """Rz(ψ)ᵀ [3 × 3]: NED (or any frame turned by ψ about down) to the frame ψ further on."""
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def level_rows(yaw_ref: float, q: Any) -> tuple[float, ...]:
    """R_hb = Rz(ψ̄)ᵀ R_nb(q) (:func:`yaw_rotation` times :func:`~marinefmu.frames.quat_to_rot`),
    its nine entries row by row on Python floats: R_nb's rows r from the unit quaternion
    q = (w, x, y, z), then cos ψ̄ r₀ + sin ψ̄ r₁, cos ψ̄ r₁ − sin ψ̄ r₀ and r₂. Written out
    because two 3 × 3 arrays a step cost more than the arithmetic."""
    w, x, y, z = q
    ww, xx, yy, zz = w * w, x * x, y * y, z * z
    a0, a1, a2 = ww + xx - yy - zz, 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)
    b0, b1, b2 = 2.0 * (x * y + w * z), ww - xx + yy - zz, 2.0 * (y * z - w * x)
    c, s = math.cos(yaw_ref), math.sin(yaw_ref)
    return (c * a0 + s * b0, c * a1 + s * b1, c * a2 + s * b2,
            c * b0 - s * a0, c * b1 - s * a1, c * b2 - s * a2,
            2.0 * (x * z - w * y), 2.0 * (y * z + w * x), ww - xx - yy + zz)


def turn_map(arms: np.ndarray) -> np.ndarray:
    """(3P, 9) map M from R's entries row by row to R r_p for the P lever arms ``arms`` (P, 3)
    [m]: M_p[i, 3i + j] = r_p,j, so that (R − I) r_p for every point is one product with the
    nine entries of R − I, and so are its mean, rate and acceleration (linear in R)."""
    arms = np.asarray(arms, dtype=float).reshape(-1, 3)
    m = np.zeros((len(arms), 3, 3, 3))
    for i in range(3):
        m[:, i, i, :] = arms
    return m.reshape(3 * len(arms), 9)


def location_map(arms: np.ndarray) -> np.ndarray:
    """(12, 3(P + 1)) map from one row of [the nine entries of R − I, the IMU's surge, sway and
    heave] to the surge, sway and heave of the IMU and of each of the P points at ``arms``
    (P, 3) [m], in that order: the IMU's motion plus (R − I) r (:func:`turn_map`), so that a
    quantity (position, rate, acceleration, delayed position) at every location is one product."""
    arms = np.asarray(arms, dtype=float).reshape(-1, 3)
    m = np.zeros((12, 3 * (len(arms) + 1)))
    m[:9, 3:] = turn_map(arms).T
    m[9:, :] = np.tile(np.eye(3), len(arms) + 1)
    return m


def unwrap(previous: float, yaw: float) -> float:
    """``yaw`` [rad] shifted by whole turns to lie within π of ``previous``."""
    return previous + math.remainder(yaw - previous, 2.0 * math.pi)


def acceleration_weights(dt: float) -> np.ndarray:
    """(1, W) weights giving the second derivative at the newest of W samples (oldest first)
    of a polynomial of degree :data:`DERIVATIVE_DEGREE` fitted over :data:`DERIVATIVE_WINDOW`
    s (module docstring)."""
    n = max(DERIVATIVE_DEGREE + 2, int(round(DERIVATIVE_WINDOW / dt)) | 1)
    return savgol_coeffs(n, DERIVATIVE_DEGREE, deriv=2, delta=dt, pos=n - 1, use="dot")[None, :]


def turn_rate_rows(rot: Sequence[float], rates: Sequence[float], slow_yaw_rate: float) -> list[float]:
    """The nine entries, row by row, of Ṙ = R [ω]× − ψ̇_s [ẑ]× R [1/s] (module docstring):
    the rate of the wave-frequency turn R (``rot``, row by row) of a body turning at ``rates``
    ω (3,) [rad/s, body] whose slow yaw turns at ``slow_yaw_rate`` ψ̇_s [rad/s], which R
    leaves out."""
    r0, r1, r2, r3, r4, r5, r6, r7, r8 = rot
    wx, wy, wz = rates
    s = slow_yaw_rate
    return [r1 * wz - r2 * wy + s * r3, r2 * wx - r0 * wz + s * r4, r0 * wy - r1 * wx + s * r5,
            r4 * wz - r5 * wy - s * r0, r5 * wx - r3 * wz - s * r1, r3 * wy - r4 * wx - s * r2,
            r7 * wz - r8 * wy, r8 * wx - r6 * wz, r6 * wy - r7 * wx]
