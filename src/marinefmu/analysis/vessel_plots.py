"""Plots and a printed summary of a simulation result (matplotlib, Agg backend)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def vessel_components(result: np.ndarray) -> list[str]:
    """Names of the components in ``result`` that look like VesselMotion (they have truth.wave)."""
    return [n[: -len(".truth.wave")] for n in result.dtype.names if n.endswith(".truth.wave")]


def vessel_summary(result: np.ndarray, comp: str) -> dict[str, float]:
    """Key statistics of a VesselMotion component's recorded outputs.

    Returns
    -------
    dict
        ``hs_realised`` [m] (4·std of the wave elevation), standard deviations of COG heave
        [m], roll and pitch [deg], point heave [m], RMS IMU errors (measured − true specific
        force [m/s²], rate [rad/s]) and the fraction of time the GNSS fix is valid.
    """
    def g(name: str) -> np.ndarray:
        return np.asarray(result[f"{comp}.{name}"], dtype=float)

    acc_err = np.stack([g(f"imu.acc.{a}") - g(f"truth.imu_f.{a}") for a in "xyz"])
    gyro_err = np.stack([g(f"imu.gyro.{a}") - g(f"truth.rate.{a}") for a in "xyz"])
    return {
        "hs_realised_m": 4.0 * float(np.std(g("truth.wave"))),
        "heave_std_m": float(np.std(g("truth.cog.d"))),
        "roll_std_deg": math.degrees(float(np.std(g("truth.roll")))),
        "pitch_std_deg": math.degrees(float(np.std(g("truth.pitch")))),
        "point_heave_std_m": float(np.std(g("truth.point.d"))),
        "imu_acc_error_rms_mps2": float(np.sqrt(np.mean(acc_err**2))),
        "imu_gyro_error_rms_radps": float(np.sqrt(np.mean(gyro_err**2))),
        "gnss_valid_fraction": float(np.mean(np.asarray(result[f"{comp}.gnss.valid"], dtype=float))),
    }


def plot_vessel(result: np.ndarray, comp: str, out_dir: str | Path) -> list[Path]:
    """Write PNG plots of a VesselMotion component: motions, IMU vs truth, GNSS, monitoring point."""
    plt = pyplot()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t = result["time"]

    def g(name: str) -> np.ndarray:
        return np.asarray(result[f"{comp}.{name}"], dtype=float)

    paths = []
    fig, ax = plt.subplots(4, 1, figsize=(10, 9), sharex=True)
    ax[0].plot(t, g("truth.wave"), lw=0.8)
    ax[0].set_ylabel("wave η [m, up]")
    ax[1].plot(t, g("truth.cog.d"), lw=0.8, label="COG")
    point = g("truth.point.d")
    ax[1].plot(t, point - point.mean(), lw=0.8, label="monitoring point (about its mean)")
    ax[1].set_ylabel("heave [m, down]")
    ax[1].legend(loc="upper right")
    for name, lab in (("roll", "roll"), ("pitch", "pitch"), ("yaw", "yaw")):
        ax[2].plot(t, np.degrees(g(f"truth.{name}")), lw=0.8, label=lab)
    ax[2].set_ylabel("angle [deg]")
    ax[2].legend(loc="upper right")
    for a in "ned":
        ax[3].plot(t, g(f"truth.cog.{a}"), lw=0.8, label=a)
    ax[3].set_ylabel("COG position [m]")
    ax[3].set_xlabel("time [s]")
    ax[3].legend(loc="upper right")
    fig.suptitle(f"{comp}: true motion")
    paths.append(_save(fig, out / f"{comp}_motion.png"))

    fig, ax = plt.subplots(3, 2, figsize=(12, 8), sharex=True)
    for i, a in enumerate("xyz"):
        ax[i, 0].plot(t, g(f"imu.acc.{a}"), lw=0.6, label="measured")
        ax[i, 0].plot(t, g(f"truth.imu_f.{a}"), lw=0.8, label="truth")
        ax[i, 0].set_ylabel(f"f_{a} [m/s²]")
        ax[i, 1].plot(t, g(f"imu.gyro.{a}"), lw=0.6, label="measured")
        ax[i, 1].plot(t, g(f"truth.rate.{a}"), lw=0.8, label="truth")
        ax[i, 1].set_ylabel(f"ω_{a} [rad/s]")
    ax[0, 0].legend(loc="upper right")
    ax[2, 0].set_xlabel("time [s]")
    ax[2, 1].set_xlabel("time [s]")
    fig.suptitle(f"{comp}: IMU specific force and angular rate (body frame)")
    paths.append(_save(fig, out / f"{comp}_imu.png"))

    fig, ax = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    for i in range(1, 5):
        ax[0].plot(t, g(f"gnss.ant{i}.d"), lw=0.8, label=f"antenna {i}")
    ax[0].set_ylabel("GNSS down [m]")
    ax[0].legend(loc="upper right")
    ax[1].step(t, g("gnss.valid"), where="post")
    ax[1].set_ylabel("gnss.valid")
    ax[1].set_xlabel("time [s]")
    fig.suptitle(f"{comp}: GNSS antenna positions (NED)")
    paths.append(_save(fig, out / f"{comp}_gnss.png"))
    return paths


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return path
