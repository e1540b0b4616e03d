"""The ``hydro`` part of ``marinefmu bench``: the BEM presets at full resolution, and what BEM
motion changes for the estimators.

- **Presets** (:func:`solve_presets`): each BEM preset (:data:`marinefmu.sea.hydro.presets.BEM_PRESETS`)
  solved by Capytaine at its shipped resolution: panels, frequencies, wall time (goal ≤ 5 min
  each on the 2-core machine), natural periods, peak RAOs, and the largest difference from the
  shipped CSV (0 when the shipped tables are current), and the largest deviation of the damping
  from the Haskind-Newman relation (:func:`marinefmu.sea.hydro.validation.haskind_deviation`).
- **Grid cover** (:func:`grid_cover`): for each shipped table and benchmark sea, the bound on the
  heave, roll and pitch above the table's last frequency (:func:`marinefmu.sea.hydro.validation.tail_bound`).
- **Closed form against BEM** (:func:`compare_presets`): natural periods and peak RAOs of each
  closed-form preset beside its BEM counterpart.
- **Estimators on BEM motion** (:func:`estimator_errors`): the AttitudeEstimator and the
  HeaveObserver at their defaults on VesselMotion records of each closed-form preset and of its
  BEM counterpart in one sea (:data:`SEA`): RMS roll / pitch error [°] from
  :func:`marinefmu.papers.tilt_bound.estimator_errors` and RMS real-time heave error at the IMU
  [cm] scored as paper 003's checks (:func:`marinefmu.papers.paper003.imu_error`).
"""
from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np

#: Sea of the estimator comparison: Hs [m], Tp [s], travel direction from the bow [rad]
#: (bow-quartering, paper 003's checks), seed, record length [s].
SEA = {"hs": 3.0, "tp": 10.0, "heading": 0.75 * math.pi, "seed": 3, "duration": 1920.0}
#: Closed-form preset → BEM counterpart.
PAIRS = {"polar_supply": "polar_supply_bem", "research36": "research36_bem", "semisub": "semisub_bem"}


def solve_presets(out_dir: Path | None = None, names: tuple[str, ...] | None = None) -> dict[str, dict]:
    """Solve the BEM presets at their shipped resolution; tables and plots into ``out_dir``.

    Returns
    -------
    dict
        Per preset: :func:`marinefmu.sea.hydro.export.summary` plus ``wall_s`` and
        ``max_diff_shipped`` (largest |ΔRAO| against the shipped CSV, m/m or rad/m).
    """
    from ..sea.hydro import bem, export, presets, validation
    from ..sea.vessel import bem_preset_path, load_rao_csv

    out = {}
    for name in names or tuple(presets.BEM_PRESETS):
        p = presets.preset(name)
        t0 = time.perf_counter()
        hull = p.hull()
        r = bem.solve(hull, presets.mass_properties(p, hull), bem.default_omega(p.omega_max),
                      roll_damping=p.roll_damping, heave_damping=p.heave_damping, pitch_damping=p.pitch_damping,
                      progress=False)
        wall = time.perf_counter() - t0
        s = export.summary(r)
        s["wall_s"] = round(wall, 1)
        v = hull.full()[0]                              # solver frame: y to port, so body y = −v_y
        radius = float(np.max(np.hypot(v[:, 0] - r.cog[0], -v[:, 1] - r.cog[1])))
        s["haskind_omega_max"] = min(float(r.omega[-1]), validation.haskind_omega_limit(r, radius))
        s["haskind_deviation"] = validation.haskind_deviation(r, s["haskind_omega_max"])
        shipped = bem_preset_path(name)
        if shipped.exists():
            old = load_rao_csv(shipped)
            same = old.rao.shape == r.rao.shape and np.allclose(old.omega, r.omega)
            s["max_diff_shipped"] = float(np.abs(old.rao - r.rao).max()) if same else None
        if out_dir is not None:
            export.write_rao_csv(r, out_dir / f"{name}.csv")
            export.plot_raos(r, out_dir / f"hydro_{name}.png")
        t = r.natural_periods
        print(f"hydro {name}: {r.panels} panels, {r.omega.size} frequencies × (6 + {r.heading.size}) problems in {wall:.0f} s; "
              f"T heave / roll / pitch {t['heave']:.2f} / {t['roll']:.2f} / {t['pitch']:.2f} s; "
              f"max |ΔRAO| against the shipped table {s.get('max_diff_shipped')}; Haskind-Newman deviation "
              f"(ω ≤ {s['haskind_omega_max']:.2f} rad/s) "
              + ", ".join(f"{d} {v:.3f}" for d, v in s["haskind_deviation"].items()), flush=True)
        out[name] = s
    return out


def grid_cover() -> dict[str, dict]:
    """Bound on the motion above each shipped table's last frequency in each benchmark sea.

    Returns
    -------
    dict
        ``{preset: {"Hs/Tp": {dof: {"lost_std", "lost_fraction", "kept_std"}}}}`` for heave
        [m], roll and pitch [deg], each at its :data:`~marinefmu.sea.hydro.export.PEAK_HEADING_DEG`.
    """
    from ..sea.hydro.export import PEAK_HEADING_DEG
    from ..sea.hydro.presets import BEM_PRESETS
    from ..sea.hydro.validation import tail_bound
    from ..sea.vessel import bem_preset_path, load_rao_csv
    from ..sea.waves import SeaState
    from .cases import SEAS

    out: dict[str, dict] = {}
    for name in BEM_PRESETS:
        table = load_rao_csv(bem_preset_path(name))
        for hs, tp in SEAS:
            row = {}
            for dof in ("heave", "roll", "pitch"):
                d = tail_bound(table, SeaState(hs=hs, tp=tp), math.radians(PEAK_HEADING_DEG[dof]))[dof]
                scale = 1.0 if dof == "heave" else math.degrees(1.0)
                row[dof] = {"kept_std": scale * d["kept_std"], "lost_std": scale * d["lost_std"],
                            "lost_fraction": d["lost_fraction"]}
            out.setdefault(name, {})[f"{hs:g}/{tp:g}"] = row
            print(f"hydro grid cover {name} Hs {hs:g} Tp {tp:g}: lost above {table.omega[-1]:g} rad/s ≤ "
                  + ", ".join(f"{d} {v['lost_std']:.2g} ({100 * v['lost_fraction']:.2g} %)" for d, v in row.items()),
                  flush=True)
    return out


def compare_presets(solved: dict[str, dict]) -> dict[str, dict]:
    """Natural periods [s] and peak RAOs (m/m, deg/m) of each closed-form preset beside its BEM
    counterpart (same heading per DOF as :data:`marinefmu.sea.hydro.export.PEAK_HEADING_DEG`)."""
    from ..sea.hydro.export import PEAK_HEADING_DEG
    from ..sea.vessel import DOFS, PRESETS, preset_raos

    out = {}
    for closed, bem_name in PAIRS.items():
        if bem_name not in solved:
            continue
        hull, table = PRESETS[closed], preset_raos(closed)
        peaks = {}
        for d, dof in enumerate(DOFS):
            j = int(np.argmin(np.abs(np.angle(np.exp(1j * (table.heading - math.radians(PEAK_HEADING_DEG[dof])))))))
            amp = np.abs(table.rao[d, :, j])
            i = int(np.argmax(amp))
            scale = 1.0 if d < 3 else math.degrees(1.0)
            b = solved[bem_name]["peak_raos"][dof]
            peaks[dof] = {"closed_form": scale * float(amp[i]), "closed_form_period": float(2 * math.pi / table.omega[i]),
                          "bem": scale * b["value"], "bem_period": b["period"]}
            if "at_natural" in b:
                wn = 2 * math.pi / getattr(hull, f"t_{dof}")
                peaks[dof]["closed_form_at_natural"] = scale * float(np.interp(wn, table.omega, amp))
                peaks[dof]["bem_at_natural"] = scale * b["at_natural"]
        out[closed] = {
            "bem": bem_name,
            "natural_periods_s": {dof: {"closed_form": getattr(hull, f"t_{dof}"), "bem": solved[bem_name]["natural_periods_s"][dof]}
                                  for dof in ("heave", "roll", "pitch")},
            "peak_raos": peaks,
        }
    return out


def _record(preset: str | None, rao_file: str | None) -> dict[str, np.ndarray]:
    from ..papers import paper003
    from ..sea.motion_model import VesselMotionParams, simulate_record

    flat = {"sea.hs": SEA["hs"], "sea.tp": SEA["tp"], "sea.heading": SEA["heading"], "sea.seed": SEA["seed"],
            **{f"imu.{a}": v for a, v in zip("xyz", paper003.IMU)},
            **{f"point.{a}": i + r for a, i, r in zip("xyz", paper003.IMU, paper003.ARM)}}
    if preset:
        flat["vessel.preset"] = preset
    if rao_file:
        flat["vessel.rao_file"] = rao_file
    return simulate_record(VesselMotionParams.from_flat(flat), SEA["duration"], paper003.DT)


def estimator_errors(pairs: dict[str, str] | None = None) -> dict[str, dict]:
    """AttitudeEstimator and HeaveObserver errors at defaults on closed-form and BEM motion.

    The BEM tables are read from the shipped CSV files as ``vessel.rao_file``.

    Returns
    -------
    dict
        ``{closed: {"closed_form": {...}, "bem": {...}}}``, each with ``roll_deg``,
        ``pitch_deg`` (RMS attitude errors), ``heave_cm`` (RMS real-time heave error at the IMU)
        and the truth's ``roll_std_deg``, ``pitch_std_deg``, ``heave_std_cm``.
    """
    from ..estimators.heave.common import HeaveObserverParams
    from ..papers import paper003, tilt_bound
    from ..sea.vessel import bem_preset_path

    out = {}
    for closed, bem_name in (pairs or PAIRS).items():
        row = {}
        for label, rec in (("closed_form", _record(closed, None)), ("bem", _record(None, str(bem_preset_path(bem_name))))):
            roll, pitch = tilt_bound.estimator_errors(rec, dt=paper003.DT)
            heave, _ = paper003.run_observer(HeaveObserverParams(), rec)
            err = paper003.imu_error(rec, heave[:, 0])
            k0 = int(paper003.SETTLE / paper003.DT)
            row[label] = {"roll_deg": roll, "pitch_deg": pitch, "heave_cm": 100 * float(np.sqrt(np.mean(err**2))),
                          "roll_std_deg": math.degrees(float(np.std(rec["truth.roll"][k0:]))),
                          "pitch_std_deg": math.degrees(float(np.std(rec["truth.pitch"][k0:]))),
                          "heave_std_cm": 100 * float(np.std(rec["truth.imu.d"][k0:]))}
        c, b = row["closed_form"], row["bem"]
        print(f"hydro estimators {closed} → {bem_name} (Hs {SEA['hs']:g} Tp {SEA['tp']:g}): roll error "
              f"{c['roll_deg']:.3f} → {b['roll_deg']:.3f}°, pitch {c['pitch_deg']:.3f} → {b['pitch_deg']:.3f}°, "
              f"heave {c['heave_cm']:.2f} → {b['heave_cm']:.2f} cm (truth std roll {c['roll_std_deg']:.2f} → "
              f"{b['roll_std_deg']:.2f}°, heave {c['heave_std_cm']:.1f} → {b['heave_std_cm']:.1f} cm)", flush=True)
        out[closed] = row
    return out


def hydro_bench(out_dir: Path) -> dict:
    """The whole part: presets (tables and plots into ``out_dir/hydro``), comparison, estimators."""
    solved = solve_presets(out_dir / "hydro")
    return {"presets": solved, "closed_form_vs_bem": compare_presets(solved), "grid_cover": grid_cover(),
            "sea": SEA, "estimators": estimator_errors()}


if __name__ == "__main__":  # python -m marinefmu.bench.hydro: the part alone, printed
    with tempfile.TemporaryDirectory() as d:
        hydro_bench(Path(d))
