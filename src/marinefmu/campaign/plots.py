"""A campaign's plots (matplotlib, Agg): accuracy maps over Hs–Tp and comparisons of set labels.

- **Accuracy maps** (``maps/<component>.png``), when the grid varies the vessel's ``sea.hs``
  and ``sea.tp``: one panel per metric of the component, the mean over the runs of each
  (Hs, Tp) cell (over seeds, headings and whatever else varies), written in the cell; a cell
  without a succeeded run is blank.
- **Comparisons** (``compare_<axis>.png``), per ``[sets.<axis>]`` with two labels or more
  (a sensor-placement comparison, say): one panel per metric, a bar per label at the mean over
  its runs with the smallest and largest as whiskers.

Metrics plotted: the errors, not the bookkeeping (``valid_fraction``, ``scored_s``, the truth's
``*_std_*``).
"""
from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path
from typing import Any

from ..analysis.vessel_plots import pyplot
from ..analysis.scoring import COMMON_METRICS
from .spec import CampaignSpec

#: Cells and bars drawn per figure row.
PANELS_PER_ROW = 3


def _plotted(metric_columns: list[str]) -> dict[str, list[str]]:
    """Component → its error metric columns (``component.metric``)."""
    out: dict[str, list[str]] = defaultdict(list)
    for col in metric_columns:
        comp, _, metric = col.partition(".")
        if metric not in COMMON_METRICS and "_std_" not in metric:
            out[comp].append(col)
    return dict(out)


def _grid(plt, n: int, width: float, height: float):
    rows = math.ceil(n / PANELS_PER_ROW)
    cols = min(n, PANELS_PER_ROW)
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


def _mean(values: list[float]) -> float:
    vals = [v for v in values if isinstance(v, float) and math.isfinite(v)]
    return sum(vals) / len(vals) if vals else math.nan


def plot_campaign(spec: CampaignSpec, rows: list[dict[str, Any]], out: str | Path) -> list[Path]:
    """Write the campaign's plots (module docstring) from its table rows (``table.read_table``);
    their paths."""
    import numpy as np

    plt = pyplot()
    out = Path(out)
    ok = [r for r in rows if r["status"] == "ok"]
    # the metrics are the table's component.metric columns (the grid keys have dots too)
    metric_columns = [c for c in (rows[0] if rows else {}) if "." in c and c not in spec.axes]
    # a metric no run gave (the heave observer not yet valid in a short run, say) has nothing to draw
    by_comp = _plotted([c for c in metric_columns if any(math.isfinite(r.get(c, math.nan)) for r in ok)])
    written: list[Path] = []
    hs_key, tp_key = f"{spec.vessel}.sea.hs", f"{spec.vessel}.sea.tp"
    if ok and len(spec.grid.get(hs_key, ())) > 1 and len(spec.grid.get(tp_key, ())) > 1:
        hs, tp = sorted(spec.grid[hs_key]), sorted(spec.grid[tp_key])
        (out / "maps").mkdir(exist_ok=True)
        for comp, cols in by_comp.items():
            fig, axes = _grid(plt, len(cols), 4.2, 3.4)
            for ax, col in zip(axes, cols):
                cell = np.array([[_mean([r[col] for r in ok if r[hs_key] == h and r[tp_key] == p]) for p in tp]
                                 for h in hs])
                im = ax.imshow(cell, origin="lower", aspect="auto", cmap="viridis")
                for i, j in np.ndindex(cell.shape):
                    if math.isfinite(cell[i, j]):
                        ax.text(j, i, f"{cell[i, j]:.3g}", ha="center", va="center", fontsize=8,
                                bbox={"facecolor": "white", "alpha": 0.7, "edgecolor": "none", "pad": 1})
                ax.set_xticks(range(len(tp)), [f"{p:g}" for p in tp])
                ax.set_yticks(range(len(hs)), [f"{h:g}" for h in hs])
                ax.set_xlabel("Tp [s]")
                ax.set_ylabel("Hs [m]")
                ax.set_title(col.partition(".")[2], fontsize=10)
                fig.colorbar(im, ax=ax)
            fig.suptitle(f"{spec.name}: {comp}, mean over the other axes ({len(ok)} runs)")
            fig.tight_layout()
            path = out / "maps" / f"{comp}.png"
            fig.savefig(path, dpi=90)
            plt.close(fig)
            written.append(path)
    for axis, labels in spec.sets.items():
        if len(labels) < 2 or not ok:
            continue
        cols = [c for cs in by_comp.values() for c in cs]
        fig, axes = _grid(plt, len(cols), 3.6, 3.0)
        for ax, col in zip(axes, cols):
            means, lo, hi = [], [], []
            for label in labels:
                vals = [r[col] for r in ok if r[axis] == label and math.isfinite(r[col])]
                means.append(_mean(vals))
                lo.append(means[-1] - min(vals) if vals else 0.0)
                hi.append(max(vals) - means[-1] if vals else 0.0)
            ax.bar(range(len(labels)), means, yerr=[lo, hi], capsize=3, color="tab:blue")
            ax.set_xticks(range(len(labels)), list(labels), rotation=30, ha="right")
            ax.set_title(col, fontsize=9)
        fig.suptitle(f"{spec.name}: by {axis} (mean over the other axes; whiskers min–max)")
        fig.tight_layout()
        path = out / f"compare_{axis}.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        written.append(path)
    return written
