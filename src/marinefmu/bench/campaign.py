"""The ``campaign`` part of ``marinefmu bench``: how a campaign scales on Dask.

- **Throughput**: the same 8 runs (the ``system`` scenario, :data:`RUN_S` simulated seconds
  each, Hs × Tp × seed) on a local cluster of 1 and of 2 workers, in runs per hour from the
  first submission to the last result; each cluster size :data:`REPEATS` times, alternating,
  and the best of each kept (this shared machine's speed varies by tens of percent from one
  minute to the next). Project goal: 2 workers ≥ 1.8 × 1 worker.
- **Engine overhead per run** (scheduling, serialisation, result transfer, table writing): on
  the 1-worker cluster, the wall time between first submission and last result minus the time
  the worker spent inside the runs (each run's own ``wall_s``), per run; against the wall time
  of a 10-minute run (the runs' simulation time scaled to 600 s). Project goal ≤ 5 %.
- **Memory per worker**: :data:`MEMORY_RUNS` runs of :data:`MEMORY_RUN_S` s (one seed each) on 2
  workers, about 100 a worker; each run reports its worker's resident memory after it
  (``rss_mb``). Per worker: the growth over its first :data:`WARM_UP` runs (glibc's heap and
  the caches fill: measured in a plain process, the resident set rises for about 20 runs and
  then stays within a few MB over 150), and the growth from then to its last runs (the means of
  five runs each) with the least-squares slope. Project goal: flat, read as at most :data:`FLAT_MB` MB of
  growth after the warm-up (the FMUs' own memory goal).
"""
from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import numpy as np

#: Simulated time of each throughput run [s], and how many times each cluster size runs them.
RUN_S = 60.0
REPEATS = 2
#: Simulated time of each memory run [s], and how many of them.
MEMORY_RUN_S = 5.0
MEMORY_RUNS = 200
#: A worker's first runs, not held to the flatness goal.
WARM_UP = 20
#: Largest growth of a worker's memory after its warm-up still called flat [MB].
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
"vessel.sea.seed" = {{ start = 1, stop = {runs}, step = 1 }}
"""


def campaign_bench(fmu_dir: Path, work: Path | None = None) -> dict:
    """Run the three measurements (module docstring); return them as a JSON-able dict."""
    from ..campaign import parse_spec, run_campaign
    from ..campaign.table import read_log

    work = Path(work or tempfile.mkdtemp(prefix="marinefmu_bench_campaign_"))
    shutil.rmtree(work, ignore_errors=True)
    spec = parse_spec(_THROUGHPUT.format(duration=RUN_S), fmu_dir, "bench throughput")
    runs: dict[int, dict] = {}
    for rep in range(REPEATS):
        for n in (1, 2):
            out = work / f"throughput_{n}_{rep}"
            o = run_campaign(spec, out, workers=n, progress=False)
            recs = list(read_log(out).values())
            this = {"workers": n, "runs": o.ran, "failed": o.failed, "wall_s": o.wall_s, "startup_s": o.startup_s,
                    "runs_per_hour": o.ran / o.wall_s * 3600,
                    "mean_run_s": float(np.mean([r["run_s"] for r in recs])),
                    "mean_task_s": float(np.mean([r["wall_s"] for r in recs]))}
            print(f"  campaign, {o.ran} runs of {RUN_S:g} s on {n} worker(s): {o.wall_s:.1f} s after {o.startup_s:.1f} s "
                  f"of start-up, {this['runs_per_hour']:.0f} runs/h ({o.failed} failed)")
            walls = runs.get(n, {}).get("all_wall_s", []) + [o.wall_s]
            if n not in runs or o.wall_s < runs[n]["wall_s"]:
                runs[n] = this
            runs[n]["all_wall_s"] = walls
    one = runs[1]
    overhead = (one["wall_s"] - one["runs"] * one["mean_task_s"]) / one["runs"]
    ten_minutes = one["mean_run_s"] / RUN_S * 600.0
    speedup = runs[2]["runs_per_hour"] / one["runs_per_hour"]
    print(f"  2 workers / 1 worker: {speedup:.2f} (project goal >= 1.8); engine overhead {overhead:.3f} s per run, "
          f"{100 * overhead / ten_minutes:.2f} % of a 10-minute run ({ten_minutes:.0f} s) (project goal <= 5 %)")

    mem_spec = parse_spec(_MEMORY.format(duration=MEMORY_RUN_S, runs=MEMORY_RUNS), fmu_dir, "bench memory", check_values=False)
    out = work / "memory"
    o = run_campaign(mem_spec, out, workers=2, progress=False)
    recs = list(read_log(out).values())   # in the order they finished
    workers = {}
    for w in sorted({r["worker"] for r in recs}):
        rss = np.array([r["rss_mb"] for r in recs if r["worker"] == w], dtype=float)
        after = rss[WARM_UP - 5:]
        slope = float(np.polyfit(np.arange(after.size), after, 1)[0]) if after.size > 1 else 0.0
        workers[w] = {"runs": int(rss.size), "first_mb": float(rss[:5].mean()), "warm_mb": float(after[:5].mean()),
                      "last_mb": float(rss[-5:].mean()), "warm_up_growth_mb": float(after[:5].mean() - rss[:5].mean()),
                      "growth_mb": float(rss[-5:].mean() - after[:5].mean()), "slope_mb_per_run": slope,
                      "rss_mb": rss.round(2).tolist()}
        print(f"  campaign memory, worker {w}: {rss.size} runs, {workers[w]['first_mb']:.1f} MB after its first runs, "
              f"{workers[w]['warm_mb']:.1f} after {WARM_UP}, {workers[w]['last_mb']:.1f} after its last "
              f"(growth after the warm-up {workers[w]['growth_mb']:+.1f} MB, slope {1000 * slope:.1f} kB/run; project goal <= {FLAT_MB:g} MB)")
    flat = all(v["growth_mb"] <= FLAT_MB for v in workers.values())
    shutil.rmtree(work, ignore_errors=True)
    return {"throughput": runs, "speedup_2_over_1": speedup, "speedup_goal": 1.8, "overhead_s_per_run": overhead,
            "ten_minute_run_s": ten_minutes, "overhead_pct_of_10_min": 100 * overhead / ten_minutes, "overhead_goal_pct": 5.0,
            "memory": {"runs": o.ran, "failed": o.failed, "run_s": MEMORY_RUN_S, "warm_up_runs": WARM_UP,
                       "workers": workers, "flat": flat, "flat_mb": FLAT_MB}}
