"""Batch (non-causal) refinement of roll and pitch from the record's gravity direction.

Paper 000 integrates the gyros and lives with their drift; the real-time aided filter of
:mod:`.attitude` bounds it, but it has to aid slowly (its aiding sees the wave motion as
noise) and so keeps most of the gyro's bias instability: 0.07° RMS on the semi-submersible
example with a 10°/h MEMS gyro, almost all of it below 0.01 Hz.

In post-processing the slow tilt error can be read off the record itself. With the estimated
attitude R̂ = (I − [ε×]) R (ε small, NED), the horizontal components of the rotated specific
force are

.. math::
    \\hat f_n = \\hat R f_b = a_n - g_n + ε × g_n + O(ε a),\\qquad
    (ε × g_n)_{N,E} = (g\\,ε_E,\\; -g\\,ε_N),

where a_n, the acceleration of a floating body, is zero-mean and, in a sea, has no energy
below about half the spectral peak. A zero-phase low-pass of f̂_N, f̂_E below the sea band
(``cutoff``; Butterworth by scipy's ``sosfiltfilt``, so no lag) therefore leaves g·ε alone:
ε_N = −LP(f̂_E)/g, ε_E = LP(f̂_N)/g, and R = exp([ε×]) R̂ (exact rotation, scipy's
``Rotation``). The O(ε a) term is a product of slow ε and wave-band a and lies in the wave
band, which the filter removes; a second pass removes what is left of the small-angle
linearisation. This is the paper's own idea of screening what lies below the motion band,
applied to the attitude instead of the displacement. Yaw is not observable from gravity: the
correction turns about horizontal axes only (the ZYX yaw moves by second-order terms,
≈ 0.001° on the semi-submersible example).

What remains: the tilt error above ``cutoff`` (gyro noise and bias instability integrated
over less than 1/cutoff seconds: a few thousandths of a degree for a MEMS gyro at 0.02 Hz)
and the accelerometer bias (b/g rad, unobservable by any gravity-based method). The first and
last ≈ 4/cutoff seconds carry the filter's edge effects (records are padded by even
reflection; on a 0.5° slow error the edge error falls from 0.02° at 1/cutoff from the end to
5e-5° at 4/cutoff): score or use the refined attitude inside them.
"""
from __future__ import annotations

import logging
import math

import numpy as np
from scipy.signal import butter, sosfiltfilt
from scipy.spatial.transform import Rotation

from ...errors import ParameterError, check_int, check_range
from ...frames import G
from ..samples import MAX_SPECIFIC_FORCE

log = logging.getLogger(__name__)

#: Butterworth order of the low-pass (doubled in magnitude by the forward-backward pass).
FILTER_ORDER = 4


def refine_tilt(q: np.ndarray, acc: np.ndarray, dt: float, cutoff: float = 0.02, *, iterations: int = 2) -> np.ndarray:
    """Remove the slow roll/pitch error of an attitude record with the gravity direction.

    Parameters
    ----------
    q : numpy.ndarray
        (N, 4) unit quaternions (w, x, y, z) of R_nb, e.g. ``estimate_attitude(...)["q"]``.
    acc : numpy.ndarray
        (N, 3) specific force at the same instants [m/s², b]. Non-finite or absurd samples
        are bridged by linear interpolation of the rotated force (a warning says how many).
    dt : float
        Sample interval [s], > 0.
    cutoff : float
        Low-pass cutoff [Hz], 0 < cutoff < Nyquist: below the sea's energy (half the
        spectral peak or less), above the gyro error's. Default 0.02 Hz.
    iterations : int
        Number of passes, 1 … 10 (the second removes the small-angle linearisation error).

    Returns
    -------
    numpy.ndarray
        (N, 4) refined unit quaternions (w, x, y, z).

    Raises
    ------
    ParameterError
        On a bad ``dt``, ``cutoff``, ``iterations``, mismatched shapes, a record shorter than
        1/cutoff or one without a valid sample.
    """
    dt = check_range("dt", dt, lo=0.0, lo_open=True, unit="s")
    cutoff = check_range("cutoff", cutoff, lo=0.0, hi=0.5 / dt, lo_open=True, hi_open=True, unit="Hz")
    iterations = check_int("iterations", iterations, lo=1, hi=10)
    q = np.asarray(q, dtype=float)
    acc = np.asarray(acc, dtype=float)
    if q.ndim != 2 or q.shape[1] != 4 or acc.shape != (len(q), 3):
        raise ParameterError(f"q must be (N, 4) and acc (N, 3) with the same N; got {q.shape} and {acc.shape}")
    period = int(round(1.0 / (cutoff * dt)))
    if len(q) < period:
        raise ParameterError(f"record of {len(q)} samples is too short for refine_tilt: it must span one period "
                             f"of the cutoff, 1/cutoff = {1.0 / cutoff:g} s ({period} samples)")
    sos = butter(FILTER_ORDER, cutoff, fs=1.0 / dt, output="sos")
    good = np.all(np.isfinite(acc), axis=1)
    good[good] = np.linalg.norm(acc[good], axis=1) <= MAX_SPECIFIC_FORCE
    if not good.any():
        raise ParameterError("acc has no finite sample within the plausible range")
    if not good.all():
        log.warning("refine_tilt: %d of %d acc samples non-finite or absurd; bridged by interpolation",
                    int((~good).sum()), len(good))
    k = np.arange(len(q))
    rot = Rotation.from_quat(q, scalar_first=True)
    for _ in range(iterations):
        f_n = rot[good].apply(acc[good])
        f_h = np.column_stack([np.interp(k, k[good], f_n[:, i]) for i in range(2)])
        lp = sosfiltfilt(sos, f_h, axis=0, padtype="even", padlen=period - 1)
        eps = np.column_stack((-lp[:, 1], lp[:, 0], np.zeros(len(q)))) / G
        rot = Rotation.from_rotvec(eps) * rot
    return rot.as_quat(scalar_first=True)


def tilt_rms_bound_deg(gyro_noise: float, gyro_bias_sigma: float, gyro_bias_tau: float, cutoff: float) -> float:
    """RMS tilt error [deg] left above ``cutoff`` by the gyro (one axis), for the docs and tests.

    The angle error of white rate noise N [rad/s/√Hz] has the spectrum N²/(2πf)², that of a
    Gauss–Markov bias (σ, τ) ≈ 2σ²/(τ (2πf)⁴) above its corner; integrated from ``cutoff`` up:
    N²/(4π² f_c) + 2σ²/(3 τ (2π)⁴ f_c³).
    """
    var = gyro_noise ** 2 / (4 * math.pi ** 2 * cutoff)
    var += 2 * gyro_bias_sigma ** 2 / (3 * gyro_bias_tau * (2 * math.pi) ** 4 * cutoff ** 3)
    return math.degrees(math.sqrt(var))
