"""BEM results out: the RAO table and CSV that ``vessel.rao_file`` reads, a summary, the plot.

The CSV is :func:`marinefmu.sea.vessel.save_rao_csv`'s format (same columns, frames and phase
convention, read back by :func:`~marinefmu.sea.vessel.load_rao_csv`) with extra ``#`` comment
lines naming the hull, its mass properties, natural periods, the frequency range and the
irregular-frequency flags. The RAOs are for zero forward speed.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..vessel import DOFS, RaoTable, save_rao_csv
from .bem import HydroResult

#: Headings [deg] whose RAOs are plotted and summarised (following, quartering, beam, bow, head).
PLOT_HEADINGS_DEG = (0.0, 45.0, 90.0, 135.0, 180.0)
#: Heading [deg] at which each DOF's peak RAO is reported: head seas for surge and pitch, beam seas for
#: sway, heave and roll (where heave resonates: in head seas a ship's length cancels it), bow-quartering for yaw.
PEAK_HEADING_DEG = {"surge": 180.0, "sway": 90.0, "heave": 90.0, "roll": 90.0, "pitch": 180.0, "yaw": 135.0}


def rao_table(result: HydroResult, name: str | None = None) -> RaoTable:
    """The RAOs of ``result`` as a :class:`~marinefmu.sea.vessel.RaoTable` (validated)."""
    return RaoTable(omega=np.asarray(result.omega, float), heading=np.asarray(result.heading, float),
                    rao=np.asarray(result.rao, complex), name=name or result.name)


def _column(result: HydroResult, deg: float) -> int:
    return int(np.argmin(np.abs(np.angle(np.exp(1j * (result.heading - math.radians(deg)))))))


def peak_raos(result: HydroResult) -> dict[str, dict[str, float]]:
    """Largest |RAO| of each DOF over the frequency grid at its :data:`PEAK_HEADING_DEG`.

    Returns
    -------
    dict
        ``{dof: {"value": peak [m/m or rad/m], "period": wave period at the peak [s],
        "heading_deg": heading [deg]}}``; heave, roll and pitch also carry ``"at_natural"``,
        |RAO| at their natural period (the resonance; the peak of a well-damped heave is the
        long-wave limit 1).
    """
    out = {}
    for d, dof in enumerate(DOFS):
        j = _column(result, PEAK_HEADING_DEG[dof])
        amp = np.abs(result.rao[d, :, j])
        i = int(np.argmax(amp))
        out[dof] = {"value": float(amp[i]), "period": float(2 * math.pi / result.omega[i]),
                    "heading_deg": float(np.degrees(result.heading[j]))}
        t = result.natural_periods.get(dof)
        if t is not None and np.isfinite(t):
            out[dof]["at_natural"] = float(np.interp(2 * math.pi / t, result.omega, amp))
    return out


def summary(result: HydroResult) -> dict:
    """JSON-serialisable summary: hull, mass properties, hydrostatics, natural periods, peaks, cost."""
    return {
        "name": result.name, "description": result.description, "panels": result.panels,
        "seconds": round(result.seconds, 2), "volume_m3": result.volume, "mass_kg": result.mass,
        "cog_m": list(result.cog), "radii_m": list(result.radii), "gm_t_m": result.gm_t, "gm_l_m": result.gm_l,
        "natural_periods_s": dict(result.natural_periods), "roll_damping": result.roll_damping,
        "heave_damping": result.heave_damping, "pitch_damping": result.pitch_damping,
        "omega_range_rad_s": [float(result.omega[0]), float(result.omega[-1])], "n_omega": int(result.omega.size),
        "n_heading": int(result.heading.size), "irregular_omega_rad_s": result.irregular_omega,
        "irregular_flagged": int(np.sum(result.irregular)), "lid_z_m": result.lid_z,
        "peak_raos": peak_raos(result),
    }


def header_lines(result: HydroResult, command: str = "") -> list[str]:
    """The ``#`` comment lines written above the table."""
    try:
        from importlib.metadata import version

        cpt_version = version("capytaine")
    except Exception:  # metadata missing: only the header loses the version
        cpt_version = "?"
    t = result.natural_periods
    irr = (f"frequencies >= {result.irregular_omega:.4g} rad/s may show irregular-frequency errors: "
           f"{int(np.sum(result.irregular))} of {result.omega.size} rows flagged"
           if np.any(result.irregular) else
           f"no irregular frequency below {result.irregular_omega:.4g} rad/s (Capytaine's estimate"
           + (f", lid at z = {result.lid_z:.3g} m)" if result.lid_z is not None else ", no lid needed)"))
    lines = [
        f"BEM RAOs by marinefmu hydro (Capytaine {cpt_version}), zero forward speed: {result.name}",
        result.description,
        f"panels {result.panels}; displacement {result.volume:.6g} m3, mass {result.mass:.6g} kg (rho {result.rho:g} kg/m3)",
        f"COG {tuple(round(c, 4) for c in result.cog)} m from the waterline origin (x fwd, y stbd, z down); "
        f"radii of gyration {tuple(round(r, 4) for r in result.radii)} m",
        f"GM_T {result.gm_t:.4g} m, GM_L {result.gm_l:.4g} m; viscous damping (fraction of critical) heave "
        f"{result.heave_damping:g}, roll {result.roll_damping:g}, pitch {result.pitch_damping:g}",
        f"natural periods heave {t['heave']:.4g} s, roll {t['roll']:.4g} s, pitch {t['pitch']:.4g} s",
        f"omega {result.omega[0]:.4g}..{result.omega[-1]:.4g} rad/s ({result.omega.size} values; zero response above), "
        f"{result.heading.size} headings",
        irr,
    ]
    if np.any(result.irregular):
        lines.append("irregular_omega_rows " + " ".join(f"{w:.6g}" for w in result.omega[result.irregular]))
    if command:
        lines.append(f"regenerate: {command}")
    return lines


def write_rao_csv(result: HydroResult, path: str | Path, command: str = "") -> Path:
    """Write the RAO CSV of ``result`` to ``path`` (read by ``vessel.rao_file``); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    save_rao_csv(rao_table(result), path)
    body = path.read_text()
    path.write_text("".join(f"# {ln}\n" for ln in header_lines(result, command)) + body)
    return path


def write_summary(result: HydroResult, path: str | Path) -> Path:
    """Write :func:`summary` as JSON."""
    path = Path(path)
    path.write_text(json.dumps(summary(result), indent=2) + "\n")
    return path


def plot_raos(result: HydroResult, path: str | Path, headings_deg: tuple[float, ...] = PLOT_HEADINGS_DEG) -> Path:
    """Plot the amplitudes of the six RAOs against wave period, one curve per heading.

    Translations in m/m, rotations in deg/m; the heave, roll and pitch natural periods are
    marked. Written as PNG at ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    period = 2 * math.pi / result.omega
    fig, axes = plt.subplots(2, 3, figsize=(12, 6.5), sharex=True)
    for d, (dof, ax) in enumerate(zip(DOFS, axes.ravel())):
        scale = 1.0 if d < 3 else math.degrees(1.0)
        for deg in headings_deg:
            j = _column(result, deg)
            ax.plot(period, scale * np.abs(result.rao[d, :, j]), label=f"{deg:g}°")
        t = result.natural_periods.get(dof)
        if t is not None and np.isfinite(t):
            ax.axvline(t, color="0.5", ls=":", lw=1)
        if np.any(result.irregular):
            ax.axvspan(period.min(), 2 * math.pi / result.irregular_omega, color="0.9", zorder=0)
        ax.set_title(dof)
        ax.set_ylabel("m/m" if d < 3 else "deg/m")
        ax.grid(alpha=0.3)
        ax.set_xlim(0, min(period.max(), 40.0))
    for ax in axes[1]:
        ax.set_xlabel("wave period [s]")
    axes[0, 0].legend(title="heading", fontsize=8)
    fig.suptitle(f"BEM RAOs (Capytaine), {result.description}", fontsize=10)
    fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
