"""A campaign's results on disk: an append-only log of finished runs and the tidy table made from it.

``runs.jsonl`` holds one JSON record per finished run, appended and flushed as each run ends;
it is what a rerun reads to skip finished runs. A line cut short by a crash or a Ctrl-C in the
middle of a write is ignored (that run is simply run again). ``results.csv`` is the tidy table
(one row per run, in the campaign's order; columns ``id``, ``status``, the varied parameters,
the metrics, ``run_s``, ``wall_s``, ``worker``, ``rss_mb``, ``error``), rewritten whole from
the log after every run through a temporary file and an atomic rename, so it is never half
written.
"""
from __future__ import annotations

import csv
import json
import logging
import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from .spec import Run

log = logging.getLogger("marinefmu.campaign")
LOG_NAME = "runs.jsonl"
TABLE_NAME = "results.csv"
_TAIL = ("run_s", "wall_s", "worker", "rss_mb", "error")


def read_log(out: Path) -> dict[str, dict[str, Any]]:
    """Finished runs in ``out/runs.jsonl``: run id → record (the last record of an id wins)."""
    path = Path(out) / LOG_NAME
    done: dict[str, dict[str, Any]] = {}
    if not path.exists():
        return done
    with path.open(encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            try:
                rec = json.loads(line)
                done[rec["id"]] = rec
            except (json.JSONDecodeError, KeyError, TypeError):
                log.warning("%s line %d is incomplete or not a run record; that run will be run again", path, n)
    return done


def append_log(out: Path, record: dict[str, Any]) -> None:
    """Append one finished run to ``out/runs.jsonl`` and flush it to disk."""
    rec = {k: v for k, v in record.items() if k != "series"}
    line = json.dumps(rec, allow_nan=True) + "\n"
    path = Path(out) / LOG_NAME
    # a torn line (a write cut short) would otherwise glue onto the next record
    if path.exists() and path.stat().st_size:
        with path.open("rb") as f:
            f.seek(-1, os.SEEK_END)
            if f.read(1) != b"\n":
                line = "\n" + line
    with path.open("a", encoding="utf-8") as f:
        f.write(line)
        f.flush()
        os.fsync(f.fileno())


def columns(axes: list[str], records: Iterable[dict[str, Any]], metrics: tuple[str, ...] | None) -> list[str]:
    """The table's columns: ``id``, ``status``, the axes, the metrics (the spec's, or every one
    found, in the order first found), then the run's bookkeeping."""
    found: dict[str, None] = dict.fromkeys(metrics or ())
    if metrics is None:
        for rec in records:
            found.update(dict.fromkeys(rec.get("metrics", {})))
    return ["id", "status", *axes, *found, *_TAIL]


def write_table(out: Path, axes: list[str], runs: list[Run], done: dict[str, dict[str, Any]],
                metrics: tuple[str, ...] | None) -> Path:
    """Rewrite ``out/results.csv`` from the finished runs among ``runs`` (module docstring)."""
    rows = [done[r.id] for r in runs if r.id in done]
    cols = columns(axes, rows, metrics)
    path = Path(out) / TABLE_NAME
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="", encoding="utf-8") as f:
        w = csv.writer(f)
        w.writerow(cols)
        for rec in rows:
            flat = {**rec.get("values", {}), **rec.get("metrics", {}), **{k: rec.get(k, "") for k in _TAIL},
                    "id": rec["id"], "status": rec["status"]}
            w.writerow(["" if isinstance(v, float) and math.isnan(v) else v for v in (flat.get(c, "") for c in cols)])
    os.replace(tmp, path)
    return path


def read_table(path: str | Path) -> list[dict[str, Any]]:
    """``results.csv`` as a list of rows, numbers as floats (empty cells NaN)."""
    def value(text: str) -> Any:
        if text == "":
            return math.nan
        try:
            return float(text)
        except ValueError:
            return text

    with Path(path).open(newline="", encoding="utf-8") as f:
        return [{k: (v if k in ("id", "status", "worker", "error") else value(v)) for k, v in row.items()}
                for row in csv.DictReader(f)]
