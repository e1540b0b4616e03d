"""The MotionReferenceUnit's accuracy goals and the points they are scored at.

Each goal is an RMS error with the truth's and the error's means removed (:func:`rms_about_mean`:
motion about the mean position; the motion filters have no output at zero frequency), against
the truth's standard deviation on the same axis (a vendor's "5 % of amplitude" is 5 % of about
√2 σ for a sinusoid, 2σ for Hs = 4σ of a sea, so their percentages are looser than these by that
factor):

- real-time surge and sway ≤ max(2 cm, 5 % of std) at every point;
- real-time heave ≤ max(2 cm, 2.5 % of std), or ≤ :data:`BOUND_FACTOR` × the causal bound
  (:func:`marinefmu.papers.motion_bound.causal_motion_bound`) where that is higher;
- the delayed outputs ≤ half the real-time error.

The benchmark (:mod:`marinefmu.bench.mru`) and the bound
(:mod:`marinefmu.papers.motion_bound`) both score with these, at :data:`POINTS`.
"""
from __future__ import annotations

import numpy as np

#: Monitoring points relative to the IMU, body frame [m]: a point near the IMU, one aft and to
#: port, one high on the beam, and one 59.8 m forward and above (a crane or gangway tip on the
#: longest lever arm the goals cover).
POINTS: tuple[tuple[float, float, float], ...] = ((20.0, 5.0, -5.0), (-30.0, -8.0, -10.0), (0.0, 10.0, -20.0),
                                                  (59.0, 0.0, -10.0))

#: The heave goal's multiple of the causal bound, where that is above max(2 cm, 2.5 % of std).
BOUND_FACTOR = 1.2


def rms_about_mean(err: np.ndarray) -> np.ndarray:
    """RMS of ``err`` (N, …) over axis 0 with its mean removed."""
    return np.sqrt(np.mean((err - err.mean(axis=0)) ** 2, axis=0))


def goals(std_cm: np.ndarray, bound_cm: np.ndarray | None = None) -> np.ndarray:
    """(…, 3) goals [cm] of surge, sway, heave for truth standard deviations ``std_cm``; with
    the causal bound ``bound_cm`` (…, 3) [cm], the heave goal is :data:`BOUND_FACTOR` × its heave
    where that is higher."""
    goal = np.maximum(2.0, np.asarray(std_cm) * np.array([0.05, 0.05, 0.025]))
    if bound_cm is not None:
        goal[..., 2] = np.maximum(goal[..., 2], BOUND_FACTOR * np.asarray(bound_cm)[..., 2])
    return goal
