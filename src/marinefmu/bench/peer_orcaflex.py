"""Someone else's data: marinefmu and smsfusion on an OrcaFlex vessel simulation.

The record (``data/peer/smsfusion_orcaflex/``; from 4Subsea's smsfusion-python repository,
``tests/testdata/ains_ahrs_imu.parquet`` at commit 491aa06b, MIT licence, converted to CSV) is
an OrcaFlex simulation of a vessel in irregular waves: about 6 minutes at 10.24 Hz, true
position, velocity and Euler angles of the IMU point, true and noisy specific force and angular
rate (body frame), a GNSS-like position with 5 cm white noise and a compass heading with 0.1°
white noise. Nothing of it comes from marinefmu's own simulator.

Every filter is told the same sensor noise: the white-noise densities of the IMU read off the
record (:func:`sensor_noise`, the standard deviation of measured − true times √Δt, as a
datasheet would give them; the record has no bias), the receiver's 5 cm and the compass's
0.1°. Everything else stays at each library's defaults. The smsfusion filters start from the
true initial attitude (and AidedINS from the true position and velocity), as smsfusion's own
test on this record does; marinefmu's AttitudeEstimator levels itself from the first 10 s.
Errors are scored, as smsfusion's test does, from sample 600 (58.6 s) on.

- **Roll and pitch**: :class:`~marinefmu.estimators.attitude.estimator.AttitudeEstimator`
  against smsfusion's ``VRU`` and ``AHRS`` (the latter also aided by the compass).
- **Heave** from the accelerometer alone:
  :class:`~marinefmu.estimators.heave.observer.HeaveObserver` fed by the AttitudeEstimator's
  roll and pitch; scored from the time it turns valid (its 120 s window) against the true down
  position minus its record mean. smsfusion has no accelerometer-only heave filter to put
  beside it.
- **GNSS-aided position** (1 Hz fixes, every 10th sample, as smsfusion's test aids its INS):
  the fusion filter of :mod:`~marinefmu.estimators.gnss_fusion` on one receiver
  (:class:`~marinefmu.estimators.gnss_fusion.filter.GnssAccFusion` with ``attitude =
  "input"``: the specific force rotated with the AttitudeEstimator's roll and pitch and the
  compass heading, the receiver at the IMU) against smsfusion's ``AidedINS`` aided by the same
  fixes and compass. The fusion's ``q`` and ``q_down`` are not
  tuned on this record: :func:`tune_receiver_q` picks them on a VesselMotion record with the
  same sensors (a grid, the truth of our own simulator) and :data:`RECEIVER_Q` holds its
  result, checked by a test.

**Through the FMUs** (:func:`fmu_runs`, ``compare_orcaflex(fmu_dir=…)``): the record is played by
the SensorRecording FMU (mapping :data:`MAPPING`, the worked example
``examples/recordings/orcaflex.toml``, with a ``new`` column that marks every 10th sample's fix)
into the AttitudeEstimator, HeaveObserver and GnssAccFusion (``attitude = "input"``, yaw from
the compass) FMUs, wired as ``marinefmu replay`` wires them. The attitude is then the
in-process figure exactly. Under the co-simulation's one-step coupling the HeaveObserver and
the fusion get the roll and pitch of the previous sample (in-process: of the same sample); the
fusion turns them forward with the gyro (``attitude_lag`` one step), and their figures differ
from the in-process ones in the last digits. On the inputs it was given, the fusion FMU is the
in-process estimator exactly (a test).
"""
from __future__ import annotations

import gzip
import math
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

SETTLE_SAMPLES = 600          # scored from this sample on, as smsfusion's own test [-]
FIX_EVERY = 10                # a GNSS fix every 10th sample (1.02 s) [-]
RECEIVER_SIGMA = 0.05         # [m] white noise of the record's position
COMPASS_SIGMA = math.radians(0.1)   # [rad] white noise of the record's heading
# q and q_down of the one-receiver fusion as multiples of N², N the accelerometer's white-noise
# density: what tune_receiver_q() picks on marinefmu's simulator (a test checks it)
RECEIVER_Q_FACTORS = (100.0, 1.0)


@dataclass(frozen=True)
class OrcaflexRecord:
    """The record in SI units and radians (NED; body x forward, y starboard, z down).

    Attributes
    ----------
    dt : float
        Mean sample interval [s].
    acc, gyro : numpy.ndarray
        (N, 3) measured specific force [m/s²] and angular rate [rad/s], body frame.
    acc_true, gyro_true : numpy.ndarray
        (N, 3) the same without noise.
    pos, vel : numpy.ndarray
        (N, 3) true position [m] and velocity [m/s] of the IMU point, NED.
    euler : numpy.ndarray
        (N, 3) true roll, pitch, yaw [rad].
    gnss : numpy.ndarray
        (N, 3) measured position [m], NED.
    heading : numpy.ndarray
        (N,) measured heading (compass) [rad].
    """

    dt: float
    acc: np.ndarray
    gyro: np.ndarray
    acc_true: np.ndarray
    gyro_true: np.ndarray
    pos: np.ndarray
    vel: np.ndarray
    euler: np.ndarray
    gnss: np.ndarray
    heading: np.ndarray


#: The record's sample rate [Hz] (its stamps are rounded to 1 ms).
RATE = 10.24
#: The record's mapping sidecar (as ``examples/recordings/orcaflex.toml``, which a test compares).
MAPPING = """[time]
column = "time"
unit = "s"
rate = 10.24
[imu]
max_gap = 0.25
acc = { x = "Ax_meas", y = "Ay_meas", z = "Az_meas", unit = "m/s2" }
gyro = { x = "Gx_meas", y = "Gy_meas", z = "Gz_meas", unit = "deg/s" }
[gnss]
max_gap = 0.25
ant1 = { n = "X_meas", e = "Y_meas", d = "Z_meas", unit = "m" }
[heading]
column = "Gamma_meas"
unit = "deg"
[ref]
max_gap = 0.25
roll = { column = "Alpha", unit = "deg" }
pitch = { column = "Beta", unit = "deg" }
yaw = { column = "Gamma", unit = "deg" }
heave = { column = "Z", unit = "m" }
imu = { n = "X", e = "Y", d = "Z", unit = "m" }
imu_vel = { n = "VX", e = "VY", d = "VZ", unit = "m/s" }
rate = { x = "Gx", y = "Gy", z = "Gz", unit = "deg/s" }
imu_f = { x = "Ax", y = "Ay", z = "Az", unit = "m/s2" }
"""


#: The AttitudeEstimator's aiding on this record: fixed, slow (1 Hz) and loose (3 m/s, 10 m), the
#: setting the comparison was measured with. The auto-sized default aids faster and is worse in
#: pitch on this record (0.032° against 0.014°), and the one-receiver fusion fed by it with it.
FIXED_AIDING = {"aid_sizing": "fixed", "vel_sigma": 3.0, "pos_sigma": 10.0, "aid_rate": 1.0}


def data_file() -> Path:
    """The packaged record (``ains_ahrs_imu.csv.gz``)."""
    return Path(str(resources.files("marinefmu") / "data" / "peer" / "smsfusion_orcaflex" / "ains_ahrs_imu.csv.gz"))


def load_orcaflex(path: str | Path | None = None) -> OrcaflexRecord:
    """Read the record (default the packaged one) into SI units and radians."""
    path = Path(path) if path is not None else data_file()
    with gzip.open(path, "rt") as fh:
        names = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    col = {n: data[:, i] for i, n in enumerate(names)}
    cols = lambda *keys: np.column_stack([col[k] for k in keys])  # noqa: E731
    return OrcaflexRecord(
        dt=float(np.mean(np.diff(col["time"]))),
        acc=cols("Ax_meas", "Ay_meas", "Az_meas"), gyro=np.radians(cols("Gx_meas", "Gy_meas", "Gz_meas")),
        acc_true=cols("Ax", "Ay", "Az"), gyro_true=np.radians(cols("Gx", "Gy", "Gz")),
        pos=cols("X", "Y", "Z"), vel=cols("VX", "VY", "VZ"), euler=np.radians(cols("Alpha", "Beta", "Gamma")),
        gnss=cols("X_meas", "Y_meas", "Z_meas"), heading=np.radians(col["Gamma_meas"]),
    )


def sensor_noise(rec: OrcaflexRecord) -> tuple[float, float]:
    """White-noise densities of the record's accelerometer [m/s²/√Hz] and gyro [rad/s/√Hz]:
    the largest axis's standard deviation of measured − true, times √Δt."""
    root = math.sqrt(rec.dt)
    return (float(np.max(np.std(rec.acc - rec.acc_true, axis=0))) * root,
            float(np.max(np.std(rec.gyro - rec.gyro_true, axis=0))) * root)


def _imu_errors(acc_noise: float, gyro_noise: float) -> tuple[dict, dict]:
    from ..sea.sensors import ImuParams

    d = ImuParams()  # smsfusion's bias defaults equal VesselMotion's (5e-4 m/s², 5e-5 rad/s, 50 s)
    return ({"N": acc_noise, "B": d.acc_bias_instability, "tau_cb": d.bias_tau},
            {"N": gyro_noise, "B": d.gyro_bias_instability, "tau_cb": d.bias_tau})


def _quat(euler: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler("ZYX", np.asarray(euler)[::-1]).as_quat(scalar_first=True)


def attitude_runs(rec: OrcaflexRecord) -> dict[str, np.ndarray]:
    """Roll and pitch [rad], (N, 2), of marinefmu's AttitudeEstimator and smsfusion's VRU and
    AHRS (module docstring)."""
    from ..estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
    from .peer_smsfusion import smsfusion_module

    sf = smsfusion_module()
    acc_n, gyro_n = sensor_noise(rec)
    ours = estimate_attitude(rec.gyro, rec.acc, rec.dt, AttitudeEstimatorParams(acc_noise=acc_n, gyro_noise=gyro_n, **FIXED_AIDING))
    err_acc, err_gyro = _imu_errors(acc_n, gyro_n)
    x0 = np.zeros(16)
    x0[6:10] = _quat(rec.euler[0])
    runs = {"marinefmu AttitudeEstimator": np.c_[ours["roll"], ours["pitch"]]}
    for name in ("VRU", "AHRS"):
        f = getattr(sf, name)(fs=1.0 / rec.dt, x0_prior=x0, err_acc=err_acc, err_gyro=err_gyro, cold_start=False)
        out = np.empty((len(rec.acc), 2))
        for k in range(len(rec.acc)):
            if name == "AHRS":
                f.update(rec.acc[k], rec.gyro[k], head=rec.heading[k], head_var=COMPASS_SIGMA ** 2, head_degrees=False)
            else:
                f.update(rec.acc[k], rec.gyro[k])
            out[k] = f.euler()[:2]
        runs[f"smsfusion {name}"] = out
    return runs


def heave_run(rec: OrcaflexRecord, roll: np.ndarray, pitch: np.ndarray,
              **params: Any) -> tuple[np.ndarray, np.ndarray]:
    """Heave [m, down] and ``valid`` of marinefmu's HeaveObserver fed by ``roll``/``pitch``
    (``params``: more :class:`~marinefmu.estimators.heave.common.HeaveObserverParams` fields)."""
    from ..estimators.heave.common import HeaveObserverParams
    from ..estimators.heave.observer import HeaveObserver

    obs = HeaveObserver(HeaveObserverParams(acc_noise=sensor_noise(rec)[0], **params), quiet=True)
    heave = np.empty(len(rec.acc))
    valid = np.empty(len(rec.acc), dtype=bool)
    for k in range(len(rec.acc)):
        r = obs.step(rec.acc[k], float(roll[k]), float(pitch[k]), rec.dt)
        heave[k], valid[k] = r.heave, r.valid
    return heave, valid


def heave_scores(rec: OrcaflexRecord, roll: np.ndarray, pitch: np.ndarray, **params: Any) -> dict[str, float]:
    """Heave RMS error and true heave std [cm] of :func:`heave_run`, from the sample where the
    observer turns valid (``from_s``)."""
    heave, valid = heave_run(rec, roll, pitch, **params)
    kv = int(np.argmax(valid)) if valid.any() else len(valid)
    truth_d = rec.pos[:, 2] - rec.pos[:, 2].mean()
    return {"heave_cm": 100.0 * float(_rms(heave[kv:] - truth_d[kv:])),
            "heave_std_cm": 100.0 * float(np.std(truth_d[kv:])), "from_s": kv * rec.dt}


def rotate_to_ned(acc: np.ndarray, roll: np.ndarray, pitch: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """Specific force rotated into NED, f_n = R_nb(roll, pitch, yaw) f_b, (N, 3)."""
    from scipy.spatial.transform import Rotation

    rot = Rotation.from_euler("ZYX", np.column_stack([yaw, pitch, roll])).as_matrix()
    return np.einsum("kij,kj->ki", rot, acc)


def fusion_parameters(dt: float, q: tuple[float, float], lag: float = 0.0) -> dict[str, Any]:
    """The one-receiver fusion's settings, FMI-named (the GnssAccFusion FMU's and, through
    :func:`~marinefmu.fmu.tables.fusion_params`, :func:`receiver_fusion`'s): ``attitude =
    "input"``, the receiver and the accelerometer at the IMU point (the record's origin; no lever
    arm), R = :data:`RECEIVER_SIGMA`² (r = σ²Δt for the step ``dt``, ``noise_sizing = "fixed"``), ``q`` = (q, q_down), and
    ``attitude_lag`` = ``lag`` [s] (one step through the FMUs: the co-simulation's coupling).

    ``coast = "inertial"``: the records have no gap longer than the 2 s after which the default
    wave-model coast would start, so it would only cost time (its band observers are 95 % of
    the run) and change nothing."""
    at_imu = {f"{v}.{a}": 0.0 for v in ("ant1", "acc_lever_arm") for a in "xyz"}
    return {"attitude": "input", "attitude_lag": lag, "q": q[0], "q_down": q[1], "r": RECEIVER_SIGMA ** 2 * dt,
            "noise_sizing": "fixed", "coast": "inertial", **at_imu}


def receiver_fusion(acc: np.ndarray, euler: np.ndarray, gnss: np.ndarray, dt: float, q: tuple[float, float],
                    gyro: np.ndarray | None = None, lag: float = 0.0) -> np.ndarray:
    """Position [m, NED] of the one-receiver fusion (:func:`fusion_parameters`) with a fix every
    :data:`FIX_EVERY` samples: ``acc`` (N, 3) the specific force [m/s², body], ``euler`` (N, 3)
    the roll, pitch, yaw [rad] that rotate it (their roll and pitch ``lag`` s late, turned
    forward with ``gyro`` (N, 3) [rad/s, body]), ``gnss`` (N, 3) the receiver [m, NED]."""
    from ..estimators.gnss_fusion.runs import fuse
    from ..fmu.tables import fusion_params

    new = np.arange(len(acc)) % FIX_EVERY == 0
    return fuse(acc, dt, gnss, new, gyro, fusion_params(fusion_parameters(dt, q, lag)), euler=euler)["pos"]


def aided_ins_run(rec: OrcaflexRecord) -> np.ndarray:
    """Position [m, NED] of smsfusion's AidedINS aided by the same fixes and the compass."""
    from .peer_smsfusion import smsfusion_module

    acc_n, gyro_n = sensor_noise(rec)
    err_acc, err_gyro = _imu_errors(acc_n, gyro_n)
    x0 = np.zeros(16)
    x0[:3], x0[3:6], x0[6:10] = rec.pos[0], rec.vel[0], _quat(rec.euler[0])
    ins = smsfusion_module().AidedINS(fs=1.0 / rec.dt, x0_prior=x0, P0_prior=np.diag([1e-2] * 6 + [1e-4] * 3 + [1e-8] * 3),
                                err_acc=err_acc, err_gyro=err_gyro, cold_start=False)
    out = np.empty((len(rec.acc), 3))
    head = {"head_var": COMPASS_SIGMA ** 2, "head_degrees": False}
    for k in range(len(rec.acc)):
        if k % FIX_EVERY == 0:
            ins.update(rec.acc[k], rec.gyro[k], pos=rec.gnss[k], pos_var=[RECEIVER_SIGMA ** 2] * 3, head=rec.heading[k], **head)
        else:
            ins.update(rec.acc[k], rec.gyro[k], head=rec.heading[k], **head)
        out[k] = ins.position()
    return out


def _rms(e: np.ndarray) -> np.ndarray:
    return np.sqrt(np.mean(e ** 2, axis=0))


@dataclass(frozen=True)
class FmuRuns:
    """What the FMU path (:func:`fmu_runs`) gives, one row per sample of the record.

    Attributes
    ----------
    roll, pitch : numpy.ndarray
        (N,) the AttitudeEstimator FMU's roll and pitch after each sample [rad].
    heave, heave_valid, heave_band, heave_band_valid : numpy.ndarray
        (N,) the HeaveObserver FMUs' heave [m, down] and valid (default model and ``band``).
    pos : numpy.ndarray
        (N, 3) the GnssAccFusion FMU's position after each sample [m, NED].
    fusion_euler : numpy.ndarray
        (N, 3) the roll, pitch, yaw [rad] the fusion FMU was given with each sample: the
        AttitudeEstimator's after the previous sample (the one-step coupling, which the fusion's
        ``attitude_lag`` turns forward) and the compass.
    acc, gyro, gnss : numpy.ndarray
        (N, 3) specific force [m/s², body], angular rate [rad/s, body] and position (held between
        the fixes) [m, NED] as the recording FMU played them.
    heading : numpy.ndarray
        (N,) the compass [rad] as played.
    """

    roll: np.ndarray
    pitch: np.ndarray
    heave: np.ndarray
    heave_valid: np.ndarray
    heave_band: np.ndarray
    heave_band_valid: np.ndarray
    pos: np.ndarray
    fusion_euler: np.ndarray
    acc: np.ndarray
    gyro: np.ndarray
    gnss: np.ndarray
    heading: np.ndarray


def _record_with_fixes(path: Path, dest: Path) -> None:
    """The record with a column ``fix_new``, 1 on every :data:`FIX_EVERY`-th sample (the
    harness's 1 Hz fixes; the record has a position on every sample), written to ``dest``."""
    with (gzip.open(path, "rt") if path.suffix == ".gz" else open(path)) as fh:
        lines = [line.rstrip("\n") for line in fh if line.strip()]
    rows = [f"{lines[0]},fix_new", *(f"{line},{int(k % FIX_EVERY == 0)}" for k, line in enumerate(lines[1:]))]
    dest.write_text("\n".join(rows) + "\n", encoding="utf-8")


def fix_mapping() -> str:
    """:data:`MAPPING` with the GNSS epochs marked by the column ``fix_new`` of
    :func:`_record_with_fixes` (and a ``max_gap`` longer than their interval)."""
    old = '[gnss]\nmax_gap = 0.25\n'
    if old not in MAPPING:
        raise RuntimeError("MAPPING has no [gnss] max_gap = 0.25 to mark the fixes in")
    return MAPPING.replace(old, '[gnss]\nmax_gap = 2.0\nnew = "fix_new"\n')


def fmu_runs(fmu_dir: str | Path, rec: OrcaflexRecord | None = None, path: str | Path | None = None,
             band: bool = True) -> FmuRuns:
    """Play the record through the SensorRecording, AttitudeEstimator, HeaveObserver and
    GnssAccFusion FMUs (module docstring); ``path`` the record (default the packaged one);
    ``band`` also runs a HeaveObserver with ``model = "band"`` (else its fields are NaN / false)."""
    import tempfile

    from ..cosim.replay import plan_replay, run_replay

    rec = rec or load_orcaflex(path)
    acc_n, gyro_n = sensor_noise(rec)
    with tempfile.TemporaryDirectory() as tmp:
        mapping = Path(tmp) / "orcaflex.toml"
        mapping.write_text(fix_mapping(), encoding="utf-8")
        record = Path(tmp) / "orcaflex.csv"
        _record_with_fixes(Path(path or data_file()), record)
        n = len(rec.acc)
        # one step past the last sample, so the estimators take it too (the recording then holds)
        step = 1.0 / RATE
        plan = plan_replay(record, mapping, "attitude,heave,fusion", step=step, duration=n * step)
        from dataclasses import replace

        from ..cosim.ssp import Connection

        # the library's defaults and the record's noise, as in-process (not the system scenario's tuning)
        q = tuple(f * acc_n ** 2 for f in RECEIVER_Q_FACTORS)
        own = {"att": {"acc_noise": acc_n, "gyro_noise": gyro_n, **FIXED_AIDING}, "heave": {"acc_noise": acc_n},
               "fusion": fusion_parameters(step, q, lag=step)}
        comps = tuple(replace(c, parameters=own[c.name]) if c.name in own else c for c in plan.system.components)
        plan = replace(plan, system=replace(plan.system, components=comps))
        heave = next(c for c in plan.system.components if c.name == "heave")
        extra = replace(heave, name="heave_band", parameters={**heave.parameters, "model": "band"})
        wires = tuple(Connection(c.start, c.start_var, "heave_band", c.end_var) for c in plan.system.connections
                      if c.end == "heave")
        system = replace(plan.system, components=plan.system.components + (extra,) * band,
                         connections=plan.system.connections + wires * band)
        res, _ = run_replay(replace(plan, system=system), fmu_dir, progress=False)
    col = lambda name: np.asarray(res[name], dtype=float)  # noqa: E731
    after = slice(1, n + 1)        # estimator outputs after sample k are in row k + 1
    played = slice(0, n)           # the recording's sample k is in row k
    return FmuRuns(
        roll=col("att.roll")[after], pitch=col("att.pitch")[after],
        heave=col("heave.heave")[after], heave_valid=np.asarray(res["heave.valid"], dtype=bool)[after],
        heave_band=col("heave_band.heave")[after] if band else np.full(n, np.nan),
        heave_band_valid=np.asarray(res["heave_band.valid"], dtype=bool)[after] if band else np.zeros(n, bool),
        pos=np.column_stack([col(f"fusion.pos.{a}")[after] for a in "ned"]),
        fusion_euler=np.column_stack([col("att.roll")[played], col("att.pitch")[played], col("rec.heading")[played]]),
        acc=np.column_stack([col(f"rec.imu.acc.{a}")[played] for a in "xyz"]),
        gyro=np.column_stack([col(f"rec.imu.gyro.{a}")[played] for a in "xyz"]),
        gnss=np.column_stack([col(f"rec.gnss.ant1.{a}")[played] for a in "ned"]),
        heading=col("rec.heading")[played],
    )


def heave_score(rec: OrcaflexRecord, heave: np.ndarray, valid: np.ndarray) -> dict[str, float]:
    """Heave RMS error and true heave std [cm] of a heave run, from the sample it turns valid."""
    kv = int(np.argmax(valid)) if valid.any() else len(valid)
    truth_d = rec.pos[:, 2] - rec.pos[:, 2].mean()
    return {"heave_cm": 100.0 * float(_rms(heave[kv:] - truth_d[kv:])),
            "heave_std_cm": 100.0 * float(np.std(truth_d[kv:])), "from_s": kv * rec.dt}


def compare_orcaflex(rec: OrcaflexRecord | None = None, fmu_dir: str | Path | None = None) -> dict[str, dict[str, float]]:
    """RMS errors on the record (module docstring): roll/pitch [deg], heave and position [cm].

    Parameters
    ----------
    rec : OrcaflexRecord, optional
        The record (default the packaged one).
    fmu_dir : str or Path, optional
        Run marinefmu's estimators through the FMUs in this folder (:func:`fmu_runs`) instead
        of in-process.

    Returns
    -------
    dict
        Run name → metric → value; ``"raw GNSS"`` scores the fixes themselves (at the fix
        samples).
    """
    if fmu_dir is not None:
        return _compare_fmu(rec or load_orcaflex(), fmu_dir)
    rec = rec or load_orcaflex()
    k0 = SETTLE_SAMPLES
    out: dict[str, dict[str, float]] = {}
    att = attitude_runs(rec)
    for name, rp in att.items():
        e = np.degrees(_rms(rp[k0:] - rec.euler[k0:, :2]))
        out[name] = {"roll_deg": float(e[0]), "pitch_deg": float(e[1])}
    roll, pitch = att["marinefmu AttitudeEstimator"].T
    out["marinefmu HeaveObserver"] = heave_scores(rec, roll, pitch)                 # the default, model = "wiener"
    out["marinefmu HeaveObserver (band)"] = heave_scores(rec, roll, pitch, model="band")
    fix = np.arange(len(rec.acc)) % FIX_EVERY == 0
    fix[:k0] = False
    q = tuple(f * sensor_noise(rec)[0] ** 2 for f in RECEIVER_Q_FACTORS)
    ours = receiver_fusion(rec.acc, np.c_[roll, pitch, rec.heading], rec.gnss, rec.dt, q)
    for name, pos in (("marinefmu fusion (one receiver)", ours),
                      ("smsfusion AidedINS", aided_ins_run(rec)), ("raw GNSS", None)):
        e = 100.0 * (_rms(rec.gnss[fix] - rec.pos[fix]) if pos is None else _rms(pos[k0:] - rec.pos[k0:]))
        out[name] = {f"pos_{a}_cm": float(e[i]) for i, a in enumerate("ned")}
    return out


def _compare_fmu(rec: OrcaflexRecord, fmu_dir: str | Path) -> dict[str, dict[str, float]]:
    """:func:`compare_orcaflex` with marinefmu's runs through the FMUs (the peers as before)."""
    k0 = SETTLE_SAMPLES
    runs = fmu_runs(fmu_dir, rec)
    out: dict[str, dict[str, float]] = {}
    peers = {k: v for k, v in attitude_runs(rec).items() if not k.startswith("marinefmu")}
    for name, rp in {"marinefmu AttitudeEstimator": np.c_[runs.roll, runs.pitch], **peers}.items():
        e = np.degrees(_rms(rp[k0:] - rec.euler[k0:, :2]))
        out[name] = {"roll_deg": float(e[0]), "pitch_deg": float(e[1])}
    out["marinefmu HeaveObserver"] = heave_score(rec, runs.heave, runs.heave_valid)
    out["marinefmu HeaveObserver (band)"] = heave_score(rec, runs.heave_band, runs.heave_band_valid)
    fix = np.arange(len(rec.acc)) % FIX_EVERY == 0
    fix[:k0] = False
    for name, pos in (("marinefmu fusion (one receiver)", runs.pos),
                      ("smsfusion AidedINS", aided_ins_run(rec)), ("raw GNSS", None)):
        e = 100.0 * (_rms(rec.gnss[fix] - rec.pos[fix]) if pos is None else _rms(pos[k0:] - rec.pos[k0:]))
        out[name] = {f"pos_{a}_cm": float(e[i]) for i, a in enumerate("ned")}
    return out


def tune_receiver_q(duration: float = 600.0, factors: tuple[float, ...] = (1.0, 10.0, 100.0, 1e3, 1e4, 1e5),
                    seed: int = 7) -> tuple[float, float]:
    """Pick (q, q_down) of the one-receiver fusion on marinefmu's own simulator, not on the
    OrcaFlex record.

    A VesselMotion record resembling the OrcaFlex one (``polar_supply`` in head seas, Hs 2.5 m,
    Tp 13 s, sampled at 10.24 Hz, the IMU at the COG with the record's noise densities and no
    bias) gets a 1 Hz receiver (true IMU position + 5 cm white noise) and a compass (true yaw +
    0.1°), both seeded; the specific force is rotated with the AttitudeEstimator's roll and
    pitch and the compass, as on the record. The grid is ``factors`` × N², N the
    accelerometer's white-noise density: the filter's process noise cannot be less than the
    sensor's own (below it the down axis keeps improving on a bias-free simulator for no
    physical reason). The axes of the filter are independent, so one run per grid value gives
    both the best horizontal ``q`` (mean north/east RMS error) and the best ``q_down`` (from
    60 s on). Returns the factors of N² for (q, q_down).
    """
    from ..estimators.attitude.estimator import AttitudeEstimatorParams, estimate_attitude
    from ..sea.motion_model import VesselMotionParams, simulate_record, stack

    acc_noise, gyro_noise = sensor_noise(load_orcaflex())
    dt = 1.0 / 10.24
    flat = {"sea.hs": 2.5, "sea.tp": 13.0, "sea.heading": math.pi, "vessel.preset": "polar_supply",
            "imu.acc_noise": acc_noise, "imu.gyro_noise": gyro_noise, "imu.acc_bias_instability": 0.0,
            "imu.gyro_bias_instability": 0.0, "sensors.seed": seed}
    rec = simulate_record(VesselMotionParams.from_flat(flat), duration, dt)
    acc, gyro = stack(rec, "imu.acc"), stack(rec, "imu.gyro")
    truth = stack(rec, "truth.imu", "ned")
    rng = np.random.default_rng(seed)
    gnss = truth + rng.normal(0.0, RECEIVER_SIGMA, truth.shape)
    heading = rec["truth.yaw"] + rng.normal(0.0, COMPASS_SIGMA, len(truth))
    att = estimate_attitude(gyro, acc, dt, AttitudeEstimatorParams(acc_noise=acc_noise, gyro_noise=gyro_noise, **FIXED_AIDING))
    euler = np.c_[att["roll"], att["pitch"], heading]
    k0 = int(round(60.0 / dt))
    grid = [f * acc_noise ** 2 for f in factors]
    scores = []
    for q in grid:
        e = _rms(receiver_fusion(acc, euler, gnss, dt, (q, q))[k0:] - truth[k0:])
        scores.append((float(np.mean(e[:2])), float(e[2])))
    scores_arr = np.array(scores)
    return factors[int(np.argmin(scores_arr[:, 0]))], factors[int(np.argmin(scores_arr[:, 1]))]
