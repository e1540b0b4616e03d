"""Linear 6-DOF wave-frequency vessel response through RAOs.

RAO convention (our frames, the design page): for a regular wave of amplitude a, elevation
η = a cos(ω_e t + ε) at the origin of the frame moving with the vessel (positive up), the
response of DOF j is x_j(t) = Re(RAO_j(ω, β) · a · e^{i(ω_e t + ε)}). DOFs are surge, sway,
heave (NED, heave positive down) [m/m] and roll, pitch, yaw (ZYX Euler, FRD body) [rad/m].
Tables are indexed by *wave* frequency ω and travel direction β relative to the bow;
the time signal runs at the encounter frequency ω_e = ω − kU cos β. A user table must
therefore hold the RAOs for the vessel speed it is used with.

Built-in presets are *plausible*, not hydrodynamic results: a closed-form strip model of a
box-like hull (:func:`parametric_raos`) with the natural periods and damping ratios given
in :data:`PRESETS` (sources in each preset's ``source`` text). For real work, bring RAOs
from WAMIT, OrcaFlex or Capytaine as a CSV file (:func:`load_rao_csv`). The BEM presets
(:data:`BEM_PRESETS`) are such files, computed with Capytaine by ``marinefmu hydro``
(:mod:`marinefmu.sea.hydro`) and shipped under ``marinefmu/data/hydro``.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

from typing import TYPE_CHECKING

import numpy as np

from ..errors import RaoFileError, check_choice, check_range
from ..frames import G

if TYPE_CHECKING:
    from .waves import WaveField

DOFS = ("surge", "sway", "heave", "roll", "pitch", "yaw")
CSV_COLUMNS = ("omega", "heading") + tuple(f"{d}_{p}" for d in DOFS for p in ("amp", "phase"))


@dataclass(frozen=True)
class RaoTable:
    """Complex RAOs on a frequency × heading grid.

    Attributes
    ----------
    omega : numpy.ndarray
        (nf,) strictly increasing wave frequencies [rad/s].
    heading : numpy.ndarray
        (nh,) strictly increasing travel directions relative to the bow, in [0, 2π) [rad].
    rao : numpy.ndarray
        (6, nf, nh) complex RAOs, translations [m/m], rotations [rad/m].
    name : str
        Where the table came from (preset name or file path).
    """

    omega: np.ndarray
    heading: np.ndarray
    rao: np.ndarray
    name: str = "table"

    def __post_init__(self) -> None:
        nf, nh = self.omega.size, self.heading.size
        if self.rao.shape != (6, nf, nh):
            raise RaoFileError(f"{self.name}: RAO array has shape {self.rao.shape}, expected (6, {nf}, {nh})")
        if nf < 2 or np.any(np.diff(self.omega) <= 0) or self.omega[0] <= 0:
            raise RaoFileError(f"{self.name}: omega must hold ≥ 2 strictly increasing values > 0 [rad/s]")
        if nh < 1 or np.any(np.diff(self.heading) <= 0) or self.heading[0] < 0 or self.heading[-1] >= 2 * math.pi:
            raise RaoFileError(f"{self.name}: heading must hold strictly increasing values in [0, 2π) [rad]")
        if not np.all(np.isfinite(self.rao)):
            raise RaoFileError(f"{self.name}: RAO values must be finite")

    def interpolate(self, omega: np.ndarray, heading: np.ndarray) -> np.ndarray:
        """RAOs at wave frequencies ``omega`` [rad/s] and directions ``heading`` [rad].

        Linear in the real and imaginary parts; periodic in heading. Below the table's lowest
        frequency the lowest-frequency value is held (long waves: the vessel follows the
        surface); above the highest, the response is zero (the hull filters short waves).

        Returns
        -------
        numpy.ndarray
            (6, n) complex RAOs.
        """
        w = np.asarray(omega, dtype=float)
        h = np.mod(np.asarray(heading, dtype=float), 2 * math.pi)
        hs = np.concatenate([self.heading, [self.heading[0] + 2 * math.pi]])
        table = np.concatenate([self.rao, self.rao[:, :, :1]], axis=2)
        # heading: locate the bracketing pair (periodic)
        if self.heading.size == 1:
            per_h = np.repeat(self.rao[:, :, :1], w.size, axis=2)  # (6, nf, n)
        else:
            hh = np.where(h < hs[0], h + 2 * math.pi, h)
            j = np.clip(np.searchsorted(hs, hh, side="right") - 1, 0, hs.size - 2)
            fh = (hh - hs[j]) / (hs[j + 1] - hs[j])
            per_h = table[:, :, j] * (1 - fh) + table[:, :, j + 1] * fh  # (6, nf, n)
        wc = np.clip(w, self.omega[0], self.omega[-1])
        i = np.clip(np.searchsorted(self.omega, wc, side="right") - 1, 0, self.omega.size - 2)
        fw = (wc - self.omega[i]) / (self.omega[i + 1] - self.omega[i])
        cols = np.arange(w.size)
        out = per_h[:, i, cols] * (1 - fw) + per_h[:, i + 1, cols] * fw
        out[:, w > self.omega[-1]] = 0.0
        return out


@dataclass(frozen=True)
class HullParticulars:
    """Main dimensions and natural periods of a preset hull.

    Attributes
    ----------
    length, beam, draft : float
        Waterline length, beam and draft [m].
    t_heave, t_roll, t_pitch : float
        Undamped natural periods [s].
    zeta_heave, zeta_roll, zeta_pitch : float
        Linear damping ratios [-].
    source : str
        Where the numbers come from.
    """

    length: float
    beam: float
    draft: float
    t_heave: float
    t_roll: float
    t_pitch: float
    zeta_heave: float
    zeta_roll: float
    zeta_pitch: float
    source: str


PRESETS: dict[str, HullParticulars] = {
    "semisub": HullParticulars(
        82.0, 71.2, 36.0, 20.0, 32.0, 32.0, 0.05, 0.05, 0.05,
        "Paper 000 (Liu et al.), semi-submersible model: 82 × 71.2 m, draft 36 m, displacement "
        "65,700 m³, radii of gyration 22.8/23.2/23.2 m. Natural periods typical of deep-draft "
        "semi-submersibles (heave ~20 s, roll/pitch 30-35 s; DNV-RP-C205 §7, Chakrabarti 2005).",
    ),
    "polar_supply": HullParticulars(
        134.2, 22.0, 7.65, 6.6, 12.5, 6.3, 0.20, 0.06, 0.20,
        "Paper 002 (Zhang et al.), S.A. Agulhas II: LOA 134.2 m, beam 22 m, draught 7.65 m. "
        "Heave/pitch period ≈ 2.4√T (Journée & Massie 2001, ch. 6); roll period from the IMO "
        "weather-criterion formula T = 2cB/√GM with c = 0.4, GM ≈ 2 m.",
    ),
    "research36": HullParticulars(
        36.0, 9.4, 3.5, 4.5, 7.5, 4.2, 0.20, 0.07, 0.20,
        "Paper 002 (Zhang et al.), RV Simon Stevin: LOA 36 m, beam 9.4 m, draught 3.5 m. "
        "Heave/pitch period ≈ 2.4√T; roll period T = 2cB/√GM with c = 0.4, GM ≈ 1 m.",
    ),
}


def _sinc(x: np.ndarray) -> np.ndarray:
    """sin(x)/x with the limit 1 at x = 0 (force of a uniform strip under a sinusoidal pressure)."""
    return np.sinc(np.asarray(x) / math.pi)


def _moment_factor(x: np.ndarray) -> np.ndarray:
    """3(sin x − x cos x)/x³ with the limit 1 at x = 0 (moment of a uniform strip)."""
    x = np.asarray(x, dtype=float)
    ax = np.abs(x)
    small = ax < 1e-3
    xs = np.where(small, 1.0, x)
    out = 3.0 * (np.sin(xs) - xs * np.cos(xs)) / xs**3
    return np.where(small, 1.0 - x**2 / 10.0, out)


def _tapered_factors(kx: np.ndarray, length: float, n: int = 401) -> tuple[np.ndarray, np.ndarray]:
    """Force and moment factors of a tapered waterplane w(x) = cos²(πx/L), |x| ≤ L/2.

    F(k_x) = ∫w cos(k_x x) dx / ∫w and M(k_x) = ∫x w sin(k_x x) dx / (k_x ∫x² w dx), both → 1
    for long waves. A ship's waterplane narrows towards bow and stern, so unlike a box (sinc)
    the excitation has no deep zeros when the wavelength is close to the ship length.
    """
    x = np.linspace(-length / 2, length / 2, n)
    w = np.cos(np.pi * x / length) ** 2
    arg = kx[..., None] * x
    force = np.trapezoid(w * np.cos(arg), x, axis=-1) / np.trapezoid(w, x)
    i2 = np.trapezoid(x**2 * w, x)
    safe = np.where(np.abs(kx) < 1e-9, 1.0, kx)
    moment = np.where(np.abs(kx) < 1e-9, 1.0, np.trapezoid(x * w * np.sin(arg), x, axis=-1) / (safe * i2))
    return force, moment


def _oscillator(omega_e: np.ndarray, period: float, zeta: float) -> np.ndarray:
    """Dynamic amplification H = 1 / (1 − r² + 2iζr), r = ω_e/ω_n."""
    r = np.abs(omega_e) * period / (2 * math.pi)
    return 1.0 / (1.0 - r**2 + 2j * zeta * r)


def parametric_raos(hull: HullParticulars, name: str, speed: float = 0.0) -> RaoTable:
    """Closed-form RAOs of a box-like hull (plausible, not a hydrodynamic solution).

    Each DOF is its long-wave limit (the hull follows the surface: heave = −η, pitch =
    ∂η/∂x, roll = −∂η/∂y, surge/sway = horizontal particle motion), times an attenuation for
    waves short compared with the hull (force/moment factors of a tapered waterplane along
    the length, :func:`_tapered_factors`, and of a uniform strip across the beam, and the
    pressure decay e^{−kT} over the draft), times a one-DOF dynamic amplification at the
    encounter frequency for heave, roll and pitch.

    Parameters
    ----------
    hull : HullParticulars
        Dimensions, natural periods and damping.
    name : str
        Table name.
    speed : float
        Forward speed U [m/s] at which the resonances are placed (encounter frequency).
    """
    omega = np.linspace(0.05, 4.0, 80)
    heading = np.deg2rad(np.arange(0.0, 360.0, 15.0))
    w, b = np.meshgrid(omega, heading, indexing="ij")
    k = w**2 / G
    we = w - k * speed * np.cos(b)
    cb, sb = np.cos(b), np.sin(b)
    xb = k * hull.beam * sb / 2.0
    fl, ml = _tapered_factors(k * cb, hull.length)
    depth = np.exp(-k * hull.draft)
    rao = np.empty((6,) + w.shape, dtype=complex)
    rao[0] = -1j * cb * fl * depth
    rao[1] = -1j * sb * _sinc(xb) * depth
    rao[2] = -1.0 * fl * _sinc(xb) * depth * _oscillator(we, hull.t_heave, hull.zeta_heave)
    rao[3] = 1j * k * sb * _moment_factor(xb) * fl * depth * _oscillator(we, hull.t_roll, hull.zeta_roll)
    rao[4] = -1j * k * cb * ml * _sinc(xb) * depth * _oscillator(we, hull.t_pitch, hull.zeta_pitch)
    rao[5] = -0.5 * k * sb * cb * ml * depth
    return RaoTable(omega=omega, heading=heading, rao=rao, name=name)


#: BEM presets: zero-speed RAO tables from Capytaine (``marinefmu hydro --preset all``), read at
#: run time from ``marinefmu/data/hydro/<name>.csv``.
BEM_PRESETS = ("box_barge", "polar_supply_bem", "semisub_bem", "research36_bem")
#: Every name ``vessel.preset`` takes: the closed-form presets, then the BEM presets.
PRESET_NAMES = (*PRESETS, *BEM_PRESETS)


def bem_preset_path(name: str) -> Path:
    """The shipped CSV file of BEM preset ``name`` (inside the package, for the FMU bundle)."""
    return Path(__file__).resolve().parent.parent / "data" / "hydro" / f"{name}.csv"


def preset_raos(name: str, speed: float = 0.0) -> RaoTable:
    """RAO table of a built-in preset: closed-form (``"semisub"``, ``"polar_supply"``,
    ``"research36"``, at forward speed ``speed`` [m/s]) or BEM (:data:`BEM_PRESETS`, computed
    for zero speed: ``speed`` only shifts the encounter frequency, as for a ``vessel.rao_file``)."""
    check_choice("vessel.preset", name, PRESET_NAMES)
    if name in BEM_PRESETS:
        t = load_rao_csv(bem_preset_path(name))
        return RaoTable(omega=t.omega, heading=t.heading, rao=t.rao, name=name)
    return parametric_raos(PRESETS[name], name, speed)


def save_rao_csv(table: RaoTable, path: str | Path) -> None:
    """Write ``table`` as a CSV file in the format :func:`load_rao_csv` reads.

    One row per (omega, heading) pair; columns ``omega`` [rad/s], ``heading`` [rad] and, per
    DOF, ``<dof>_amp`` [m/m or rad/m] and ``<dof>_phase`` [rad]; lines starting with ``#`` are
    comments.
    """
    with open(path, "w", newline="") as fh:
        fh.write("# marinefmu RAO table: NED/FRD frames, heave positive down, rotations ZYX Euler\n")
        fh.write("# response = Re(amp*exp(i*phase) * a*exp(i*(omega_e*t + eps))), eta positive up\n")
        writer = csv.writer(fh)
        writer.writerow(CSV_COLUMNS)
        for i, w in enumerate(table.omega):
            for j, h in enumerate(table.heading):
                row = [repr(float(w)), repr(float(h))]
                for d in range(6):
                    z = table.rao[d, i, j]
                    row += [repr(float(abs(z))), repr(float(np.angle(z)))]
                writer.writerow(row)


def load_rao_csv(path: str | Path) -> RaoTable:
    """Read an RAO table from a CSV file (see :func:`save_rao_csv` for the format).

    Raises
    ------
    RaoFileError
        If the file cannot be read, a column is missing, a value is not a finite number, the
        grid is incomplete, or an amplitude is negative. The message names the file, the row
        and the column.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise RaoFileError(f"vessel.rao_file = {str(path)!r} cannot be read: {exc.strerror}") from exc
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise RaoFileError(f"vessel.rao_file {path}: no header row found")
    rows = list(csv.reader(lines))
    header = [c.strip() for c in rows[0]]
    missing = [c for c in CSV_COLUMNS if c not in header]
    if missing:
        raise RaoFileError(f"vessel.rao_file {path}: missing column(s) {', '.join(missing)}; expected {', '.join(CSV_COLUMNS)}")
    idx = [header.index(c) for c in CSV_COLUMNS]
    data = np.empty((len(rows) - 1, len(CSV_COLUMNS)))
    for r, row in enumerate(rows[1:], start=2):
        for c, k in enumerate(idx):
            try:
                v = float(row[k])
            except (IndexError, ValueError):
                raise RaoFileError(f"vessel.rao_file {path}: data row {r - 1}, column {CSV_COLUMNS[c]!r}: not a number") from None
            if not math.isfinite(v):
                raise RaoFileError(f"vessel.rao_file {path}: data row {r - 1}, column {CSV_COLUMNS[c]!r}: not finite")
            data[r - 2, c] = v
    if data.shape[0] == 0:
        raise RaoFileError(f"vessel.rao_file {path}: no data rows")
    if np.any(data[:, 2::2] < 0):
        raise RaoFileError(f"vessel.rao_file {path}: amplitudes must be >= 0")
    omega, heading = np.unique(data[:, 0]), np.unique(np.mod(data[:, 1], 2 * math.pi))
    if omega.size * heading.size != data.shape[0]:
        raise RaoFileError(
            f"vessel.rao_file {path}: {data.shape[0]} rows do not form a complete grid of "
            f"{omega.size} frequencies × {heading.size} headings"
        )
    rao = np.full((6, omega.size, heading.size), np.nan, dtype=complex)
    i = np.searchsorted(omega, data[:, 0])
    j = np.searchsorted(heading, np.mod(data[:, 1], 2 * math.pi))
    for d in range(6):
        rao[d, i, j] = data[:, 2 + 2 * d] * np.exp(1j * data[:, 3 + 2 * d])
    if np.isnan(rao).any():
        raise RaoFileError(f"vessel.rao_file {path}: duplicate (omega, heading) rows leave the grid incomplete")
    return RaoTable(omega=omega, heading=heading, rao=rao, name=str(path))


@dataclass(frozen=True)
class MotionSeries:
    """Precomputed sum of sinusoids for the six DOFs, their first two derivatives and the wave.

    ``coef`` is (19, N) complex: rows 0-5 position coefficients C, 6-11 iω_e C, 12-17 −ω_e² C,
    row 18 the wave elevation a e^{iε}; one matrix-vector product with e^{iω_e t} yields all
    19 values exactly.
    """

    coef: np.ndarray
    omega_e: np.ndarray

    @classmethod
    def build(cls, table: RaoTable, trans: "WaveField", speed: float, rot: "WaveField | None" = None) -> "MotionSeries":
        """Combine RAOs and wave components into the coefficient matrix.

        Parameters
        ----------
        table : RaoTable
            Vessel RAOs.
        trans : WaveField
            Realisation driving the translations (and the rotations when ``rot`` is None).
        speed : float
            Forward speed [m/s] (encounter frequencies).
        rot : WaveField, optional
            An independent realisation driving the rotations (independent-rotation mode): the
            matrix then has 2N columns, translations on the first N, rotations on the last N.
        """
        def coefficients(field: "WaveField") -> tuple[np.ndarray, np.ndarray]:
            c = table.interpolate(field.omega, field.direction) * field.amplitude * np.exp(1j * field.phase)
            return c, field.encounter_frequency(speed)

        c, we = coefficients(trans)
        wave = trans.amplitude * np.exp(1j * trans.phase)
        if rot is not None:
            cr, wr = coefficients(rot)
            zeros = np.zeros((3, c.shape[1]))
            c = np.vstack([np.hstack([c[:3], zeros]), np.hstack([zeros, cr[3:]])])
            we = np.concatenate([we, wr])
            wave = np.concatenate([wave, np.zeros(cr.shape[1])])
        coef = np.vstack([c, 1j * we * c, -(we**2) * c, wave[None]])
        return cls(coef=coef, omega_e=np.asarray(we, dtype=float))

    def at(self, t: float) -> np.ndarray:
        """(19,) [x(6), ẋ(6), ẍ(6), η] at time ``t`` [s]."""
        return (self.coef @ np.exp(1j * (self.omega_e * t))).real

    def series(self, t: np.ndarray, chunk: int = 2048) -> np.ndarray:
        """(n, 19) values at the times ``t`` (vectorised, for analysis and tests)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.empty((t.size, self.coef.shape[0]))
        for i in range(0, t.size, chunk):
            out[i : i + chunk] = (np.exp(1j * np.outer(t[i : i + chunk], self.omega_e)) @ self.coef.T).real
        return out


def check_speed(speed: float) -> float:
    """Validate a forward speed [m/s] (0 … 20)."""
    return check_range("vessel.speed", speed, lo=0.0, hi=20.0, unit="m/s")
