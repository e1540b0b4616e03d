"""The BEM presets: hulls from the closed-form presets' main particulars, solved by Capytaine.

Each preset is a parametric hull, its mass properties and the frequency range of its solve.
The CSV tables it produces ship under ``marinefmu/data/hydro/<name>.csv``, and VesselMotion
selects them like the closed-form presets (``vessel.preset``, see
:data:`marinefmu.sea.vessel.BEM_PRESETS`). Regenerate them all with::

    marinefmu hydro --preset all --out src/marinefmu/data/hydro --plots docs

Main particulars are those of :data:`marinefmu.sea.vessel.PRESETS` (sources there); what a
closed-form preset does not give is stated here as an assumption: the hull shape (a Wigley-type
form of block coefficient 0.60 for the two ships, the semi-submersible's pontoons and columns
sized to the paper's displacement), the metacentric height of the semi-submersible, the radii
of gyration of the ships (r_xx = 0.4 B, the c of the IMO roll-period formula the closed-form
presets use; r_yy = r_zz = 0.25 L).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

from ...errors import check_choice
from .bem import MassProperties, fit_panels
from .hulls import HullMesh, box_barge, semisubmersible, ship_hull


@dataclass(frozen=True)
class BemPreset:
    """A hull, its mass properties and solve settings.

    Attributes
    ----------
    name : str
        Preset (and CSV file) name.
    counterpart : str or None
        The closed-form preset of the same ship in :data:`marinefmu.sea.vessel.PRESETS`.
    build : callable
        ``build(panel)`` → :class:`~marinefmu.sea.hydro.hulls.HullMesh` with panels ≤ ``panel`` [m].
    gm_t : float or None
        Transverse metacentric height [m] that places the COG height (KG = KB + BM − GM), or
        None to use ``cog_z``.
    cog_z : float
        COG below the waterline [m, body z down] when ``gm_t`` is None.
    radii : tuple of float
        Radii of gyration about the COG, roll, pitch, yaw [m].
    roll_damping : float
        Viscous roll damping, fraction of critical [-].
    omega_max : float
        Highest wave frequency of the shipped table [rad/s]; the panels follow from it.
    source : str
        Where the numbers come from.
    heave_damping, pitch_damping : float
        Viscous heave and pitch damping, fractions of critical [-] (0: potential damping only).
    """

    name: str
    counterpart: str | None
    build: Callable[[float], HullMesh]
    gm_t: float | None
    cog_z: float
    radii: tuple[float, float, float]
    roll_damping: float
    omega_max: float
    source: str
    heave_damping: float = 0.0
    pitch_damping: float = 0.0

    def hull(self, coarse: bool = False, omega_max: float | None = None) -> HullMesh:
        """The hull mesh at the shipped resolution, a coarse one (ω ≤ :data:`COARSE_OMEGA_MAX`),
        or one resolving ``omega_max`` [rad/s]."""
        return fit_panels(self.build, omega_max or self.omega_limit(coarse))

    def omega_limit(self, coarse: bool = False) -> float:
        """Highest frequency solved [rad/s]."""
        return COARSE_OMEGA_MAX if coarse else self.omega_max


#: Highest frequency of the coarse meshes the tests use [rad/s] (a 27 m wave).
COARSE_OMEGA_MAX = 1.5


BEM_PRESETS: dict[str, BemPreset] = {
    p.name: p for p in (
        BemPreset(
            "box_barge", None, lambda panel: box_barge(100.0, 20.0, 5.0, panel), None, 0.0,
            (7.0, 25.0, 26.0), 0.05, 2.2,
            "Box barge 100 × 20 × 5 m, COG on the waterline on the centre line (GM 4.17 m), radii of "
            "gyration 0.35 B, 0.25 L, 0.26 L; viscous roll damping 5 % of critical.",
        ),
        BemPreset(
            "polar_supply_bem", "polar_supply", lambda panel: ship_hull(134.2, 22.0, 7.65, panel, p=3.0, q=4.0, freeboard=8.0),
            2.0, 0.0, (0.4 * 22.0, 0.25 * 134.2, 0.25 * 134.2), 0.06, 2.2,
            "S.A. Agulhas II main particulars (paper 002): 134.2 × 22 × 7.65 m; Wigley-type hull of C_B 0.60; "
            "GM 2 m and viscous roll damping 6 % of critical as the closed-form preset; r_xx = 0.4 B, "
            "r_yy = r_zz = 0.25 L.",
        ),
        BemPreset(
            "semisub_bem", "semisub",
            lambda panel: semisubmersible(82.0, 71.2, 36.0, 18.0, 18.0, 11.6, panel, freeboard=15.0),
            2.5, 0.0, (22.8, 23.2, 23.2), 0.05, 1.6,
            "Paper 000 semi-submersible: 82 × 71.2 m, draft 36 m, radii of gyration 22.8/23.2/23.2 m; two "
            "pontoons 82 × 18 × 11.6 m and four 18 m square columns, 65,866 m³ (paper: 65,700 m³); GM 2.5 m "
            "(assumed, typical of deep-draft semi-submersibles); viscous damping 5 % of critical in heave, roll "
            "and pitch (the closed-form preset's ratios; the potential damping of a deep-draft semi-submersible "
            "is nearly zero at its 19 s heave and pitch resonances).",
            heave_damping=0.05, pitch_damping=0.05,
        ),
        BemPreset(
            "research36_bem", "research36", lambda panel: ship_hull(36.0, 9.4, 3.5, panel, p=3.0, q=4.0, freeboard=3.5),
            1.0, 0.0, (0.4 * 9.4, 0.25 * 36.0, 0.25 * 36.0), 0.07, 3.5,
            "RV Simon Stevin main particulars (paper 002): 36 × 9.4 × 3.5 m; Wigley-type hull of C_B 0.60; "
            "GM 1 m and viscous roll damping 7 % of critical as the closed-form preset; r_xx = 0.4 B, "
            "r_yy = r_zz = 0.25 L.",
        ),
    )
}


def preset(name: str) -> BemPreset:
    """The BEM preset ``name`` (one of :data:`BEM_PRESETS`)."""
    check_choice("hydro preset", name, BEM_PRESETS)
    return BEM_PRESETS[name]


def mass_properties(p: BemPreset, hull: HullMesh) -> MassProperties:
    """COG and radii of ``p`` on ``hull``: the COG height from the target GM_T and the mesh's
    hydrostatics (:func:`~marinefmu.sea.hydro.bem.cog_for_gm`)."""
    from .bem import cog_for_gm

    cog_z = cog_for_gm(hull, p.gm_t) if p.gm_t is not None else p.cog_z
    if not math.isfinite(cog_z):
        raise ValueError(f"{p.name}: no COG height gives GM {p.gm_t} m")
    return MassProperties(cog=(0.0, 0.0, cog_z), radii=p.radii)
