"""Frame conventions shared by the whole project (see DESIGN.md).

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

import numpy as np

#: Standard gravity [m/s²] (ISO 80000-3), used for g_n = [0, 0, G].
G = 9.80665
#: Gravity vector in NED [m/s²].
GRAVITY_N = np.array([0.0, 0.0, G])


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
    cf, sf = math.cos(roll), math.sin(roll)
    ct, st = math.cos(pitch), math.sin(pitch)
    cp, sp = math.cos(yaw), math.sin(yaw)
    return np.array(
        [
            [cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf],
            [sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf],
            [-st, ct * sf, ct * cf],
        ]
    )


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
