"""Run a campaign on Dask (``dask.distributed``): a local cluster or an existing scheduler.

Each run is one task (:func:`~marinefmu.campaign.worker.run_one`) on a worker process with one
thread (pythonfmu FMUs of one process share its interpreter). Without a scheduler address a
:class:`~distributed.LocalCluster` is started with ``workers`` processes (default: one per
core) and closed at the end; with one, the campaign connects to that scheduler, so the same
command runs on a cluster. Runs already in the output folder's log are skipped (failed ones
too, unless ``retry_failed``), results are written as runs finish (:mod:`.table`), and a
Ctrl-C cancels what is left and leaves a consistent table: rerun the command to go on.
"""
from __future__ import annotations

import logging
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..cosim.ssp import SystemDescription
from ..errors import MarineFmuError
from .spec import CampaignSpec
from .table import append_log, read_log, write_table
from .worker import Job, prepare, run_one

log = logging.getLogger("marinefmu.campaign")
#: How long to wait for a scheduler given by address [s].
CONNECT_TIMEOUT = 10.0


class CampaignError(MarineFmuError, RuntimeError):
    """A campaign cannot run (an unreachable scheduler, a bad worker count)."""


@dataclass(frozen=True)
class CampaignOutcome:
    """What a call of :func:`run_campaign` did.

    Attributes
    ----------
    total, ok, failed : int
        Runs of the campaign, and how many of them are in the table as succeeded / failed.
    ran, skipped : int
        Runs made by this call, and runs skipped because the table already had them.
    interrupted : bool
        The call was stopped (Ctrl-C) before every run was done.
    table : Path
        ``results.csv``.
    wall_s : float
        Wall time of the runs of this call, from the first submission to the last result [s].
    startup_s : float
        Wall time before that: the FMUs sent to the workers and the workers prepared
        (:func:`~.worker.prepare`) [s]; the cluster's own start is not in it.
    """

    total: int
    ok: int
    failed: int
    ran: int
    skipped: int
    interrupted: bool
    table: Path
    wall_s: float
    startup_s: float


def connect(scheduler: str | None, workers: int | None):
    """A Dask client (and the local cluster it owns, or None) for :func:`run_campaign`."""
    from dask.distributed import Client, LocalCluster

    import dask

    logging.getLogger("distributed").setLevel(logging.ERROR)   # its INFO lines would drown the progress bar
    # A worker's statistical profiler takes the GIL every 10 ms to walk the task's stack: with
    # pure-Python FMUs that is time taken from the runs. The config reaches the workers a local
    # cluster starts (their nanny passes it on); a remote cluster keeps its own.
    dask.config.set({"distributed.worker.profile.enabled": False})
    if scheduler:
        try:
            return Client(scheduler, timeout=CONNECT_TIMEOUT), None
        except (OSError, TimeoutError, ValueError) as exc:
            raise CampaignError(f"--scheduler {scheduler!r}: cannot reach a Dask scheduler there within "
                                f"{CONNECT_TIMEOUT:g} s ({type(exc).__name__}: {exc})") from None
    n = (os.cpu_count() or 1) if workers is None else workers
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise CampaignError(f"--workers = {workers!r} is out of range: must be an integer >= 1")
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


def portable(spec: CampaignSpec) -> tuple[SystemDescription, dict[str, bytes]]:
    """The scenario's system with each component naming its FMU by file name, and those files'
    contents: what a worker on any machine needs (it writes them into a folder of its own)."""
    files: dict[str, Path] = {}
    comps = []
    for c in spec.scenario.system.components:
        src = c.path(spec.fmu_dir).resolve()
        if files.setdefault(src.name, src) != src:
            raise CampaignError(f"components.{c.name}: two different FMU files are named {src.name} "
                                f"({files[src.name]} and {src}); rename one")
        comps.append(replace(c, source=src.name))
    system = replace(spec.scenario.system, components=tuple(comps))
    return system, {name: path.read_bytes() for name, path in files.items()}


def run_campaign(spec: CampaignSpec, out: str | Path, scheduler: str | None = None,
                 workers: int | None = None, retry_failed: bool = False, progress: bool = True) -> CampaignOutcome:
    """Run every run of ``spec`` not yet in ``out`` (module docstring).

    Parameters
    ----------
    spec : CampaignSpec
        The validated campaign.
    out : str or Path
        Output folder: ``spec.toml`` (a copy), ``runs.jsonl``, ``results.csv``, ``series/``.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); default a local cluster.
    workers : int, optional
        Worker processes of the local cluster (default one per core).
    retry_failed : bool
        Run again the runs the table holds as failed.
    progress : bool
        Show a progress bar (done, failed, remaining, ETA).

    Raises
    ------
    CampaignError
        An unreachable scheduler or a bad worker count, before any run.
    KeyboardInterrupt
        After cancelling the runs left and writing the table (``outcome`` is then lost:
        rerun to go on).
    """
    import time

    from tqdm import tqdm

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "spec.toml").write_text(spec.text)
    runs = spec.runs()
    done = read_log(out)
    todo = [r for r in runs if r.id not in done or (retry_failed and done[r.id]["status"] == "failed")]
    table = write_table(out, spec.axes, runs, done, spec.metrics)
    ran, interrupted, wall, startup = 0, False, 0.0, 0.0
    if todo:
        client, cluster = connect(scheduler, workers)
        futures: list[Any] = []
        try:
            from dask.distributed import as_completed

            t_start = time.perf_counter()
            system, files = portable(spec)
            fmus = client.scatter([files], broadcast=True)[0]
            job = client.scatter([Job(system, spec)], broadcast=True)[0]
            client.run(prepare, cluster is not None)   # every worker imports the estimators now, not in its first run
            startup = time.perf_counter() - t_start
            by_id = {r.id: r for r in todo}
            t0 = time.perf_counter()
            futures = [client.submit(run_one, r, job, fmus, key=f"run-{r.id}", pure=False, retries=0) for r in todo]
            bar = tqdm(total=len(todo), unit="run", desc=spec.name, disable=not progress, smoothing=0.1)
            failed_now = 0
            try:
                for fut in as_completed(futures):
                    run_id = fut.key.removeprefix("run-")
                    try:
                        rec = fut.result()
                    except Exception as exc:  # noqa: BLE001 - a worker died (KilledWorker) or the task broke
                        rec = {"id": run_id, "values": by_id[run_id].values, "status": "failed", "metrics": {},
                               "error": f"{type(exc).__name__}: {exc}"}
                    fut.release()
                    if rec.get("series") is not None:
                        import numpy as np

                        (out / "series").mkdir(exist_ok=True)
                        np.save(out / "series" / f"{run_id}.npy", rec["series"])
                    append_log(out, rec)
                    done[run_id] = rec
                    ran += 1
                    failed_now += rec["status"] != "ok"
                    if rec["status"] != "ok":
                        log.warning("run %s %s failed: %s", run_id, rec["values"], rec["error"])
                    table = write_table(out, spec.axes, runs, done, spec.metrics)
                    bar.set_postfix(done=ran - failed_now, failed=failed_now, left=len(todo) - ran, refresh=False)
                    bar.update(1)
            finally:
                bar.close()
                wall = time.perf_counter() - t0
        except KeyboardInterrupt:
            interrupted = True
            client.cancel(futures)
            # Ctrl-C can fall between a run's log line and the table's rewrite (a run in
            # runs.jsonl but not in results.csv): the table follows the log again
            write_table(out, spec.axes, runs, read_log(out), spec.metrics)
            raise
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    statuses = [done[r.id]["status"] for r in runs if r.id in done]
    return CampaignOutcome(len(runs), statuses.count("ok"), len(statuses) - statuses.count("ok"), ran,
                           len(runs) - len(todo), interrupted, table, wall, startup)
