"""The paper examples by name, for ``marinefmu example NAME``: each entry runs one example,
writes its plot into a folder and returns the figures worth printing."""
from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np


def _sdof(out: Path) -> dict:
    from . import paper000_sdof

    r = paper000_sdof.run(out=out)
    return {"max displacement error [% of peak]": r["max_error_pct"]}


def _semisub(out: Path, noise: bool) -> dict:
    from . import paper000_semisub

    r = paper000_semisub.run(noise=noise, out=out)
    return {"roll/pitch/yaw RMS error [deg]": r["attitude_rms_deg"], "COG RMS error N/E/D [% of std]": r["cog_rms_pct"]}


def _fig7(out: Path) -> dict:
    from . import paper001

    r = paper001.horizontal(out=out)
    return {f"{rate:g} Hz GNSS: {key} [cm]": 100 * r[rate][key] for rate in r for key in ("fused", "gnss")}


def _tilting(out: Path) -> dict:
    from . import paper001

    return {f"{k} RMS error N/E/D [cm]": 100 * v for k, v in paper001.tilting().items()}


def _buoy(out: Path) -> dict:
    from . import paper001

    return paper001.buoy()


def _faults(out: Path) -> dict:
    from . import paper001

    return paper001.faults()


def _dropout(out: Path) -> dict:
    from . import paper001

    r = paper001.dropout_trace(out=out)
    return {"max error in the gap N/E/D, real time [cm]": 100 * r["max_error_m"],
            "max error in the gap N/E/D, RTS-smoothed [cm]": 100 * r["max_error_smoothed_m"],
            "largest error / pos_std N/E/D": r["max_z"]}


def _cr_convergence(out: Path) -> dict:
    from . import paper002

    r = paper002.convergence()
    return {f"{name} CR error x/y/z [m]": r[name]["error"] for name in paper002.SENSORS} | {
        "floor of the record x/y/z [m]": r["bridge"]["floor"], "bridge - aft CR x/y/z [m]": r["agreement"]["final"]}


def _cr_weak(out: Path) -> dict:
    from . import paper002

    r = paper002.weak_translation()
    return {f"{name} CR error x/y/z [m]": r[name]["error"] for name in paper002.SENSORS}


def _cr_angles(out: Path) -> dict:
    from . import paper002

    r = paper002.angle_errors()
    out.mkdir(parents=True, exist_ok=True)
    paper002.plot(r, out / "paper002_angle_errors.png")
    return {f"{label} ({rms:.2f} deg RMS): CR shift x/y/z [m]": np.array(shift) for label, rms, *shift in r["rows"]}


def _heave(out: Path) -> dict:
    from . import paper003

    r = paper003.compare()
    out.mkdir(parents=True, exist_ok=True)
    paper003.plot(r, out / "paper003_heave.png")
    figures = {f"{label} RMS error IMU/point [cm]": 100 * np.array([run["rms_imu"], run["rms_point"]])
               for label, run in r["runs"].items()}
    figures["band delayed heave RMS error [cm]"] = 100 * r["runs"]["band"]["rms_delayed"]
    figures["wiener delayed heave RMS error [cm]"] = 100 * r["runs"]["wiener"]["rms_delayed"]
    figures["heave std IMU/point [cm]"] = 100 * np.array([r["std_imu"], r["std_point"]])
    return figures


#: name → (description, runner(out folder) → printable figures)
EXAMPLES: dict[str, tuple[str, Callable[[Path], dict]]] = {
    "paper000-sdof": ("Paper 000 §4: SDOF Cummins model, decomposition and drift-free reconstruction", _sdof),
    "paper000-semisub": ("Paper 000 §5: semi-submersible 6-DOF tracking, noise-free gyro-only attitude",
                         lambda out: _semisub(out, False)),
    "paper000-semisub-noise": ("Paper 000 §5 with default MEMS noise: aided + refined attitude",
                               lambda out: _semisub(out, True)),
    "paper001-fig7": ("Paper 001 Fig. 7: GNSS at 10/5/2/1 Hz fused with 100 Hz acceleration (plot)", _fig7),
    "paper001-tilting": ("Paper 001 Fig. 11: errors with and without attitude correction", _tilting),
    "paper001-buoy": ("Paper 001 §4.3: buoy-like case, vertical error from attitude", _buoy),
    "paper001-faults": ("Paper 001 robustness: 20 m GNSS jump and 30 s dropout at 1 Hz", _faults),
    "paper001-dropout": ("Paper 001: COG error through the hardest 30 s GNSS dropout at 1 Hz (seed 27), real time "
                         "with ±2 pos_std and RTS-smoothed (plot)", _dropout),
    "paper002-convergence": ("Paper 002: CR of two sensors against known truth (10 min, MEMS noise)", _cr_convergence),
    "paper002-weak-translation": ("Paper 002: CR with weak translations (small floor), against truth", _cr_weak),
    "paper002-angle-errors": ("Paper 002's z discrepancy: CR shift from roll/pitch errors and the high-pass angles (plot)", _cr_angles),
    "paper003-heave": ("Paper 003: real-time and delayed heave at the IMU and a bow point vs truth, the paper's modes "
                       "and high-pass integration, Hs 2.5 m Tp 9 s, 12 min (plot)", _heave),
}


def format_value(value) -> str:
    """Compact text for a scalar or a small array."""
    if isinstance(value, np.ndarray):
        return " / ".join(f"{v:.4g}" for v in value.ravel())
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)
