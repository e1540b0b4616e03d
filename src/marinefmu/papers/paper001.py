"""Paper 001's experiments re-created with VesselMotion (GNSS 1 cm / 1.5 cm RTK noise, default
MEMS accelerometer and gyro, 100 Hz).

(a) Horizontal motion without attitude change (their section 3.1, Fig. 7): the polar_supply
    hull with its rotational RAOs set to zero, GNSS at 10, 5, 2 and 1 Hz fused with 100 Hz
    acceleration (:func:`horizontal`).
(b) Motion with attitude changes (section 3.2, Fig. 11): the full hull in beam seas, fused
    with and without attitude correction (:func:`tilting`).
(c) A buoy-like case (section 4.3): antenna 0.97 m above the waterline, vertical error from
    attitude before and after correction (:func:`buoy`).
Plus the robustness goals: a 20 m GNSS jump and a 30 s dropout (:func:`faults`).

Errors are RMS over the scored interval (after ``settle`` s) of the fused COG position
against VesselMotion's exact COG, per NED axis [m].
"""
from __future__ import annotations

import math
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy import signal

from ..estimators.gnss_fusion.runs import fuse
from ..estimators.gnss_fusion.filter import COAST_AFTER, GnssAccFusionParams
from ..sea.motion_model import VesselMotionParams, simulate_record, stack
from ..sea.sensors import IMU_GRADES
from ..sea.vessel import preset_raos, save_rao_csv

DT = 0.01
IMU = (8.0, 3.0, -9.0)  # accelerometer near the antenna mast, relative to the COG [m]
ANT = ((10.0, -4.0, -10.0), (10.0, 4.0, -10.0), (-10.0, -4.0, -10.0), (-10.0, 4.0, -10.0))
SEA = {"sea.hs": 3.0, "sea.tp": 8.0, "sea.heading": 0.5 * math.pi, "vessel.preset": "polar_supply"}


def _flat(extra: dict) -> dict:
    v = {**SEA, "imu.x": IMU[0], "imu.y": IMU[1], "imu.z": IMU[2]}
    for i, a in enumerate(ANT):
        v.update({f"gnss.ant{i + 1}.x": a[0], f"gnss.ant{i + 1}.y": a[1], f"gnss.ant{i + 1}.z": a[2]})
    v.update(extra)
    return v


def simulate(duration: float, extra: dict | None = None) -> dict[str, np.ndarray]:
    """VesselMotion record at 100 Hz: acc, gyro (N, 3), gnss (N, 12), gnss_new and gnss_valid
    (N,), cog (N, 3), euler (N, 3)."""
    rec = simulate_record(VesselMotionParams.from_flat(_flat(extra or {})), duration, DT)
    return {
        "acc": stack(rec, "imu.acc"), "gyro": stack(rec, "imu.gyro"),
        "gnss": np.hstack([stack(rec, f"gnss.ant{i}", "ned") for i in range(1, 5)]),
        "gnss_new": rec["gnss.new"], "gnss_valid": rec["gnss.valid"],
        "cog": stack(rec, "truth.cog", "ned"), "euler": stack(rec, "truth", ("roll", "pitch", "yaw")),
    }


def raw_gnss_cog(rec: dict) -> np.ndarray:
    """COG from the latest GNSS epoch held between epochs (what GNSS alone gives) [m]."""
    from ..estimators.gnss_fusion.antenna_attitude import antenna_attitude

    arms = np.array(ANT)
    out = np.full((len(rec["acc"]), 3), np.nan)
    last = np.full(3, np.nan)
    for k in range(len(out)):
        if rec["gnss_new"][k]:
            fix = antenna_attitude(rec["gnss"][k], arms)
            if not isinstance(fix, str):
                last = fix.cog
        out[k] = last
    return out


def rms(est: np.ndarray, truth: np.ndarray, settle: float) -> np.ndarray:
    """Per-axis RMS error [m] after ``settle`` s."""
    s = slice(int(settle / DT), None)
    return np.sqrt(np.nanmean((est[s] - truth[s]) ** 2, axis=0))


#: The process and measurement noise the reproduction was tuned and measured with (the paper's
#: one q for all axes, R = r/Δt as given): the filter's defaults are sized for a vessel in waves.
PAPER_NOISE = {"q": 0.005, "q_down": None, "r": 1e-5, "noise_sizing": "fixed"}


def params(**kw) -> GnssAccFusionParams:
    """GnssAccFusionParams for this set-up (antennas and accelerometer position of :data:`ANT`, :data:`IMU`)."""
    return replace(GnssAccFusionParams(antennas=ANT, acc_lever_arm=IMU, **PAPER_NOISE), **kw)


def horizontal(rates=(10.0, 5.0, 2.0, 1.0), duration: float = 600.0, settle: float = 60.0,
               records: bool = False, out: str | Path | None = None) -> dict:
    """Experiment (a): translation-only hull, GNSS at each rate; RMS errors of fused and raw GNSS.

    Returns, per rate, ``fused`` and ``gnss`` RMS errors [m] per axis and ``spectrum_db``, the
    largest deviation of the fused position's spectrum from the truth's within the motion
    band (:func:`spectrum_deviation_db`) per axis. With ``records`` also the time series
    (``time``, ``fused_pos``, ``gnss_pos``, ``truth``); with ``out`` a plot in the style of
    the paper's Fig. 7 is written there (``paper001_fig7.png``).
    """
    with tempfile.TemporaryDirectory() as tmp:
        table = preset_raos("polar_supply")
        rao = table.rao.copy()
        rao[3:] = 0.0
        path = Path(tmp) / "translation_only.csv"
        save_rao_csv(replace(table, rao=rao, name="translation only"), path)
        result = {}
        for rate in rates:
            rec = simulate(duration, {"vessel.rao_file": str(path), "gnss.rate": rate})
            r = fuse(rec["acc"], DT, rec["gnss"], rec["gnss_new"], rec["gyro"], params())
            raw = raw_gnss_cog(rec)
            s = slice(int(settle / DT), None)
            result[rate] = {"fused": rms(r["pos"], rec["cog"], settle), "gnss": rms(raw, rec["cog"], settle),
                            "spectrum_db": spectrum_deviation_db(r["pos"][s], rec["cog"][s], DT)}
            if records or out is not None:
                result[rate].update(time=(np.arange(len(raw)) + 1) * DT, fused_pos=r["pos"], gnss_pos=raw,
                                    truth=rec["cog"])
    if out is not None:
        _plot_fig7(result, Path(out), settle)
    return result


#: Motion band of :func:`spectrum_deviation_db`: frequencies where the truth's spectrum holds
#: at least this fraction of its peak.
BAND_FRACTION = 0.01


def welch_psd(x: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided Welch PSD of each column [unit²/Hz] (scipy, Hann, 8192-sample segments,
    linear detrend): frequencies (F,) [Hz] and PSD (F, k)."""
    return signal.welch(x, fs=1.0 / dt, nperseg=min(len(x), 8192), detrend="linear", axis=0)


def spectrum_deviation_db(est: np.ndarray, truth: np.ndarray, dt: float, min_std: float = 1e-3) -> np.ndarray:
    """Largest |10 log10 (PSD_est / PSD_truth)| [dB] per axis over the motion band (the
    frequencies where the truth's PSD is at least :data:`BAND_FRACTION` of its peak);
    NaN for an axis whose truth moves less than ``min_std`` [m] (standard deviation)."""
    f, p_est = welch_psd(est, dt)
    _, p_true = welch_psd(truth, dt)
    out = np.full(p_true.shape[1], np.nan)
    for i in range(p_true.shape[1]):
        peak = p_true[:, i].max()
        band = p_true[:, i] >= BAND_FRACTION * peak
        if np.std(truth[:, i]) >= min_std and band.any():
            out[i] = np.max(np.abs(10.0 * np.log10(p_est[band, i] / p_true[band, i])))
    return out


def _plot_fig7(result: dict, out: Path, settle: float) -> None:
    """Paper 001 Fig. 7 re-created: sway time series (truth, GNSS held, fused) for each GNSS
    rate and the spectra of fused and raw GNSS against the truth."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    rates = list(result)
    fig, ax = plt.subplots(len(rates), 2, figsize=(12, 2.6 * len(rates)), squeeze=False)
    for row, rate in enumerate(rates):
        r = result[rate]
        t = r["time"]
        w = (t >= settle) & (t < settle + 30.0)
        a = ax[row, 0]
        a.plot(t[w], r["truth"][w, 1], "k", lw=1.5, label="truth")
        a.plot(t[w], r["gnss_pos"][w, 1], color="tab:orange", lw=1, label=f"GNSS {rate:g} Hz (held)")
        a.plot(t[w], r["fused_pos"][w, 1], "--", color="tab:blue", lw=1, label="fused with 100 Hz acc")
        a.set_ylabel("sway (east) [m]")
        a.set_title(f"{rate:g} Hz GNSS: RMS error fused {100 * r['fused'][1]:.2f} cm, GNSS {100 * r['gnss'][1]:.2f} cm",
                    fontsize=9)
        a.legend(loc="upper right", fontsize=7)
        a.grid(alpha=0.3)
        s = t >= settle
        good = s & np.all(np.isfinite(r["gnss_pos"]), axis=1)
        f, p_true = welch_psd(r["truth"][s, 1:2], DT)
        _, p_fused = welch_psd(r["fused_pos"][s, 1:2], DT)
        f_g, p_gnss = welch_psd(r["gnss_pos"][good, 1:2], DT)
        b = ax[row, 1]
        b.semilogy(f, p_true[:, 0], "k", lw=1.5, label="truth")
        b.semilogy(f_g, p_gnss[:, 0], color="tab:orange", lw=1, label="GNSS (held)")
        b.semilogy(f, p_fused[:, 0], "--", color="tab:blue", lw=1,
                   label=f"fused (band deviation {r['spectrum_db'][1]:.2f} dB)")
        b.set_xlim(0.0, 2.0)
        b.set_ylim(p_true[:, 0].max() * 1e-8, p_true[:, 0].max() * 10)
        b.set_ylabel("PSD [m²/Hz]")
        b.legend(loc="upper right", fontsize=7)
        b.grid(alpha=0.3)
    ax[-1, 0].set_xlabel("time [s]")
    ax[-1, 1].set_xlabel("frequency [Hz]")
    fig.suptitle("Paper 001 Fig. 7 re-created: translation-only hull, beam seas Hs 3 m Tp 8 s, RTK 1 cm")
    fig.tight_layout()
    fig.savefig(out / "paper001_fig7.png", dpi=100)
    plt.close(fig)


def tilting(rate: float = 1.0, duration: float = 600.0, settle: float = 60.0) -> dict:
    """Experiment (b): full hull in beam seas; RMS errors with and without attitude correction.

    The uncorrected filter runs without the innovation gate, as the paper's: its acceleration
    is off by g·sin(roll) (0.7 m/s² at 4°), so with the gate it rejects a fifth of the fixes
    and coasts on that error (``uncorrected_gated``: a sway error of close to a metre RMS)."""
    rec = simulate(duration, {"gnss.rate": rate})
    out = {"gnss": rms(raw_gnss_cog(rec), rec["cog"], settle)}
    for name, kw in (("corrected", {}), ("uncorrected", {"attitude_correction": False, "gate": math.inf}),
                     ("uncorrected_gated", {"attitude_correction": False})):
        r = fuse(rec["acc"], DT, rec["gnss"], rec["gnss_new"], rec["gyro"], params(**kw))
        out[name] = rms(r["pos"], rec["cog"], settle)
    return out


def buoy_setup(height: float = 0.97, **kw) -> tuple[dict, GnssAccFusionParams]:
    """Experiment (c)'s set-up: the VesselMotion settings (small hull, Hs 2 m, Tp 6 s, the IMU at
    the antennas' height) and the GnssAccFusionParams (four antennas in a 1 m square ``height`` m above
    the COG; ``kw`` changes more)."""
    ant = ((0.5, -0.5, -height), (0.5, 0.5, -height), (-0.5, -0.5, -height), (-0.5, 0.5, -height))
    extra = {"vessel.preset": "research36", "sea.hs": 2.0, "sea.tp": 6.0, "imu.x": 0.0, "imu.y": 0.0, "imu.z": -height}
    for i, a in enumerate(ant):
        extra.update({f"gnss.ant{i + 1}.x": a[0], f"gnss.ant{i + 1}.y": a[1], f"gnss.ant{i + 1}.z": a[2]})
    return extra, GnssAccFusionParams(antennas=ant, acc_lever_arm=(0.0, 0.0, -height), **{**PAPER_NOISE, **kw})


def buoy(duration: float = 600.0, settle: float = 60.0, height: float = 0.97) -> dict:
    """Experiment (c): small hull (research36) in beam seas, four antennas in a 1 m square
    ``height`` m above the COG at the waterline. Vertical RMS error [m] of the antenna
    centroid's elevation taken as the buoy's (no attitude correction: the tilt drops the
    antennas by h(1 − cos θ) and swings them), of the fix's COG (antenna attitude applied),
    and of the fused COG."""
    extra, fusion = buoy_setup(height)
    ant = fusion.antennas
    rec = simulate(duration, extra)
    new = rec["gnss_new"]
    s = np.arange(len(new)) >= int(settle / DT)
    cen = rec["gnss"][:, 2::3].mean(axis=1) + height  # antenna elevation (down) moved to the waterline
    from ..estimators.gnss_fusion.antenna_attitude import antenna_attitude

    fix_d = np.array([antenna_attitude(g, np.array(ant)).cog[2] for g in rec["gnss"][new & s]])
    r = fuse(rec["acc"], DT, rec["gnss"], new, rec["gyro"], fusion)
    err = lambda e: float(np.sqrt(np.mean(e ** 2)))  # noqa: E731
    return {"uncorrected": err(cen[new & s] - rec["cog"][new & s, 2]), "fix": err(fix_d - rec["cog"][new & s, 2]),
            "fused": err(r["pos"][s, 2] - rec["cog"][s, 2]), "roll_std_deg": float(np.degrees(rec["euler"][s, 0].std()))}


#: The dropouts of the coast's bench figures, (start [s], seed): at 270, 300 and 320 s of seeds
#: 1-10 (used to choose the coast's settings), at 400 s of seeds 11-20 and at 350 s of seeds
#: 21-40 (neither used to choose settings).
DROPOUTS = tuple((s, seed) for s in (270.0, 300.0, 320.0) for seed in range(1, 11)) + \
    tuple((400.0, seed) for seed in range(11, 21)) + tuple((350.0, seed) for seed in range(21, 41))


#: The same (start + 900 s, seed): 19.5-21.7 min into a run, when the coast's spectrum window has
#: grown to its longest (:data:`~marinefmu.estimators.heave.common.WINDOW_MAX`, 1200 s), as it has
#: on a vessel that has been on station for a while; the dropouts above come 4.5-6.7 min into
#: a run, with a spectrum from at most 400 s of data.
LATE_DROPOUTS = tuple((start + 900.0, seed) for start, seed in DROPOUTS)


#: Five-minute dropouts (start [s], seed), bridged by the wave coast: at 270 s of seeds 1-4.
LONG_DROPOUTS = tuple((270.0, seed) for seed in range(1, 5))


#: A tactical-grade gyro (bias instability [rad/s], white-noise density [rad/s/√Hz]): the gyro of
#: VesselMotion's ``imu.grade = tactical`` (:data:`~marinefmu.sea.sensors.IMU_GRADES`), 1e-5 rad/s
#: = 2 °/h and 1.5e-5 rad/s/√Hz = an angle random walk of 0.05 °/√h, against the default MEMS
#: gyro's 5e-5 and 5e-5 (10 °/h, 0.17 °/√h). For :func:`dropouts` with ``gyro``: the tail of the
#: 30 s dropout is the coast's tilt estimate, which the gyro's bias wander and angle random walk
#: turn through the gap. Only the gyro's figures replace the default's here (the grade's
#: accelerometer and bias time constant do not), as in the dropout study's decision record.
TACTICAL_GYRO = (IMU_GRADES["tactical"].gyro_bias_instability, IMU_GRADES["tactical"].gyro_noise)


def dropout_record(start: float, seed: int, duration: float = 30.0,
                   gyro: tuple[float, float] | None = None) -> dict[str, np.ndarray]:
    """:func:`simulate` record of a ``duration`` s GNSS dropout at ``start`` s (1 Hz RTK, sea and
    sensor ``seed``), running on 10 s after it; ``gyro`` = (bias instability [rad/s], white-noise
    density [rad/s/√Hz]) replaces the default MEMS gyro's (e.g. :data:`TACTICAL_GYRO`)."""
    extra = {"gnss.rate": 1.0, "gnss.dropout.start": start, "gnss.dropout.duration": duration,
             "sea.seed": seed, "sensors.seed": seed}
    if gyro is not None:
        extra.update({"imu.gyro_bias_instability": gyro[0], "imu.gyro_noise": gyro[1]})
    return simulate(start + duration + 10.0, extra)


def gap_slices(start: float, duration: float) -> tuple[slice, slice]:
    """Sample slices of a record (:func:`dropout_record`) for the gap, and for its part from the
    coast's first pseudo-fix on (:data:`~marinefmu.estimators.gnss_fusion.filter.COAST_AFTER` s in)."""
    gap = slice(int(round(start / DT)), int(round((start + duration) / DT)))
    return gap, slice(int(round((start + COAST_AFTER) / DT)), gap.stop)


def dropouts(cases=DROPOUTS, duration: float = 30.0, goal: float = 0.10,
             gyro: tuple[float, float] | None = None) -> dict:
    """The fused real-time COG through a ``duration`` s GNSS dropout (1 Hz RTK, wave-model
    coast) for each (start, seed) of ``cases``: the largest error per axis [m] in the gap.

    Returns ``cases`` (start, seed, max_error_m N/E/D), ``over_goal`` (cases with an axis at or
    over ``goal`` m), ``worst_m`` per axis and ``mean_m`` per axis (of the per-case maxima), and
    ``pos_std``: how well the output's ``pos_std`` tells the error once the coast's pseudo-fixes
    have started (:data:`~marinefmu.estimators.gnss_fusion.filter.COAST_AFTER` s into the gap), over
    all cases per axis — ``rms_z`` (RMS of error / ``pos_std``; 1 is calibrated, below 1
    cautious), ``beyond_2`` and ``beyond_3`` (fractions of the time |z| > 2 and > 3; 4.6 % and
    0.27 % for a Gaussian), ``mean_std_m`` and ``rms_error_m``. The same for the RTS-smoothed
    output (post-processing, :func:`~marinefmu.estimators.gnss_fusion.runs.fuse` with ``smooth``;
    the record runs on 10 s after the gap, so the smoother has 10 s of fixes after it): per case
    ``max_error_smoothed_m``, and ``smoothed`` with its ``over_goal``, ``worst_m`` and
    ``mean_m``. Prints one line per case as it goes (about 5 s each, 20 s at
    :data:`LATE_DROPOUTS`). ``gyro`` (bias instability [rad/s], white-noise density
    [rad/s/√Hz]), e.g. :data:`TACTICAL_GYRO`, replaces the default MEMS gyro in the simulation,
    and the fusion is told it (``gyro_bias_sigma``, ``gyro_noise``).
    """
    rows, err_all, std_all = [], [], []
    fusion = params() if gyro is None else params(gyro_bias_sigma=gyro[0], gyro_noise=gyro[1])
    for i, (start, seed) in enumerate(cases):
        rec = dropout_record(start, seed, duration, gyro)
        r = fuse(rec["acc"], DT, rec["gnss"], rec["gnss_new"], rec["gyro"], fusion, gnss_valid=rec["gnss_valid"],
                 smooth=True)
        gap, coasted = gap_slices(start, duration)
        err = np.max(np.abs(r["pos"][gap] - rec["cog"][gap]), axis=0)
        err_s = np.max(np.abs(r["pos_smooth"][gap] - rec["cog"][gap]), axis=0)
        err_all.append(r["pos"][coasted] - rec["cog"][coasted])
        std_all.append(r["pos_std"][coasted])
        rows.append({"start": start, "seed": seed, "max_error_m": err.tolist(), "max_error_smoothed_m": err_s.tolist()})
        print(f"dropout {i + 1}/{len(cases)} at {start:g} s, seed {seed}: max N / E / D "
              f"{' / '.join(f'{100 * e:.1f}' for e in err)} cm (RTS-smoothed "
              f"{' / '.join(f'{100 * e:.1f}' for e in err_s)} cm)", flush=True)
    return {"cases": rows, "duration_s": duration, "goal_m": goal, "gyro": gyro,
            **max_error_summary([row["max_error_m"] for row in rows], goal),
            "smoothed": max_error_summary([row["max_error_smoothed_m"] for row in rows], goal),
            "pos_std": calibration(np.concatenate(err_all), np.concatenate(std_all))}


def max_error_summary(max_errors: list, goal: float) -> dict:
    """``over_goal`` (cases with an axis at or over ``goal`` m), ``worst_m`` and ``mean_m`` per
    axis of per-case maximum errors ``max_errors`` ((cases, 3) [m])."""
    e = np.array(max_errors)
    return {"over_goal": int(np.sum(np.any(e >= goal, axis=1))), "worst_m": e.max(axis=0).tolist(),
            "mean_m": e.mean(axis=0).tolist()}


def calibration(err: np.ndarray, std: np.ndarray) -> dict:
    """How well a standard deviation ``std`` tells the error ``err`` [m] ((N, 3) each), per axis:
    ``rms_z`` (RMS of error / std; 1 is calibrated, below 1 cautious), ``beyond_2`` and
    ``beyond_3`` (fractions of the samples with |z| > 2 and > 3; 4.6 % and 0.27 % for a
    Gaussian), ``mean_std_m`` and ``rms_error_m``."""
    z = np.abs(err) / std
    return {"rms_z": np.sqrt(np.mean(z**2, axis=0)).tolist(), "beyond_2": np.mean(z > 2.0, axis=0).tolist(),
            "beyond_3": np.mean(z > 3.0, axis=0).tolist(), "mean_std_m": std.mean(axis=0).tolist(),
            "rms_error_m": np.sqrt(np.mean(err**2, axis=0)).tolist()}


#: Runs of :func:`pos_std_between_fixes`: name → (GNSS rate [Hz], seeds, GnssAccFusionParams changes,
#: set-up: ``"tilting"`` the paper-001 set-up of experiment (b), ``"buoy"`` experiment (c)).
POS_STD_CASES = {
    "1 Hz": (1.0, tuple(range(1, 11)), {}, "tilting"),
    "10 Hz": (10.0, (1, 2, 3), {}, "tilting"),
    "uncorrected, 1 Hz": (1.0, (1, 2, 3), {"attitude_correction": False, "gate": math.inf}, "tilting"),
    "buoy, 1 Hz": (1.0, (1, 2, 3), {}, "buoy"),
    "held attitude, 1 Hz": (1.0, (1, 2, 3), {"propagation": "hold"}, "tilting"),
}


def pos_std_run(rate: float, seed: int, kw: dict | None = None, setup: str = "tilting", duration: float = 300.0,
                settle: float = 100.0) -> dict:
    """One run without a GNSS gap (sea and sensor ``seed``): :func:`calibration` of the fused
    output's ``pos_std`` after ``settle`` s, plus ``fix``: the fraction of GNSS epochs accepted."""
    if setup == "buoy":
        extra, fusion = buoy_setup(**(kw or {}))
    else:
        extra, fusion = {}, params(**(kw or {}))
    rec = simulate(duration, {**extra, "gnss.rate": rate, "sea.seed": seed, "sensors.seed": seed})
    r = fuse(rec["acc"], DT, rec["gnss"], rec["gnss_new"], rec["gyro"], fusion, gnss_valid=rec["gnss_valid"])
    s = slice(int(round(settle / DT)), None)
    epochs = r["fix"][rec["gnss_new"]]
    return {**calibration(r["pos"][s] - rec["cog"][s], r["pos_std"][s]),
            "fix": float(np.mean(epochs == "accepted"))}


def pos_std_between_fixes(cases: dict = POS_STD_CASES) -> dict:
    """``pos_std`` against the error away from GNSS gaps (:mod:`~marinefmu.estimators.gnss_fusion.error_model`):
    per case of ``cases`` the ``rms_z`` of each seed and the largest of them per axis
    (``worst_rms_z``), the smallest (``least_rms_z``) and the mean ``beyond_2`` over the seeds.
    About 5 s a run; prints a line per run."""
    out = {}
    for name, (rate, seeds, kw, setup) in cases.items():
        runs = []
        for seed in seeds:
            runs.append(pos_std_run(rate, seed, kw, setup))
            print(f"pos_std {name}, seed {seed}: error / pos_std RMS "
                  f"{' / '.join(f'{v:.2f}' for v in runs[-1]['rms_z'])}", flush=True)
        z = np.array([r["rms_z"] for r in runs])
        out[name] = {"seeds": list(seeds), "runs": runs, "worst_rms_z": z.max(axis=0).tolist(),
                     "least_rms_z": z.min(axis=0).tolist(),
                     "beyond_2": np.mean([r["beyond_2"] for r in runs], axis=0).tolist()}
    return out


def dropout_trace(start: float = 350.0, seed: int = 27, duration: float = 30.0, out: str | Path | None = None) -> dict:
    """One GNSS dropout (1 Hz RTK) traced: the fused COG's error per axis in real time, with its
    ``pos_std``, and RTS-smoothed, from 20 s before the gap to 10 s after it. The default is the
    hardest of :data:`DROPOUTS` (seed 27 at 350 s).

    Returns ``max_error_m`` (real time) and ``max_error_smoothed_m`` per axis in the gap [m],
    and ``max_z`` per axis: the largest |error| / ``pos_std`` in the gap once the coast's
    pseudo-fixes have started. With ``out`` the plot ``paper001_dropout.png`` is written there.
    """
    rec = dropout_record(start, seed, duration)
    r = fuse(rec["acc"], DT, rec["gnss"], rec["gnss_new"], rec["gyro"], params(), gnss_valid=rec["gnss_valid"],
             smooth=True)
    gap, coasted = gap_slices(start, duration)
    err, err_s = r["pos"] - rec["cog"], r["pos_smooth"] - rec["cog"]
    result = {"max_error_m": np.max(np.abs(err[gap]), axis=0), "max_error_smoothed_m": np.max(np.abs(err_s[gap]), axis=0),
              "max_z": np.max(np.abs(err[coasted]) / r["pos_std"][coasted], axis=0)}
    if out is not None:
        _plot_dropout(err, err_s, r["pos_std"], start, seed, duration, result, Path(out))
    return result


def _plot_dropout(err: np.ndarray, err_s: np.ndarray, std: np.ndarray, start: float, seed: int, duration: float,
                  result: dict, out: Path) -> None:
    """Error per axis through the dropout, real time with ±2 ``pos_std`` and RTS-smoothed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out.mkdir(parents=True, exist_ok=True)
    t = (np.arange(len(err)) + 1) * DT
    w = t >= start - 20.0
    fig, ax = plt.subplots(3, 1, figsize=(10, 7.5), sharex=True)
    for i, name in enumerate(("north", "east", "down")):
        a = ax[i]
        a.axvspan(start, start + duration, color="0.92", label="GNSS dropout")
        a.fill_between(t[w], -200 * std[w, i], 200 * std[w, i], color="tab:blue", alpha=0.15, label="±2 pos_std")
        a.plot(t[w], 100 * err[w, i], color="tab:blue", lw=1,
               label=f"real time (max in gap {100 * result['max_error_m'][i]:.1f} cm)")
        a.plot(t[w], 100 * err_s[w, i], "--", color="tab:green", lw=1,
               label=f"RTS-smoothed ({100 * result['max_error_smoothed_m'][i]:.1f} cm)")
        for goal in (-10.0, 10.0):
            a.axhline(goal, color="tab:red", lw=0.8, ls=":")
        a.set_ylabel(f"{name} error [cm]")
        a.set_ylim(-20.0, 20.0)
        a.grid(alpha=0.3)
        a.legend(loc="lower left", fontsize=7, ncol=2)
    ax[-1].set_xlabel("time [s]")
    fig.suptitle(f"Paper 001 set-up, 1 Hz RTK: COG error through a {duration:g} s GNSS dropout at {start:g} s "
                 f"(seed {seed}); dotted: the project goal, 10 cm", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "paper001_dropout.png", dpi=100)
    plt.close(fig)


def faults(duration: float = 360.0, start: float = 300.0) -> dict:
    """A 20 m GNSS jump lasting 10 s, and a 30 s dropout, both at ``start`` s, 1 Hz GNSS.
    Returns the largest deviation [m] of the fused COG from the fault-free run during the jump
    window, and the largest 3-D error [m] against truth through the dropout (``start`` leaves
    the wave-model coast its 180 s spectrum window and 120 s of GNSS fixes)."""
    base = simulate(duration, {"gnss.rate": 1.0})
    ref = fuse(base["acc"], DT, base["gnss"], base["gnss_new"], base["gyro"], params())
    jump = simulate(duration, {"gnss.rate": 1.0, "gnss.jump.start": start, "gnss.jump.duration": 10.0,
                               "gnss.jump.n": 20.0})
    rj = fuse(jump["acc"], DT, jump["gnss"], jump["gnss_new"], jump["gyro"], params())
    drop = simulate(duration, {"gnss.rate": 1.0, "gnss.dropout.start": start, "gnss.dropout.duration": 30.0})
    rd = fuse(drop["acc"], DT, drop["gnss"], drop["gnss_new"], drop["gyro"], params(), gnss_valid=drop["gnss_valid"])
    w = slice(int(start / DT), int((start + 40.0) / DT))
    return {
        "jump_shift": float(np.max(np.linalg.norm(rj["pos"][w] - ref["pos"][w], axis=1))),
        "jump_rejected": int(np.sum(rj["fix"] == "rejected")),
        "dropout_error": float(np.max(np.linalg.norm(rd["pos"][w] - drop["cog"][w], axis=1))),
        "dropout_error_axes": np.max(np.abs(rd["pos"][w] - drop["cog"][w]), axis=0),
        "normal_error": float(np.max(np.linalg.norm(ref["pos"][w] - base["cog"][w], axis=1))),
    }
