"""A peer library side by side: smsfusion (4Subsea's marine sensor-fusion library, PyPI) on the
same sensor records as marinefmu's estimators (issue 7).

:func:`vru_roll_pitch` runs ``smsfusion.VRU`` (a multiplicative extended Kalman filter with
zero-velocity pseudo-aiding, its vertical reference unit) told the same IMU noise as
VesselMotion generates. Conventions agree with ours: NED navigation frame, body x forward,
y starboard, z down, specific force (at rest f = [0, 0, −g]). ``VRU.update`` corrects with the
pseudo-aiding and then projects ahead with the sample; its state after sample k is compared
with the truth at t_k (a one-sample shift measures 0.0001° worse on the ``system`` sea).

:func:`compare_attitude` scores it and :class:`~.estimators.attitude.AttitudeEstimator` on one
VesselMotion record against the truth.
"""
from __future__ import annotations

import math

import numpy as np

from .sea.sensors import ImuParams


def vru_roll_pitch(acc: np.ndarray, gyro: np.ndarray, dt: float, imu: ImuParams | None = None) -> np.ndarray:
    """Roll and pitch [rad] from ``smsfusion.VRU`` for (N, 3) specific force [m/s², body] and
    angular rate [rad/s, body] sampled every ``dt`` s; returns (N, 2).

    ``imu`` gives the noise the filter is told (white-noise density, bias instability and its
    correlation time); default VesselMotion's default MEMS IMU.
    """
    try:
        from smsfusion import VRU
    except ImportError as exc:  # a bench dependency (pyproject [dev])
        raise ImportError("the peer comparison needs smsfusion: pip install smsfusion") from exc
    imu = imu or ImuParams()
    vru = VRU(fs=1.0 / dt, err_acc={"N": imu.acc_noise, "B": imu.acc_bias_instability, "tau_cb": imu.bias_tau},
              err_gyro={"N": imu.gyro_noise, "B": imu.gyro_bias_instability, "tau_cb": imu.bias_tau})
    out = np.empty((len(acc), 2))
    for k in range(len(acc)):
        vru.update(acc[k], gyro[k])
        out[k] = vru.euler()[:2]
    return out


def compare_attitude(rec: dict[str, np.ndarray], dt: float, settle: float = 60.0) -> dict[str, dict[str, float]]:
    """Roll and pitch RMS errors [deg] after ``settle`` s of marinefmu's AttitudeEstimator
    (default parameters) and smsfusion's VRU on one VesselMotion record (``simulate_record``)."""
    from .estimators.attitude import estimate_attitude
    from .sea.motion_model import stack

    acc, gyro = stack(rec, "imu.acc"), stack(rec, "imu.gyro")
    truth = np.c_[rec["truth.roll"], rec["truth.pitch"]]
    ours = estimate_attitude(gyro, acc, dt)
    runs = {"marinefmu AttitudeEstimator": np.c_[ours["roll"], ours["pitch"]], "smsfusion VRU": vru_roll_pitch(acc, gyro, dt)}
    k0 = int(round(settle / dt))
    return {name: {a: math.degrees(float(np.sqrt(np.mean((est[k0:, i] - truth[k0:, i]) ** 2))))
                   for i, a in enumerate(("roll_deg", "pitch_deg"))} for name, est in runs.items()}
