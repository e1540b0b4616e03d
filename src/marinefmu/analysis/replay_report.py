"""Scores and the HTML report of a replay (``marinefmu replay``): estimates on a recording.

Where the record holds a reference signal (``rec.ref.*``), each estimate is scored against it:

================================  =====================================  ==========
estimate                          reference                              about mean
================================  =====================================  ==========
``att.roll``, ``att.pitch``       ``ref.roll``, ``ref.pitch``            no
``heave.heave``                   ``ref.heave`` (at the IMU, down)       yes
``heave.point.heave``             ``ref.point.d``                        yes
``fusion.pos.{n,e,d}``            ``ref.cog.{n,e,d}``                    no
``recon.disp.*``                  ``ref.cog.*``                          yes
================================  =====================================  ==========

(``recon.disp.*`` are the window-centre estimate, ``recon.delay`` s late) on the steps where the
estimator's ``valid`` and the reference's ``valid`` are both true, from
``settle`` s after the estimator first turned valid. A recorded reference and an estimate made
from the same record can be offset in time (the co-simulation's one-step coupling, a sensor's
own latency, a centred estimate's delay): each score is **lag-aligned**, the estimate compared
with the reference ``lag`` earlier, the lag (≥ 0) that minimises the RMS error, found by
cross-correlation and refined on the RMS itself; the report states it, with the RMS at lag 0.

Where a reference is missing, the report shows the estimates, their spectra and the validity
timeline. In every case it states, per sensor, how many samples of the record were bad, how many
gaps were longer than ``max_gap``, and on how many steps the sensor's ``valid`` was false.
"""
from __future__ import annotations

import html
from pathlib import Path

import numpy as np

from ..cosim.replay import REC, ReplayPlan
from .html_report import figure_png

#: (estimate, reference, reference valid, about the mean, what, unit of the score, factor from SI).
PAIRS: tuple[tuple[str, str, str, bool, str, str, float], ...] = (
    ("att.roll", "ref.roll", "ref.roll.valid", False, "roll", "deg", 180.0 / np.pi),
    ("att.pitch", "ref.pitch", "ref.pitch.valid", False, "pitch", "deg", 180.0 / np.pi),
    ("heave.heave", "ref.heave", "ref.heave.valid", True, "heave at the IMU", "cm", 100.0),
    ("heave.point.heave", "ref.point.d", "ref.point.valid", True, "heave at the point", "cm", 100.0),
    *((f"fusion.pos.{a}", f"ref.cog.{a}", "ref.cog.valid", False, f"COG position {a}", "cm", 100.0) for a in "ned"),
    *((f"recon.disp.{a}", f"ref.cog.{a}", "ref.cog.valid", True, f"COG displacement {a}", "cm", 100.0)
      for a in "ned"),
)


def _f(result: np.ndarray, name: str) -> np.ndarray:
    return np.asarray(result[name], dtype=float)


def best_lag(est: np.ndarray, ref: np.ndarray, max_lag: int) -> tuple[int, float, float]:
    """(lag ≥ 0 in samples, RMS at that lag, RMS at lag 0) of ``est[k] − ref[k − lag]``.

    Both arrays are already restricted to a contiguous span; ``max_lag`` bounds the search."""
    n = len(est)
    max_lag = max(0, min(max_lag, n // 2))

    def rms(lag: int) -> float:
        e = est[lag:] - ref[:n - lag]
        return float(np.sqrt(np.mean(e ** 2)))

    a, b = est - est.mean(), ref - ref.mean()
    size = 1 << int(np.ceil(np.log2(2 * n)))
    xc = np.fft.irfft(np.fft.rfft(a, size) * np.conj(np.fft.rfft(b, size)), size)[:max_lag + 1]
    guess = int(np.argmax(xc)) if len(xc) else 0
    candidates = {0, *range(max(0, guess - 3), min(max_lag, guess + 3) + 1)}
    lag = min(candidates, key=rms)
    return lag, rms(lag), rms(0)


def replay_scores(result: np.ndarray, plan: ReplayPlan, settle: float = 60.0, max_lag_s: float = 120.0) -> dict[str, dict]:
    """Each estimate against its reference (module docstring).

    Returns
    -------
    dict
        Estimate name → ``{"what", "unit", "rms", "rms_lag0", "lag_s", "scored_s", "from_s"}``;
        only the pairs whose estimate ran and whose reference the record has.
    """
    t = _f(result, "time")
    names = set(result.dtype.names)
    dt = plan.system.step
    out: dict[str, dict] = {}
    for est, ref, ref_valid, about_mean, what, unit, factor in PAIRS:
        comp = est.split(".")[0]
        if est not in names or f"{REC}.{ref}" not in names or ".".join(ref.split(".")[:2]) not in _ref_groups(plan):
            continue
        ok = np.asarray(result[f"{comp}.valid"], dtype=bool) & np.asarray(result[f"{REC}.{ref_valid}"], dtype=bool)
        if not ok.any():
            continue
        k0 = int(np.argmax(np.asarray(result[f"{comp}.valid"], dtype=bool)))
        k0 = int(np.searchsorted(t, t[k0] + settle))
        span = np.flatnonzero(ok[k0:]) + k0
        if len(span) < 10:
            continue
        lo, hi = span[0], span[-1] + 1
        e, r = _f(result, est)[lo:hi], _f(result, f"{REC}.{ref}")[lo:hi]
        keep = ok[lo:hi]
        e, r = np.where(keep, e, np.nan), np.where(keep, r, np.nan)
        e, r = _fill(e), _fill(r)
        if about_mean:
            e, r = e - e.mean(), r - r.mean()
        lag, rms, rms0 = best_lag(e, r, int(round(max_lag_s / dt)))
        out[est] = {"what": what, "unit": unit, "rms": rms * factor, "rms_lag0": rms0 * factor, "lag_s": lag * dt,
                    "scored_s": (hi - lo) * dt, "from_s": float(t[lo])}
    return out


def _fill(x: np.ndarray) -> np.ndarray:
    """NaN (an invalid step inside the span) filled by the nearest earlier value."""
    bad = np.isnan(x)
    if not bad.any():
        return x
    idx = np.where(~bad, np.arange(len(x)), 0)
    np.maximum.accumulate(idx, out=idx)
    return x[idx]


def _ref_groups(plan: ReplayPlan) -> set[str]:
    return {g for g in plan.mapping.channels if g.startswith("ref.")}


def validity_counts(result: np.ndarray, plan: ReplayPlan) -> list[tuple[str, int, int, int, int, float]]:
    """Per sensor of the record: (group, samples, bad samples, gaps > max_gap, steps with valid
    false, longest interval [s])."""
    s = plan.summary
    rows = []
    from ..sea.recording.schema import GROUP

    for g in plan.mapping.channels:
        v = f"{REC}.{GROUP[g].valid}"
        steps = int((~np.asarray(result[v], dtype=bool)).sum()) if v in result.dtype.names else -1
        rows.append((g, s.samples[g], s.bad[g], s.gaps[g], steps, s.max_interval[g]))
    return rows


def _figures(result: np.ndarray, plan: ReplayPlan, scores: dict[str, dict], plt) -> list[tuple[str, str]]:
    from scipy.signal import welch

    t = _f(result, "time")
    dt = plan.system.step
    figs = []
    names = set(result.dtype.names)
    for est, sc in scores.items():
        pair = next(p for p in PAIRS if p[0] == est)
        ref, factor = f"{REC}.{pair[1]}", pair[6]
        e, r = _f(result, est) * factor, _f(result, ref) * factor
        if pair[3]:
            e, r = e - np.nanmean(e), r - np.nanmean(r)
        lag = int(round(sc["lag_s"] / dt))
        fig, ax = plt.subplots(figsize=(9, 2.6))
        ax.plot(t, r, lw=0.8, label=f"reference {pair[1]}")
        ax.plot(t - sc["lag_s"], e, lw=0.8, label=f"{est} (shifted back by the lag {sc['lag_s']:.3g} s)")
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"[{sc['unit']}]")
        ax.legend(fontsize=7, loc="upper right")
        figs.append((f"{est} against {pair[1]}: RMS {sc['rms']:.4g} {sc['unit']} at lag {sc['lag_s']:.3g} s "
                     f"({lag} step(s))", figure_png(fig)))
    unscored = [n for n in names if n.split(".")[0] in plan.estimators and n not in scores
                and result[n].dtype != bool and n.split(".", 1)[1] in _SHOWN]
    if unscored:
        fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 3))
        for n in sorted(unscored):
            x = _f(result, n)
            a1.plot(t, x, lw=0.7, label=n)
            if len(x) > 64:
                f, p = welch(x - x.mean(), fs=1.0 / dt, nperseg=min(len(x), 4096))
                a2.semilogy(f[1:], p[1:], lw=0.7, label=n)
        a1.set_xlabel("time [s]")
        a2.set_xlabel("frequency [Hz]")
        a2.set_ylabel("PSD")
        a1.legend(fontsize=6)
        figs.append(("estimates without a reference in the record, and their spectra (Welch)", figure_png(fig)))
    flags = sorted(n for n in names if n.endswith("valid") and (n.split(".")[0] in plan.estimators or
                   (n.startswith(f"{REC}.") and _mapped_flag(plan, n))))
    if flags:
        fig, ax = plt.subplots(figsize=(9, 0.35 * len(flags) + 1))
        for i, n in enumerate(flags):
            v = np.asarray(result[n], dtype=bool)
            ax.fill_between(t, i + 0.1, i + 0.9, where=v, step="post", color="#3a7d44", lw=0)
            ax.fill_between(t, i + 0.1, i + 0.9, where=~v, step="post", color="#c0392b", lw=0)
        ax.set_yticks(np.arange(len(flags)) + 0.5, flags, fontsize=7)
        ax.set_xlabel("time [s]")
        figs.append(("validity timeline (green valid, red not)", figure_png(fig)))
    return figs


_SHOWN = {"roll", "pitch", "yaw", "heave", "point.heave", "pos.n", "pos.e", "pos.d", "disp.n",
          "disp.e", "disp.d", "cr.x", "cr.y", "cr.z"}


def _mapped_flag(plan: ReplayPlan, name: str) -> bool:
    from ..sea.recording.schema import GROUP

    flag = name.split(".", 1)[1]
    return any(GROUP[g].valid == flag for g in plan.mapping.channels)


def write_replay_report(result: np.ndarray, plan: ReplayPlan, scores: dict[str, dict], out_dir: str | Path,
                        title: str) -> Path:
    """Write ``report.html`` in ``out_dir`` (module docstring); return its path."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t = _f(result, "time")
    esc = html.escape
    score_rows = "\n".join(
        f"<tr><td>{esc(n)}</td><td>{esc(s['what'])}</td><td class='num'>{s['rms']:.4g} {esc(s['unit'])}</td>"
        f"<td class='num'>{s['lag_s']:.4g} s</td><td class='num'>{s['rms_lag0']:.4g} {esc(s['unit'])}</td>"
        f"<td class='num'>{s['from_s']:.4g} s, {s['scored_s']:.4g} s</td></tr>" for n, s in scores.items())
    valid_rows = "\n".join(
        f"<tr><td>{esc(g)}</td><td class='num'>{n}</td><td class='num'>{bad}</td><td class='num'>{gaps}</td>"
        f"<td class='num'>{steps}</td><td class='num'>{iv:.4g} s</td></tr>"
        for g, n, bad, gaps, steps, iv in validity_counts(result, plan))
    notes = "".join(f"<li>{esc(n)}</li>" for n in plan.notes)
    figures = "\n".join(f"<figure><img src='data:image/png;base64,{png}'><figcaption>{esc(cap)}</figcaption></figure>"
                        for cap, png in _figures(result, plan, scores, plt))
    scored = (f"<table><tr><th>estimate</th><th>quantity</th><th>RMS error</th><th>lag</th><th>RMS at lag 0</th>"
              f"<th>scored from, length</th></tr>\n{score_rows}</table>") if scores else \
        "<p>The record has no reference signal for these estimates: the figures show the estimates, their spectra and the validity timeline.</p>"
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{esc(title)}</title>
<style>
body {{ font-family: sans-serif; max-width: 1000px; margin: 2em auto; color: #222; }}
table {{ border-collapse: collapse; margin: 1em 0; }} td, th {{ border: 1px solid #ccc; padding: 3px 8px; }}
td.num {{ text-align: right; font-family: monospace; }} figure {{ margin: 1.5em 0; }} img {{ max-width: 100%; }}
figcaption {{ font-size: 0.9em; color: #555; }}
</style></head><body>
<h1>{esc(title)}</h1>
<p>Record {esc(str(plan.record.path))} ({plan.summary.rows:,} rows, {plan.summary.duration:.6g} s from its first time stamp
{esc(plan.summary.start_time)}), mapping {esc(plan.mapping.source)}; estimators {esc(', '.join(plan.estimators))};
{t[-1] - t[0]:.6g} s simulated at a {plan.system.step:.6g} s step.</p>
<ul>{notes}</ul>
<h2>Estimates against the record's reference</h2>
<p>RMS errors on the steps where the estimate and the reference are both valid, from 60 s after the estimator first turned
valid; lag-aligned: the estimate compared with the reference <i>lag</i> earlier (the lag that minimises the error).</p>
{scored}
<h2>The record's sensors</h2>
<table><tr><th>sensor</th><th>samples</th><th>bad samples (NaN, Inf, missing field, flagged invalid)</th>
<th>gaps &gt; max_gap</th><th>steps with valid false</th><th>longest interval</th></tr>
{valid_rows}</table>
<h2>Figures</h2>
{figures}
</body></html>
"""
    path = out / "report.html"
    path.write_text(page, encoding="utf-8")
    return path


#: Longest result also written as CSV [rows] (as ``marinefmu simulate``).
CSV_MAX_ROWS = 360_001


def replay_and_report(plan: ReplayPlan, fmu_dir: str | Path, out_dir: str | Path, engine: str = "fmpy",
                      progress: bool | None = None, settle: float = 60.0) -> dict:
    """Run a replay, write ``results.npy`` (and ``results.csv`` up to :data:`CSV_MAX_ROWS`
    rows), score it and write ``report.html``; return what was written and measured."""
    import time

    from ..cosim.replay import run_replay
    from ..cosim.system import save_csv

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    result, runner = run_replay(plan, fmu_dir, out, engine=engine, progress=progress)
    wall = time.perf_counter() - t0
    csv = save_csv(result, out / "results.csv") if result.size <= CSV_MAX_ROWS else None
    scores = replay_scores(result, plan, settle=settle)
    page = write_replay_report(result, plan, scores, out, f"marinefmu replay: {plan.record.path.name}")
    return {"result": result, "npy": out / "results.npy", "csv": csv, "report": page, "scores": scores,
            "validity": validity_counts(result, plan), "wall_s": wall, "messages": runner.messages}
