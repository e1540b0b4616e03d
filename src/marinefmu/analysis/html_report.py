"""A one-page, self-contained HTML report of a whole-system run.

:func:`write_report` takes a :class:`~.cosim.system.SystemRunner` result, the scenario and the
scores of :func:`~.scoring.score`, and writes ``report.html`` with the figures embedded (PNG,
base64): the system's diagram, truth against estimate for every estimator over the last minute,
error traces over the run, the heave spectra, the centre-of-rotation convergence, and a table of
each estimator's accuracy against its goal, named by its source (:data:`GOALS`). It is written
for a reader who has not read the code: every figure and row says what it shows and in which
unit.
"""
from __future__ import annotations

import base64
import html
import io
import math
from pathlib import Path

import numpy as np

from ..cosim.ssp import SystemDescription

#: Goals per (FMU type, metric): (text naming the goal's source, test on the scores of that
#: component returning True when met). Metrics without a goal are reported without one.
GOALS = {
    ("AttitudeEstimator", "roll_deg"): ("≤ 0.02° (project goal)", lambda s: s["roll_deg"] <= 0.02),
    ("AttitudeEstimator", "pitch_deg"): ("≤ 0.02° (project goal)", lambda s: s["pitch_deg"] <= 0.02),
    ("HeaveObserver", "heave_cm"): ("≤ max(2 cm, 2.5 % of std) (beyond the 5 cm / 5 % of commercial MRUs)",
                                    lambda s: s["heave_cm"] <= max(2.0, 0.025 * s["heave_std_cm"])),
    ("HeaveObserver", "point_heave_cm"): ("≤ max(2 cm, 2.5 % of std) (beyond the 5 cm / 5 % of commercial MRUs)",
                                          lambda s: s["point_heave_cm"] <= max(2.0, 0.025 * s["point_heave_std_cm"])),
    **{("CentreOfRotation", f"cr_{a}_m"): ("≤ 0.1 m (project goal)", lambda s, a=a: s[f"cr_{a}_m"] <= 0.1) for a in "xyz"},
    **{("GnssAccFusion", f"pos_{a}_cm"): ("≤ 0.5 × raw GNSS (project goal)",
                                         lambda s, a=a: None if f"raw_gnss_{a}_cm" not in s else s[f"pos_{a}_cm"] <= 0.5 * s[f"raw_gnss_{a}_cm"])
       for a in "ned"},
    # the MotionReferenceUnit: the goals (heave as the HeaveObserver's; surge and sway twice as loose, as
    # they are for commercial units; the delayed outputs half the real-time error)
    **{("MotionReferenceUnit", f"{a}_deg"): ("≤ 0.02° (project goal, as the AttitudeEstimator)",
                                             lambda s, a=a: s[f"{a}_deg"] <= 0.02) for a in ("roll", "pitch")},
    **{("MotionReferenceUnit", f"{p}{a}_cm"): (f"≤ max(2 cm, {pct:g} % of std) (project goal)",
                                               lambda s, p=p, a=a, pct=pct: s[f"{p}{a}_cm"] <= max(2.0, pct / 100 * s[f"{p}{a}_std_cm"]))
       for p in ("", "point_") for a, pct in (("surge", 5.0), ("sway", 5.0), ("heave", 2.5))},
    **{("MotionReferenceUnit", f"{p}delayed_{a}_cm"): ("≤ ½ × the real-time error (project goal)",
                                                       lambda s, p=p, a=a: s[f"{p}delayed_{a}_cm"] <= 0.5 * s[f"{p}{a}_cm"])
       for p in ("", "point_") for a in ("surge", "sway", "heave")},
    # the AHC goals are for the loop fed by a heave estimator (the winch that has vs_ideal/vs_classical)
    ("AhcWinch", "residual_pct"): ("≤ 5 % when fed by the observer (project goal)",
                                   lambda s: None if "vs_ideal" not in s and "vs_classical" not in s else s["residual_pct"] <= 5.0),
    ("AhcWinch", "vs_ideal"): ("≤ 1.5 (project goal)", lambda s: s["vs_ideal"] <= 1.5),
    ("AhcWinch", "vs_classical"): ("< 1 (project goal)", lambda s: s["vs_classical"] < 1.0),
    ("AhcWinch", "limited_pct"): ("≤ 1 % (project goal)", lambda s: s["limited_pct"] <= 1.0),
}
LABELS = {
    "roll_deg": "roll RMS error [deg]", "pitch_deg": "pitch RMS error [deg]",
    "pos_n_cm": "COG north RMS error [cm]", "pos_e_cm": "COG east RMS error [cm]", "pos_d_cm": "COG down RMS error [cm]",
    **{f"raw_gnss_{a}_cm": f"COG {w} from the antennas alone (raw GNSS), RMS error [cm]"
       for a, w in zip("ned", ("north", "east", "down"))},
    "heave_cm": "heave at the IMU, RMS error [cm]", "heave_std_cm": "true heave std at the IMU [cm]",
    "point_heave_cm": "heave at the point, RMS error [cm]", "point_heave_std_cm": "true heave std at the point [cm]",
    "cr_x_m": "centre of rotation x, RMS error [m]", "cr_y_m": "centre of rotation y, RMS error [m]",
    "cr_z_m": "centre of rotation z, RMS error [m]",
    "disp_n_cm": "COG north (window centre, delay s late), RMS error [cm]",
    "disp_e_cm": "COG east (window centre, delay s late), RMS error [cm]",
    "disp_d_cm": "COG down (window centre, delay s late), RMS error [cm]",
    **{f"{p}{d}{a}_cm": f"{a} at the {where}{', delayed' if d else ''}, RMS error [cm]"
       for p, where in (("", "IMU"), ("point_", "point")) for d in ("", "delayed_") for a in ("surge", "sway", "heave")},
    **{f"{p}{a}_std_cm": f"true {a} std at the {where} [cm]" for p, where in (("", "IMU"), ("point_", "point"))
       for a in ("surge", "sway", "heave")},
    "point_3d_cm": "point position (3-D), RMS length of the error [cm]",
    "point_distance_m": "point's distance from the IMU [m]",
    "valid_fraction": "fraction of the run with valid output", "scored_s": "time scored [s]",
    "tip_heave_cm": "crane-tip heave std [cm]", "load_heave_cm": "load heave std [cm]",
    "residual_pct": "load heave / tip heave [%]", "tip_motion_cm": "crane-tip vertical motion std, all frequencies [cm]",
    "load_motion_cm": "load vertical motion std, all frequencies [cm]",
    "residual_total_pct": "load / tip vertical motion, all frequencies [%]",
    "vs_ideal": "residual / residual of the truth-fed loop", "vs_classical": "residual / residual of the classical-fed loop",
    "limited_pct": "time with a winch limit acting [%]",
    **{f"{n}_pct": f"time {n.replace('_', ' ')} [%]" for n in ("speed_limited", "acc_limited", "stroke_limited", "slack")},
}


def figure_png(fig) -> str:
    """A matplotlib figure as a base64 PNG for an ``<img>`` tag (the figure is closed)."""
    import matplotlib.pyplot as plt

    buf = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return base64.b64encode(buf.getvalue()).decode()


def _diagram(system: SystemDescription, plt) -> str:
    """Boxes for the components (sources left, consumers right) and one arrow per linked pair."""
    feeds: dict[tuple[str, str], int] = {}
    for c in system.connections:
        feeds[(c.start, c.end)] = feeds.get((c.start, c.end), 0) + 1
    level = {c.name: 0 for c in system.components}
    for _ in system.components:            # longest path from a source
        for (a, b) in feeds:
            level[b] = max(level[b], level[a] + 1)
    columns: dict[int, list[str]] = {}
    for name in level:
        columns.setdefault(level[name], []).append(name)
    pos = {n: (3.2 * lv, -1.2 * i + 0.6 * (len(col) - 1)) for lv, col in columns.items() for i, n in enumerate(col)}
    fig, ax = plt.subplots(figsize=(10, 1.2 + 1.1 * max(len(c) for c in columns.values())))
    kinds = {c.name: c.kind for c in system.components}
    for (a, b), n in feeds.items():
        (xa, ya), (xb, yb) = pos[a], pos[b]
        ax.annotate("", xy=(xb - 1.1, yb), xytext=(xa + 1.1, ya), arrowprops={"arrowstyle": "->", "color": "0.4"})
        ax.text((xa + xb) / 2, (ya + yb) / 2 + 0.1, f"{n}", fontsize=7, color="0.4", ha="center")
    for n, (x, y) in pos.items():
        ax.add_patch(plt.Rectangle((x - 1.1, y - 0.4), 2.2, 0.8, fc="#e8f0fa", ec="#3060a0"))
        ax.text(x, y + 0.1, n, ha="center", fontsize=10, weight="bold")
        ax.text(x, y - 0.22, kinds[n], ha="center", fontsize=8)
    ax.set_xlim(-1.4, 3.2 * max(columns) + 1.4)
    ax.set_ylim(min(p[1] for p in pos.values()) - 0.7, max(p[1] for p in pos.values()) + 0.7)
    ax.axis("off")
    ax.set_title("System: boxes are FMU instances, arrows carry the number of connected variables", fontsize=9)
    return figure_png(fig)


def _figures(result: np.ndarray, system: SystemDescription, vessel: str, plt) -> list[tuple[str, str]]:
    t = np.asarray(result["time"], dtype=float)
    last = t >= t[-1] - 60.0
    fields = set(result.dtype.names)

    def g(name: str) -> np.ndarray:
        return np.asarray(result[name], dtype=float)

    out = []
    for comp in system.components:
        kind, c, v = comp.kind, comp.name, vessel
        if kind == "AttitudeEstimator" and f"{c}.roll" in fields:
            fig, ax = plt.subplots(2, 1, figsize=(10, 5.5))
            for a, col in (("roll", "tab:blue"), ("pitch", "tab:orange")):
                ax[0].plot(t[last], np.degrees(g(f"{v}.truth.{a}")[last]), color=col, lw=2, alpha=0.4, label=f"true {a}")
                ax[0].plot(t[last], np.degrees(g(f"{c}.{a}")[last]), color=col, lw=0.9, label=f"estimated {a}")
                ax[1].plot(t, np.degrees(g(f"{c}.{a}") - g(f"{v}.truth.{a}")), color=col, lw=0.6, label=a)
            ax[0].set_ylabel("angle [deg]")
            ax[0].legend(loc="upper right", ncol=4, fontsize=8)
            ax[1].set_ylabel("error [deg]")
            ax[1].set_xlabel("time [s]")
            ax[1].legend(loc="upper right", fontsize=8)
            settled = t >= t[0] + 60.0
            if settled.any():     # scale to the settled error, not the start transient
                worst = max(float(np.max(np.abs(np.degrees(g(f"{c}.{a}") - g(f"{v}.truth.{a}"))[settled])))
                            for a in ("roll", "pitch"))
                if math.isfinite(worst) and worst > 0:
                    ax[1].set_ylim(-1.5 * worst, 1.5 * worst)
            out.append((f"{c}: roll and pitch, the last minute and the error over the run", figure_png(fig)))
        elif kind == "HeaveObserver" and f"{c}.heave" in fields:
            valid = np.asarray(result[f"{c}.valid"], dtype=bool)
            fig, ax = plt.subplots(2, 1, figsize=(10, 5.5), sharex=True)
            for i, (est, truth, label) in enumerate(((f"{c}.heave", f"{v}.truth.imu.d", "IMU"),
                                                     (f"{c}.point.heave", f"{v}.truth.point.d", "monitoring point"))):
                if est not in fields or truth not in fields:
                    continue
                tr = g(truth)
                tr = tr - tr[valid].mean() if valid.any() else tr
                ax[i].plot(t[last], -tr[last], "k", lw=2, alpha=0.4, label="truth")
                ax[i].plot(t[last], -g(est)[last], lw=0.9, label="real-time estimate")
                ax[i].set_ylabel(f"heave at the {label} [m, up]")
                ax[i].legend(loc="upper right", fontsize=8)
            ax[1].set_xlabel("time [s]")
            out.append((f"{c}: heave in real time against the truth, the last minute", figure_png(fig)))
            if valid.sum() > 2048:
                from scipy import signal

                dt = t[1] - t[0]
                tr = g(f"{v}.truth.imu.d")[valid]
                seg = min(int(valid.sum()), int(round(200.0 / dt)))       # 200 s segments: 0.03 rad/s bins
                f, p_true = signal.welch(tr - tr.mean(), fs=1.0 / dt, nperseg=seg)
                _, p_est = signal.welch(g(f"{c}.heave")[valid], fs=1.0 / dt, nperseg=seg)
                _, p_err = signal.welch(g(f"{c}.heave")[valid] - (tr - tr.mean()), fs=1.0 / dt, nperseg=seg)
                fig, ax = plt.subplots(figsize=(10, 3.8))
                w = 2 * math.pi * f
                for p, label in ((p_true, "truth"), (p_est, "estimate"), (p_err, "error")):
                    ax.semilogy(w[1:], p[1:], lw=1.2, label=label)
                ax.set_xlim(0, 3)
                ax.set_ylim(1e-7 * p_true.max(), 3 * p_true.max())
                ax.set_xlabel("ω [rad/s]")
                ax.set_ylabel("heave PSD [m²/Hz]")
                ax.legend(fontsize=8)
                out.append((f"{c}: heave spectra at the IMU (Welch) while valid", figure_png(fig)))
        elif kind == "GnssAccFusion" and f"{c}.pos.d" in fields:
            fig, ax = plt.subplots(2, 1, figsize=(10, 5.5))
            for a, col in (("n", "tab:blue"), ("e", "tab:orange"), ("d", "tab:green")):
                ax[0].plot(t[last], g(f"{v}.truth.cog.{a}")[last], color=col, lw=2, alpha=0.4, label=f"true {a}")
                ax[0].plot(t[last], g(f"{c}.pos.{a}")[last], color=col, lw=0.9, label=f"fused {a}")
                ax[1].plot(t, 100 * (g(f"{c}.pos.{a}") - g(f"{v}.truth.cog.{a}")), color=col, lw=0.6, label=a)
            ax[0].set_ylabel("COG position [m, NED]")
            ax[0].legend(loc="upper right", ncol=3, fontsize=8)
            ax[1].set_ylabel("error [cm]")
            ax[1].set_ylim(-5, 5)
            ax[1].set_xlabel("time [s]")
            ax[1].legend(loc="upper right", fontsize=8)
            out.append((f"{c}: GNSS + accelerometer fused COG position, the last minute and the error", figure_png(fig)))
        elif kind == "CentreOfRotation" and f"{c}.cr.x" in fields:
            fig, ax = plt.subplots(figsize=(10, 3.8))
            for a in "xyz":
                line, = ax.plot(t, g(f"{c}.cr.{a}"), lw=1.0, label=f"estimated {a}")
                if f"{v}.truth.cr.{a}" in fields and np.asarray(result[f"{v}.truth.cr.defined"], dtype=bool).any():
                    ax.plot(t, g(f"{v}.truth.cr.{a}"), "--", color=line.get_color(), lw=1.0, label=f"true {a}")
            ax.set_ylabel("centre of rotation [m, body, from COG]")
            ax.set_xlabel("time [s]")
            ax.legend(loc="upper right", ncol=3, fontsize=8)
            out.append((f"{c}: convergence of the centre of rotation (settled running mean)", figure_png(fig)))
        elif kind == "DisplacementReconstructor" and f"{c}.disp.d" in fields and f"{c}.delay" in fields:
            delay = float(g(f"{c}.delay")[-1])
            lag = int(round(delay / (t[1] - t[0])))
            valid = np.asarray(result[f"{c}.valid"], dtype=bool)
            window = last & valid
            if window.any() and lag < len(t):
                fig, ax = plt.subplots(figsize=(10, 3.8))
                k = np.flatnonzero(window)
                k = k[k >= lag]
                for a, col in (("n", "tab:blue"), ("e", "tab:orange"), ("d", "tab:green")):
                    truth, est = g(f"{v}.truth.cog.{a}")[k - lag], g(f"{c}.disp.{a}")[k]
                    ax.plot(t[k - lag], truth - truth.mean(), color=col, lw=2, alpha=0.4, label=f"true COG {a}")
                    ax.plot(t[k - lag], est - est.mean(), color=col, lw=0.9, label=f"reconstructed {a}")
                ax.set_ylabel("displacement about the mean [m, NED]")
                ax.set_xlabel(f"time [s] (the estimate is available {delay:g} s later)")
                ax.legend(loc="upper right", ncol=3, fontsize=8)
                out.append((f"{c}: COG displacement reconstructed from acceleration alone (no GNSS), at the "
                            f"window centre, {delay:g} s behind real time", figure_png(fig)))
        elif kind == "MotionReferenceUnit" and f"{c}.motion.valid" in fields:
            fig = _mru_figure(result, system, c, v, plt)
            if fig is not None:
                out.append(fig)
    winches = [c.name for c in system.components if c.kind == "AhcWinch" and f"{c.name}.load.d" in fields]
    tip = f"{vessel}.truth.point.d"
    if winches and tip in fields:
        fig, ax = plt.subplots(figsize=(10, 3.8))
        ax.plot(t[last], -(g(tip)[last] - g(tip)[last].mean()), "k", lw=2, alpha=0.4, label="crane tip")
        for w in winches:
            load = g(f"{w}.load.d")[last]
            ax.plot(t[last], -(load - load.mean()), lw=0.9, label=f"load, {w}")
        ax.set_ylabel("vertical motion about the mean [m, up]")
        ax.set_xlabel("time [s]")
        ax.legend(loc="upper right", ncol=3, fontsize=8)
        out.append(("heave compensation: the crane tip and each winch's load, the last minute", figure_png(fig)))
    return out


def _mru_figure(result: np.ndarray, system: SystemDescription, c: str, v: str, plt) -> tuple[str, str] | None:
    """A MotionReferenceUnit at the vessel's point (:func:`~.scoring.mru_point`): surge, sway
    and heave over the last minute, the truth against the real-time and the delayed outputs
    (each drawn at the time it refers to), and the 3-D error over the run; None without the
    point's outputs and truth recorded."""
    from .scoring import mru_arm, mru_point

    fields = set(result.dtype.names)
    prefix = mru_point(system, c, v)
    names = [f"{c}.{prefix}{a}" for a in ("surge", "sway", "heave")] + [f"{v}.truth.point.{a}" for a in "ned"]
    if prefix is None or not all(n in fields for n in names):
        return None
    t = np.asarray(result["time"], dtype=float)
    valid = np.asarray(result[f"{c}.motion.valid"], dtype=bool)
    if not valid.any() or len(t) < 3:
        return None
    dt = t[1] - t[0]
    has_delayed = f"{c}.delayed.delay" in fields and f"{c}.{prefix}delayed.heave" in fields
    lag = int(round(float(result[f"{c}.delayed.delay"][-1]) / dt)) if has_delayed else 0
    # Jacobi coupling: the row k + 1 output is computed from the vessel's row k; the delayed output
    # for row k comes lag rows later. The window: the last minute the delayed output has reached.
    end = len(t) - 1 - lag - 1
    k = np.arange(max(0, end - int(round(60.0 / dt))), end)
    k = k[valid[k]]
    fig, ax = plt.subplots(4, 1, figsize=(10, 9.5))
    err = np.zeros(len(t) - 1)
    for i, (axis, ned) in enumerate((("surge", "n"), ("sway", "e"), ("heave", "d"))):
        truth = np.asarray(result[f"{v}.truth.point.{ned}"], dtype=float)
        truth = truth - truth[valid].mean()
        est = np.asarray(result[f"{c}.{prefix}{axis}"], dtype=float)
        e = est[1:] - truth[:-1]
        e -= e[valid[1:]].mean()
        err += e ** 2
        ax[i].plot(t[k], truth[k], "k", lw=2, alpha=0.4, label="truth")
        ax[i].plot(t[k], est[k + 1], lw=0.9, label="real time")
        if has_delayed:
            delayed = np.asarray(result[f"{c}.{prefix}delayed.{axis}"], dtype=float)
            ax[i].plot(t[k], delayed[k + 1 + lag], "--", lw=0.9, label=f"delayed (given {lag * dt:g} s later)")
        ax[i].set_ylabel(f"{axis} [m, {'down' if ned == 'd' else 'level frame'}]")
        ax[i].legend(loc="upper right", ncol=3, fontsize=8)
    ax[2].set_xlabel("time [s]")
    ok = valid[1:]
    ax[3].plot(t[:-1][ok], 100 * np.sqrt(err[ok]), lw=0.5, color="tab:red")
    ax[3].set_ylabel("3-D error, real time [cm]")
    ax[3].set_xlabel("time [s]")
    distance = float(np.linalg.norm(mru_arm(system, c, prefix)))
    return (f"{c}: three-axis motion of monitoring point {prefix.rstrip('.')} ({distance:.1f} m from the IMU) "
            "about its mean, truth against the real-time and the delayed outputs over the last minute the delayed output "
            "covers, and the real-time 3-D error over the run", figure_png(fig))


def accuracy_rows(system: SystemDescription, scores: dict[str, dict[str, float]]) -> list[tuple[str, str, float, str, str]]:
    """(component, metric label, value, goal, status) rows of the accuracy table; status is
    ``met``, ``not met`` or empty for a metric without a goal."""
    kinds = {c.name: c.kind for c in system.components}
    rows = []
    for comp, metrics in scores.items():
        for metric, value in metrics.items():
            goal = GOALS.get((kinds[comp], metric))
            verdict = None if goal is None or not math.isfinite(value) else goal[1](metrics)
            status = "" if verdict is None else ("met" if verdict else "not met")
            rows.append((comp, LABELS.get(metric, metric), value, goal[0] if goal else "", status))
    return rows


def write_report(result: np.ndarray, system: SystemDescription, scores: dict[str, dict[str, float]], vessel: str,
                 out_dir: str | Path, title: str, description: str) -> Path:
    """Write ``report.html`` in ``out_dir`` (module docstring); return its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t = np.asarray(result["time"], dtype=float)
    rows = accuracy_rows(system, scores)
    table = "\n".join(
        f"<tr><td>{html.escape(c)}</td><td>{html.escape(m)}</td><td class='num'>{v:.4g}</td>"
        f"<td>{html.escape(g)}</td><td class='{s.replace(' ', '')}'>{s}</td></tr>" for c, m, v, g, s in rows)
    figures = [("system", _diagram(system, plt))] + _figures(result, system, vessel, plt)
    body = "\n".join(f"<figure><img src='data:image/png;base64,{png}'><figcaption>{html.escape(cap)}</figcaption></figure>"
                     for cap, png in figures)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>
body {{ font-family: sans-serif; max-width: 1000px; margin: 2em auto; color: #222; }}
table {{ border-collapse: collapse; margin: 1em 0; }} td, th {{ border: 1px solid #ccc; padding: 3px 8px; }}
td.num {{ text-align: right; font-family: monospace; }} td.met {{ color: #176b2c; font-weight: bold; }}
td.notmet {{ color: #a01818; font-weight: bold; }} figure {{ margin: 1.5em 0; }} img {{ max-width: 100%; }}
figcaption {{ font-size: 0.9em; color: #555; }}
</style></head><body>
<h1>{html.escape(title)}</h1>
<p>{html.escape(description)}</p>
<p>{len(system.components)} FMUs, {len(system.connections)} connections, {t[-1] - t[0]:g} s simulated at a
{system.step:g} s base step. Estimates are scored against the exact truth of <b>{html.escape(vessel)}</b>
from 60 s after each estimator first reports <code>valid</code>, on its valid samples (RMS errors).</p>
<h2>Accuracy against the goals</h2>
<table><tr><th>component</th><th>quantity</th><th>value</th><th>goal</th><th></th></tr>
{table}
</table>
<h2>Figures</h2>
{body}
</body></html>
"""
    path = out / "report.html"
    path.write_text(page, encoding="utf-8")
    return path
