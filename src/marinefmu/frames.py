"""Frame conventions shared by the whole project (see the design page).

- World frame n: NED, origin at the mean position of the vessel reference point.
- Body frame b: x forward, y starboard, z down (SNAME/Fossen).
- Euler angles ZYX: R_nb = Rz(yaw) Ry(pitch) Rx(roll).
- Specific force f_b = R_nbᵀ (a_n − g_n), g_n = [0, 0, +g]: a level sensor at rest reads [0, 0, −g].

The hot path (one call per FMU step) uses hand-written 3×3 formulas on Python floats because
``scipy.spatial.transform.Rotation`` costs ~20 µs per call; the tests check these functions
against scipy's Rotation to 1e-15.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

#: Standard gravity [m/s²] (ISO 80000-3), used for g_n = [0, 0, G].
G = 9.80665
#: Gravity vector in NED [m/s²].
GRAVITY_N = np.array([0.0, 0.0, G])
#: Lowest frequency of heave [rad/s]: heave is the vertical motion at periods up to 2π/0.2 = 31 s.
#: Wave periods at sea are 3-25 s; slower vertical motion (a drifting attitude times a lever arm)
#: is not heave, nor what heave compensation is for. Used by the AHC scores and design.
HEAVE_CUTOFF = 0.2


def rot_nb(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Rotation matrix from body to NED, R_nb = Rz(ψ) Ry(θ) Rx(φ).

    Parameters
    ----------
    roll, pitch, yaw : float
        Euler angles φ, θ, ψ [rad], ZYX convention.

    Returns
    -------
    numpy.ndarray
        (3, 3) rotation matrix; ``R @ v_b`` gives the vector in NED.
    """
    return np.array(rot_nb_rows(roll, pitch, yaw)).reshape(3, 3)


def rot_nb_rows(roll: float, pitch: float, yaw: float) -> tuple[float, ...]:
    """:func:`rot_nb`'s nine entries row by row, as Python floats (for per-sample code, where
    an array costs more than the arithmetic)."""
    cf, sf = math.cos(roll), math.sin(roll)
    ct, st = math.cos(pitch), math.sin(pitch)
    cp, sp = math.cos(yaw), math.sin(yaw)
    return (cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf,
            sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf,
            -st, ct * sf, ct * cf)


def euler_rates_to_body(euler: np.ndarray, euler_dot: np.ndarray, euler_ddot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Body angular rate ω_b and angular acceleration α_b from ZYX Euler angles and their derivatives.

    .. math::
        p = \\dot φ - \\dot ψ \\sin θ,\\quad
        q = \\dot θ \\cos φ + \\dot ψ \\cos θ \\sin φ,\\quad
        r = -\\dot θ \\sin φ + \\dot ψ \\cos θ \\cos φ

    and α_b is the exact time derivative of these expressions (Fossen 2021, eq. 2.41).

    Parameters
    ----------
    euler, euler_dot, euler_ddot : numpy.ndarray
        (3,) [φ, θ, ψ] [rad], their rates [rad/s] and accelerations [rad/s²].

    Returns
    -------
    tuple of numpy.ndarray
        ω_b [rad/s] and α_b [rad/s²], body frame.
    """
    f, t = euler[0], euler[1]
    fd, td, pd = euler_dot
    fdd, tdd, pdd = euler_ddot
    cf, sf, ct, st = math.cos(f), math.sin(f), math.cos(t), math.sin(t)
    w = np.array([fd - pd * st, td * cf + pd * ct * sf, -td * sf + pd * ct * cf])
    a = np.array(
        [
            fdd - pdd * st - pd * td * ct,
            tdd * cf - td * fd * sf + pdd * ct * sf - pd * td * st * sf + pd * fd * ct * cf,
            -tdd * sf - td * fd * cf + pdd * ct * cf - pd * td * st * cf - pd * fd * ct * sf,
        ]
    )
    return w, a


def body_to_euler_rates(euler: list[float], omega: list[float]) -> list[float]:
    """ZYX Euler-angle rates from the body angular rate, Θ̇ = T(Θ) ω_b (Fossen 2021, eq. 2.41;
    the inverse of the first half of :func:`euler_rates_to_body`, singular at pitch ±90°).

    Parameters
    ----------
    euler : list of float
        [φ, θ, ψ] [rad].
    omega : list of float
        Body angular rate [p, q, r] [rad/s].

    Returns
    -------
    list of float
        [φ̇, θ̇, ψ̇] [rad/s].
    """
    f, t = euler[0], euler[1]
    p, q, r = omega
    cf, sf, ct, tt = math.cos(f), math.sin(f), math.cos(t), math.tan(t)
    return [p + (q * sf + r * cf) * tt, q * cf - r * sf, (q * sf + r * cf) / ct]


def attitude_kinematics(euler: list[float], euler_dot: list[float], euler_ddot: list[float]) -> tuple[np.ndarray, list[float], list[float]]:
    """R_nb, ω_b and α_b in one pass (shares the trigonometry of :func:`rot_nb` and
    :func:`euler_rates_to_body`; used on the FMU hot path, checked against both in the tests).

    Parameters
    ----------
    euler, euler_dot, euler_ddot : list of float
        [φ, θ, ψ] [rad], rates [rad/s], accelerations [rad/s²].

    Returns
    -------
    tuple
        (R_nb (3, 3), ω_b [rad/s] as 3 floats, α_b [rad/s²] as 3 floats).
    """
    f, t, y = euler
    fd, td, pd = euler_dot
    fdd, tdd, pdd = euler_ddot
    cf, sf = math.cos(f), math.sin(f)
    ct, st = math.cos(t), math.sin(t)
    cp, sp = math.cos(y), math.sin(y)
    rot = np.array(
        [
            [cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf],
            [sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf],
            [-st, ct * sf, ct * cf],
        ]
    )
    w = [fd - pd * st, td * cf + pd * ct * sf, -td * sf + pd * ct * cf]
    a = [
        fdd - pdd * st - pd * td * ct,
        tdd * cf - td * fd * sf + pdd * ct * sf - pd * td * st * sf + pd * fd * ct * cf,
        -tdd * sf - td * fd * cf + pdd * ct * cf - pd * td * st * cf - pd * fd * ct * sf,
    ]
    return rot, w, a


def rigid_point_operator(w: list[float], a: list[float]) -> np.ndarray:
    """(9, 3) stacked operator [I; [ω×]; [α×] + [ω×]²] acting on body lever arms.

    ``arms @ op.T`` gives, per arm l, the body-frame offset l, velocity ω × l and
    acceleration α × l + ω × (ω × l) in one product.
    """
    wx, wy, wz = w
    ax, ay, az = a
    return np.array(
        [
            [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0],
            [0.0, -wz, wy], [wz, 0.0, -wx], [-wy, wx, 0.0],
            [-wy * wy - wz * wz, wx * wy - az, wx * wz + ay],
            [wx * wy + az, -wx * wx - wz * wz, wy * wz - ax],
            [wx * wz - ay, wy * wz + ax, -wx * wx - wy * wy],
        ]
    )


def specific_force(rot: np.ndarray, acc_n: np.ndarray) -> np.ndarray:
    """Specific force in the body frame, f_b = R_nbᵀ (a_n − g_n) [m/s²]."""
    return rot.T @ (acc_n - GRAVITY_N)


def cross3(a: Any, b: Any) -> np.ndarray:
    """a × b of two 3-vectors. Written out for the per-step hot path: ``np.cross`` spends about
    40 µs per call on axis handling (measured: a fifth of GnssAccFusion's step); a test checks
    it against ``np.cross``."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


# --- Unit quaternions q = [w, x, y, z] (scalar first, Hamilton product) representing R_nb --------
# v_n = q ⊗ [0, v_b] ⊗ q*. Hand-written for the per-step hot path (scipy's Rotation costs tens of
# µs per call); the tests check every function against scipy.spatial.transform.Rotation.


def floats(v: Any) -> Any:
    """The entries of a 1-D array as Python floats (a list), anything else as it is: the
    hand-written functions below do their arithmetic on them, which on numpy scalars costs
    about three times as much (the same IEEE operations, so the same results)."""
    return v.tolist() if isinstance(v, np.ndarray) else v


def quat_mul(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton product p ⊗ q of quaternions [w, x, y, z] (paper 000, eq. 4)."""
    pw, px, py, pz = floats(p)
    qw, qx, qy, qz = floats(q)
    return np.array([
        pw * qw - px * qx - py * qy - pz * qz,
        pw * qx + px * qw + py * qz - pz * qy,
        pw * qy - px * qz + py * qw + pz * qx,
        pw * qz + px * qy - py * qx + pz * qw,
    ])


def quat_from_rotvec(v: np.ndarray) -> np.ndarray:
    """Exact unit quaternion of the rotation vector ``v`` [rad]: [cos(|v|/2), sin(|v|/2) v/|v|].

    Uses the Taylor series of sin(x/2)/x below |v| = 1e-4 rad so that tiny rotations keep
    full precision.
    """
    vx, vy, vz = floats(v)
    s, c = half_angle_coefficients(vx * vx + vy * vy + vz * vz)
    return np.array([c, s * vx, s * vy, s * vz])


def half_angle_coefficients(a2: float) -> tuple[float, float]:
    """(sin(|v|/2)/|v|, cos(|v|/2)) from a2 = |v|² [rad²], the coefficients of the unit
    quaternion of a rotation vector v; their Taylor series below |v| = 1e-4 rad."""
    if a2 < 1e-8:
        return 0.5 - a2 / 48.0, 1.0 - a2 / 8.0 + a2 * a2 / 384.0
    a = math.sqrt(a2)
    return math.sin(0.5 * a) / a, math.cos(0.5 * a)


def quat_to_rot(q: np.ndarray) -> np.ndarray:
    """R_nb of the unit quaternion ``q`` (the transpose of C_e in paper 000, eq. 8)."""
    w, x, y, z = floats(q)
    return np.array([
        [w * w + x * x - y * y - z * z, 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), w * w - x * x + y * y - z * z, 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), w * w - x * x - y * y + z * z],
    ])


def quat_to_euler(q: np.ndarray) -> tuple[float, float, float]:
    """ZYX Euler angles (roll, pitch, yaw) [rad] of ``q`` (paper 000, eq. 9).

    The extracted text of eq. 9 has a sign slip in the yaw denominator
    (q0² + q1² + q2² − q3²); the correct ZYX form, used here, is q0² + q1² − q2² − q3².
    """
    w, x, y, z = floats(q)
    roll = math.atan2(2.0 * (y * z + w * x), w * w - x * x - y * y + z * z)
    pitch = -math.asin(max(-1.0, min(1.0, 2.0 * (x * z - w * y))))
    yaw = math.atan2(2.0 * (x * y + w * z), w * w + x * x - y * y - z * z)
    return roll, pitch, yaw


def euler_to_quat(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Unit quaternion of R_nb = Rz(ψ) Ry(θ) Rx(φ)."""
    cr, sr = math.cos(0.5 * roll), math.sin(0.5 * roll)
    cp, sp = math.cos(0.5 * pitch), math.sin(0.5 * pitch)
    cy, sy = math.cos(0.5 * yaw), math.sin(0.5 * yaw)
    return np.array([
        cy * cp * cr + sy * sp * sr,
        cy * cp * sr - sy * sp * cr,
        cy * sp * cr + sy * cp * sr,
        sy * cp * cr - cy * sp * sr,
    ])


def level_angles(f_b: np.ndarray) -> tuple[float, float]:
    """Roll and pitch [rad] that make the specific force ``f_b`` [m/s², b] point straight up
    (f_b = R_nbᵀ(−g_n) for a sensor at rest): φ = atan2(−f_y, −f_z), θ = atan2(f_x, √(f_y² + f_z²))."""
    fx, fy, fz = f_b
    return math.atan2(-fy, -fz), math.atan2(fx, math.hypot(fy, fz))


def nav_tilt(rot: np.ndarray) -> np.ndarray:
    """The tilt of the attitude R_nb about the north and east axes [rad]: the horizontal part
    of the rotation vector of R_nb·R_z(ψ)ᵀ, the attitude with its yaw ψ taken off (to first
    order roll and pitch turned into NED by the heading). A small rotation of the attitude,
    R_nb → exp([ε]×)·R_nb, moves it by (ε_N, ε_E) to second order in the angles (the wave tilt
    of :class:`~marinefmu.estimators.gnss_fusion.wave_coast.WaveCoast`).

    Examples
    --------
    >>> [round(float(v), 12) for v in nav_tilt(rot_nb(0.01, 0.0, math.pi / 2))]
    [0.0, 0.01]
    """
    yaw = math.atan2(rot[1, 0], rot[0, 0])
    c, s = math.cos(yaw), math.sin(yaw)
    rel = rot @ np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
    # once per coast band step (20 Hz), not per sample: scipy's Rotation is cheap enough here
    return Rotation.from_matrix(rel).as_rotvec()[:2]
