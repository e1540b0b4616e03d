"""The ``ahc`` part of ``marinefmu bench``: how long the heave-compensation design
loop takes (identify, tune, verify, plots, with the defaults of ``marinefmu design-ahc``), and
the four-way comparison of the built-in scenario ``ahc`` (its residuals, limit time, wall time
and real-time factor under the FMPy runner)."""
from __future__ import annotations

import time
from pathlib import Path


def ahc_bench(fmu_dir: Path, out_dir: Path) -> dict:
    """Run both measurements; return them as a JSON-able dict."""
    from ..ahc.loop import design_loop
    from ..cosim.system import SystemRunner
    from ..cosim.scenarios import load_scenario
    from ..analysis.scoring import score

    sc = load_scenario("ahc")
    t0 = time.perf_counter()
    r = design_loop(sc, "ctrl_observer", fmu_dir, out_dir / "ahc_design")
    total = time.perf_counter() - t0
    c = r.design.controller
    loop = {"total_s": total, "stages_s": r.seconds, "k_p": c.k_p, "k_i": c.k_i, "k_ff": c.k_ff,
            "crossover_rad_s": r.design.crossover, "phase_margin_deg": r.design.phase_margin,
            "predicted_pct": r.predicted_pct, "predicted_ideal_pct": r.predicted_ideal_pct,
            "verified_pct": r.measured.get("residual_pct"), "verified_scored_s": r.measured.get("scored_s")}
    print(f"  AHC design loop: {total:.1f} s (" + ", ".join(f"{k} {v:.1f} s" for k, v in r.seconds.items())
          + f"); predicted {r.predicted_pct:.2f} %, verified {loop['verified_pct']:.2f} % of the tip's heave")
    t0 = time.perf_counter()
    res = SystemRunner(sc.system, fmu_dir).run(sc.duration, record=sc.record, progress=False)
    wall = time.perf_counter() - t0
    s = score(res, sc.system, "vessel")
    winches = {k: v for k, v in s.items() if k.startswith("winch_")}
    print(f"  AHC comparison, {sc.duration:g} s in {wall:.1f} s (real-time factor {sc.duration / wall:.1f}):")
    for name, m in winches.items():
        print(f"    {name:16s} load heave {m['residual_pct']:7.2f} % of the tip's, all frequencies "
              f"{m['residual_total_pct']:7.2f} %, a limit acting {m['limited_pct']:.2f} % of the time")
    return {"design_loop": loop, "comparison": {"duration_s": sc.duration, "wall_s": wall, "winches": winches}}
