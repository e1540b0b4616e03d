"""Paper 002's centre-of-rotation estimator checked against known truth, and its failure
re-created.

VesselMotion in the independent-rotation mode (``vessel.mode = 1``): the research36 hull
(Simon Stevin-like, LOA 36 m), Hs 1.5 m, Tp 6 s, waves 45° off the bow, rotations about the
CR (3, 0, −1.5) m (relative to the COG) independent of its translation, default MEMS noise.

* :func:`convergence`: two sensors, on the bridge wing and aft low, 10 minutes each; error of
  each CR estimate against the truth, the record's floor (:func:`offset_floor`), and the
  agreement between the sensors.
* :func:`weak_translation`: the same with the translational RAOs scaled by 0.05, where the
  floor is small and the filter has to converge to the truth itself.
* :func:`angle_errors`: the paper's two-sensor discrepancy in z. One sensor gets a roll/pitch
  error of 0.1-1° RMS of three kinds (a constant misalignment, an error proportional to the
  angle, the high-pass angle method at several cutoffs); the shift of its CR estimate is
  compared with the error-free run of the same sensor. :func:`angle_errors` also runs the
  remedy: the drift-corrected :class:`~marinefmu.estimators.attitude.estimator.AttitudeEstimator` as the
  angle input.
"""
from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from ..estimators.attitude.estimator import estimate_attitude
from ..estimators.centre_of_rotation.filter import (
    CentreOfRotationParams, estimate_centre_of_rotation, lever_matrix, offset_floor,
)
from ..frames import rot_nb
from ..sea.motion_model import VesselMotionParams, simulate_record, stack
from ..sea.vessel import preset_raos, save_rao_csv

DT = 0.01
DURATION = 600.0
CR = (3.0, 0.0, -1.5)
SENSORS = {"bridge": (8.0, 2.0, -4.0), "aft": (-10.0, -3.0, -8.0)}
SEA = {"sea.hs": 1.5, "sea.tp": 6.0, "sea.heading": 0.75 * math.pi, "vessel.preset": "research36",
       "vessel.mode": 1, "vessel.cr.x": CR[0], "vessel.cr.y": CR[1], "vessel.cr.z": CR[2]}
#: Cutoffs of the high-pass angle method compared in :func:`angle_errors` [Hz].
HP_CUTOFFS = (0.002, 0.005, 0.02, 0.05)
#: RMS angle errors of the injected misalignment and proportional errors [deg].
ANGLE_ERRORS_DEG = (0.1, 0.3, 1.0)


def record(sensor: tuple[float, float, float], seed: int = 7, duration: float = DURATION,
           extra: dict | None = None) -> dict[str, np.ndarray]:
    """VesselMotion record (every output by name) with the IMU at ``sensor`` [m, b, rel. COG]."""
    flat = {**SEA, "sea.seed": seed, "imu.x": sensor[0], "imu.y": sensor[1], "imu.z": sensor[2], **(extra or {})}
    return simulate_record(VesselMotionParams.from_flat(flat), duration, DT)


def truth_floor(rec: dict, sensor: tuple[float, float, float]) -> np.ndarray:
    """:func:`offset_floor` of a record, from its exact CR acceleration [m, b]."""
    rot = np.array([rot_nb(*e) for e in stack(rec, "truth", ("roll", "pitch", "yaw"))])
    w, a = stack(rec, "truth.rate"), stack(rec, "truth.ang_acc")
    arm = np.asarray(sensor) - stack(rec, "truth.cr")[0]
    lever = np.array([lever_matrix(wk, ak) @ arm for wk, ak in zip(w, a)])
    acc_cr = stack(rec, "truth.imu_acc", "ned") - np.einsum("kij,kj->ki", rot, lever)
    return offset_floor(acc_cr, rot, w, a)


def estimate(rec: dict, sensor: tuple[float, float, float], euler: np.ndarray | None = None,
             **params) -> dict[str, np.ndarray]:
    """Run the estimator on a record (``euler`` given: ``angles="input"``)."""
    p = CentreOfRotationParams(sensor=sensor, angles="input" if euler is not None else "gyro_hp", **params)
    return estimate_centre_of_rotation(stack(rec, "imu.acc"), stack(rec, "imu.gyro"), DT, p, euler)


def convergence(seed: int = 7, extra: dict | None = None, duration: float = DURATION) -> dict[str, dict]:
    """Per sensor: ``error`` (final offset estimate − truth), ``mean_error`` (settled mean −
    truth), ``floor`` and ``std`` [m, b]; plus ``agreement``: CR(bridge) − CR(aft) for the final
    and the mean estimates."""
    out: dict[str, dict] = {}
    cr = {}
    for name, sensor in SENSORS.items():
        rec = record(sensor, seed, duration, extra)
        r = estimate(rec, sensor)
        truth = stack(rec, "truth.cr")[-1]
        final = r["offset"][-1] + sensor
        out[name] = {"error": final - truth, "mean_error": r["cr"][-1] - truth,
                     "floor": truth_floor(rec, sensor), "std": r["offset_std"][-1]}
        cr[name] = (final, r["cr"][-1])
    out["agreement"] = {"final": cr["bridge"][0] - cr["aft"][0], "mean": cr["bridge"][1] - cr["aft"][1]}
    return out


def weak_translation(seed: int = 7, scale: float = 0.05, duration: float = DURATION) -> dict[str, dict]:
    """:func:`convergence` with the hull's surge, sway and heave RAOs multiplied by ``scale``."""
    table = preset_raos("research36")
    rao = table.rao.copy()
    rao[0:3] *= scale
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "weak_translation.csv"
        save_rao_csv(type(table)(table.omega, table.heading, rao, "weak_translation"), path)
        return convergence(seed, {"vessel.rao_file": str(path)}, duration)


def angle_errors(seed: int = 7, sensor: str = "bridge", duration: float = DURATION) -> dict[str, list]:
    """CR shift [m] of one sensor caused by its angle errors (each row: label, RMS roll/pitch
    error [deg], CR shift x, y, z against the same sensor with exact angles)."""
    arm = SENSORS[sensor]
    rec = record(arm, seed, duration)
    euler = stack(rec, "truth", ("roll", "pitch", "yaw"))
    ref = estimate(rec, arm, euler)["offset"][-1]
    rows: list[tuple] = []

    def add(label: str, angles: np.ndarray | None, **params) -> None:
        r = estimate(rec, arm, angles, **params)
        k = np.arange(len(euler))
        at = k - np.round(r["delay"] / DT).astype(int)       # the sample each row refers to
        ok = r["valid"] & (at >= 0)
        used = r["euler"][ok, :2] - euler[at[ok], :2]
        rms = math.degrees(float(np.sqrt(np.mean(used[len(used) // 10:] ** 2))))
        rows.append((label, rms, *(r["offset"][-1] - ref)))

    for e in ANGLE_ERRORS_DEG:
        add(f"misaligned {e}°", euler + np.radians([e, e, 0.0]))
    scale = {ax: float(np.std(euler[:, ax])) for ax in (0, 1)}
    for e in ANGLE_ERRORS_DEG:
        k = np.array([math.radians(e) / scale[0], math.radians(e) / scale[1], 0.0])
        add(f"proportional {e}°", euler * (1.0 + k))
    for fc in HP_CUTOFFS:
        add(f"high-pass {fc} Hz", None, hp_cutoff=fc)
    att = estimate_attitude(stack(rec, "imu.gyro"), stack(rec, "imu.acc"), DT)
    add("AttitudeEstimator", np.column_stack((att["roll"], att["pitch"], att["yaw"])))
    return {"rows": rows}


def plot(result: dict, path: str | Path) -> None:
    """Bar chart of the CR z shift per angle-error case (needs matplotlib)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = result["rows"]
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.barh([f"{r[0]} ({r[1]:.2f}° RMS)" for r in rows], [r[4] for r in rows], color="tab:blue")
    ax.set_xlabel("shift of the estimated CR z [m] (positive down)")
    ax.set_title("Paper 002: angle errors move the CR height (bridge sensor, 10 min)")
    ax.axvline(0.0, color="k", lw=0.5)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(out: str | Path = "results/paper002") -> dict:
    """Run all three studies, print their tables and write ``angle_errors.png``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    fmt = lambda v: "(" + ", ".join(f"{x:+.3f}" for x in v) + ")"  # noqa: E731
    results = {"convergence": convergence(), "weak_translation": weak_translation(), "angle_errors": angle_errors()}
    for study in ("convergence", "weak_translation"):
        res = results[study]
        print(f"{study}: CR error [m] (x, y, z), floor of the record, agreement between sensors")
        for name in SENSORS:
            r = res[name]
            print(f"  {name:7s} final {fmt(r['error'])}  mean {fmt(r['mean_error'])}  floor {fmt(r['floor'])}  std {fmt(r['std'])}")
        print(f"  agreement final {fmt(res['agreement']['final'])}  mean {fmt(res['agreement']['mean'])}")
    print("angle errors: CR shift of the bridge sensor [m] (x, y, z)")
    for label, rms, *shift in results["angle_errors"]["rows"]:
        print(f"  {label:24s} {rms:6.3f}° RMS  {fmt(shift)}")
    plot(results["angle_errors"], out / "angle_errors.png")
    return results


if __name__ == "__main__":
    main()
