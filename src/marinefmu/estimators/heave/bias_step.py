"""Detection of a step in an accelerometer's bias within a buffered window (beyond paper 003).

A bias step b at time t_s puts a kink into the integral of the acceleration: the "velocity"
V(t) = ∫ (a − ā) dt gains b·(t − t_s) after it, while the sea's share of V is the heave velocity,
an oscillation about zero. The step is found by least squares: V, from block means of
:data:`BLOCK` s, is fitted with a line plus one hinge b·max(t − t_s, 0) for every candidate t_s,
and the t_s that explains most of V is taken (the fit is exact for a clean step: b to 1e-3
relative and t_s to a block on a wave record). It is reported only when it is significant:
z = |b|·A / (√2·σ_v) ≥ :data:`MIN_Z`, with A the step's age and σ_v the standard deviation of V
about its :data:`SMOOTH` s moving average (the sea's velocity; the noise of b·A, a difference of
two values of V), and when |b| ≥ :data:`MIN_STEP`.

:data:`MIN_Z` sits well above the largest z that the heave checks' records reach without a
step, while a step of a few cm/s² still reaches it within a minute or two
(docs/decisions/heave-wiener.md). Candidates are at least :data:`MIN_AGE` s old (a younger kink is not yet told from a
wave) and :data:`EDGE` s inside the window's old end (a hinge there is nearly the line, and its
b is noise).

Hand-written (numpy least squares): scipy and statsmodels offer change-point tests for a mean
(CUSUM), which on the acceleration itself drown in the waves; the velocity's kink does not.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Length of the block means [s].
BLOCK = 1.0
#: Youngest step considered [s].
MIN_AGE = 5.0
#: Candidates start this far from the window's old end [s].
EDGE = 60.0
#: Oldest step considered [s] (older ones have been caught already).
MAX_AGE = 600.0
#: Moving average that separates the sea's velocity from the kink [s].
SMOOTH = 61.0
#: Shortest window searched [s]: σ_v needs a few times the moving average.
MIN_WINDOW = 240.0
#: Significance a step needs.
MIN_Z = 8.0
#: Smallest step reported [m/s²].
MIN_STEP = 0.002


@dataclass(frozen=True)
class BiasStep:
    """A step found in a window."""

    index: int      # first sample of the window that has the step
    size: float     # [m/s²]
    z: float        # significance (module docstring)


def find_bias_step(window: np.ndarray, dt: float, at: int | None = None) -> BiasStep | None:
    """The most likely bias step in ``window`` if it is significant (module docstring).

    Parameters
    ----------
    window : numpy.ndarray
        (N,) acceleration samples [m/s²], oldest first.
    dt : float
        Sample interval [s].
    at : int, optional
        Index of a step found before: its size is estimated again, at that sample's block,
        and returned whatever its significance (the caller refines a step as it ages).

    Returns
    -------
    BiasStep or None
        None when the window is shorter than :data:`MIN_WINDOW` or, without ``at``, no step is
        significant or the likeliest one is younger than :data:`MIN_AGE` (a younger kink is
        not told from a wave, and a fit restricted to older ones would misplace it).

    Examples
    --------
    >>> t = np.arange(0, 600, 0.05)
    >>> a = 0.5 * np.sin(0.7 * t) + np.where(t >= 400.0, 0.1, 0.0)
    >>> s = find_bias_step(a, 0.05)
    >>> float(t[s.index]), round(s.size, 3)
    (400.0, 0.1)
    """
    m = max(1, int(round(BLOCK / dt)))
    n = len(window) // m
    skip = len(window) - n * m
    if n * m * dt < MIN_WINDOW:
        return None
    if at is None:
        starts = np.arange(max(int(round(EDGE / (m * dt))), n - int(round(MAX_AGE / (m * dt)))), n - 1)
    else:
        starts = np.array([min(max((at - skip) // m - 1, 1), n - 2)])
    smooth = int(round(SMOOTH / (m * dt))) | 1
    y = np.asarray(window[skip:], dtype=float).reshape(n, m).mean(axis=1)
    v = np.cumsum(y - y.mean()) * (m * dt)
    sigma = float(np.std((v - np.convolve(v, np.ones(smooth) / smooth, mode="same"))[smooth:-smooth]))
    # the hinges h_s(j) = max(j − s, 0) against V less its line, in closed form (O(n), not O(n²)):
    # with r = V less its least-squares line, h_s·r = Σ_{j>s} (j − s) r_j, and h_s less its own
    # line has |h_s|² − (Σh_s)²/n − (Σ h_s (j − j̄))²/Σ(j − j̄)²
    j = np.arange(n, dtype=float)
    centred = j - j.mean()
    residual = v - v.mean() - centred * (centred @ v) / (centred @ centred)
    suffix0 = np.cumsum(residual[::-1])[::-1]             # Σ_{j≥i} r_j
    suffix1 = np.cumsum((j * residual)[::-1])[::-1]       # Σ_{j≥i} j r_j
    after = starts + 1
    num = (suffix1[after] - starts * suffix0[after]) * (m * dt)
    length = n - 1 - starts                               # L: the hinge's nonzero terms 1 … L
    sum1 = length * (length + 1) / 2.0
    sum2 = length * (length + 1) * (2 * length + 1) / 6.0
    along = sum2 + (starts - j.mean()) * sum1
    den = (sum2 - sum1**2 / n - along**2 / (centred @ centred)) * (m * dt) ** 2
    best = int(np.argmax(num**2 / den))
    size = float(num[best] / den[best])
    step = int(starts[best]) + 1          # V, a cumulative sum, has the kink a block before the step
    age = (n - step) * m * dt
    z = abs(size) * age / (math.sqrt(2.0) * max(sigma, 1e-12))
    if at is None and (z < MIN_Z or abs(size) < MIN_STEP or age < MIN_AGE):
        return None
    return BiasStep(skip + step * m, size, z)
