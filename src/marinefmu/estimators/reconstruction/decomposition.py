"""Non-integral displacement reconstruction from acceleration (paper 000, sections 3.2-3.5).

The method, per axis of the tilt-corrected acceleration a(t):

1. **Tilt correction** (eqs. 10-15). ``tilt="exact"`` (default) rotates the specific force into
   NED with the estimated attitude, a_n = R_nb f_b + g_n. ``tilt="small_angle"`` is the paper's
   form: only the gravity projection is removed with cos Φ ≈ 1, sin Φ ≈ Φ, and the dynamic
   acceleration stays in the sensor axes. In our frames (NED/FRD, f_b = R_nbᵀ(a_n − g_n);
   the paper is z-up) eq. 15 reads a ≈ f_b + g·[−θ, φ, 1].
2. **Complex-exponential decomposition** (eqs. 16-23): a_k = Σ γ_i e^{λ_i k Δt}. The Hankel
   matrices H(0), H(1) (eq. 17) are built from the samples, H(0) = U S Vᵀ (eq. 18) is truncated
   to the model order ``od``, the system matrix A = S^{-½} Uᵀ H(1) V S^{-½} (eq. 19, the
   eigensystem realisation algorithm) gives the discrete poles μ_i = eig(A) and
   λ_i = ln(μ_i)/Δt, and the amplitudes γ_i follow from a least-squares fit of eq. 22 to all
   samples. The order grows by 2 from od = 2 until the stopping criterion of eqs. 20-21,
   SC_sw = |(S^{od+2} − S^{od}) / S^{od}| < ``sc_tol`` with S^{od} the peak of the model
   signal's periodogram in dB, or until ``max_components`` components (a conjugate pair or a
   real pole counts once) are reached.
3. **Screening** (eqs. 24-25): components with frequency |Im λ|/2π ≤ F (``cutoff``) are the
   drift-causing terms (offset, trends, slow transients) and are dropped. (The paper writes
   f > F; a real signal's conjugate partner has −f, so |f| is meant.)
4. **Displacement and velocity without integration** (eqs. 29-31): x(t) = Σ γ/λ² e^{λt},
   v(t) = Σ γ/λ e^{λt} over the kept components.
5. **Transfer to the COG** (eq. 32) with the exact rotation: p_cog = p_s − R_nb l (l the sensor
   lever arm from the COG, body frame), keeping the zero-mean convention of the reconstruction.

Beyond the paper, for speed and long records:

- the signal is low-pass filtered (Butterworth, zero-phase) and decimated to about 10 × ``fmax``
  before the SVD; the continuous-time poles are then evaluated at the original sample times;
- the SVD is a randomised truncated SVD (Halko, Martinsson & Tropp 2011; written here in numpy
  because scipy has none, and ``scipy.sparse.linalg.svds`` is slow for hundreds of triplets)
  when the Hankel matrix is much larger than the model order, else LAPACK's full SVD;
- records longer than ``segment`` are processed in half-overlapping segments blended with a
  cos² cross-fade (a partition of unity), so the cost is linear in the record length and the
  model order stays moderate however many wave components the sea holds;
- ``stop="residual"`` is an alternative stopping rule (relative RMS of the fit residual below
  ``sc_tol``) to compare with the paper's spectral-peak criterion.
"""
from __future__ import annotations

import math
from functools import lru_cache
from dataclasses import dataclass, field

import numpy as np
from scipy import linalg, signal

from ...errors import ParameterError, ShapeError, check_choice, check_int, check_range
from ...frames import G
from ..numerics import one_blas_thread

TILT_CHOICES = ("exact", "small_angle")
STOP_CHOICES = ("sc_sw", "residual")
COMPONENT_DTYPE = np.dtype([
    ("axis", "i4"), ("segment", "i4"), ("t0", "f8"), ("frequency", "f8"), ("damping", "f8"),
    ("amplitude", "f8"), ("phase", "f8"), ("kept", "?"),
])


# ------------------------------------------------------------------------------------------------
# Tilt correction and COG transfer
# ------------------------------------------------------------------------------------------------
def rotations(roll: np.ndarray, pitch: np.ndarray, yaw: np.ndarray) -> np.ndarray:
    """(N, 3, 3) R_nb = Rz(ψ) Ry(θ) Rx(φ) for arrays of ZYX Euler angles [rad] (vectorised
    :func:`marinefmu.frames.rot_nb`)."""
    cf, sf = np.cos(roll), np.sin(roll)
    ct, st = np.cos(pitch), np.sin(pitch)
    cp, sp = np.cos(yaw), np.sin(yaw)
    return np.stack([
        np.stack([cp * ct, cp * st * sf - sp * cf, cp * st * cf + sp * sf], -1),
        np.stack([sp * ct, sp * st * sf + cp * cf, sp * st * cf - cp * sf], -1),
        np.stack([-st, ct * sf, ct * cf], -1),
    ], -2)


def tilt_correct(f_b: np.ndarray, euler: np.ndarray, method: str = "exact", rot: np.ndarray | None = None) -> np.ndarray:
    """Acceleration without gravity from specific force and attitude (paper 000, eqs. 10-15).

    Parameters
    ----------
    f_b : numpy.ndarray
        (N, 3) specific force [m/s², b].
    euler : numpy.ndarray
        (N, 3) roll, pitch, yaw [rad].
    method : {"exact", "small_angle"}
        ``"exact"``: a_n = R_nb f_b + g_n [m/s², NED]. ``"small_angle"``: eq. 15,
        a ≈ f_b + g·[−θ, φ, 1] (sensor axes; yaw is not used).
    rot : numpy.ndarray, optional
        (N, 3, 3) :func:`rotations` of ``euler``, if already computed.

    Returns
    -------
    numpy.ndarray
        (N, 3) acceleration [m/s²].
    """
    check_choice("tilt", method, TILT_CHOICES)
    f_b = _as_n3("f_b", f_b)
    euler = _as_n3("euler", euler)
    if len(euler) != len(f_b):
        raise ShapeError(f"euler must have the length of f_b ({len(f_b)}), got {len(euler)}")
    if method == "small_angle":
        return f_b + G * np.column_stack((-euler[:, 1], euler[:, 0], np.ones(len(f_b))))
    if rot is None:
        rot = rotations(euler[:, 0], euler[:, 1], euler[:, 2])
    return np.einsum("nij,nj->ni", rot, f_b) + np.array([0.0, 0.0, G])


def lever_arm_offset(euler: np.ndarray, lever_arm: np.ndarray, dt: float | None = None,
                     cutoff: float | None = None, rot: np.ndarray | None = None) -> np.ndarray:
    """The part of the sensor's offset from the COG, R_nb(t) l [m, NED], that eq. 32 subtracts
    from a reconstructed displacement to move it to the COG.

    The reconstruction holds only the motion above the screening frequency, so the offset is
    taken in the same band: with ``dt`` and ``cutoff`` given, R_nb l is high-pass filtered at
    ``cutoff`` (zero-phase 4th-order Butterworth); otherwise only its mean is removed. The band
    matters: a slow yaw drift of 0.6° at a 54 m horizontal lever arm moves R_nb l by 0.5 m,
    all of it below the cutoff, where the reconstruction has nothing to subtract it from.

    Parameters
    ----------
    euler : numpy.ndarray
        (N, 3) roll, pitch, yaw [rad].
    lever_arm : array_like
        (3,) sensor position relative to the COG, body frame [m].
    dt, cutoff : float, optional
        Sample interval [s] and screening frequency [Hz].
    rot : numpy.ndarray, optional
        (N, 3, 3) :func:`rotations` of ``euler``, if already computed.
    """
    euler = _as_n3("euler", euler)
    if rot is None:
        rot = rotations(euler[:, 0], euler[:, 1], euler[:, 2])
    off = rot @ np.asarray(lever_arm, dtype=float)
    if dt is None or cutoff is None or len(off) < 30:
        return off - off.mean(axis=0)
    sos = _butter_sos(4, cutoff, "highpass", 1.0 / dt)
    return signal.sosfiltfilt(sos, off, axis=0)


@lru_cache(maxsize=16)
def _butter_sos(order: int, wn: float, btype: str, fs: float | None) -> np.ndarray:
    """Butterworth second-order sections (``scipy.signal.butter``), designed once per setting
    and shared: ``sosfiltfilt`` does not change its ``sos``."""
    return signal.butter(order, wn, btype=btype, fs=fs, output="sos")


# ------------------------------------------------------------------------------------------------
# Decomposition
# ------------------------------------------------------------------------------------------------
@dataclass
class Decomposition:
    """Complex exponentials a(t) = Σ γ_i e^{λ_i (t − t0)} of one signal (eq. 22).

    Attributes
    ----------
    lam : numpy.ndarray
        (M,) continuous-time poles λ [1/s].
    gamma : numpy.ndarray
        (M,) complex amplitudes γ [signal unit].
    t0 : float
        Time of the first sample [s].
    kept : numpy.ndarray
        (M,) bool, False for screened (drift-causing) components.
    order : int
        Model order used.
    sc : float
        Last value of the stopping criterion.
    """

    lam: np.ndarray
    gamma: np.ndarray
    t0: float = 0.0
    kept: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    order: int = 0
    sc: float = math.nan

    @property
    def frequency(self) -> np.ndarray:
        """|Im λ| / 2π [Hz] (eq. 24)."""
        return np.abs(self.lam.imag) / (2 * math.pi)

    def screen(self, cutoff: float, max_damping: float | None = None) -> None:
        """Keep components with frequency above ``cutoff`` [Hz] (eq. 25) and, if
        ``max_damping`` is given, with |damping ratio| ≤ max_damping."""
        self.kept = self.frequency > cutoff
        if max_damping is not None:
            self.kept &= np.abs(self.damping) <= max_damping

    @property
    def damping(self) -> np.ndarray:
        """Damping ratio ξ = −Re λ / |λ| (negative for a growing component)."""
        mag = np.abs(self.lam)
        return np.where(mag > 0, -self.lam.real / np.where(mag > 0, mag, 1.0), 0.0)

    def evaluate(self, t: np.ndarray, power: int, kept_only: bool = True) -> np.ndarray:
        """Σ γ λ^{-power} e^{λ(t − t0)}: acceleration (0), velocity (1), displacement (2).

        Parameters
        ----------
        t : numpy.ndarray
            Times [s].
        power : int
            0, 1 or 2 (eqs. 22, 29, 30).
        kept_only : bool
            Sum only the kept components (after screening).
        """
        sel = self.kept if kept_only else np.ones(len(self.lam), dtype=bool)
        lam, gam = self.lam[sel], self.gamma[sel]
        if len(lam) == 0:
            return np.zeros(np.shape(t))
        coef = gam / lam ** power
        tt = np.asarray(t, dtype=float) - self.t0
        return np.real(np.exp(np.multiply.outer(tt, lam)) @ coef)

    def evaluate_grid(self, start: float, dt: float, n: int, powers: tuple[int, ...] = (2, 1, 0)) -> np.ndarray:
        """(n, len(powers)) kept-component sums of :meth:`evaluate` on the uniform grid
        t = start + k·dt, k = 0 … n − 1, sharing one exponential matrix (:func:`exp_grid`)."""
        lam, gam = self.lam[self.kept], self.gamma[self.kept]
        if len(lam) == 0:
            return np.zeros((n, len(powers)))
        coef = np.stack([gam / lam ** pw for pw in powers], axis=1) * np.exp(lam * (start - self.t0))[:, None]
        return np.real(exp_grid(lam, dt, n) @ coef)

    def table(self, axis: int = 0, segment: int = 0) -> np.ndarray:
        """One row per component of :data:`COMPONENT_DTYPE` (conjugate partners dropped)."""
        pos = self.lam.imag >= 0
        lam, gam, kept = self.lam[pos], self.gamma[pos], self.kept[pos] if len(self.kept) else np.zeros(pos.sum(), bool)
        out = np.zeros(len(lam), dtype=COMPONENT_DTYPE)
        out["axis"], out["segment"], out["t0"] = axis, segment, self.t0
        out["frequency"] = lam.imag / (2 * math.pi)
        out["damping"] = self.damping[pos]
        paired = lam.imag > 0
        out["amplitude"] = np.abs(gam) * np.where(paired, 2.0, 1.0)  # real amplitude of the pair
        out["phase"] = np.angle(gam)
        out["kept"] = kept
        return np.sort(out, order="frequency")


def hankel_pair(x: np.ndarray, rows: int) -> tuple[np.ndarray, np.ndarray]:
    """H(0) and H(1) of eq. 17 with ``rows`` rows and N − rows columns (all samples used)."""
    n = len(x)
    cols = n - rows
    h = np.lib.stride_tricks.sliding_window_view(x, cols)  # (rows + 1, cols) view
    return h[:rows], h[1:rows + 1]


def truncated_svd(h: np.ndarray, k: int, rng: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Leading ``k`` singular triplets of ``h``: full LAPACK SVD when ``h`` is small, else a
    randomised SVD (Halko et al. 2011, algorithm 4.4 with 2 power iterations, oversampling 20).

    The switch is at min(m, n) = 7·(k + 20), where the two cost about the same
    (docs/decisions/reconstruction-svd.md)."""
    m, n = h.shape
    if min(m, n) <= 7 * (k + 20):
        u, s, vt = linalg.svd(h, full_matrices=False, lapack_driver="gesdd", check_finite=False)
        return u[:, :k], s[:k], vt[:k]
    rng = rng or np.random.default_rng(0)
    y = h @ rng.standard_normal((n, k + 20))
    for _ in range(2):
        q, _ = np.linalg.qr(y)
        q, _ = np.linalg.qr(h.T @ q)
        y = h @ q
    q, _ = np.linalg.qr(y)
    ub, s, vt = linalg.svd(q.T @ h, full_matrices=False, check_finite=False)
    return (q @ ub)[:, :k], s[:k], vt[:k]


def _project(u: np.ndarray, h1: np.ndarray, vt: np.ndarray) -> np.ndarray:
    """Uᵀ H(1) V (k × k) of the leading k singular vectors: the system matrix of every order
    od ≤ k is built from its leading od × od block (eq. 19), so one product serves all orders."""
    return u.T @ (h1 @ vt.T)


def _poles_amplitudes(u: np.ndarray, s: np.ndarray, vt: np.ndarray, p: np.ndarray, od: int) -> tuple[np.ndarray, np.ndarray]:
    """Discrete poles μ (eq. 19) and ERA amplitudes of the order-``od`` realisation;
    ``p`` = :func:`_project` (U, H(1), V)."""
    si = 1.0 / np.sqrt(s[:od])
    a = (si[:, None] * p[:od, :od]) * si[None, :]
    mu, psi = linalg.eig(a, check_finite=False)
    sq = np.sqrt(s[:od])
    c = u[0, :od] * sq
    b = vt[:od, 0] * sq
    try:
        gamma = (c @ psi) * linalg.solve(psi, b, check_finite=False)
    except linalg.LinAlgError:
        gamma = np.zeros(od, dtype=complex)
    return mu, gamma


def _poles(u: np.ndarray, s: np.ndarray, vt: np.ndarray, p: np.ndarray, od: int, dt: float, n: int) -> np.ndarray:
    """Continuous poles λ = ln(μ)/Δt of the order-``od`` realisation, without the numerically
    dead ones (μ = 0) and the spurious ones that grow by more than e^30 over the ``n`` samples
    (they cannot describe a measured record and overflow when evaluated).

    Only the eigenvalues are computed (LAPACK ``geev`` without eigenvectors: the same QR
    iteration, so the same μ as :func:`_poles_amplitudes`, without its vectors and solve)."""
    si = 1.0 / np.sqrt(s[:od])
    a = (si[:, None] * p[:od, :od]) * si[None, :]
    return _clean_poles(linalg.eigvals(a, check_finite=False), dt, n)


def _clean_poles(mu: np.ndarray, dt: float, n: int) -> np.ndarray:
    mu = mu.astype(complex)
    mag = np.abs(mu)
    ok = (mag > 0) & np.isfinite(mag)
    ok[ok] &= np.log(mag[ok]) * n < 30.0
    return np.log(mu[ok]) / dt


def _order_from_energy(h0: np.ndarray, s: np.ndarray, limit: int, tol: float) -> tuple[int, float]:
    """Smallest order whose discarded singular values hold less than tol² of the Hankel matrix's
    energy (relative RMS residual of the truncated H(0) below ``tol``)."""
    total = float(np.einsum("ij,ij->", h0, h0))
    kept = np.cumsum(s[:limit] ** 2)
    rel = np.sqrt(np.clip(total - kept, 0.0, None) / total)
    hit = np.nonzero(rel < tol)[0]
    od = int(hit[0]) + 1 if len(hit) else limit
    return od, float(rel[od - 1])


def _order_sc_sw(u, s, vt, p, limit: int, dt: float, n: int, max_components: int, sc_tol: float) -> tuple[int, float, np.ndarray]:
    """Paper 000's iterative order increase: od = 2, 4, … until SC_sw (eqs. 20-21) < sc_tol,
    the order limit, or one component more than ``max_components``."""
    od = min(2, limit)
    prev = None
    sc = math.nan
    lam = np.zeros(0, complex)
    prev_od = od
    while True:
        mu, gam = _poles_amplitudes(u, s, vt, p, od)
        lam_od = _clean_poles(mu, dt, n)
        if count_components(lam_od) > max_components and len(lam):
            return prev_od, sc, lam  # one pair too many: keep the previous order
        lam, prev_od = lam_od, od
        level = _peak_db(mu, gam, n)
        if prev is not None and math.isfinite(level) and math.isfinite(prev) and prev != 0:
            sc = abs((level - prev) / prev)
        prev = level
        if sc < sc_tol or od >= limit:
            return od, sc, lam
        od = min(od + 2, limit)


def _peak_db(mu: np.ndarray, gamma: np.ndarray, n: int) -> float:
    """max over frequency of 20 log10 |X(f)|² / n, X the DFT of Σ γ μ^k over n samples (eq. 21),
    evaluated in closed form on the rfft grid (at most 2048 frequencies)."""
    nf = min(n // 2 + 1, 2048)
    z = np.exp(-2j * math.pi * np.linspace(0.0, 0.5, nf))
    r = np.multiply.outer(z, mu)  # (nf, M)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        terms = np.where(np.abs(1 - r) > 1e-12, (1 - r ** n) / (1 - r), n)
    x = terms @ gamma
    p = np.max(np.abs(x) ** 2) / n
    return 10.0 * math.log10(p) if p > 0 and math.isfinite(p) else -math.inf


def count_components(lam: np.ndarray) -> int:
    """Number of distinct components: a conjugate pair or a real pole counts once."""
    return int(np.sum(lam.imag >= 0))


def decompose(x: np.ndarray, dt: float, *, max_components: int = 60, sc_tol: float = 1e-3,
              stop: str = "residual", rows: int | None = None, t0: float = 0.0,
              cutoff: float | None = None, fmax: float | None = None,
              rng: np.random.Generator | None = None) -> Decomposition:
    """Complex-exponential decomposition of one uniformly sampled signal (eqs. 16-23).

    Parameters
    ----------
    x : numpy.ndarray
        (N,) finite samples.
    dt : float
        Sample interval [s].
    max_components : int
        Largest number of components (pairs count once), ≥ 1.
    sc_tol : float
        Threshold of the stopping criterion (eq. 20, or the relative residual for
        ``stop="residual"``).
    stop : {"sc_sw", "residual"}
        Stopping rule; see the module docstring.
    rows : int, optional
        Rows of H(0); default min(N // 2, max(4·(2·max_components + 1), 64)).
    t0 : float
        Time of the first sample [s].
    cutoff : float, optional
        Screening frequency [Hz]; with ``stop="residual"`` the order is chosen to minimise the
        displacement the fit would miss above it (:func:`displacement_residual`).
    fmax : float, optional
        Highest signal frequency [Hz]. With ``stop="residual"`` the spectrum between 2.5·fmax
        and the Nyquist frequency is taken as noise, and the order stops where the residual
        reaches that noise level (:func:`noise_level`) instead of fitting the noise.

    Returns
    -------
    Decomposition
        Empty (no components) for a signal that is all zero or too short (N < 4).
    """
    check_choice("stop", stop, STOP_CHOICES)
    with one_blas_thread():
        return _decompose(np.asarray(x, dtype=float), dt, max_components, sc_tol, stop, rows, t0, cutoff, fmax, rng)


def _decompose(x: np.ndarray, dt: float, max_components: int, sc_tol: float, stop: str, rows: int | None,
               t0: float, cutoff: float | None, fmax: float | None, rng: np.random.Generator | None) -> Decomposition:
    n = len(x)
    scale = float(np.max(np.abs(x))) if n else 0.0
    empty = Decomposition(np.zeros(0, complex), np.zeros(0, complex), t0, np.zeros(0, bool), 0, math.nan)
    if n < 4 or scale == 0.0 or not math.isfinite(scale):
        return empty
    max_order = 2 * max_components + 1
    rows = rows or min(n // 2, max(4 * max_order, 64))
    rows = max(2, min(rows, n - 2))
    h0, h1 = hankel_pair(x / scale, rows)
    k = min(max_order + 2, *h0.shape)
    u, s, vt = truncated_svd(h0, k, rng)
    rank = int(np.sum(s > s[0] * 1e-13)) if s[0] > 0 else 0
    if rank == 0:
        return empty
    limit = min(rank, max_order)
    xs = x / scale
    p = _project(u, h1, vt)
    if stop == "residual":
        tol = max(sc_tol, noise_level(xs, dt, fmax)) if fmax else sc_tol
        od, sc = _order_from_energy(h0, s, limit, tol)
        od, lam, gamma, sc = _best_order_near(xs, u, s, vt, p, od, limit, dt, max_components, cutoff)
    else:
        od, sc, lam = _order_sc_sw(u, s, vt, p, limit, dt, n, max_components, sc_tol)
        gamma = _least_squares_amplitudes(xs, lam, dt)
    return Decomposition(lam, gamma * scale, t0, np.ones(len(lam), bool), od, sc)


def noise_level(x: np.ndarray, dt: float, fmax: float) -> float:
    """Relative RMS of the white noise in ``x``, estimated from its periodogram between
    2.5·fmax (above the second harmonics that rotations put into the acceleration) and 0.75 ×
    the Nyquist frequency (no signal there after the low-pass of
    :func:`lowpass_decimate`; 0 when that band is empty), extrapolated to the whole band."""
    f = np.fft.rfftfreq(len(x), dt)
    band = (f > 2.5 * fmax) & (f < 0.75 * 0.5 / dt)
    if band.sum() < 4:
        return 0.0
    p = np.abs(np.fft.rfft((x - x.mean()) * np.hanning(len(x)))) ** 2  # Hann: no leakage from the peaks
    noise_psd = float(np.median(p[band]))  # median: robust to a stray harmonic
    sig = float(np.sum(p[1:]))
    return math.sqrt(noise_psd * (len(f) - 1) / sig) if sig > 0 else 0.0


def displacement_residual(r: np.ndarray, dt: float, cutoff: float | None) -> float:
    """RMS of the displacement that an acceleration residual ``r`` would carry above
    ``cutoff`` [Hz]: the residual's spectrum weighted by 1/ω² (what is lost from the
    reconstruction when ``r`` is not modelled). Without a cutoff, the plain RMS of ``r``."""
    if cutoff is None:
        return float(np.sqrt(np.mean(r ** 2)))
    spec = np.fft.rfft(r)
    f = np.fft.rfftfreq(len(r), dt)
    band = f > cutoff
    w = np.zeros_like(f)
    w[band] = 1.0 / (2 * math.pi * f[band]) ** 2
    return float(np.sqrt(np.sum(np.abs(spec * w) ** 2) * 2) / len(r))


def _best_order_near(xs, u, s, vt, p, od0: int, limit: int, dt: float, max_components: int,
                     cutoff: float | None, span: int = 4) -> tuple[int, np.ndarray, np.ndarray, float]:
    """Among the orders od0 − 2·span … od0 + 2·span, the one whose least-squares fit leaves the
    smallest :func:`displacement_residual`. A truncated SVD can produce a few spurious poles at
    one order and not at the next; judging each candidate by the displacement it would miss
    makes the choice robust (checked on VesselMotion records, see the tests)."""
    n = len(xs)
    best = None
    for od in sorted({min(max(2, od0 + 2 * j), limit) for j in range(-span, span + 1)}):
        lam = _poles(u, s, vt, p, od, dt, n)
        if count_components(lam) > max_components:
            continue
        gamma, fit = _least_squares_amplitudes(xs, lam, dt, with_fit=True)
        score = displacement_residual(xs - fit, dt, cutoff)
        if best is None or score < best[3]:
            best = (od, lam, gamma, score)
    if best is None:
        lam = _poles(u, s, vt, p, 2, dt, n)
        return 2, lam, _least_squares_amplitudes(xs, lam, dt), math.nan
    return best


def exp_grid(lam: np.ndarray, dt: float, n: int, block: int = 64) -> np.ndarray:
    """(n, M) matrix e^{λ_m k Δt}, k = 0 … n − 1, on a uniform grid.

    Built as e^{λ(aB + b)Δt} = e^{λ aBΔt} · e^{λ bΔt} from two small tables (B = ``block``):
    one complex multiplication per entry instead of one complex exponential, about 5× faster
    and within a few ulp of ``np.exp``. Entries that overflow are inf, as with ``np.exp``."""
    lam = np.asarray(lam, dtype=complex)
    nb = -(-n // block)
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        outer = np.exp(np.multiply.outer(np.arange(nb) * (block * dt), lam))  # (nb, M)
        inner = np.exp(np.multiply.outer(np.arange(block) * dt, lam))  # (B, M)
        v = (outer[:, None, :] * inner[None, :, :]).reshape(nb * block, len(lam))
    return v[:n]


def _least_squares_amplitudes(x: np.ndarray, lam: np.ndarray, dt: float, with_fit: bool = False):
    """γ minimising Σ_k |x_k − Σ γ_i e^{λ_i k Δt}|² (eq. 22 fitted to every sample).

    ``x`` is real and the poles of a real system matrix come in exact conjugate pairs, so the
    fit is solved in real arithmetic: one column Re e^{λt} per real pole and two, Re and Im,
    per pair (λ, λ̄), giving γ = (a − ib)/2 for λ and its conjugate for λ̄ — the unique complex
    least-squares solution, at about a quarter of the cost. Poles without an exact partner fall
    back to the complex solve. The columns are normalised before the solve: a slightly growing
    or fast-decaying pole makes column norms differ by many orders of magnitude, and the
    rank-revealing solver would otherwise drop the small ones. With ``with_fit``, also returns
    the fitted signal (zeros if there are no poles)."""
    n = len(x)
    zero = np.zeros(len(lam), complex)
    if len(lam) == 0:
        return (zero, np.zeros(n)) if with_fit else zero
    upper = lam.imag > 0
    real = lam.imag == 0
    match = lam[None, :] == np.conj(lam[upper])[:, None]  # row i: the exact partners of the i-th upper pole
    paired = bool(np.all(match.sum(axis=1) == 1)) and upper.sum() * 2 + real.sum() == len(lam)
    if not paired:
        return _complex_least_squares(x, lam, dt, with_fit)
    basis_poles = np.concatenate((lam[upper], lam[real]))
    e = exp_grid(basis_poles, dt, n)
    if not np.all(np.isfinite(e)):
        return (zero, np.zeros(n)) if with_fit else zero
    m = int(upper.sum())
    v = np.concatenate((e[:, :m].real, e[:, :m].imag, e[:, m:].real), axis=1)
    norms = np.linalg.norm(v, axis=0)
    norms[norms == 0] = 1.0
    v /= norms
    coef = _lstsq(v, x)
    fit = v @ coef
    coef /= norms
    gamma = np.zeros(len(lam), complex)
    g_up = 0.5 * (coef[:m] - 1j * coef[m:2 * m])
    if m:
        gamma[np.nonzero(upper)[0]] = g_up
        gamma[np.argmax(match, axis=1)] = np.conj(g_up)
    gamma[np.nonzero(real)[0]] = coef[2 * m:]
    return (gamma, fit) if with_fit else gamma


def _lstsq(v: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Least-squares solution of v c ≈ x for a basis ``v`` of unit columns.

    Real and well conditioned (the Cholesky factor of vᵀv has no diagonal entry below
    :data:`_CHOL_MIN_DIAG`, so cond(v) stays near the 10-100 of these bases): the normal
    equations with one step of iterative refinement, c += (vᵀv)⁻¹ vᵀ(x − v c), which brings
    the solution to rounding times cond(v), as a QR solve gives, at a third of its cost.
    Otherwise LAPACK's complete orthogonal factorisation (``gelsy``) when it finds ``v`` of full
    column rank, else the SVD-based minimum-norm solve (``gelsd``)."""
    if not np.iscomplexobj(v):
        try:
            cf = linalg.cho_factor(v.T @ v, lower=False, check_finite=False)
        except linalg.LinAlgError:
            cf = None
        if cf is not None and np.min(np.abs(np.diag(cf[0]))) >= _CHOL_MIN_DIAG:
            coef = linalg.cho_solve(cf, v.T @ x, check_finite=False)
            coef += linalg.cho_solve(cf, v.T @ (x - v @ coef), check_finite=False)
            return coef
    coef, _, rank, _ = linalg.lstsq(v, x, check_finite=False, lapack_driver="gelsy")
    if rank < v.shape[1]:
        coef, *_ = linalg.lstsq(v, x, check_finite=False, lapack_driver="gelsd")
    return coef


#: Smallest diagonal entry of the Cholesky factor of vᵀv (unit columns) for the normal
#: equations: below it cond(v) may exceed ~1e3, where one refinement step no longer suffices.
_CHOL_MIN_DIAG = 1e-2


def _complex_least_squares(x: np.ndarray, lam: np.ndarray, dt: float, with_fit: bool):
    """Complex-arithmetic form of :func:`_least_squares_amplitudes` for poles not in exact
    conjugate pairs; returns the real part of the fit."""
    v = exp_grid(lam, dt, len(x))
    if not np.all(np.isfinite(v)):
        gamma = np.zeros(len(lam), complex)
        return (gamma, np.zeros(len(x))) if with_fit else gamma
    norms = np.linalg.norm(v, axis=0)
    norms[norms == 0] = 1.0
    v /= norms
    gamma = _lstsq(v, x.astype(complex))
    if with_fit:
        return gamma / norms, np.real(v @ gamma)
    return gamma / norms


# ------------------------------------------------------------------------------------------------
# Batch reconstruction
# ------------------------------------------------------------------------------------------------
@dataclass
class Reconstruction:
    """Result of :func:`reconstruct_displacement`.

    Attributes
    ----------
    displacement, velocity, acceleration : numpy.ndarray
        Same shape as the input: reconstructed displacement [m], velocity [m/s] and the
        kept part of the acceleration model [m/s²] at the input sample times.
    components : numpy.ndarray
        Structured array (:data:`COMPONENT_DTYPE`): axis, segment, t0 [s], frequency [Hz],
        damping ratio, amplitude, phase [rad], kept.
    decompositions : list of list of Decomposition
        Per axis, per segment.
    """

    displacement: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    components: np.ndarray
    decompositions: list[list[Decomposition]]


def decimation_factor(dt: float, fmax: float) -> int:
    """Largest integer q with 1/(q·dt) ≥ 10·fmax (1 if the signal is already that slow).

    Ten samples per period of ``fmax`` rather than the Nyquist minimum: at 5 per period the
    zero-phase filter's edge transients sit close to the band and the realisation needs
    spurious growing poles to describe them (seen on VesselMotion records)."""
    return max(1, int(math.floor(1.0 / (dt * 10.0 * fmax) + 1e-9)))


def lowpass_decimate(x: np.ndarray, q: int) -> np.ndarray:
    """Zero-phase 8th-order Butterworth low-pass at 0.8 × the new Nyquist frequency, then every
    q-th sample (sample 0 kept). Butterworth is maximally flat: at fmax the gain is 1 − 2e-5.
    Records shorter than the filter's padding (54 samples) are only sub-sampled."""
    if q == 1 or len(x) <= 27 * 2:  # too short for the filter's padding: plain sub-sampling
        return np.asarray(x, dtype=float)[::q]
    sos = _butter_sos(8, 0.8 / q, "lowpass", None)
    return signal.sosfiltfilt(sos, x, axis=0)[::q]


def check_reconstruction_params(dt: float, cutoff: float, max_components: int, fmax: float, segment: float | None) -> None:
    """Refuse invalid settings with the parameter name and allowed range."""
    check_range("dt", dt, lo=0.0, lo_open=True, unit="s")
    nyq = 0.5 / dt
    check_range("cutoff", cutoff, lo=0.0, hi=nyq, lo_open=True, hi_open=True, unit="Hz")
    check_int("max_components", max_components, lo=1, hi=2000)
    check_range("fmax", fmax, lo=cutoff, hi=nyq, lo_open=True, unit="Hz")
    if segment is not None and not (isinstance(segment, float) and math.isinf(segment) and segment > 0):
        check_range("segment", segment, lo=2.0 / cutoff, unit="s")


def reconstruct_displacement(acc: np.ndarray, dt: float, cutoff: float, *, max_components: int = 60,
                             sc_tol: float = 1e-5, stop: str = "residual", fmax: float = 0.5,
                             segment: float | None = None, max_damping: float | None = 0.8) -> Reconstruction:
    """Displacement and velocity from acceleration without integration (paper 000, eqs. 16-31).

    Parameters
    ----------
    acc : numpy.ndarray
        (N,) or (N, 3) acceleration [m/s²] (tilt-corrected, any fixed frame), uniformly sampled.
    dt : float
        Sample interval [s].
    cutoff : float
        Screening frequency F [Hz] (eq. 25): components at or below it are removed;
        0 < cutoff < Nyquist.
    max_components : int
        Most components per axis and segment (a conjugate pair counts once), 1 … 2000.
    sc_tol : float
        Stopping threshold: relative residual for ``stop="residual"`` (raised to the measured
        noise level), SC_sw (eq. 20) for ``stop="sc_sw"`` (the paper uses 1e-3).
    stop : {"sc_sw", "residual"}
        Stopping rule (module docstring).
    max_damping : float or None
        Also screen out components with |damping ratio| above this (beyond the paper: heavily
        damped or growing poles that a noisy record produces have large γ/λ² and no physical
        meaning; the SDOF transients of section 4 have ξ ≤ 0.58). None keeps the paper's
        frequency-only screening.
    fmax : float
        Highest motion frequency of interest [Hz]; the signal is decimated to ≈ 10·fmax before
        the decomposition (cutoff < fmax ≤ Nyquist).
    segment : float or None
        Length of the analysis segments [s] (≥ 2/cutoff), overlapping by half; ``math.inf``
        = the whole record in one decomposition (the paper); None (default) = max(200 s,
        4/cutoff). Short segments keep the model order
        moderate: a 200 s window of an irregular sea holds ~70 resolvable spectral lines.

    Returns
    -------
    Reconstruction
        ``displacement`` and ``velocity`` with the shape of ``acc``, and the component table.

    Raises
    ------
    ParameterError
        For an invalid setting (the message names it) or non-finite samples.
    """
    check_reconstruction_params(dt, cutoff, max_components, fmax, segment)
    a = np.asarray(acc, dtype=float)
    if a.ndim not in (1, 2) or (a.ndim == 2 and a.shape[1] < 1):
        raise ShapeError(f"acc must have shape (N,) or (N, k), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ParameterError("acc contains NaN or Inf: remove or interpolate the bad samples first")
    a2 = a.reshape(len(a), -1)
    n = len(a2)
    duration = n * dt
    if segment is None:
        segment = max(200.0, 4.0 / cutoff)
    segment = min(segment, duration)
    seg_n = max(4, int(round(segment / dt)))
    starts = segment_starts(n, seg_n)
    q = decimation_factor(dt, fmax)
    t = np.arange(n) * dt
    disp = np.zeros_like(a2)
    vel = np.zeros_like(a2)
    acc_fit = np.zeros_like(a2)
    weights = np.zeros(n)
    decs: list[list[Decomposition]] = [[] for _ in range(a2.shape[1])]
    tables = []
    for j, s0 in enumerate(starts):
        s1 = min(n, s0 + seg_n)
        w = blend_weights(s1 - s0, first=j == 0, last=j == len(starts) - 1)
        weights[s0:s1] += w
        xd = lowpass_decimate(a2[s0:s1], q)
        for axis in range(a2.shape[1]):
            d = decompose(xd[:, axis], dt * q, max_components=max_components, sc_tol=sc_tol, stop=stop, t0=t[s0], cutoff=cutoff, fmax=fmax)
            d.screen(cutoff, max_damping)
            decs[axis].append(d)
            tables.append(d.table(axis, j))
            dva = d.evaluate_grid(t[s0], dt, s1 - s0) * w[:, None]
            disp[s0:s1, axis] += dva[:, 0]
            vel[s0:s1, axis] += dva[:, 1]
            acc_fit[s0:s1, axis] += dva[:, 2]
    disp /= weights[:, None]
    vel /= weights[:, None]
    acc_fit /= weights[:, None]
    comps = np.concatenate(tables) if tables else np.zeros(0, COMPONENT_DTYPE)
    shape = a.shape
    return Reconstruction(disp.reshape(shape), vel.reshape(shape), acc_fit.reshape(shape), comps, decs)


def segment_starts(n: int, seg_n: int) -> list[int]:
    """Start indices of half-overlapping segments of ``seg_n`` samples covering ``n`` samples
    (the last one ends at ``n``)."""
    if seg_n >= n:
        return [0]
    hop = seg_n // 2
    starts = list(range(0, n - seg_n + 1, hop))
    if starts[-1] + seg_n < n:
        starts.append(n - seg_n)
    return starts


def blend_weights(m: int, first: bool, last: bool) -> np.ndarray:
    """cos² cross-fade over the outer halves of a segment; flat where no neighbour overlaps.

    With a hop of half a segment, the weights of overlapping segments sum to 1 (sin² + cos²);
    :func:`reconstruct_displacement` normalises by the summed weights anyway (the last segment
    may overlap more).
    """
    w = np.ones(m)
    half = m // 2
    ramp = np.sin(0.5 * math.pi * (np.arange(half) + 0.5) / half) ** 2
    if not first:
        w[:half] = ramp
    if not last:
        w[m - half:] = ramp[::-1]
    return w


def _as_n3(name: str, x: np.ndarray) -> np.ndarray:
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ShapeError(f"{name} must have shape (N, 3), got {arr.shape}")
    return arr
