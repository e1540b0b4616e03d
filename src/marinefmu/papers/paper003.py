"""Paper 003's heave observer on a vessel in waves, against truth and the classical baseline.

VesselMotion (polar_supply, waves 45° off the bow, default MEMS noise, 20 Hz, IMU at
(−5, 1, −3) m from the COG, bow point 40 m forward of the IMU). The observer gets the IMU's
specific force and the true roll and pitch; errors are RMS after 2 minutes of settling, heave
positive down, against the truth at the IMU and at the bow point.

* :func:`compare`: the band model (real time and delayed), the paper's undamped modes
  (``model = peaks`` with the paper's fixed 120 s spectrum window), the causal Wiener filter
  from the spectrum (``model = wiener``, beyond the paper; the default), and the high-pass
  double integration of most motion reference units (4th-order Butterworth, causal) at the
  cutoff best for the record among :data:`HP_CUTOFFS` (chosen at each place), fed the vertical
  acceleration at the IMU (the same sensor) and, at the bow point, the point's exact
  acceleration (a noise-free sensor there: its best case).
* :func:`plot`: a minute of bow heave (truth and the four real-time estimates) and the error
  of each over the whole run.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..estimators.heave.common import HeaveObserverParams, vertical_acceleration
from ..estimators.heave.observer import HeaveObserver
from ..estimators.numerics import highpass_double_integration
from ..sea.motion_model import VesselMotionParams, simulate_record, stack

DT = 0.05
SETTLE = 120.0
IMU, ARM = (-5.0, 1.0, -3.0), (40.0, 0.0, -5.0)
#: High-pass corners tried for the baseline [rad/s].
HP_CUTOFFS = (0.05, 0.1, 0.2)


def record(hs: float, tp: float, duration: float = 1920.0, seed: int = 3,
           extra: dict | None = None) -> dict[str, np.ndarray]:
    """VesselMotion record of the checks (30 min after 2 min at the default duration);
    ``extra``: more VesselMotion parameters (e.g. ``{"imu.acc_noise": 0.0}``)."""
    flat = {"sea.hs": hs, "sea.tp": tp, "sea.seed": seed, "sea.heading": 0.75 * math.pi,
            **{f"imu.{a}": v for a, v in zip("xyz", IMU)}, **{f"point.{a}": i + r for a, i, r in zip("xyz", IMU, ARM)},
            **(extra or {})}
    return simulate_record(VesselMotionParams.from_flat(flat), duration, DT)


def run_observer(params: HeaveObserverParams,
                 rec: dict[str, np.ndarray]) -> tuple[np.ndarray, HeaveObserver]:
    """(N, 3) real-time heave at the IMU, at the point, and delayed heave at the IMU [m, down]
    (``params.model`` an observer's or ``"wiener"``)."""
    obs = HeaveObserver(params)
    acc, roll, pitch = stack(rec, "imu.acc"), rec["truth.roll"], rec["truth.pitch"]
    out = np.array([[r.heave, r.point_heave, r.delayed_heave]
                    for r in (obs.step(acc[k], roll[k], pitch[k], DT) for k in range(len(acc)))])
    return out, obs


def _rms(e: np.ndarray) -> float:
    return float(np.sqrt(np.mean(e ** 2)))


def imu_error(rec: dict[str, np.ndarray], heave: np.ndarray) -> np.ndarray:
    """Real-time heave error at the IMU [m] from :data:`SETTLE` on, against the truth less its
    mean over that part (the checks' scoring)."""
    k0 = int(SETTLE / DT)
    return heave[k0:] - (rec["truth.imu.d"][k0:] - rec["truth.imu.d"][k0:].mean())


def compare(hs: float = 2.5, tp: float = 9.0, duration: float = 720.0) -> dict:
    """RMS errors [m] of the band model, the paper's modes, the Wiener filter (``model="wiener"``)
    and the high-pass baseline."""
    rec = record(hs, tp, duration)
    k0 = int(SETTLE / DT)
    truth = {"imu": rec["truth.imu.d"] - rec["truth.imu.d"][k0:].mean(),
             "point": rec["truth.point.d"] - rec["truth.point.d"][k0:].mean()}
    runs = {}
    for label, params in (("band", HeaveObserverParams(point=ARM, model="band")),
                          ("peaks (paper)", HeaveObserverParams(point=ARM, model="peaks", offset_noise=3e-4,
                                                                window_max=120.0)),    # the paper's fixed window
                          ("wiener", HeaveObserverParams(point=ARM, model="wiener"))):
        out, obs = run_observer(params, rec)
        lag = int(round(obs.delay / DT))
        runs[label] = {"imu": out[:, 0], "point": out[:, 1],
                       "rms_imu": _rms(out[k0:, 0] - truth["imu"][k0:]),
                       "rms_point": _rms(out[k0:, 1] - truth["point"][k0:]),
                       "rms_delayed": _rms(out[k0 + lag:, 2] - truth["imu"][k0:len(out) - lag]), "delay": obs.delay}
    a_imu = vertical_record(rec)
    a_pt = rec["truth.point_acc.d"]  # at the point the baseline gets the exact acceleration: its best case
    hp = {}
    for where, acc in (("imu", a_imu), ("point", a_pt)):
        tried = {c: highpass_double_integration(acc, DT, c) for c in HP_CUTOFFS}
        rms = {c: _rms(z[k0:] - truth[where][k0:]) for c, z in tried.items()}
        cutoff = min(rms, key=rms.get)
        hp[where], hp[f"rms_{where}"], hp[f"cutoff_{where}"] = tried[cutoff], rms[cutoff], cutoff
    runs["high-pass"] = hp
    return {"sea": (hs, tp), "t": (np.arange(len(a_imu)) + 1) * DT, "truth": truth, "runs": runs,
            "std_imu": float(np.std(truth["imu"][k0:])), "std_point": float(np.std(truth["point"][k0:]))}


#: The accelerometer's noise and bias switched off in VesselMotion (:func:`band_min_study`).
PERFECT_ACCELEROMETER = {"imu.acc_noise": 0.0, "imu.acc_bias_instability": 0.0}


def band_min_study(values: tuple[float, ...] = (0.25, 0.3, 0.35), duration: float = 1920.0) -> dict:
    """Real-time heave RMS error at the IMU [cm] against ``band_min`` (the band model's lowest
    element, :class:`~marinefmu.estimators.heave.common.HeaveObserverParams`), and how much of it lies
    below 0.2 rad/s: on the Tp 14 s seas of the checks, on Hs 4 / Tp 14 with the accelerometer's
    noise and bias off (:data:`PERFECT_ACCELEROMETER`), and on smsfusion's OrcaFlex record
    (true roll and pitch, :func:`marinefmu.bench.peer_orcaflex.heave_scores`)."""
    from scipy import signal

    from ..bench.peer_orcaflex import heave_scores, load_orcaflex

    def errors(rec: dict, band_min: float) -> dict[str, float]:
        e = imu_error(rec, run_observer(HeaveObserverParams(point=ARM, model="band", band_min=band_min), rec)[0][:, 0])
        f, psd = signal.welch(e, fs=1.0 / DT, nperseg=8192)
        low = 2.0 * math.pi * f < 0.2
        return {"rms_cm": 100.0 * _rms(e), "below_0.2_rad_s_cm": 100.0 * math.sqrt(float(np.sum(psd[low])) * f[1])}

    cases = {"Hs 4 Tp 14": record(4.0, 14.0, duration), "Hs 1 Tp 14": record(1.0, 14.0, duration),
             "Hs 4 Tp 14, perfect accelerometer": record(4.0, 14.0, duration, extra=PERFECT_ACCELEROMETER)}
    result: dict = {name: {f"{b:g}": errors(rec, b) for b in values} for name, rec in cases.items()}
    orca = load_orcaflex()
    result["OrcaFlex, true angles"] = {
        f"{b:g}": {"rms_cm": heave_scores(orca, orca.euler[:, 0], orca.euler[:, 1], model="band", band_min=b)["heave_cm"]}
        for b in values}
    return result


def window_max_study(values: tuple[float, ...] = (120.0, 600.0, 1200.0), duration: float = 1920.0) -> dict:
    """Real-time heave RMS error at the IMU [cm] against ``window_max`` (the longest spectrum
    window; 120 s is the paper's fixed window of the default length) on the long seas of the
    checks (Hs 4 m, Tp 12 and 14 s) and on smsfusion's OrcaFlex record (6 minutes, true
    angles: no window longer than 6 minutes is reached), for the band observer and the Wiener
    filter."""
    from ..bench.peer_orcaflex import heave_scores, load_orcaflex

    result: dict = {}
    for hs, tp in ((4.0, 12.0), (4.0, 14.0)):
        rec = record(hs, tp, duration)
        for model in ("band", "wiener"):
            result[f"Hs {hs:g} Tp {tp:g}, {model}"] = {
                f"{w:g}": 100.0 * _rms(imu_error(rec, run_observer(HeaveObserverParams(point=ARM, model=model,
                                                                                       window_max=w), rec)[0][:, 0]))
                for w in values}
    orca = load_orcaflex()
    for model in ("band", "wiener"):
        result[f"OrcaFlex, true angles, {model}"] = {
            f"{w:g}": heave_scores(orca, orca.euler[:, 0], orca.euler[:, 1], model=model, window_max=w)["heave_cm"]
            for w in values}
    return result


#: Windows after a bias step scored by :func:`bias_step_study` [s after the step].
STEP_WINDOWS = ((0.0, 60.0), (60.0, 120.0), (120.0, 300.0), (300.0, 600.0), (600.0, 1200.0), (1200.0, 1500.0))


def bias_step_study(steps: tuple[float, ...] = (0.05, 0.5), at: float = 900.0, hs: float = 2.5, tp: float = 9.0,
                    duration: float = 2500.0) -> dict:
    """Real-time heave RMS error at the IMU [cm] per window after a bias step in mid-run
    (:data:`STEP_WINDOWS`), for the band observer and the Wiener filter: the checks' record
    (seed 3) with ``step`` m/s² added to the body-z specific force from ``at`` s, beside the
    same record without a step (``"before"``: from :data:`SETTLE` to the step). The truth's
    mean is removed as in the checks."""
    clean = record(hs, tp, duration)
    t = np.arange(1, len(clean["imu.acc.z"]) + 1) * DT
    scored = t[int(SETTLE / DT):]                    # the times of imu_error's samples
    result: dict = {}
    for step in (0.0, *steps):
        rec = dict(clean)
        rec["imu.acc.z"] = clean["imu.acc.z"] + np.where(t > at, step, 0.0)
        for model in ("band", "wiener"):
            e = imu_error(rec, run_observer(HeaveObserverParams(model=model), rec)[0][:, 0])
            row = {"before": 100.0 * _rms(e[scored <= at])}
            row.update({f"{a:g}-{b:g} s": 100.0 * _rms(e[(scored > at + a) & (scored <= at + b)])
                        for a, b in STEP_WINDOWS})
            result[f"{step:g} m/s2, {model}"] = row
    return result


#: Seeds of the records that train :func:`causal_bound` (the checks' record is seed 3).
BOUND_TRAINING_SEEDS = (4, 5, 6)


def vertical_record(rec: dict[str, np.ndarray]) -> np.ndarray:
    """(N,) vertical specific force f_d [m/s², NED] the observer is fed: the IMU's, rotated with
    the true roll and pitch (``vertical="ned"``)."""
    f, roll, pitch = stack(rec, "imu.acc"), rec["truth.roll"], rec["truth.pitch"]
    return np.array([vertical_acceleration(f[k], roll[k], pitch[k], "ned") for k in range(len(f))])


@dataclass(frozen=True)
class CausalFir:
    """The causal FIR filters of :func:`causal_bound` (:func:`fit_causal_bound`): heave at the
    IMU [m, down] from the block means of the vertical specific force [m/s², NED].

    Attributes
    ----------
    weights : tuple of numpy.ndarray
        Least-squares weights (:func:`fit_causal_fir`) of the filter of the full memory and, when
        ``settle`` is shorter, of the one of memory ``settle`` that fills the part of the scored
        window where the full memory has not yet elapsed; each (taps + 1,), the constant last.
    decimate : int
        Samples averaged per filter input.
    settle : float
        Start of the scored part of a record [s] (:data:`SETTLE`, as the checks).
    """

    weights: tuple[np.ndarray, ...]
    decimate: int
    settle: float

    def heave(self, a: np.ndarray) -> np.ndarray:
        """(N,) estimate at every sample [m, down] from the vertical specific force ``a`` (N,)
        [m/s², NED] of one record from its start: the longest filter whose memory has elapsed,
        NaN before the shortest one's."""
        out = np.full(len(a), np.nan)
        for w in self.weights:
            taps = len(w) - 1
            est = np.full(len(a), np.nan)
            for offset in range(self.decimate):          # the blocks that end at every sample
                x, _, ends = fir_rows(a[offset:], a[offset:], taps, self.decimate)
                est[ends + offset] = x @ w
            out = np.where(np.isnan(out), est, out)
        return out

    def score(self, rec: dict[str, np.ndarray]) -> dict[str, float]:
        """Error of :meth:`heave` on the record ``rec`` (:func:`record`) from ``settle`` on, at
        every sample, as the checks score the observer (:func:`imu_error`): ``bound_cm``, the RMS
        error less its mean (the estimate's constant set best), and ``heave_std_cm``, the true
        heave std over that part [cm]."""
        k0 = int(self.settle / DT)
        z = rec["truth.imu.d"][k0:]
        e = self.heave(vertical_record(rec))[k0:] - z
        return {"bound_cm": 100.0 * float(np.std(e)), "heave_std_cm": 100.0 * float(np.std(z))}


def fit_causal_bound(hs: float, tp: float, memory: float = 180.0, decimate: int = 8,
                     train: tuple[int, ...] = BOUND_TRAINING_SEEDS, train_duration: float = 3600.0,
                     settle: float = SETTLE, extra: dict | None = None) -> CausalFir:
    """The filters of :func:`causal_bound`, trained on ``train_duration`` s records of the sea
    (:func:`record`) with the seeds ``train`` (parameters as there).

    Raises
    ------
    ParameterError
        If ``settle`` is shorter than one block (``decimate`` samples).
    """
    block = decimate * DT
    if settle < block:
        raise ParameterError(f"settle = {settle:g} is out of range: must be >= decimate * DT = {block:g} [s]")
    pairs = [(vertical_record(rec), rec["truth.imu.d"])
             for rec in (record(hs, tp, train_duration, seed=seed, extra=extra) for seed in train)]
    taps = [int(round(memory / block))]
    if int(settle / block) < taps[0]:
        taps.append(int(settle / block))      # its first estimate is at the last sample before settle
    return CausalFir(tuple(fit_causal_fir(pairs, n, decimate) for n in taps), decimate, settle)


def causal_bound(hs: float, tp: float, memory: float = 180.0, decimate: int = 8,
                 train: tuple[int, ...] = BOUND_TRAINING_SEEDS, train_duration: float = 3600.0,
                 duration: float = 1920.0, settle: float = SETTLE, extra: dict | None = None) -> dict[str, float]:
    """Estimated lower bound on the real-time heave error at the IMU of *any* causal linear
    estimator fed this IMU (the causal Wiener filter), for the sea and record of the checks.

    The best causal FIR filter is fitted by least squares: heave at the IMU at each time from the
    vertical specific force of the last ``memory`` seconds, block-averaged over ``decimate``
    samples (20 Hz → 2.5 Hz by default; the sea's heave has no energy above 1 Hz), plus a
    constant, trained on ``train_duration`` s records of the same sea with other seeds
    (``train``), then run at every sample of the checks' record (seed 3) and scored over the
    checks' window: RMS from ``settle`` (:data:`SETTLE`), the mean error removed (the checks
    remove the truth's mean; the error's own mean is the constant that lowers the figure most).
    From ``settle`` until ``memory`` seconds of record have passed, a second filter of memory
    ``settle``, trained alike, gives the estimate: like the observer, the bound sees only the
    record since its start (:class:`CausalFir`). It knows the sea's and the sensor's statistics
    exactly, which an adaptive observer must estimate, so a real-time estimator cannot be
    expected to do better; finite memory, the averaging and the finite training make it an
    estimate from above of the true (infinite-memory) bound, in expectation: it is the achieved
    error of a real causal filter on one record, so fewer or shorter training records give a
    less well trained filter, higher on average, not on every record. On Hs 4 / Tp 14 a longer
    memory or a finer block rate than the defaults moves it by well under 0.1 cm. Hand-written
    (numpy normal equations): neither scipy nor python-control offers a data-driven Wiener
    filter.

    Parameters
    ----------
    hs, tp : float
        Significant wave height [m] and peak period [s] (:func:`record`).
    memory : float
        Length of the filter [s].
    decimate : int
        Samples averaged per filter input.
    train : tuple of int
        Seeds of the training records.
    train_duration, duration : float
        Length of each training record and of the scored record [s].
    settle : float
        Start of the scored part [s].
    extra : dict, optional
        More VesselMotion parameters (:func:`record`), for every record.

    Returns
    -------
    dict
        ``bound_cm`` (RMS error), ``heave_std_cm`` (true heave std over the scored part) and
        ``taps`` (of the full-memory filter).
    """
    fir = fit_causal_bound(hs, tp, memory, decimate, train, train_duration, settle, extra)
    return {**fir.score(record(hs, tp, duration, extra=extra)), "taps": len(fir.weights[0]) - 1}


def fir_rows(a: np.ndarray, z: np.ndarray, taps: int, decimate: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Regression rows of a causal FIR filter (:func:`causal_bound`): block means of ``a`` over
    ``decimate`` samples, the last ``taps`` of them and a constant per row; the target ``z`` at
    each block's last sample, and that sample's index."""
    n = len(a) // decimate * decimate
    blocks = np.asarray(a[:n], dtype=float).reshape(-1, decimate).mean(axis=1)
    x = np.lib.stride_tricks.sliding_window_view(blocks, taps)
    ends = (np.arange(len(x)) + taps) * decimate - 1
    return np.column_stack([x, np.ones(len(x))]), np.asarray(z)[ends], ends


def fit_causal_fir(pairs: list[tuple[np.ndarray, np.ndarray]], taps: int, decimate: int) -> np.ndarray:
    """Least-squares weights (taps + 1,) of :func:`fir_rows` over the (input, target) records
    ``pairs`` (numpy normal equations, accumulated record by record)."""
    normal, moment = 0.0, 0.0
    for a, z in pairs:
        x, target, _ = fir_rows(a, z, taps, decimate)
        normal, moment = normal + x.T @ x, moment + x.T @ target
    return np.linalg.solve(normal, moment)


def plot(result: dict, path: str | Path) -> None:
    """A minute of bow heave and the error of each estimate over the run (needs matplotlib)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t, truth, runs = result["t"], result["truth"]["point"], result["runs"]
    k0 = int(SETTLE / DT)
    window = (t >= t[-1] - 60.0)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(10, 6.5))
    top.plot(t[window], -truth[window], "k", lw=2, label="truth")
    colours = {"band": "tab:blue", "peaks (paper)": "tab:orange", "high-pass": "tab:green", "wiener": "tab:red"}
    for label, r in runs.items():
        name = f"{label} ({100 * r['rms_point']:.1f} cm RMS)"
        top.plot(t[window], -r["point"][window], color=colours[label], lw=1, label=name)
        bottom.plot(t[k0:], 100 * (r["point"][k0:] - truth[k0:]), color=colours[label], lw=0.6, label=label)
    hs, tp = result["sea"]
    top.set_title(f"Paper 003: real-time heave at a bow point 40 m from the IMU (Hs {hs:g} m, Tp {tp:g} s)")
    top.set_ylabel("heave, up [m]")
    top.legend(loc="upper right", fontsize=8)
    bottom.set_ylabel("error [cm]")
    bottom.set_xlabel("time [s]")
    bottom.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(out: str | Path = "results/paper003") -> dict:
    """Run :func:`compare`, print the table and write ``heave.png``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    r = compare()
    print(f"heave std: {100 * r['std_imu']:.1f} cm at the IMU, {100 * r['std_point']:.1f} cm at the bow point")
    for label, run in r["runs"].items():
        delayed = f", delayed {100 * run['rms_delayed']:.2f} cm" if "rms_delayed" in run else ""
        print(f"  {label:14s} RMS error: IMU {100 * run['rms_imu']:.2f} cm, point {100 * run['rms_point']:.2f} cm{delayed}")
    plot(r, out / "heave.png")
    return r


if __name__ == "__main__":
    main()
