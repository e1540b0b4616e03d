"""Checks of a BEM result against exact relations, and of an RAO table against a sea's grid.

- :func:`haskind_damping`: the radiation damping predicted from the wave excitation by the
  Haskind-Newman relation (J. N. Newman, "The exciting forces on fixed bodies in waves",
  *J. Ship Research* 6(4), 10-17, 1962; *Marine Hydrodynamics*, MIT Press, 1977, § 6.18). The
  relation is exact in potential flow, so the solver's damping (from the radiation problems)
  and its excitation (from the diffraction problems) must satisfy it; their difference measures
  the discretisation error of the mesh on that hull.
- :func:`tail_bound`: an upper bound on the motion a sea puts above an RAO table's highest
  frequency, where VesselMotion's response is zero (:meth:`marinefmu.sea.vessel.RaoTable.interpolate`),
  so that a table's grid can be checked against VesselMotion's spectrum grid (0.5 ω_p … 5 ω_p by
  default, :attr:`marinefmu.sea.waves.SeaState.omega_range`).

Hand-written: Capytaine has no Haskind check, and the tail bound is specific to how
VesselMotion reads a table.
"""
from __future__ import annotations

import math

import numpy as np

from ...frames import G
from ..vessel import DOFS, RaoTable
from ..waves import SeaState
from .bem import HydroResult


def haskind_damping(result: HydroResult, g: float = G) -> np.ndarray:
    """Radiation damping from the excitation by the Haskind-Newman relation, deep water.

    B_jj(ω) = k / (8π ρ g c_g) ∫₀^{2π} |X_j(ω, β)|² dβ, with k = ω²/g and c_g = g/(2ω)
    (Newman 1977, eq. 6.173), X_j the complex excitation per unit wave amplitude [N/m, N·m/m]
    of DOF j about the same point as the damping (the COG) and β the wave direction. The
    integral over β is the trapezoidal rule on ``result.heading``, which must cover the circle
    evenly (the trapezoidal rule of a smooth periodic function converges geometrically).

    Parameters
    ----------
    result : HydroResult
        A BEM result with headings evenly spaced over [0, 2π).
    g : float
        Gravity [m/s²].

    Returns
    -------
    numpy.ndarray
        (nf, 6) predicted B_jj [kg/s, kg·m²/s for rotations], DOF order surge … yaw.

    Raises
    ------
    ValueError
        If the headings are not evenly spaced over the full circle.
    """
    h = np.asarray(result.heading, dtype=float)
    step = 2 * math.pi / h.size
    if h.size < 8 or not np.allclose(np.diff(np.concatenate([h, [h[0] + 2 * math.pi]])), step, atol=1e-9):
        raise ValueError(f"haskind_damping needs ≥ 8 headings evenly spaced over [0, 2π); got {np.degrees(h).round(2).tolist()} deg")
    w = np.asarray(result.omega, dtype=float)
    k, cg = w**2 / g, g / (2 * w)
    integral = step * np.sum(np.abs(result.excitation) ** 2, axis=2)      # (6, nf)
    return (k / (8 * math.pi * result.rho * g * cg))[:, None] * integral.T


def haskind_omega_limit(result: HydroResult, radius: float, g: float = G) -> float:
    """Highest ω [rad/s] at which the heading grid resolves the Haskind integral over β.

    |X(β)|² of a body of horizontal radius R (from the point the excitation is taken about) holds
    Fourier modes in β up to about 2kR; the trapezoidal rule on N headings integrates modes below
    N exactly, so k R ≤ N/3 keeps a margin: ω = √(g N / (3 R)). (24 headings and R = 51 m, the
    100 × 20 m box: 1.2 rad/s.)
    """
    return math.sqrt(g * np.asarray(result.heading).size / (3.0 * radius))


def haskind_deviation(result: HydroResult, omega_max: float | None = None, g: float = G) -> dict[str, float]:
    """Largest |B_Haskind − B| of each DOF over ω ≤ ``omega_max``, relative to max B_jj.

    Frequencies flagged irregular (:attr:`HydroResult.irregular`) are left out; ``omega_max``
    should not exceed :func:`haskind_omega_limit`, above which the heading grid, not the
    solver, decides the figure.

    Returns
    -------
    dict of str to float
        ``{dof: deviation [-]}`` for the six DOFs.
    """
    pred = haskind_damping(result, g)
    keep = ~np.asarray(result.irregular, bool)
    if omega_max is not None:
        keep &= result.omega <= omega_max
    out = {}
    for j, dof in enumerate(DOFS):
        b = result.damping[:, j, j]
        out[dof] = float(np.max(np.abs(pred[keep, j] - b[keep])) / np.max(np.abs(b)))
    return out


def tail_bound(table: RaoTable, sea: SeaState, heading: float, n: int = 4000) -> dict[str, dict[str, float]]:
    """What a sea puts above a table's highest frequency, bounded, per DOF, long-crested.

    Above ``table.omega[-1]`` VesselMotion's response is zero. A hull's RAOs fall off in short
    waves, so the RAO held at its last tabulated value bounds what is lost:
    σ²_lost ≤ |RAO(ω_max)|² ∫_{ω_max}^{ω_hi} S(ω) dω, against σ²_kept = ∫_{ω_lo}^{ω_max} |RAO|² S dω,
    over the sea's realised range (ω_lo, ω_hi) = :attr:`SeaState.omega_range`. Below the table's
    lowest frequency VesselMotion holds the lowest value (long waves), which is reported as
    ``below`` (True when the sea reaches below the table).

    Parameters
    ----------
    table : RaoTable
        The RAO table VesselMotion reads.
    sea : SeaState
        The sea (its spectrum and frequency range; direction taken from ``heading``).
    heading : float
        Wave travel direction relative to the bow [rad].
    n : int
        Integration points over the sea's range.

    Returns
    -------
    dict
        ``{dof: {"kept_std", "lost_std" [m or rad], "lost_fraction" (σ_lost/σ_kept [-])}}`` and
        ``"below": bool``.
    """
    lo, hi = sea.omega_range
    w = np.linspace(lo, hi, n)
    s = sea.density(w)
    inside = w <= table.omega[-1]
    rao = np.abs(table.interpolate(w, np.full(w.size, heading)))
    last = np.abs(table.interpolate(np.array([table.omega[-1]]), np.array([heading])))[:, 0]
    out: dict = {"below": bool(lo < table.omega[0])}
    for j, dof in enumerate(DOFS):
        kept = float(np.trapezoid(rao[j] ** 2 * s * inside, w))
        lost = float(last[j] ** 2 * np.trapezoid(s * ~inside, w))
        out[dof] = {"kept_std": math.sqrt(kept), "lost_std": math.sqrt(lost),
                    "lost_fraction": math.sqrt(lost / kept) if kept > 0 else 0.0}
    return out
