"""Conversion of mapped columns into the project's conventions (the mapping's module doc).

Pure numpy on whole blocks of rows: raw column values in, SI values in NED/FRD out, with
specific force and heave positive down.
"""
from __future__ import annotations

import numpy as np

from .mapping import G, Mapping
from .schema import GROUP

#: Record world axes → NED (rows: n, e, d from the record's own axis order).
_ENU_TO_NED = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]])   # (e, n, u) → (n, e, d)
_FLU_TO_FRD = np.diag([1.0, -1.0, -1.0])


def euler_matrix(roll: np.ndarray, pitch: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """(N, 3, 3) R = Rz(yaw) Ry(pitch) Rx(roll) of ZYX Euler angles [rad]."""
    cr, sr, cp, sp, cy, sy = np.cos(roll), np.sin(roll), np.cos(pitch), np.sin(pitch), np.cos(yaw), np.sin(yaw)
    return np.stack([
        np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], -1),
        np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], -1),
        np.stack([-sp, cp * sr, cp * cr], -1),
    ], -2)


def matrix_euler(r: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ZYX Euler angles (roll, pitch, yaw) [rad] of (N, 3, 3) rotation matrices."""
    return (np.arctan2(r[:, 2, 1], r[:, 2, 2]), -np.arcsin(np.clip(r[:, 2, 0], -1.0, 1.0)),
            np.arctan2(r[:, 1, 0], r[:, 0, 0]))


def world_to_ned(v: np.ndarray, world: str) -> np.ndarray:
    """(N, 3) vectors in the record's world axes (its own axis order) → NED."""
    return v if world == "ned" else v @ _ENU_TO_NED.T


def body_to_frd(v: np.ndarray, body: str) -> np.ndarray:
    """(N, 3) vectors in the record's body axes → FRD."""
    return v if body == "frd" else v * np.array([1.0, -1.0, -1.0])


def angles_to_ned_frd(roll: np.ndarray | None, pitch: np.ndarray | None, yaw: np.ndarray | None,
                      world: str, body: str) -> tuple[np.ndarray | None, np.ndarray | None, np.ndarray | None]:
    """ZYX Euler angles of the record's body in its world axes → of FRD in NED [rad].

    ``enu``/``flu`` (the usual z-up pair) has a closed form (roll kept, pitch negated, yaw →
    π/2 − yaw) that converts each angle alone; any other mix goes through R_nb = A R_rec B and
    needs all three angles (checked by the mapping)."""
    if (world, body) == ("ned", "frd"):
        return roll, pitch, yaw
    if (world, body) == ("enu", "flu"):
        return (roll, None if pitch is None else -pitch,
                None if yaw is None else np.angle(np.exp(1j * (0.5 * np.pi - yaw))))
    a = np.eye(3) if world == "ned" else _ENU_TO_NED
    b = np.eye(3) if body == "frd" else _FLU_TO_FRD
    return matrix_euler(a @ euler_matrix(roll, pitch, yaw) @ b)


def gravity_to_specific_force(acc: np.ndarray, roll: np.ndarray, pitch: np.ndarray) -> np.ndarray:
    """Body-axis acceleration without gravity a_b (FRD) → specific force f_b = a_b − R_nbᵀ g_n,
    g_n = [0, 0, g]: ``R_nbᵀ g_n = g [−sin θ, sin φ cos θ, cos φ cos θ]`` (yaw drops out)."""
    cp = np.cos(pitch)
    g_b = G * np.column_stack([-np.sin(pitch), np.sin(roll) * cp, np.cos(roll) * cp])
    return acc - g_b


def convert(mapping: Mapping, raw: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """SI values in the project's frames of every mapped group.

    Parameters
    ----------
    mapping : Mapping
        The sidecar.
    raw : dict of str to numpy.ndarray
        Column name → (N,) raw values (NaN where missing).

    Returns
    -------
    dict of str to numpy.ndarray
        Group name → (N, channels) values, channels in the order of
        :data:`~.schema.GROUPS`' outputs (NED, FRD, SI, radians). A compass ``heading`` is
        taken as a heading (from north, clockwise) whatever the record's frames.
    """
    out: dict[str, np.ndarray] = {}
    for name, chans in mapping.channels.items():
        v = np.column_stack([(raw[c.column] * c.scale + c.offset) * c.factor for c in chans])
        frame = GROUP[name].frame
        if frame == "body":
            v = body_to_frd(v, mapping.body)
        elif frame == "world":
            v = np.hstack([world_to_ned(v[:, i:i + 3], mapping.world) for i in range(0, v.shape[1], 3)])
        elif frame == "heave" and mapping.heave == "up":
            v = -v
        out[name] = v
    angles = [out.get(k) for k in ("ref.roll", "ref.pitch", "ref.yaw")]
    if any(a is not None for a in angles) and (mapping.world, mapping.body) != ("ned", "frd"):
        conv = angles_to_ned_frd(*(None if a is None else a[:, 0] for a in angles), mapping.world, mapping.body)
        for k, a in zip(("ref.roll", "ref.pitch", "ref.yaw"), conv):
            if a is not None and k in out:
                out[k] = a[:, None]
    if mapping.acc == "gravity_removed":
        roll, pitch = out["ref.roll"][:, 0], out["ref.pitch"][:, 0]
        for k in ("imu.acc", "ref.imu_f"):
            if k in out:
                out[k] = gravity_to_specific_force(out[k], roll, pitch)
    return out
