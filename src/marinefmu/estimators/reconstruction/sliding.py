"""Paper 000's reconstruction run online on a sliding window (the DisplacementReconstructor).

Every ``hop`` seconds, once ``window`` seconds of samples are in, the tilt-corrected
acceleration of the last window is decomposed (:func:`~.decomposition.decompose`, one call per
axis), screened, and kept as a continuous-time model. Between refits each step evaluates that
model at the window's centre, t − ``delay`` with ``delay`` = window/2, where the fit has data on
both sides and is best: that is the estimate (``disp``, ``vel``).

There is no estimate of the present. The window's model evaluated past the end of its window
(at the current time, up to ``hop`` s past it) has no predictive skill: its components are a
fit of a random sea inside the window, not the sea's own modes, and a pair of growing and
decaying components that cancel inside the window diverges outside it. Dropping the growing
components, or continuing every component undamped, does no better; the measured errors are
on the FMU's page and ``marinefmu.bench.reconstruction_outputs`` reproduces them.
:meth:`DisplacementReconstructor.estimate_at` evaluates the model at any lag inside the window
(and at lag 0, the extrapolation) for such measurements.

The COG transfer (eq. 32) subtracts R_nb(t) l high-passed at ``cutoff`` over each fitted window
(:func:`~.decomposition.lever_arm_offset`, zero-phase, as the batch reconstruction does): the
screen removes the IMU's motion below ``cutoff``, so only the lever arm's motion above it is
subtracted. A far IMU's R_nb l has content below the screen (a gyro-integrated yaw's drift
times l; the slow part of the rotation at the lever arm); subtracting that too (R_nb l less only
a straight line) would leave the IMU's slow motion in the COG's: 3-5 % of the COG's motion with
the IMU 40 m from the COG and perfect inputs (decision record "The DisplacementReconstructor's
defaults in waves"). The lever arm's motion of the samples after the
fitted window (the extrapolation, lags under ``hop``) continues from the window's end by the raw
R_nb l's change.

Bad samples (NaN, Inf, |f| > 200 m/s², |roll| or |pitch| > 80°) are replaced in the window by
the last good sample; ``valid`` is False while more than ``max_bad_fraction`` of the fitted
window was replaced, on the bad step itself, and until the first window is full.

Cost per step: every step checks the sample in plain floats, stores it in the window buffers
and reads the window-centre estimate from a block of model values, less the lever arm's band
part; the block (:data:`TABLE_BLOCK` steps, the exponentials of the fixed model at the
centre's next sample times, the same arguments :meth:`~DisplacementReconstructor.estimate_at`
takes) is computed once per block. Only every ``hop`` s: the tilt correction, the decimation,
the three decompositions (one Hankel SVD each, then the eigenvalues and least squares of the
candidate orders) and the band-passed lever arm. BLAS runs on one thread for the refit and the
block. The raw R_nb l is computed only where the extrapolation needs it, from the stored angles.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from ...errors import check_choice, check_range, check_vector
from ...frames import G, rot_nb
from ..numerics import one_blas_thread
from ..samples import MAX_SPECIFIC_FORCE, MAX_TILT, MAX_YAW, angles_beyond_limit, force_beyond_limit
from .decomposition import (
    TILT_CHOICES, Decomposition, check_reconstruction_params, decimation_factor, decompose, exp_grid, lever_arm_offset,
    lowpass_decimate, rotations, tilt_correct,
)

log = logging.getLogger(__name__)

#: Steps of window-centre model values computed at once (:meth:`DisplacementReconstructor._centre`).
TABLE_BLOCK = 250


@dataclass(frozen=True)
class DisplacementReconstructorParams:
    """Parameters of :class:`DisplacementReconstructor` (FMU names in brackets).

    Parameters
    ----------
    window : float
        Window length [s], ≥ 2/cutoff and ≤ 3600. [``window``]
    hop : float
        Refit interval [s], (0, window]. [``hop``]
    cutoff : float
        Screening frequency F [Hz] (eq. 25). [``cutoff``]
    max_components : int
        Most components per axis, 1 … 2000. [``max_components``]
    lever_arm : tuple of float
        Sensor position relative to the COG, body frame [m]. [``lever_arm.{x,y,z}``]
    fmax : float
        Highest motion frequency [Hz] (decimation). [``fmax``]
    tilt : str
        ``"exact"`` or ``"small_angle"`` (eq. 15). [``tilt``]
    max_damping : float
        Screen components with |damping ratio| above this, (0, 1]; 1 keeps all. [``max_damping``]
    sc_tol : float
        Relative residual stopping threshold, (0, 1). [``sc_tol``]
    max_bad_fraction : float
        Largest fraction of replaced samples in a window for a valid estimate, [0, 0.5].
    """

    window: float = 200.0
    hop: float = 10.0
    cutoff: float = 0.03
    max_components: int = 60
    lever_arm: tuple[float, float, float] = (0.0, 0.0, 0.0)
    fmax: float = 0.5
    tilt: str = "exact"
    max_damping: float = 0.8
    sc_tol: float = 1e-5
    max_bad_fraction: float = 0.01

    def validate(self, dt: float) -> None:
        """Check the parameters against the sample interval ``dt`` [s]."""
        check_reconstruction_params(dt, self.cutoff, self.max_components, self.fmax, None)
        check_range("window", self.window, lo=2.0 / self.cutoff, hi=3600.0, unit="s")
        check_range("hop", self.hop, lo=0.0, hi=self.window, lo_open=True, unit="s")
        check_vector("lever_arm", self.lever_arm, unit="m")
        check_choice("tilt", self.tilt, TILT_CHOICES)
        check_range("max_damping", self.max_damping, lo=0.0, hi=1.0, lo_open=True)
        check_range("sc_tol", self.sc_tol, lo=0.0, hi=1.0, lo_open=True, hi_open=True)
        check_range("max_bad_fraction", self.max_bad_fraction, lo=0.0, hi=0.5)


@dataclass(frozen=True)
class DisplacementReconstructorResult:
    """One step's output: the COG displacement ``disp`` [m, NED] and velocity ``vel`` [m/s, NED]
    at t − ``delay``, the window's centre; ``delay`` [s] (window / 2); ``valid`` and the
    rejection ``warning``, if any."""

    disp: tuple[float, float, float]
    vel: tuple[float, float, float]
    delay: float
    valid: bool
    warning: str | None = None


class DisplacementReconstructor:
    """Online displacement reconstruction (module docstring).

    Parameters
    ----------
    params : DisplacementReconstructorParams
        Parameters; checked against ``dt`` at the first :meth:`step` (or call
        :meth:`configure`).
    """

    def __init__(self, params: DisplacementReconstructorParams | None = None, dt: float | None = None) -> None:
        self.params = params or DisplacementReconstructorParams()
        self.dt: float | None = None
        if dt is not None:
            self.configure(dt)

    def configure(self, dt: float) -> None:
        """Fix the sample interval [s], validate and allocate the window buffers."""
        self.params.validate(dt)
        p = self.params
        self.dt = float(dt)
        self.n_win = int(round(p.window / dt))
        self.n_hop = max(1, int(round(p.hop / dt)))
        self.q = decimation_factor(dt, p.fmax)
        self.lever = np.array(p.lever_arm, dtype=float)
        self.reset()

    def reset(self) -> None:
        """Empty the window."""
        n = self.n_win
        self.acc = np.zeros((n, 3))  # specific force [m/s², b]; tilt-corrected at each refit
        self.euler = np.zeros((n, 3))
        self.bad = np.zeros(n, dtype=bool)
        self.k = 0  # samples received
        self.last_good: tuple[np.ndarray, np.ndarray] | None = None
        self.models: list[tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None
        self.t_start = 0.0  # time of the first sample of the fitted window (sample index based)
        self.arm_band = np.zeros((0, 3))  # R_nb l in the screen's band over the fitted window [m, NED]
        self.arm_end = np.zeros(3)  # the raw R_nb l at the fitted window's last sample
        self.fit_bad_fraction = 1.0
        self._drop_table()

    def _drop_table(self) -> None:
        """Forget the block of window-centre model values (derived state, rebuilt on demand)."""
        self._tab_k0 = -1  # the sample count k of the block's first row
        self._tab = np.zeros((0, 6))

    # ---- per step ------------------------------------------------------------------------------
    def step(self, acc, euler, dt: float) -> DisplacementReconstructorResult:
        """Add one sample and return the estimate at the window centre.

        Parameters
        ----------
        acc : array_like
            (3,) specific force [m/s², b].
        euler : array_like
            (3,) roll, pitch, yaw [rad].
        dt : float
            Sample interval [s]; must stay the same.
        """
        if self.dt is None:
            self.configure(dt)
        acc = np.asarray(acc, dtype=float)
        euler = np.asarray(euler, dtype=float)
        warning = _check_sample(acc, euler)
        if warning is not None:
            log.warning("displacement reconstructor: %s; holding the last good sample", warning)
            if self.last_good is None:
                acc, euler = np.array([0.0, 0.0, -G]), np.zeros(3)
            else:
                acc, euler = self.last_good
        else:
            self.last_good = (acc, euler)
        i = self.k % self.n_win
        self.acc[i] = acc
        self.euler[i] = euler
        self.bad[i] = warning is not None
        self.k += 1
        if self.k >= self.n_win and (self.k - self.n_win) % self.n_hop == 0:
            with one_blas_thread():
                self._refit()
        return self._outputs(warning)

    def _ordered(self, buf: np.ndarray) -> np.ndarray:
        i = self.k % self.n_win
        return np.concatenate((buf[i:], buf[:i]))

    def _refit(self) -> None:
        p, dt = self.params, self.dt
        euler = self._ordered(self.euler)
        rot = rotations(euler[:, 0], euler[:, 1], euler[:, 2])
        acc = tilt_correct(self._ordered(self.acc), euler, p.tilt, rot)
        self.t_start = (self.k - self.n_win) * dt
        xd = lowpass_decimate(acc, self.q)
        models = []
        for axis in range(3):
            d: Decomposition = decompose(xd[:, axis], dt * self.q, max_components=p.max_components, sc_tol=p.sc_tol,
                                         cutoff=p.cutoff, fmax=p.fmax)
            d.screen(p.cutoff, p.max_damping)
            lam, gam = d.lam[d.kept], d.gamma[d.kept]
            models.append((lam, gam / lam ** 2, gam / lam))
        self.models = models
        self.arm_band = lever_arm_offset(euler, self.lever, dt, p.cutoff, rot)
        self.arm_end = self._arm(self.k - 1)
        self.fit_bad_fraction = float(self.bad.mean())
        self._drop_table()

    def _arm(self, k: int) -> np.ndarray:
        """The raw R_nb l [m, NED] of absolute sample ``k`` (in the window buffer)."""
        return rot_nb(*self.euler[k % self.n_win]) @ self.lever

    def _eval(self, t_rel: float) -> tuple[np.ndarray, np.ndarray]:
        disp, vel = np.zeros(3), np.zeros(3)
        for axis, (lam, c2, c1) in enumerate(self.models):
            if len(lam):
                e = np.exp(lam * t_rel)
                disp[axis] = (e @ c2).real
                vel[axis] = (e @ c1).real
        return disp, vel

    def estimate_at(self, lag: float) -> tuple[np.ndarray, np.ndarray] | None:
        """The current window model's COG displacement [m, NED] and velocity [m/s, NED] at
        ``lag`` s before the latest sample, or None before the first fit.

        ``lag`` = ``delay`` is the output of :meth:`step`; ``lag`` = 0 the model extrapolated to
        the present, up to ``hop`` s past the end of its window, which errs more than the motion
        itself (module docstring). ``lag`` is rounded to a sample, 0 ≤ ``lag`` < ``window``.
        """
        if self.dt is None or self.models is None:
            return None
        dt = self.dt
        j = int(round(lag / dt))
        if not 0 <= j < self.n_win:
            raise ValueError(f"lag must be in [0, window) = [0, {self.params.window:g}) s, got {lag!r}")
        k = self.k - 1 - j  # absolute index of the sample
        t_rel = k * dt - self.t_start  # its time from the start of the fitted window
        disp, vel = self._eval(t_rel)
        i = k - int(round(self.t_start / dt))  # the sample's place in the fitted window
        arm = self.arm_band[i] if i < len(self.arm_band) else self.arm_band[-1] + self._arm(k) - self.arm_end
        return disp - arm, vel

    def _centre(self) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """:meth:`estimate_at` (``delay``) of the latest sample, from a block of
        :data:`TABLE_BLOCK` steps of the model's values at the window centre: the model is
        fixed between refits and the centre advances one sample a step, so the block is
        e^{λ(t₀ + kΔt)} = e^{λt₀} e^{λkΔt} on a uniform grid (:func:`~.decomposition.exp_grid`),
        which equals the exponentials :meth:`_eval` takes one step at a time to a few ulp."""
        j = int(round(0.5 * self.params.window / self.dt))
        m = self.k - self._tab_k0
        if not 0 <= m < len(self._tab):
            self._build_table(j)
            m = self.k - self._tab_k0
        k = self.k - 1 - j
        i = k - int(round(self.t_start / self.dt))
        row = self._tab[m]
        if i < len(self.arm_band):
            a = self.arm_band[i]
        else:
            a = self.arm_band[-1] + self._arm(k) - self.arm_end
        return (float(row[0] - a[0]), float(row[1] - a[1]), float(row[2] - a[2])), (float(row[3]), float(row[4]), float(row[5]))

    def _build_table(self, j: int) -> None:
        """The block holding the current step, counted from the refit in whole blocks: the
        same blocks whether the steps ran on or the state was restored in between."""
        dt, n = self.dt, TABLE_BLOCK
        k_fit = int(round(self.t_start / dt)) + self.n_win  # the sample count at the refit
        k0 = k_fit + (self.k - k_fit) // n * n
        t_rel = (k0 - 1 - j) * dt - self.t_start  # of the block's first centre sample
        tab = np.zeros((n, 6))
        with one_blas_thread():
            for axis, (lam, c2, c1) in enumerate(self.models):
                if len(lam):
                    e = exp_grid(lam, dt, n)
                    shift = np.exp(lam * t_rel)
                    tab[:, axis] = (e @ (c2 * shift)).real
                    tab[:, 3 + axis] = (e @ (c1 * shift)).real
        self._tab, self._tab_k0 = tab, k0

    def _outputs(self, warning: str | None) -> DisplacementReconstructorResult:
        delay = 0.5 * self.params.window
        if self.models is None:
            z = (0.0, 0.0, 0.0)
            return DisplacementReconstructorResult(z, z, delay, False, warning)
        disp, vel = self._centre()
        valid = warning is None and self.fit_bad_fraction <= self.params.max_bad_fraction
        return DisplacementReconstructorResult(disp, vel, delay, valid, warning)

    # ---- FMU state ---------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable state (window buffers and the fitted model)."""
        if self.dt is None:
            return {"dt": None}
        models = None if self.models is None else [
            [[lam.real.tolist(), lam.imag.tolist()], [c2.real.tolist(), c2.imag.tolist()], [c1.real.tolist(), c1.imag.tolist()]]
            for lam, c2, c1 in self.models]
        return {
            "dt": self.dt, "acc": self.acc.tolist(), "euler": self.euler.tolist(), "bad": self.bad.tolist(), "k": self.k,
            "last_good": None if self.last_good is None else [self.last_good[0].tolist(), self.last_good[1].tolist()],
            "models": models, "t_start": self.t_start, "arm_band": self.arm_band.tolist(), "arm_end": self.arm_end.tolist(), "fit_bad_fraction": self.fit_bad_fraction,
        }

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        if s["dt"] is None:
            self.dt = None
            return
        self.configure(s["dt"])
        self.acc, self.euler = np.array(s["acc"]), np.array(s["euler"])
        self.bad = np.array(s["bad"], dtype=bool)
        self.k = int(s["k"])
        self.last_good = None if s["last_good"] is None else (np.array(s["last_good"][0]), np.array(s["last_good"][1]))
        self.models = None if s["models"] is None else [
            tuple(np.array(re) + 1j * np.array(im) for re, im in m) for m in s["models"]]
        self.t_start = float(s["t_start"])
        self.arm_band = np.array(s["arm_band"], dtype=float).reshape(-1, 3)
        self.arm_end = np.array(s["arm_end"], dtype=float)
        self.fit_bad_fraction = float(s["fit_bad_fraction"])


def _check_sample(acc: np.ndarray, euler: np.ndarray) -> str | None:
    """The rejection reason of a sample, or None. Plain floats for the common good sample;
    the shared limit checks decide whenever a sample comes near a limit."""
    if acc.shape != (3,) or euler.shape != (3,):
        return "sample of the wrong shape"
    a0, a1, a2 = acc.tolist()
    e0, e1, e2 = euler.tolist()
    if not (math.isfinite(a0) and math.isfinite(a1) and math.isfinite(a2)
            and math.isfinite(e0) and math.isfinite(e1) and math.isfinite(e2)):
        return "non-finite acc or attitude sample"
    if a0 * a0 + a1 * a1 + a2 * a2 > _NEAR_FORCE_SQ or abs(e0) > _NEAR_TILT or abs(e1) > _NEAR_TILT or abs(e2) > _NEAR_YAW:
        return force_beyond_limit(acc) or angles_beyond_limit(euler)
    return None


# Below these (1 % inside the limits) a sample is good whatever the rounding of the checks.
_NEAR_FORCE_SQ = (0.99 * MAX_SPECIFIC_FORCE) ** 2
_NEAR_TILT = 0.99 * MAX_TILT
_NEAR_YAW = 0.99 * MAX_YAW
