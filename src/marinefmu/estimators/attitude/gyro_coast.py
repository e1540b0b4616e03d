"""What coasting on a held gyro rate costs the aided attitude, and when the aid has removed it.

Through a gyro gap the :class:`~marinefmu.estimators.attitude.estimator.AttitudeEstimator`
holds the last good rate ω(0); the tilt then errs by the rate's change integrated over the gap,

.. math::
    e(T) = \\int_0^T \\big(ω(0) - ω(τ)\\big)\\, dτ,\\qquad
    σ_e(T) \\le \\int_0^T σ_{Δω}(τ)\\, dτ,\\qquad
    σ_{Δω}(τ) \\le \\min\\big(σ_{\\dot ω}\\, τ,\\; 2σ_ω\\big)

(Minkowski's inequality, for any stationary rate: the change over τ is the angular
acceleration integrated over τ, and the difference of two samples of RMS σ_ω; the first term
is the change's RMS to first order in τ, the second is reached by a narrow-band roll half a
period on). σ_ω and σ_ω̇ are the running RMS of the horizontal body rates (both axes
together, the bound for either axis of frame n whatever the heading) and of their change per
second between aid updates, exponential means with time constant ``tau`` corrected for the
start. For research36's COG in Hs 6 m a 0.5 s gap gives
σ_e = 0.54° (both axes); the larger of the roll and pitch errors at the ends of ten such gaps
were 0.17-0.83°, RMS 0.5°.

The estimator adds σ_e² to the tilt's variances in its covariance as the gap goes on (the coast
error is independent of the error the tilt had before the gap; within the gap the steps'
contributions are fully correlated, so their standard deviations add), so that the aid trusts
its measurements again and removes the coast error sooner (to within 0.05° of the
uninterrupted run: 20-96 s after a 2 s gap in research36's 6 m sea, 72-587 s on the filter's
steady gains), and holds its ``valid`` flag false until the tilt's variance is back within :data:`RECOVERED` × that of the same
filter without the inflation, and the x/y gyro bias's within :data:`RECOVERED_BIAS` × (its
covariance, :attr:`GyroCoast.shadow`, is propagated and updated beside the filter's from the
gap's start to the recovery: the filter's steady variance follows the sea, so its value before
the gap would not do). The bias has its own test because the aid's fast correction of the
tilt also moves the bias estimate, whose error then returns into the tilt over a minute or so
(the tilt's variance alone came back within 1.1 × while the tilt was still to move by 0.09°).
In mode 0 (gyro-only integration) there is no aid: nothing is inflated and the coast error
stays. The MotionReferenceUnit turns the inflation off for its attitude
(``AttitudeEstimator.recover_from_gyro_gaps``) and holds its angles when :meth:`GyroCoast.bound`
exceeds the tilt's standard deviation.

Written out (a few float operations at the aid rate); no library keeps these statistics.
"""
from __future__ import annotations

import math

import numpy as np

#: The tilt's variance (sum of its two axes) at which the attitude counts as recovered from a
#: gyro gap, per the variance without the gap's inflation (:attr:`GyroCoast.shadow`) ...
RECOVERED = 1.1
#: ... and the x/y gyro bias's. Over 10 gaps of 0.1, 0.5 and 2 s in each of six benchmark
#: cases the roll and pitch were then within 0.035° of the uninterrupted run's (0.061° for a
#: gap 45 s after levelling, the filter not yet settled), with RMS errors 1.14 × its at most
#: (docs/decisions/attitude-gyro-gap.md).
RECOVERED_BIAS = 1.05


class GyroCoast:
    """Running rate statistics, the coast error of a gyro gap, and the recovery after it.

    Parameters
    ----------
    tau : float
        Time constant of the running mean squares [s].

    Examples
    --------
    >>> c = GyroCoast(10.0)
    >>> for k in range(2000):                       # 0.1 rad/s roll rate at 1 rad/s, aid at 10 Hz
    ...     c.push(0.1 * math.sin(0.1 * k), 0.0, 0.1)
    >>> round(c.held_step(0.5) ** 0.5 / 0.5 ** 2 * 2, 2)   # σ_ω̇ = 0.1/√2 rad/s² from σ_e = σ_ω̇ T²/2
    0.07
    """

    __slots__ = ("tau", "ms_rate", "ms_accel", "weight", "last", "held", "std", "shadow")

    def __init__(self, tau: float) -> None:
        self.tau = tau
        self.ms_rate = 0.0        # mean square of the horizontal rates, both axes [rad²/s²]
        self.ms_accel = 0.0       # mean square of their change per second [rad²/s⁴]
        self.weight = 0.0         # 1 − (1 − β)^k of the exponential means
        self.last: tuple[float, float] | None = None
        self.held = 0.0           # time on the held rate in the current gap [s]
        self.std = 0.0            # σ_e of the current gap so far [rad]
        #: while a recovery is pending, the filter's (8, 8) covariance as it would be without the
        #: gap's inflation (the estimator propagates and updates it beside its own), else None
        self.shadow: np.ndarray | None = None

    def push(self, wx: float, wy: float, interval: float) -> None:
        """Add the horizontal body rates [rad/s, b] of an aid update, ``interval`` [s] after the
        previous one."""
        last = self.last
        self.last = (wx, wy)
        if last is None:
            return
        beta = min(1.0, interval / self.tau)
        dx, dy = wx - last[0], wy - last[1]
        self.ms_rate += beta * (wx * wx + wy * wy - self.ms_rate)
        self.ms_accel += beta * ((dx * dx + dy * dy) / (interval * interval) - self.ms_accel)
        self.weight += beta * (1.0 - self.weight)

    def break_chain(self) -> None:
        """A held rate: the next push starts a new difference."""
        self.last = None

    def bound(self, gap: float) -> float:
        """σ_e [rad] after ``gap`` [s] on a held rate (module docstring, the integral in closed
        form; 0 before the statistics have a sample)."""
        if self.weight <= 0.0:
            return 0.0
        a = math.sqrt(self.ms_accel / self.weight)          # σ_ω̇
        b = 2.0 * math.sqrt(self.ms_rate / self.weight)      # 2σ_ω
        if a * gap <= b:
            return 0.5 * a * gap * gap
        return b * (gap - 0.5 * b / a)                      # ½ a t₀² + b (T − t₀), t₀ = b / a

    def held_step(self, dt: float) -> float:
        """One step of ``dt`` [s] on the held rate: the growth of the coast error's variance
        σ_e² over it [rad²]."""
        self.held += dt
        before = self.std
        self.std = self.bound(self.held)
        return self.std * self.std - before * before

    def gap_ended(self) -> None:
        """A good rate again: the next gap starts from nothing."""
        self.held = self.std = 0.0

    def get_state(self) -> dict:
        return {"ms_rate": self.ms_rate, "ms_accel": self.ms_accel, "weight": self.weight,
                "last": None if self.last is None else list(self.last), "held": self.held, "std": self.std,
                "shadow": None if self.shadow is None else self.shadow.tolist()}

    def set_state(self, s: dict) -> None:
        self.ms_rate, self.ms_accel, self.weight = float(s["ms_rate"]), float(s["ms_accel"]), float(s["weight"])
        self.last = None if s["last"] is None else (float(s["last"][0]), float(s["last"][1]))
        self.held, self.std = float(s["held"]), float(s["std"])
        self.shadow = None if s["shadow"] is None else np.array(s["shadow"], dtype=float)
