"""Plausibility limits for single IMU samples, shared by the estimators: a sample beyond them
is a sensor fault (the estimator coasts on its last good sample, see each ``step``); and when a
step counts as a change of the step size (:func:`step_changed`)."""
from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

#: Largest angular rate [rad/s] and specific force [m/s²] accepted as a physical sample.
MAX_RATE = 10.0
MAX_SPECIFIC_FORCE = 200.0
#: Largest |roll| and |pitch| [rad] accepted from an attitude input (80°).
MAX_TILT = math.radians(80.0)
#: Largest |yaw| [rad] accepted from an attitude input: an unwrapped heading may grow with turns,
#: but 1e4 rad is some 1,600 turns, beyond any single run.
MAX_YAW = 1e4


#: Relative change of the step [-] beyond which an estimator restarts for a new step size. An
#: FMI master may pass each step as a difference of absolute times, t_{k+1} − t_k (FMPy does),
#: which differs from the step by up to a rounding of t (2⁻⁵² t): relative to a step of 0.01 s
#: that exceeds 10⁻⁹ from t = 2¹⁶ s (18 h) on, and 10⁻⁶ only from t = 2²⁶ s (2 years).
STEP_TOLERANCE = 1e-6


def step_changed(previous: float, dt: float) -> bool:
    """Whether ``dt`` [s] differs from the step ``previous`` [s] by more than
    :data:`STEP_TOLERANCE` of it (a NaN ``dt`` does not count: the callers check it apart)."""
    return abs(dt - previous) > STEP_TOLERANCE * previous


#: Squared specific force [m²/s⁴] below which a sample passes on float comparisons alone, a
#: margin inside :data:`MAX_SPECIFIC_FORCE` (the full check's norm rounds differently). NaN
#: fails every comparison, so a non-finite sample takes the full check.
FORCE_PASS2 = (0.99 * MAX_SPECIFIC_FORCE) ** 2


def force_beyond_limit(acc: np.ndarray) -> str | None:
    """Reason if the finite specific force ``acc`` [m/s²] exceeds :data:`MAX_SPECIFIC_FORCE`."""
    return f"specific force beyond {MAX_SPECIFIC_FORCE} m/s²" if math.sqrt(acc @ acc) > MAX_SPECIFIC_FORCE else None


def rate_beyond_limit(gyro: np.ndarray) -> str | None:
    """Reason if a component of the finite rate ``gyro`` [rad/s] exceeds :data:`MAX_RATE`."""
    return f"gyro sample beyond ±{MAX_RATE} rad/s" if np.max(np.abs(gyro)) > MAX_RATE else None


def force_sample_good(f: np.ndarray) -> bool:
    """The (3,) specific force ``f`` [m/s²] is finite and within
    :data:`MAX_SPECIFIC_FORCE`: on Python floats inside the
    margin of :data:`FORCE_PASS2`, else by the full check."""
    f0, f1, f2 = f.tolist()
    if f0 * f0 + f1 * f1 + f2 * f2 <= FORCE_PASS2:
        return True
    return bool(np.all(np.isfinite(f))) and force_beyond_limit(f) is None


def rate_sample_good(w: np.ndarray) -> bool:
    """The (3,) angular rate ``w`` [rad/s] is finite and each component within ±
    :data:`MAX_RATE` (float comparisons: exact, and NaN fails
    them)."""
    w0, w1, w2 = w.tolist()
    return -MAX_RATE <= w0 <= MAX_RATE and -MAX_RATE <= w1 <= MAX_RATE and -MAX_RATE <= w2 <= MAX_RATE


def angles_beyond_limit(euler: np.ndarray) -> str | None:
    """Reason if finite (roll, pitch[, yaw]) ``euler`` [rad] exceed :data:`MAX_TILT` / :data:`MAX_YAW`."""
    if max(abs(euler[0]), abs(euler[1])) > MAX_TILT:
        return f"roll or pitch beyond ±{math.degrees(MAX_TILT):.0f}°"
    if len(euler) > 2 and abs(euler[2]) > MAX_YAW:
        return f"yaw beyond ±{MAX_YAW:g} rad"
    return None


def bad_scalar(checks: Iterable[tuple[str, float, float]]) -> str | None:
    """The first of (name, value, bound) whose value is not finite or beyond ±bound, as a
    warning ("bad tip nan (not finite): holding the last good one"), or None."""
    for name, value, bound in checks:
        if not math.isfinite(value):
            return f"bad {name} {value!r} (not finite): holding the last good one"
        if abs(value) > bound:
            return f"bad {name} {value!r} (beyond ±{bound:g}): holding the last good one"
    return None
