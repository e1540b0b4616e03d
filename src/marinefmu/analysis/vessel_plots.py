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
    """Key statistics of a VesselMotion component's recorded outputs; a statistic whose
    outputs were not recorded is left out.

    Returns
    -------
    dict
        ``hs_realised`` [m] (4·std of the wave elevation), standard deviations of COG heave
        [m], roll and pitch [deg], point heave [m], RMS IMU errors (measured − true specific
        force [m/s²], rate [rad/s]) and the fraction of time the GNSS fix is valid.
    """
    fields = set(result.dtype.names)

    def g(name: str) -> np.ndarray:
        return np.asarray(result[f"{comp}.{name}"], dtype=float)

    def rms_diff(a: str, b: str) -> float:
        err = np.stack([g(f"{a}.{x}") - g(f"{b}.{x}") for x in "xyz"])
        return float(np.sqrt(np.mean(err ** 2)))

    stats = {
        "hs_realised_m": (("truth.wave",), lambda: 4.0 * float(np.std(g("truth.wave")))),
        "heave_std_m": (("truth.cog.d",), lambda: float(np.std(g("truth.cog.d")))),
        "roll_std_deg": (("truth.roll",), lambda: math.degrees(float(np.std(g("truth.roll"))))),
        "pitch_std_deg": (("truth.pitch",), lambda: math.degrees(float(np.std(g("truth.pitch"))))),
        "point_heave_std_m": (("truth.point.d",), lambda: float(np.std(g("truth.point.d")))),
        "imu_acc_error_rms_mps2": ((*(f"imu.acc.{x}" for x in "xyz"), *(f"truth.imu_f.{x}" for x in "xyz")),
                                   lambda: rms_diff("imu.acc", "truth.imu_f")),
        "imu_gyro_error_rms_radps": ((*(f"imu.gyro.{x}" for x in "xyz"), *(f"truth.rate.{x}" for x in "xyz")),
                                     lambda: rms_diff("imu.gyro", "truth.rate")),
        "gnss_valid_fraction": (("gnss.valid",), lambda: float(np.mean(g("gnss.valid")))),
    }
    return {k: value() for k, (names, value) in stats.items() if all(f"{comp}.{n}" in fields for n in names)}


def plot_vessel(result: np.ndarray, comp: str, out_dir: str | Path) -> list[Path]:
    """Write PNG plots of a VesselMotion component: motions, IMU vs truth, GNSS antennas. Each
    panel is drawn from what was recorded (a curve whose output is missing is left out); a plot
    with nothing recorded is not written."""
    plt = pyplot()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t = result["time"]
    fields = set(result.dtype.names)

    def has(*names: str) -> bool:
        return all(f"{comp}.{n}" in fields for n in names)

    def g(name: str) -> np.ndarray:
        return np.asarray(result[f"{comp}.{name}"], dtype=float)

    paths = []
    fig, ax = plt.subplots(4, 1, figsize=(10, 9), sharex=True)
    ax[0].plot(t, g("truth.wave"), lw=0.8)
    ax[0].set_ylabel("wave η [m, up]")
    if has("truth.cog.d"):
        ax[1].plot(t, g("truth.cog.d"), lw=0.8, label="COG")
    for name, label in (("truth.imu.d", "IMU"), ("truth.point.d", "monitoring point")):
        if has(name):
            x = g(name)
            ax[1].plot(t, x - x.mean(), lw=0.8, label=f"{label} (about its mean)")
    ax[1].set_ylabel("heave [m, down]")
    ax[1].legend(loc="upper right")
    for name in ("roll", "pitch", "yaw"):
        if has(f"truth.{name}"):
            ax[2].plot(t, np.degrees(g(f"truth.{name}")), lw=0.8, label=name)
    ax[2].set_ylabel("angle [deg]")
    ax[2].legend(loc="upper right")
    where = "cog" if has("truth.cog.n", "truth.cog.e", "truth.cog.d") else "imu"
    for a in "ned":
        if has(f"truth.{where}.{a}"):
            ax[3].plot(t, g(f"truth.{where}.{a}"), lw=0.8, label=a)
    ax[3].set_ylabel(f"{where.upper()} position [m]")
    ax[3].set_xlabel("time [s]")
    ax[3].legend(loc="upper right")
    fig.suptitle(f"{comp}: true motion")
    paths.append(_save(fig, out / f"{comp}_motion.png"))

    if has(*(f"imu.{s}.{a}" for s in ("acc", "gyro") for a in "xyz")):
        fig, ax = plt.subplots(3, 2, figsize=(12, 8), sharex=True)
        for i, a in enumerate("xyz"):
            ax[i, 0].plot(t, g(f"imu.acc.{a}"), lw=0.6, label="measured")
            ax[i, 1].plot(t, g(f"imu.gyro.{a}"), lw=0.6, label="measured")
            if has(f"truth.imu_f.{a}"):
                ax[i, 0].plot(t, g(f"truth.imu_f.{a}"), lw=0.8, label="truth")
            if has(f"truth.rate.{a}"):
                ax[i, 1].plot(t, g(f"truth.rate.{a}"), lw=0.8, label="truth")
            ax[i, 0].set_ylabel(f"f_{a} [m/s²]")
            ax[i, 1].set_ylabel(f"ω_{a} [rad/s]")
        ax[0, 0].legend(loc="upper right")
        ax[2, 0].set_xlabel("time [s]")
        ax[2, 1].set_xlabel("time [s]")
        fig.suptitle(f"{comp}: IMU specific force and angular rate (body frame)")
        paths.append(_save(fig, out / f"{comp}_imu.png"))

    antennas = [i for i in range(1, 5) if has(f"gnss.ant{i}.d")]
    if antennas or has("gnss.valid"):
        fig, ax = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
        for i in antennas:
            ax[0].plot(t, g(f"gnss.ant{i}.d"), lw=0.8, label=f"antenna {i}")
        ax[0].set_ylabel("GNSS down [m]")
        if antennas:
            ax[0].legend(loc="upper right")
        if has("gnss.valid"):
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
