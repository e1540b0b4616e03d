"""The BEM solve with Capytaine: mass properties, radiation and diffraction, RAOs about the COG.

For each wave frequency ω the solver computes the added mass A(ω), the radiation damping B(ω)
(six radiation problems) and the excitation force F(ω, β) (one diffraction problem per wave
direction) of the hull mesh; with the rigid-body mass matrix M and the hydrostatic stiffness C
the motion of the COG per unit wave amplitude is the solution of

.. math:: \\left[-ω^2 (M + A(ω)) - iω (B(ω) + B_v) + C\\right] ξ(ω, β) = F(ω, β)

(Capytaine's ``post_pro.rao``), B_v the optional viscous damping of roll (and of heave and
pitch, for hulls whose potential damping is near zero at resonance, like a deep-draft
semi-submersible's), each a fraction of critical at its natural frequency. Capytaine's time
convention is e^{−iωt} and its frame z-up with y to port; :func:`solve` returns RAOs in the
project's convention (the module docstring of :mod:`marinefmu.sea.vessel`): e^{+iωt},
NED/FRD, heave positive down, β the travel direction from the bow towards starboard.

Mass properties: the mass is the displaced mass ρV of the mesh (a free-floating hull in
equilibrium), the centre of gravity and the radii of gyration about it are given
(:class:`MassProperties`); the rotations are about the COG, so M = diag(m, m, m, m r_xx²,
m r_yy², m r_zz²) (products of inertia neglected).

Irregular frequencies: the boundary integral equation of a surface-piercing hull fails near
the sloshing frequencies of the hull's interior. When Capytaine's estimate of the first one is
inside the frequency grid, a lid (a panelled interior waterplane just below z = 0) is added,
which removes them (Capytaine's extended boundary-integral method); the result still flags
every frequency above the lidded body's estimate (:attr:`HydroResult.irregular`).
"""
from __future__ import annotations

import logging
import math
import time
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Iterator

import numpy as np

from ...errors import ParameterError, check_range, check_vector
from ...frames import G
from .hulls import SOLVER_FROM_BODY, HullMesh, check_closed

DOF_NAMES = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
#: Sign of each DOF from the solver frame (y port, z up) to the body frame (y stbd, z down):
#: a rotation of π about x keeps surge and roll, flips sway, heave, pitch and yaw.
DOF_SIGN = np.array([1.0, -1.0, -1.0, 1.0, -1.0, -1.0])
#: Sea water density [kg/m³].
RHO_SEA = 1025.0
#: Panels per wavelength Capytaine asks for: wavelength ≥ 8 × the largest panel radius.
PANEL_RADII_PER_WAVELENGTH = 8.0


@dataclass(frozen=True)
class MassProperties:
    """Centre of gravity and radii of gyration of a hull.

    Parameters
    ----------
    cog : tuple of float
        Centre of gravity from the hull's origin (midship, centre line, waterline), body frame
        x fwd, y stbd, z down [m]: a COG 2 m above the waterline has z = −2.
    radii : tuple of float
        Radii of gyration about the COG, roll (x), pitch (y), yaw (z) axes [m], each > 0.
    """

    cog: tuple[float, float, float] = (0.0, 0.0, 0.0)
    radii: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def __post_init__(self) -> None:
        check_vector("hull.cog", self.cog, unit="m")
        r = check_vector("hull.radii", self.radii, unit="m")
        for axis, v in zip("xyz", r):
            check_range(f"hull.radii.{axis}", v, lo=0.0, lo_open=True, unit="m")


@dataclass(frozen=True)
class HydroResult:
    """Everything a BEM run produced, in the body frame (x fwd, y stbd, z down) about the COG.

    Attributes
    ----------
    name, description : str
        Hull name and description.
    omega : numpy.ndarray
        (nf,) wave frequencies [rad/s].
    heading : numpy.ndarray
        (nh,) wave travel directions from the bow towards starboard [rad].
    rao : numpy.ndarray
        (6, nf, nh) complex RAOs in the convention of :mod:`marinefmu.sea.vessel`
        (translations [m/m], rotations [rad/m]).
    added_mass, damping : numpy.ndarray
        (nf, 6, 6) added mass [kg, kg·m, kg·m²] and radiation damping [kg/s, …], DOF order
        surge, sway, heave, roll, pitch, yaw.
    excitation : numpy.ndarray
        (6, nf, nh) complex excitation force [N/m] and moment [N·m/m] per unit wave amplitude,
        same phase convention as ``rao``.
    mass_matrix, stiffness, viscous : numpy.ndarray
        (6, 6) rigid-body mass matrix, hydrostatic stiffness [N/m, N·m/rad, …] and added viscous
        damping.
    volume, mass : float
        Displaced volume [m³] and mass ρV [kg].
    cog, radii : tuple of float
        Centre of gravity (body frame, from the waterline origin) and radii of gyration [m].
    gm_t, gm_l : float
        Transverse and longitudinal metacentric heights C44/(ρgV), C55/(ρgV) [m].
    natural_periods : dict of str to float
        Undamped natural periods of heave, roll and pitch [s], from ω²(M_ii + A_ii(ω)) = C_ii.
    roll_damping : float
        Viscous roll damping as a fraction of critical [-] (0: potential damping only).
    heave_damping, pitch_damping : float
        Viscous heave and pitch damping, fractions of critical [-].
    irregular_omega : float
        Capytaine's estimate of the first irregular frequency of the (lidded) body [rad/s].
    irregular : numpy.ndarray
        (nf,) True where ω ≥ ``irregular_omega``: values there may be spoiled.
    lid_z : float or None
        Depth of the irregular-frequency lid (solver frame, z up) [m], None without a lid.
    panels : int
        Panels of the whole hull (the lid not counted).
    seconds : float
        Wall time of the solve [s].
    """

    name: str
    description: str
    omega: np.ndarray
    heading: np.ndarray
    rao: np.ndarray
    added_mass: np.ndarray
    damping: np.ndarray
    excitation: np.ndarray
    mass_matrix: np.ndarray
    stiffness: np.ndarray
    viscous: np.ndarray
    volume: float
    mass: float
    cog: tuple[float, float, float]
    radii: tuple[float, float, float]
    gm_t: float
    gm_l: float
    natural_periods: dict[str, float]
    roll_damping: float
    irregular_omega: float
    irregular: np.ndarray
    lid_z: float | None
    panels: int
    seconds: float
    rho: float = RHO_SEA
    heave_damping: float = 0.0
    pitch_damping: float = 0.0


def wavelength(omega: float, g: float = G) -> float:
    """Deep-water wavelength 2πg/ω² [m] of wave frequency ω [rad/s]."""
    return 2.0 * math.pi * g / omega**2


def panel_for(omega_max: float, g: float = G, margin: float = 0.95) -> float:
    """Side [m] of square panels fine enough for ``omega_max`` [rad/s]: radius s/√2 ≤ λ/8."""
    return margin * math.sqrt(2.0) * wavelength(omega_max, g) / PANEL_RADII_PER_WAVELENGTH


def default_omega(omega_max: float, omega_min: float = 0.1, step: float = 0.05) -> np.ndarray:
    """Uniform wave-frequency grid ``omega_min`` … ``omega_max`` [rad/s] of about ``step`` [rad/s].

    VesselMotion holds the lowest table value below the grid (long waves: the hull follows the
    surface, which the RAO reaches at 0.1 rad/s, a 620 m wave) and takes zero response above it,
    so ``omega_max`` is chosen where the RAOs have died out (waves short against the hull)."""
    n = max(2, int(round((omega_max - omega_min) / step)) + 1)
    return np.linspace(omega_min, omega_max, n)


DEFAULT_HEADINGS = np.deg2rad(np.arange(0.0, 360.0, 15.0))


def check_grid(omega: np.ndarray, heading: np.ndarray, min_wavelength: float, g: float = G) -> tuple[np.ndarray, np.ndarray]:
    """Refuse a frequency or heading grid the solver cannot take on this mesh.

    Parameters
    ----------
    omega : array_like
        Wave frequencies [rad/s]: finite, > 0, strictly increasing, and no shorter wave than
        ``min_wavelength`` [m] (Capytaine's mesh-resolution limit, 8 × the largest panel radius).
    heading : array_like
        Travel directions [rad] in [0, 2π), strictly increasing.
    """
    w = np.asarray(omega, dtype=float).ravel()
    h = np.asarray(heading, dtype=float).ravel()
    if w.size < 2 or not np.all(np.isfinite(w)) or np.any(w <= 0) or np.any(np.diff(w) <= 0):
        raise ParameterError(f"omega = {w.tolist()} is out of range: needs ≥ 2 finite, strictly increasing "
                             "frequencies > 0 [rad/s] (Capytaine solves no diffraction problem at ω = 0 or ∞)")
    wmax = math.sqrt(2.0 * math.pi * g / min_wavelength)
    if w[-1] > wmax * (1 + 1e-9):
        raise ParameterError(
            f"omega_max = {w[-1]:.4g} rad/s is out of range for this mesh: its wavelength {wavelength(w[-1], g):.3g} m "
            f"is shorter than 8 × the largest panel radius ({min_wavelength:.3g} m), Capytaine's resolution limit; "
            f"use omega_max ≤ {wmax:.4g} rad/s or panels ≤ {panel_for(w[-1], g):.3g} m")
    if h.size < 1 or not np.all(np.isfinite(h)) or np.any(np.diff(h) <= 0) or h[0] < 0 or h[-1] >= 2 * math.pi:
        raise ParameterError(f"heading = {h.tolist()} is out of range: strictly increasing directions in [0, 2π) [rad]")
    return w, h


@contextmanager
def _quiet_capytaine(level: int = logging.ERROR) -> Iterator[None]:
    """Silence Capytaine's logger (its resolution warnings are checked here beforehand)."""
    log = logging.getLogger("capytaine")
    old = log.level
    log.setLevel(level)
    try:
        yield
    finally:
        log.setLevel(old)


def _release_matrices() -> None:
    """Free the influence matrices of the last frequency.

    Capytaine 3.0.0 caches ``NestedBlockCirculantMatrix.to_BlockCirculantMatrix`` with an
    unbounded-lifetime ``functools.lru_cache`` on the method, which keeps the matrices of every
    frequency of a doubly symmetric mesh alive (several GB for a preset); clearing it after
    each frequency keeps the memory flat.
    """
    try:
        from capytaine.tools.block_circulant_matrices import NestedBlockCirculantMatrix
    except ImportError:  # another Capytaine version: nothing to release
        return
    clear = getattr(getattr(NestedBlockCirculantMatrix, "to_BlockCirculantMatrix", None), "cache_clear", None)
    if clear is not None:
        clear()


def fit_panels(build, omega_max: float, g: float = G, tries: int = 10) -> HullMesh:
    """``build(panel)`` with the largest panel side [m] whose mesh resolves ``omega_max`` [rad/s].

    Starts from :func:`panel_for` and shrinks by 10 % until 8 × the largest panel radius (as
    Capytaine measures it: the distance from a panel's centre to its farthest vertex) is no
    longer than the wavelength; a panel of a curved hull (a triangle at the stem, a skewed
    quad) can be larger than the square the side was chosen for.
    """
    panel = panel_for(omega_max, g)
    limit = wavelength(omega_max, g) / PANEL_RADII_PER_WAVELENGTH
    for _ in range(tries):
        hull = build(panel)
        if max_panel_radius(hull) <= limit:
            return hull
        panel *= 0.9
    raise ParameterError(f"no panel size resolves omega_max = {omega_max:g} rad/s on hull {hull.name!r}")


def max_panel_radius(hull: HullMesh) -> float:
    """Largest distance [m] from a panel's centre to one of its vertices (Capytaine's
    ``faces_radiuses``; the centre is the area-weighted centroid of the panel's two triangles)."""
    p = hull.vertices[hull.faces]                                   # (m, 4, 3)
    t1, t2 = p[:, [0, 1, 2]], p[:, [0, 2, 3]]
    a1 = 0.5 * np.linalg.norm(np.cross(t1[:, 1] - t1[:, 0], t1[:, 2] - t1[:, 0]), axis=1)
    a2 = 0.5 * np.linalg.norm(np.cross(t2[:, 1] - t2[:, 0], t2[:, 2] - t2[:, 0]), axis=1)
    c = (a1[:, None] * t1.mean(axis=1) + a2[:, None] * t2.mean(axis=1)) / np.maximum(a1 + a2, 1e-300)[:, None]
    return float(np.linalg.norm(p - c[:, None, :], axis=2).max())


def green_function(cache_dir: str | None = None, attempts: int = 20, wait: float = 1.0):
    """Capytaine's Delhommeau Green function, its tabulation loaded from Capytaine's disk
    cache when whole.

    Capytaine writes the tabulation (8.5 MB, about 20 s to compute on a 2-core machine) in
    place, so a second process that loads it while the first is still writing gets a truncated
    zip file (``zipfile.BadZipFile``, which Capytaine does not catch; seen with two test
    workers on a fresh machine). Then this waits ``wait`` s and loads again, up to
    ``attempts`` times, and after that computes the tabulation in memory with a warning.

    Parameters
    ----------
    cache_dir : str, optional
        Tabulation cache folder (default Capytaine's ``cache_directory()``).
    attempts : int
        Loads tried before computing in memory.
    wait : float
        Pause between loads [s].
    """
    import zipfile

    import capytaine as cpt
    from capytaine.tools.cache_on_disk import cache_directory

    folder = cache_directory() if cache_dir is None else cache_dir
    for _ in range(attempts):
        try:
            return cpt.Delhommeau(tabulation_cache_dir=folder)
        except zipfile.BadZipFile:     # another process is writing the file
            time.sleep(wait)
    logging.getLogger(__name__).warning("Capytaine's Green-function tabulation in %s stays unreadable after %d "
                                        "tries; computing it in memory", folder, attempts)
    return cpt.Delhommeau(tabulation_cache_dir=None)


def _solver_mesh(hull: HullMesh, shift_xy: np.ndarray):
    """The Capytaine mesh of ``hull``, the COG moved to x = y = 0 (the RAOs' phase reference)."""
    import capytaine as cpt

    with _quiet_capytaine():
        mesh = cpt.Mesh(hull.vertices, hull.faces, name=hull.name)
        if hull.quarter:
            mesh = cpt.ReflectionSymmetricMesh(cpt.ReflectionSymmetricMesh(mesh, plane="xOz"), plane="yOz")
        if np.any(np.abs(shift_xy) > 1e-9):
            full = mesh.merged() if hull.quarter else mesh
            mesh = full.translated((-shift_xy[0], -shift_xy[1], 0.0))
    return mesh


def cog_for_gm(hull: HullMesh, gm_t: float, rho: float = RHO_SEA, g: float = G) -> float:
    """Depth of the COG below the waterline [m, body z down] that gives the metacentric height
    ``gm_t`` [m]: z_G = z_B + BM_T − GM_T with the centre of buoyancy and the metacentric radius
    of the mesh (Capytaine's hydrostatics)."""
    import capytaine as cpt

    check_range("hull.gm_t", gm_t, lo=0.0, lo_open=True, unit="m")
    with _quiet_capytaine():
        body = cpt.FloatingBody(mesh=_solver_mesh(hull, np.zeros(2)), name=hull.name)
        z_b = float(body.center_of_buoyancy[2])
        bm = float(body.transversal_metacentric_radius)
    return -(z_b + bm - gm_t)


def natural_period(omega: np.ndarray, added: np.ndarray, mass: float, stiffness: float) -> float:
    """Undamped natural period [s] of one DOF: the root of C − ω²(M + A(ω)) = 0.

    A(ω) is interpolated linearly on ``omega`` [rad/s] and held beyond it. Returns nan if
    C ≤ 0.
    """
    if stiffness <= 0:
        return math.nan

    def residual(w: float) -> float:
        return stiffness - w**2 * (mass + float(np.interp(w, omega, added)))

    lo, hi = 1e-4, max(omega[-1], 1.0) * 4.0
    grid = np.concatenate([[lo], omega, [hi]])
    r = np.array([residual(w) for w in grid])
    k = int(np.argmax(r < 0)) if np.any(r < 0) else -1
    if k <= 0:
        return math.nan
    from scipy.optimize import brentq

    return 2.0 * math.pi / brentq(residual, grid[k - 1], grid[k], xtol=1e-10)


def solve(hull: HullMesh, mass: MassProperties, omega: np.ndarray | None = None,
          heading: np.ndarray | None = None, *, roll_damping: float = 0.0, heave_damping: float = 0.0,
          pitch_damping: float = 0.0, rho: float = RHO_SEA, g: float = G,
          lid: bool = True, refine: bool = True, progress: bool = True, threads: int = 1) -> HydroResult:
    """Solve the radiation and diffraction problems of ``hull`` and assemble its RAOs.

    Parameters
    ----------
    hull : HullMesh
        Immersed hull surface (checked by :func:`~marinefmu.sea.hydro.hulls.check_closed`).
    mass : MassProperties
        COG (body frame, from the waterline origin) and radii of gyration [m]; the mass is the
        displaced mass.
    omega : array_like, optional
        Wave frequencies [rad/s] (default: :func:`default_omega` up to the mesh's limit).
    heading : array_like, optional
        Wave travel directions from the bow towards starboard [rad] (default every 15°).
    roll_damping : float
        Viscous roll damping as a fraction of critical, 0 ≤ ζ < 1, added at the roll natural
        frequency: B_v = 2ζ√(C44 (M44 + A44(ω_roll))) [N·m·s/rad].
    heave_damping, pitch_damping : float
        The same for heave and pitch, 0 ≤ ζ < 1 (default 0: potential damping only).
    rho, g : float
        Water density [kg/m³] and gravity [m/s²].
    lid : bool
        Remove irregular frequencies with an interior lid when they fall in the grid.
    refine : bool
        Also solve at the heave, roll and pitch natural frequencies found on the grid, so that
        the table holds the resonance peaks.
    progress : bool
        Show a progress bar (tqdm) over the frequencies.
    threads : int
        BLAS/OpenMP threads of the solve (threadpoolctl). One is fastest on the small blocks of
        a symmetric mesh, and three times faster than two on a busy two-core machine.

    Raises
    ------
    ParameterError
        For a mesh that is not closed, a COG outside the hull, non-positive radii, an unstable
        hull (GM ≤ 0) or a frequency grid the mesh cannot resolve; the message names it.
    """
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=threads):
        return _solve(hull, mass, omega, heading, damping=(heave_damping, roll_damping, pitch_damping), rho=rho, g=g,
                      lid=lid, refine=refine, progress=progress)


def _solve(hull: HullMesh, mass: MassProperties, omega: np.ndarray | None, heading: np.ndarray | None, *,
           damping: tuple[float, float, float], rho: float, g: float, lid: bool, refine: bool,
           progress: bool) -> HydroResult:
    """:func:`solve` inside its thread limit."""
    import capytaine as cpt
    from tqdm import tqdm

    t_start = time.perf_counter()
    zeta = {dof: check_range(f"hull.{dof}_damping", z, lo=0.0, hi=1.0, hi_open=True)
            for dof, z in zip(("heave", "roll", "pitch"), damping)}
    rho = check_range("rho", rho, lo=0.0, lo_open=True, unit="kg/m3")
    volume = check_closed(hull)
    cog_b = np.asarray(mass.cog, dtype=float)
    if not hull.contains(cog_b):
        raise ParameterError(f"hull.cog = {tuple(float(c) for c in cog_b)} m (body frame: x fwd, y stbd, z down, from the "
                             f"waterline origin) is outside the hull {hull.name!r} (deck {hull.freeboard:g} m above the waterline)")
    cog_s = SOLVER_FROM_BODY @ cog_b
    m = rho * volume
    if not m > 0:
        raise ParameterError(f"hull {hull.name!r}: non-positive mass {m:g} kg from the displaced volume")
    mesh = _solver_mesh(hull, cog_s[:2])
    centre = (0.0, 0.0, float(cog_s[2]))
    with _quiet_capytaine():
        body = cpt.FloatingBody(mesh=mesh, dofs=cpt.rigid_body_dofs(rotation_center=centre),
                                center_of_mass=centre, mass=m, name=hull.name)
        min_wl = body.minimal_computable_wavelength
    if omega is None:
        omega = default_omega(min(math.sqrt(2 * math.pi * g / min_wl), 4.0))
    if heading is None:
        heading = DEFAULT_HEADINGS
    omega, heading = check_grid(omega, heading, min_wl, g)
    draft = -float(hull.vertices[:, 2].min())
    lid_z = None
    with _quiet_capytaine():
        if lid and body.first_irregular_frequency_estimate(g=g) < omega[-1] * 1.05:
            lowest = float(mesh.lowest_lid_position(omega[-1] * 1.1, g=g))
            lid_z = max(-0.05 * draft, 0.5 * lowest) if np.isfinite(lowest) else -0.05 * draft
            lid_mesh = mesh.generate_lid(z=lid_z)
            body = cpt.FloatingBody(mesh=mesh, lid_mesh=lid_mesh, dofs=cpt.rigid_body_dofs(rotation_center=centre),
                                    center_of_mass=centre, mass=m, name=hull.name)
        irregular_omega = float(body.first_irregular_frequency_estimate(g=g))
        stiffness = body.compute_hydrostatic_stiffness(rho=rho, g=g)
        inertia = body.compute_rigid_body_inertia(rho=rho)
    stiffness = stiffness.sel(influenced_dof=list(DOF_NAMES), radiating_dof=list(DOF_NAMES))
    inertia = inertia.sel(influenced_dof=list(DOF_NAMES), radiating_dof=list(DOF_NAMES))
    rx, ry, rz = mass.radii
    inertia = inertia.copy(data=np.diag([m, m, m, m * rx**2, m * ry**2, m * rz**2]))
    c = stiffness.values
    gm_t, gm_l = c[3, 3] / (rho * g * volume), c[4, 4] / (rho * g * volume)
    for label, gm in (("transverse (roll)", gm_t), ("longitudinal (pitch)", gm_l)):
        if not gm > 0:
            raise ParameterError(f"hull.cog = {tuple(float(x) for x in cog_b)} m makes hull {hull.name!r} unstable: "
                                 f"{label} metacentric height GM = {gm:.3g} m ≤ 0; lower the centre of gravity")

    beta_solver = np.mod(-heading, 2 * math.pi)     # Capytaine's direction: from x towards port
    solver = cpt.BEMSolver(green_function=green_function())

    def problems(w: float) -> list:
        rad = [cpt.RadiationProblem(body=body, radiating_dof=d, omega=float(w), rho=rho, g=g) for d in DOF_NAMES]
        dif = [cpt.DiffractionProblem(body=body, wave_direction=float(b), omega=float(w), rho=rho, g=g) for b in beta_solver]
        return rad + dif

    results: list = []

    def run(freqs: np.ndarray, desc: str) -> None:
        with _quiet_capytaine():
            for w in tqdm(freqs, desc=desc, unit="ω", disable=not progress, leave=False):
                for pb in problems(w):
                    results.append(solver.solve(pb, keep_details=False, _check_wavelength=False))
                _release_matrices()

    run(omega, f"BEM {hull.name}")

    def assemble():
        with _quiet_capytaine():
            ds = cpt.assemble_dataset(results).sortby("omega")
        ds["inertia_matrix"] = inertia
        ds["hydrostatic_stiffness"] = stiffness
        return ds

    def periods(ds) -> dict[str, float]:
        w = ds.omega.values
        a = ds.added_mass.sel(radiating_dof=list(DOF_NAMES), influenced_dof=list(DOF_NAMES)).values
        mm = inertia.values
        return {dof: natural_period(w, a[:, i, i], mm[i, i], c[i, i]) for dof, i in (("heave", 2), ("roll", 3), ("pitch", 4))}

    ds = assemble()
    if refine:
        extra = []
        for t in periods(ds).values():
            if np.isfinite(t):
                wn = 2 * math.pi / t
                all_w = np.concatenate([omega, extra])
                if omega[0] < wn < omega[-1] and np.min(np.abs(all_w - wn)) > 0.002 * wn:
                    extra.append(wn)
        if extra:
            run(np.sort(extra), f"BEM {hull.name} resonances")
            ds = assemble()
    omega_all = ds.omega.values
    nat = periods(ds)
    viscous = np.zeros((6, 6))
    for dof, i in (("heave", 2), ("roll", 3), ("pitch", 4)):
        if zeta[dof] > 0:
            a_ii = ds.added_mass.sel(radiating_dof=DOF_NAMES[i], influenced_dof=DOF_NAMES[i]).values
            a_n = float(np.interp(2 * math.pi / nat[dof], omega_all, a_ii)) if np.isfinite(nat[dof]) else float(a_ii[0])
            viscous[i, i] = 2.0 * zeta[dof] * math.sqrt(c[i, i] * (inertia.values[i, i] + a_n))
    dissipation = inertia.copy(data=viscous)
    with _quiet_capytaine():
        x = cpt.post_pro.rao(ds, dissipation=dissipation)
    x = x.sel(radiating_dof=list(DOF_NAMES)).transpose("radiating_dof", "omega", "wave_direction")
    fex = ds.excitation_force.sel(influenced_dof=list(DOF_NAMES)).transpose("influenced_dof", "omega", "wave_direction")
    dirs = np.mod(x.wave_direction.values, 2 * math.pi)
    cols = np.array([int(np.argmin(np.abs(np.angle(np.exp(1j * (dirs - b)))))) for b in beta_solver])
    sign = DOF_SIGN[:, None, None]
    rao = sign * np.conj(x.values[:, :, cols])                # e^{−iωt} → e^{+iωt}, solver → body frame
    excitation = sign * np.conj(fex.values[:, :, cols])
    ss = np.outer(DOF_SIGN, DOF_SIGN)
    a = ds.added_mass.sel(radiating_dof=list(DOF_NAMES), influenced_dof=list(DOF_NAMES)).transpose("omega", "influenced_dof", "radiating_dof").values
    b = ds.radiation_damping.sel(radiating_dof=list(DOF_NAMES), influenced_dof=list(DOF_NAMES)).transpose("omega", "influenced_dof", "radiating_dof").values
    panels = int(mesh.nb_faces)
    return HydroResult(
        name=hull.name, description=hull.description, omega=omega_all, heading=heading, rao=rao,
        added_mass=a * ss, damping=b * ss, excitation=excitation, mass_matrix=inertia.values.copy(),
        stiffness=c * ss, viscous=viscous, volume=volume, mass=m, cog=tuple(float(v) for v in cog_b),
        radii=tuple(float(r) for r in mass.radii), gm_t=float(gm_t), gm_l=float(gm_l), natural_periods=nat,
        roll_damping=zeta["roll"], irregular_omega=irregular_omega, irregular=omega_all >= irregular_omega,
        lid_z=lid_z, panels=panels, seconds=time.perf_counter() - t_start, rho=rho,
        heave_damping=zeta["heave"], pitch_damping=zeta["pitch"],
    )
