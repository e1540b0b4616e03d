"""A peer library side by side: smsfusion (4Subsea's marine sensor-fusion library, PyPI) on the
same sensor records as marinefmu's estimators.

:func:`vru_roll_pitch` runs ``smsfusion.VRU`` (a multiplicative extended Kalman filter with
zero-velocity pseudo-aiding, its vertical reference unit) told the same IMU noise as
VesselMotion generates. Conventions agree with ours: NED navigation frame, body x forward,
y starboard, z down, specific force (at rest f = [0, 0, −g]). ``VRU.update`` corrects with the
pseudo-aiding and then projects ahead with the sample; its state after sample k is compared
with the truth at t_k (a one-sample shift measures 0.0001° worse on the ``system`` sea).


:func:`aided_ins_cog` runs ``smsfusion.AidedINS`` (the full aided INS, MEKF) aided at every
GNSS epoch by what the four antennas give: the COG position
(:func:`~marinefmu.estimators.gnss_fusion.antenna_attitude.antenna_attitude`, as its lever arm
from the IMU) and the heading; warm-started from the first epoch. Its IMU position is moved to
the COG with its own attitude, so it estimates what
:class:`~marinefmu.estimators.gnss_fusion.filter.GnssAccFusion` estimates.

:func:`compare_attitude` and :func:`compare_gnss_aided` score marinefmu and the peer on one
VesselMotion record against the truth.
"""
from __future__ import annotations

import math

import numpy as np

from ..sea.sensors import GnssParams, ImuParams


def smsfusion_module():
    try:
        import smsfusion
    except ImportError as exc:  # a bench and test dependency (pyproject [dev])
        raise ImportError("the peer comparison needs smsfusion: pip install smsfusion") from exc
    return smsfusion


def vru_roll_pitch(acc: np.ndarray, gyro: np.ndarray, dt: float, imu: ImuParams | None = None) -> np.ndarray:
    """Roll and pitch [rad] from ``smsfusion.VRU`` for (N, 3) specific force [m/s², body] and
    angular rate [rad/s, body] sampled every ``dt`` s; returns (N, 2).

    ``imu`` gives the noise the filter is told (white-noise density, bias instability and its
    correlation time); default VesselMotion's default MEMS IMU.
    """
    imu = imu or ImuParams()
    vru = smsfusion_module().VRU(fs=1.0 / dt, err_acc={"N": imu.acc_noise, "B": imu.acc_bias_instability, "tau_cb": imu.bias_tau},
              err_gyro={"N": imu.gyro_noise, "B": imu.gyro_bias_instability, "tau_cb": imu.bias_tau})
    out = np.empty((len(acc), 2))
    for k in range(len(acc)):
        vru.update(acc[k], gyro[k])
        out[k] = vru.euler()[:2]
    return out


def compare_attitude(rec: dict[str, np.ndarray], dt: float, settle: float = 60.0) -> dict[str, dict[str, float]]:
    """Roll and pitch RMS errors [deg] after ``settle`` s of marinefmu's AttitudeEstimator
    (default parameters) and smsfusion's VRU on one VesselMotion record (``simulate_record``)."""
    from ..estimators.attitude.estimator import estimate_attitude
    from ..sea.motion_model import stack

    acc, gyro = stack(rec, "imu.acc"), stack(rec, "imu.gyro")
    truth = np.c_[rec["truth.roll"], rec["truth.pitch"]]
    ours = estimate_attitude(gyro, acc, dt)
    runs = {"marinefmu AttitudeEstimator": np.c_[ours["roll"], ours["pitch"]], "smsfusion VRU": vru_roll_pitch(acc, gyro, dt)}
    k0 = int(round(settle / dt))
    return {name: {a: math.degrees(float(np.sqrt(np.mean((est[k0:, i] - truth[k0:, i]) ** 2))))
                   for i, a in enumerate(("roll_deg", "pitch_deg"))} for name, est in runs.items()}


def aided_ins_cog(acc: np.ndarray, gyro: np.ndarray, gnss: np.ndarray, gnss_new: np.ndarray, dt: float,
                  antennas: np.ndarray, imu_arm: np.ndarray, imu: ImuParams | None = None,
                  receiver: GnssParams | None = None) -> np.ndarray:
    """COG position [m, NED] from ``smsfusion.AidedINS`` (module docstring); (N, 3), NaN before
    the first GNSS epoch.

    Parameters
    ----------
    acc, gyro : numpy.ndarray
        (N, 3) specific force [m/s²] and angular rate [rad/s], body frame.
    gnss : numpy.ndarray
        (N, 12) the four antenna positions, NED [m]; ``gnss_new`` (N,) marks the epochs.
    dt : float
        Sample interval [s].
    antennas, imu_arm : numpy.ndarray
        (4, 3) antenna and (3,) IMU positions relative to the COG, body frame [m].
    imu, receiver : optional
        Noise the filter is told (default VesselMotion's): IMU densities and bias, and the
        receiver's σ_h, σ_v (the COG from four antennas has σ/2).
    """
    from scipy.spatial.transform import Rotation

    from ..estimators.gnss_fusion.antenna_attitude import antenna_attitude

    imu, receiver = imu or ImuParams(), receiver or GnssParams()
    arms, arm = np.asarray(antennas, dtype=float), np.asarray(imu_arm, dtype=float)
    pos_var = np.array([receiver.sigma_h, receiver.sigma_h, receiver.sigma_v]) ** 2 / len(arms)
    out = np.full((len(acc), 3), np.nan)
    epochs = np.flatnonzero(gnss_new)
    fixes = {int(k): antenna_attitude(gnss[k], arms) for k in epochs}
    fixes = {k: f for k, f in fixes.items() if not isinstance(f, str)}
    if not fixes:
        return out
    first = min(fixes)
    x0 = np.zeros(16)
    x0[:3] = fixes[first].cog + fixes[first].rot @ arm
    x0[6:10] = Rotation.from_matrix(fixes[first].rot).as_quat(scalar_first=True)
    ins = smsfusion_module().AidedINS(fs=1.0 / dt, x0_prior=x0, P0_prior=np.diag([1e-2] * 6 + [1e-4] * 3 + [1e-8] * 3),
                   err_acc={"N": imu.acc_noise, "B": imu.acc_bias_instability, "tau_cb": imu.bias_tau},
                   err_gyro={"N": imu.gyro_noise, "B": imu.gyro_bias_instability, "tau_cb": imu.bias_tau},
                   lever_arm=-arm, cold_start=False)
    head_var = (max(receiver.sigma_h, 1e-4) / float(np.ptp(arms[:, 0]) or 1.0)) ** 2   # [rad²] over the baseline
    for k in range(first, len(acc)):
        fix = fixes.get(k)
        if fix is None:
            ins.update(acc[k], gyro[k])
        else:
            yaw = Rotation.from_matrix(fix.rot).as_euler("ZYX")[0]
            ins.update(acc[k], gyro[k], pos=fix.cog, pos_var=pos_var, head=yaw, head_var=head_var, head_degrees=False)
        r = Rotation.from_euler("ZYX", ins.euler()[::-1]).as_matrix()
        out[k] = ins.position() - r @ arm
    return out


def compare_gnss_aided(rec: dict[str, np.ndarray], dt: float, imu_arm: tuple[float, float, float],
                       fusion: dict | None = None, settle: float = 60.0) -> dict[str, dict[str, float]]:
    """COG RMS errors [cm] per NED axis after ``settle`` s of marinefmu's GnssAccFusion
    (``fusion``: GnssAccFusionParams overrides) and smsfusion's AidedINS on one VesselMotion record
    with VesselMotion's default antennas."""
    from dataclasses import replace

    from ..estimators.gnss_fusion.antenna_attitude import DEFAULT_ANTENNAS
    from ..estimators.gnss_fusion.runs import fuse
    from ..estimators.gnss_fusion.filter import GnssAccFusionParams
    from ..sea.motion_model import stack

    acc, gyro = stack(rec, "imu.acc"), stack(rec, "imu.gyro")
    gnss = np.hstack([stack(rec, f"gnss.ant{i}", "ned") for i in range(1, 5)])
    truth = stack(rec, "truth.cog", "ned")
    params = replace(GnssAccFusionParams(antennas=DEFAULT_ANTENNAS, acc_lever_arm=imu_arm), **(fusion or {}))
    runs = {"marinefmu GnssAccFusion": fuse(acc, dt, gnss, rec["gnss.new"], gyro, params)["pos"],
            "smsfusion AidedINS": aided_ins_cog(acc, gyro, gnss, rec["gnss.new"], dt, np.array(DEFAULT_ANTENNAS),
                                                np.array(imu_arm))}
    k0 = int(round(settle / dt))
    return {name: {f"pos_{a}_cm": 100.0 * float(np.sqrt(np.mean((est[k0:, i] - truth[k0:, i]) ** 2)))
                   for i, a in enumerate("ned")} for name, est in runs.items()}


def system_sea(hs: float, tp: float, duration: float, dt: float = 0.01) -> tuple[dict[str, np.ndarray], tuple, dict]:
    """A VesselMotion record of the ``system`` scenario's vessel, IMU and GNSS in another sea.

    Returns
    -------
    tuple
        The record (``simulate_record``), the IMU position relative to the COG (body frame [m])
        and the scenario's GnssAccFusion overrides (``r``, ``q``, ``q_down``, ``noise_sizing``) for :func:`compare_gnss_aided`.
    """
    from ..cosim.scenarios import load_scenario
    from ..sea.motion_model import VesselMotionParams, simulate_record

    system = load_scenario("system").system
    flat = {**system.component("vessel").parameters, "sea.hs": hs, "sea.tp": tp}
    imu = tuple(float(flat[f"imu.{a}"]) for a in "xyz")
    fusion = {k: system.component("fusion").parameters[k] for k in ("r", "q", "q_down", "noise_sizing")}
    return simulate_record(VesselMotionParams.from_flat(flat), duration, dt), imu, fusion
