"""Attitude and position from four GNSS antennas (paper 001, item 1 of
:mod:`.filter`): the least-squares attitude of Wahba's problem and its error.

The four measured antenna positions p_i (NED) and their body lever arms l_i relative to the
COG satisfy p_i = p_c + R_nb l_i. The least-squares R_nb is Wahba's problem on the centred
sets, solved by ``scipy.spatial.transform.Rotation.align_vectors`` (the paper: "a relatively
simple least squares method"); then p_c = mean(p_i) − R mean(l_i), and the RMS fit residual is
the quality output. NaN coordinates or antennas that do not span a plane make the epoch
unusable (:func:`antenna_attitude` returns the reason).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .error_model import skew

#: Antennas per GNSS epoch.
ANTENNAS = 4
#: Default antenna lever arms [m] (body frame, relative to the COG): VesselMotion's defaults.
DEFAULT_ANTENNAS = ((10.0, -4.0, -10.0), (10.0, 4.0, -10.0), (-10.0, -4.0, -10.0), (-10.0, 4.0, -10.0))
#: Smallest second singular value [m] of the centred antenna positions (they must span a plane).
MIN_SPREAD = 0.05


@dataclass(frozen=True)
class AntennaFix:
    """Attitude and COG position from one GNSS epoch (:func:`antenna_attitude`).

    Attributes
    ----------
    rot : numpy.ndarray
        (3, 3) R_nb (body → NED).
    cog : numpy.ndarray
        (3,) COG position, NED [m].
    residual : float
        RMS distance between measured and fitted antenna positions [m].
    centroid : numpy.ndarray
        (3,) mean of the measured antenna positions, NED [m].
    """

    rot: np.ndarray
    cog: np.ndarray
    residual: float
    centroid: np.ndarray


def antenna_attitude(positions: np.ndarray, arms: np.ndarray) -> AntennaFix | str:
    """Least-squares attitude and COG position from antenna positions (Wahba's problem).

    Parameters
    ----------
    positions : numpy.ndarray
        (4, 3) measured antenna positions, NED [m].
    arms : numpy.ndarray
        (4, 3) antenna lever arms relative to the COG, body frame [m].

    Returns
    -------
    AntennaFix or str
        The fix, or the reason the epoch is unusable (non-finite, degenerate geometry).
    """
    p = np.asarray(positions, dtype=float).reshape(ANTENNAS, 3)
    if not np.all(np.isfinite(p)):
        return "non-finite antenna coordinates"
    pc, lc = p.mean(axis=0), arms.mean(axis=0)
    dp = p - pc
    if np.linalg.svd(dp, compute_uv=False)[1] < MIN_SPREAD:
        return "degenerate antenna geometry (coincident or collinear positions)"
    rot, _ = Rotation.align_vectors(dp, arms - lc)
    r = rot.as_matrix()
    cog = pc - r @ lc
    resid = p - (cog + arms @ r.T)
    return AntennaFix(r, cog, float(math.sqrt(np.mean(np.sum(resid ** 2, axis=1)))), pc)


def matrix_rotvec(m: np.ndarray) -> tuple[float, float, float]:
    """Rotation vector [rad] of the rotation matrix ``m``: scipy's
    ``Rotation.from_matrix(m).as_rotvec()`` written out in floats (its quaternion of the
    largest of the diagonal and the trace, normalised and made w ≥ 0, then 2·atan2(|v|, w)
    and its small-angle series below 1e-3 rad). A matrix that scipy would orthogonalise first
    (its Gram matrix not I to 1e-12) or reject is handed to scipy itself. For the fix-to-fix
    rotations at every GNSS epoch and the coast's tilt at every band step, where scipy costs
    tens of µs a call; a test checks it against scipy.

    Examples
    --------
    >>> [round(v, 12) for v in matrix_rotvec(Rotation.from_rotvec([0.1, -0.2, 0.3]).as_matrix())]
    [0.1, -0.2, 0.3]
    """
    (a, b, c), (d, e, f), (g, h, i) = m.tolist()
    gram = (a * a + b * b + c * c - 1.0, a * d + b * e + c * f, a * g + b * h + c * i,
            d * d + e * e + f * f - 1.0, d * g + e * h + f * i, g * g + h * h + i * i - 1.0)
    if not (abs(gram[0]) <= 1e-12 + 1e-5 and abs(gram[3]) <= 1e-12 + 1e-5 and abs(gram[5]) <= 1e-12 + 1e-5
            and abs(gram[1]) <= 1e-12 and abs(gram[2]) <= 1e-12 and abs(gram[4]) <= 1e-12) or (
            a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g) <= 0.0):
        return tuple(Rotation.from_matrix(m).as_rotvec().tolist())
    tr = a + e + i
    big = max(a, e, i, tr)
    if a == big:
        q = (1.0 - tr + 2.0 * a, d + b, g + c, h - f)
    elif e == big:
        q = (d + b, 1.0 - tr + 2.0 * e, h + f, c - g)
    elif i == big:
        q = (g + c, h + f, 1.0 - tr + 2.0 * i, d - b)
    else:
        q = (h - f, c - g, d - b, 1.0 + tr)
    x, y, z, w = q
    if w < 0.0 or (w == 0.0 and (x < 0.0 or (x == 0.0 and (y < 0.0 or (y == 0.0 and z < 0.0))))):
        x, y, z, w = -x, -y, -z, -w
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    x, y, z, w = x / norm, y / norm, z / norm, w / norm
    angle = 2.0 * math.atan2(math.sqrt(x * x + y * y + z * z), w)
    if angle <= 1e-3:
        a2 = angle * angle
        scale = 2.0 + a2 / 12.0 + 7.0 * a2 * a2 / 2880.0
    else:
        scale = angle / math.sin(angle / 2.0)
    return scale * x, scale * y, scale * z


def antenna_attitude_std(arms: np.ndarray, rot: np.ndarray, sigma_h: float, sigma_v: float) -> np.ndarray:
    """Standard deviations [rad] of the least-squares antenna attitude's error about the N, E
    and D axes, to first order, for independent antenna errors of ``sigma_h`` (north, east) and
    ``sigma_v`` (down) [m].

    An attitude error θ (n frame) moves antenna i by θ × r_i, r_i = R (arm_i − mean arm); the
    weighted least-squares covariance is (Σ [r_i]×ᵀ W [r_i]×)⁻¹, W = diag(σ_h⁻², σ_h⁻², σ_v⁻²)
    (the centroid decouples, the arms being centred).

    Examples
    --------
    >>> arms = np.array(DEFAULT_ANTENNAS)
    >>> (1e3 * antenna_attitude_std(arms, np.eye(3), 0.01, 0.015)).round(2)  # 8 m wide, 20 m long
    array([1.88, 0.75, 0.46])
    """
    w = np.diag([sigma_h ** -2, sigma_h ** -2, sigma_v ** -2])
    m = np.zeros((3, 3))
    for r in (arms - arms.mean(axis=0)) @ np.asarray(rot).T:
        c = skew(r)
        m += c.T @ w @ c
    return np.sqrt(np.diag(np.linalg.inv(m)))
