"""The ``campaign`` part of ``marinefmu bench`` (issue 10): how a campaign scales on Dask.

- **Throughput**: the same 8 runs (the ``system`` scenario, :data:`RUN_S` simulated seconds
  each, Hs × Tp × seed) on a local cluster of 1 and of 2 workers, in runs per hour from the
  first submission to the last result. Goal: 2 workers ≥ 1.8 × 1 worker.
- **Engine overhead per run** (scheduling, serialisation, result transfer, table writing): on
  the 1-worker cluster, the wall time between first submission and last result minus the time
  the worker spent inside the runs (each run's own ``wall_s``), per run; against the wall time
  of a 10-minute run (the runs' simulation time scaled to 600 s). Goal ≤ 5 %.
- **Memory per worker**: 100 runs of :data:`MEMORY_RUN_S` s (100 seeds) on 2 workers; each
  run reports its worker's resident memory after it (``rss_mb``). Per worker: the growth from
  the mean of its first five runs to the mean of its last five, and the least-squares slope.
  Goal: flat, here read as under :data:`FLAT_MB` MB of growth over the 100 runs.
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np

#: Simulated time of each throughput run [s].
RUN_S = 60.0
#: Simulated time of each memory run [s].
MEMORY_RUN_S = 10.0
#: Largest growth of a worker's memory over the 100 runs still called flat [MB].
FLAT_MB = 10.0
_THROUGHPUT = """
[campaign]
name = "bench_throughput"
scenario = "system"
duration = {duration}
settle = 5.0
metrics = ["att.roll_deg", "fusion.pos_d_cm"]
[grid]
"vessel.sea.hs" = [1.0, 2.0]
"vessel.sea.tp" = [6.0, 9.0]
"vessel.sea.seed" = [1, 2]
"""
_MEMORY = """
[campaign]
name = "bench_memory"
scenario = "system"
duration = {duration}
settle = 1.0
metrics = ["att.roll_deg"]
[grid]
"vessel.sea.seed" = {{ start = 1, stop = 100, step = 1 }}
"""


def campaign_bench(fmu_dir: Path, work: Path | None = None) -> dict:
    """Run the three measurements (module docstring); return them as a JSON-able dict."""
    from .campaign import parse_spec, run_campaign
    from .campaign.table import read_log

    work = Path(work or tempfile.mkdtemp(prefix="marinefmu_bench_campaign_"))
    shutil.rmtree(work, ignore_errors=True)
    spec = parse_spec(_THROUGHPUT.format(duration=RUN_S), fmu_dir, "bench throughput")
    runs: dict[int, dict] = {}
    for n in (1, 2):
        out = work / f"throughput_{n}"
        o = run_campaign(spec, out, fmu_dir, workers=n, progress=False)
        recs = list(read_log(out).values())
        runs[n] = {"workers": n, "runs": o.ran, "failed": o.failed, "wall_s": o.wall_s, "runs_per_hour": o.ran / o.wall_s * 3600,
                   "mean_run_s": float(np.mean([r["run_s"] for r in recs])),
                   "mean_task_s": float(np.mean([r["wall_s"] for r in recs]))}
        print(f"  campaign, {o.ran} runs of {RUN_S:g} s on {n} worker(s): {o.wall_s:.1f} s, "
              f"{runs[n]['runs_per_hour']:.0f} runs/h ({o.failed} failed)")
    one = runs[1]
    overhead = (one["wall_s"] - one["runs"] * one["mean_task_s"]) / one["runs"]
    ten_minutes = one["mean_run_s"] / RUN_S * 600.0
    speedup = runs[2]["runs_per_hour"] / one["runs_per_hour"]
    print(f"  2 workers / 1 worker: {speedup:.2f} (goal >= 1.8); engine overhead {overhead:.3f} s per run, "
          f"{100 * overhead / ten_minutes:.2f} % of a 10-minute run ({ten_minutes:.0f} s) (goal <= 5 %)")

    mem_spec = parse_spec(_MEMORY.format(duration=MEMORY_RUN_S), fmu_dir, "bench memory", check_values=False)
    out = work / "memory"
    o = run_campaign(mem_spec, out, fmu_dir, workers=2, progress=False)
    recs = list(read_log(out).values())   # in the order they finished
    workers = {}
    for w in sorted({r["worker"] for r in recs}):
        rss = np.array([r["rss_mb"] for r in recs if r["worker"] == w], dtype=float)
        slope = float(np.polyfit(np.arange(rss.size), rss, 1)[0]) if rss.size > 1 else 0.0
        workers[w] = {"runs": int(rss.size), "first_mb": float(rss[:5].mean()), "last_mb": float(rss[-5:].mean()),
                      "growth_mb": float(rss[-5:].mean() - rss[:5].mean()), "slope_mb_per_run": slope}
        print(f"  campaign memory, worker {w}: {rss.size} runs, {workers[w]['first_mb']:.1f} -> "
              f"{workers[w]['last_mb']:.1f} MB (slope {1000 * slope:.1f} kB/run)")
    flat = all(v["growth_mb"] <= FLAT_MB for v in workers.values())
    shutil.rmtree(work, ignore_errors=True)
    return {"throughput": runs, "speedup_2_over_1": speedup, "speedup_goal": 1.8, "overhead_s_per_run": overhead,
            "ten_minute_run_s": ten_minutes, "overhead_pct_of_10_min": 100 * overhead / ten_minutes, "overhead_goal_pct": 5.0,
            "memory": {"runs": o.ran, "failed": o.failed, "run_s": MEMORY_RUN_S, "workers": workers, "flat": flat,
                       "flat_mb": FLAT_MB}}
