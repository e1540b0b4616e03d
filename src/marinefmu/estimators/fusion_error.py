"""The error covariance of the GNSS + accelerometer fusion as it runs: ``pos_std`` between GNSS
fixes (beyond paper 001).

Why. The fusion filter's own covariance P is that of its model, q and r of eqs. 16-17. Those
set the blend (the gain depends on q/r only), not the size of the errors: on the paper-001
set-up (1 Hz RTK) P saw-tooths 3.0-8.5 cm between fixes while the error is 0.7 cm; error /
``pos_std`` had an RMS of 0.14 (seeds 1-3, 100-300 s). A ``pos_std`` that a user can weigh
needs the covariance of the error the filter actually makes. This module keeps it alongside
the filter, without changing the fused output:

1. **The state error of a suboptimal filter** (Gelb 1974, section 7.2; Simon 2006, section
   10.1): the filter's own gains K, but the sensors' noises. At each sample
   P_t ← Φ P_t Φᵀ + Q_t, Q_t of eq. 16 with the accelerometer's noise density
   (``acc_noise``², not q) and the filter's bias random walk; at each GNSS fix the Joseph
   form, valid for any gain, P_t ← (I − KH) P_t (I − KH)ᵀ + K R_t Kᵀ, with R_t the noise of the
   four antennas' centroid (``antenna_sigma_h``²/4, ``antenna_sigma_v``²/4; the fix's
   accelerometer point is the centroid plus the lever arm turned with the propagated
   attitude).
2. **The attitude's share.** The filter tracks z = centroid + R (l − c̄) (l the accelerometer's
   arm, c̄ the antennas' mean arm); the COG output is x − R l. An attitude error ε of R, slow
   next to the filter, so moves the output by ε × (R c̄): 10 m × 0.5 mrad = 5 mm on the
   paper-001 set-up, as large as step 1. Its covariance comes from the PI attitude loop
   (:func:`~.gnss_fusion.pi_pull`) as it runs, per NED axis: states (ε, β, b) — the attitude
   error, the gyro-bias error and the true Gauss-Markov bias (``gyro_bias_sigma``,
   ``gyro_bias_tau``), the gyro's angle random walk ``gyro_noise`` — pulled at each fix with
   the loop's gains and the fix attitude's noise (:func:`~.antenna_attitude.antenna_attitude_std`).
   With ``propagation="hold"`` it is the fix attitude's noise alone.
3. **A consistency check** (covariance matching: Mehra 1972; Myers & Tapley 1976): at each fix
   the innovation's square over its predicted variance, r = ν²/(H P_t⁻ Hᵀ + R_t), is 1 on
   average when the model holds. Per axis the acceleration noise density is scaled by
   1 + w (r − 1) at each fix (w = interval / :data:`NIS_MEMORY`), never below the sensor's:
   an acceleration worse than its datasheet (the uncorrected acceleration of the paper's
   "before" case, an attitude error g·ε that the loop of step 2 does not see) shows in the
   innovations, and the covariance follows. The attitude's share cancels in the innovations
   (the filter tracks it), so the check leaves it alone.

Measured (``make bench``, part ``pos_std``, 2026-11-24, the README's table; 100-300 s without a
gap, error / ``pos_std`` RMS per seed N / E / D; 1 is calibrated): paper-001 set-up at 1 Hz,
seeds 1-10, 0.76-0.91 / 0.72-0.88 / 0.93-1.05; at 10 Hz 0.68-0.88 / 0.72-0.99 / 0.98-1.01; the
buoy of experiment (c) at 1 Hz 0.66-1.02 / 0.61-0.77 / 0.97-1.05; the uncorrected acceleration
(east 14 cm RMS) 0.84-0.96 / 1.05-1.15 / 1.12-1.37 (without step 3: 14 east, a scan). Cautious
horizontally, and after a GNSS gap for about a minute (east 0.66, seeds 1-20, a scan), though
step 2's loop is calibrated (roll error 0.59 / 0.90 mrad RMS against its 0.645 / 0.96 mrad,
steady / after the gap): step 2's share and step 1's position error are added as independent,
and they partly cancel (correlation −0.47 / −0.64 east, a scan; README).
In a GNSS gap bridged by the wave coast ``pos_std`` is the coast's (:mod:`.gnss_fusion`); this
covariance then follows the filter's, and the fixes after the gap bring it down again.

Hand-written (numpy, ``functools.lru_cache``): filterpy and python-control compute the
covariance of an optimal filter, not of one run with another model's gains.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

#: Memory of the innovation consistency check [s] (step 3 of the module docstring).
NIS_MEMORY = 60.0
#: Largest scale of the acceleration noise density the consistency check may reach.
MAX_Q_SCALE = 1e8
#: Longest sub-step of the attitude loop's propagation over a fix interval [s].
LOOP_SUBSTEP = 0.1


def pi_gains(interval: float, tau: float) -> tuple[float, float]:
    """Gains of the PI attitude loop (:func:`~.gnss_fusion.pi_pull`) for a fix ``interval`` s
    after the previous one, time constant ``tau`` [s]: the proportional fraction k_p·Δt with
    k_p = 2/τ, at most 1, and the integral gain k_i·Δt = Δt/τ², capped at 1/Δt after a gap
    longer than τ: e/Δt is then the whole bias error that built the attitude error e (after a
    300 s gap at τ = 30 s the uncapped gain would correct it 100 times over)."""
    return min(1.0, 2.0 * interval / tau), interval / max(tau, interval) ** 2


def skew(r: np.ndarray) -> np.ndarray:
    """[r]×, the cross-product matrix: skew(r) @ v = r × v."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


@lru_cache(maxsize=64)
def loop_interval(interval: float, gyro_noise: float, bias_sigma: float, bias_tau: float
                  ) -> tuple[np.ndarray, np.ndarray]:
    """Transition and noise of the attitude loop's error states (ε [rad], β [rad/s], b [rad/s])
    of one axis over ``interval`` s without a fix (module docstring, step 2).

    ε is the true minus the propagated attitude, β = b − b̂ the gyro-bias error, b the true
    Gauss-Markov bias: ε̇ = −β − n (n the gyro's white noise, density ``gyro_noise``
    [rad/s/√Hz]), b_{k+1} = φ b_k + w, and b̂ is constant between fixes. Sub-steps of at most
    :data:`LOOP_SUBSTEP` s.
    """
    sub = max(1, int(math.ceil(interval / LOOP_SUBSTEP)))
    h = interval / sub
    phi = math.exp(-h / bias_tau)
    a = np.array([[1.0, -h, 0.0], [0.0, 1.0, phi - 1.0], [0.0, 0.0, phi]])
    q = np.zeros((3, 3))
    q[0, 0] = gyro_noise ** 2 * h
    q[1:, 1:] = bias_sigma ** 2 * (1.0 - phi * phi)     # w moves b and so β alike
    a_total, q_total = np.eye(3), np.zeros((3, 3))
    for _ in range(sub):
        a_total, q_total = a @ a_total, a @ q_total @ a.T + q
    return a_total, q_total


class FusionError:
    """Covariance of the fusion's position error as it runs (module docstring).

    Parameters
    ----------
    arms : numpy.ndarray
        (4, 3) antenna lever arms, body frame [m].
    acc_noise : float
        Accelerometer white-noise density [m/s²/√Hz].
    gyro_noise : float
        Gyro white-noise density [rad/s/√Hz].
    antenna_sigma : tuple of float
        Standard deviation of one antenna position, horizontal and vertical [m].
    bias_sigma, bias_tau : float
        Gyro bias instability [rad/s] and its correlation time [s].
    attitude_tau : float or None
        Time constant of the PI attitude loop [s]; None: the attitude is each fix's, held.
    """

    def __init__(self, arms: np.ndarray, acc_noise: float, gyro_noise: float, antenna_sigma: tuple[float, float],
                 bias_sigma: float, bias_tau: float, attitude_tau: float | None) -> None:
        self.mean_arm = np.asarray(arms, dtype=float).mean(axis=0)
        self.q_true = acc_noise ** 2
        self.gyro_noise = gyro_noise
        sh, sv = antenna_sigma
        self.r_true = np.array([sh, sh, sv]) ** 2 / len(arms)     # the centroid's noise
        self.bias_sigma, self.bias_tau = bias_sigma, bias_tau
        self.attitude_tau = attitude_tau
        self.reset()

    def reset(self) -> None:
        """Forget everything (no fix yet)."""
        self.P: np.ndarray | None = None            # state-error covariance of the filter [SI]
        self.loop = np.zeros((3, 3, 3))             # per NED axis: cov of (ε, β, b)
        self.eps_var = np.zeros(3)                  # attitude error variance over the fix interval [rad²]
        self.q_scale = np.ones(3)                   # per axis, of the acceleration noise density
        self.q_parts: tuple[np.ndarray, np.ndarray] | None = None  # Q_t's acceleration and bias parts
        self.Q: np.ndarray | None = None            # Q_t, the former scaled by q_scale

    def start(self, p: np.ndarray, fix_attitude_std: np.ndarray) -> None:
        """The filter (re)started on a fix with covariance ``p`` and the fix's attitude, whose
        standard deviations per NED axis are ``fix_attitude_std`` [rad]."""
        self.P = np.array(p, dtype=float)
        s2 = np.square(fix_attitude_std)
        b2 = self.bias_sigma ** 2
        self.loop = np.zeros((3, 3, 3))
        self.loop[:, 0, 0] = s2
        self.loop[:, 1:, 1:] = b2                   # b̂ kept, b unknown: β and b alike
        self.eps_var = s2.copy()

    def follow(self, p: np.ndarray) -> None:
        """Take the filter's own covariance (a pseudo-fix of the wave coast: its errors are one
        slowly growing error, which step 1 cannot model)."""
        self.P = np.array(p, dtype=float)

    def set_process_noise(self, q_acc: np.ndarray, q_bias: np.ndarray) -> None:
        """Q_t for the step size in use: ``q_acc`` eq. 16's Q with the density :attr:`q_true`
        (:func:`~.gnss_fusion.process_noise`), which the consistency check scales per axis,
        and ``q_bias`` the bias states' part."""
        self.q_parts = (q_acc, q_bias)
        self._scale_noise()

    def _scale_noise(self) -> None:
        if self.q_parts is not None:
            s = np.ones(len(self.q_parts[0]))
            s[0:3] = s[3:6] = np.sqrt(self.q_scale)
            self.Q = s[:, None] * self.q_parts[0] * s + self.q_parts[1]

    def predict(self, f: np.ndarray) -> None:
        """One sample: P_t ← Φ P_t Φᵀ + Q_t (:meth:`set_process_noise`)."""
        if self.P is not None:
            self.P = f @ self.P @ f.T + self.Q

    def fix(self, innovation: np.ndarray, k: np.ndarray, h: np.ndarray, interval: float) -> None:
        """A GNSS fix was taken with gain ``k`` (observation matrix ``h``) and ``innovation``
        z − H x⁻ [m], ``interval`` s after the previous one: the consistency check (step 3 of
        the module docstring), then the Joseph update."""
        if self.P is None:
            return
        s = np.diag(h @ self.P @ h.T) + self.r_true
        w = min(1.0, interval / NIS_MEMORY)
        ratio = np.square(innovation) / s           # 1 on average when the model holds
        self.q_scale = np.clip(self.q_scale * (1.0 + w * (ratio - 1.0)), 1.0, MAX_Q_SCALE)
        self._scale_noise()
        ikh = np.eye(len(self.P)) - k @ h
        self.P = ikh @ self.P @ ikh.T + (k * self.r_true) @ k.T

    def _prior(self, interval: float) -> np.ndarray:
        """(3, 3, 3) covariance of the loop's error states ``interval`` s after the last pull."""
        a, q = loop_interval(round(interval, 6), self.gyro_noise, self.bias_sigma, self.bias_tau)
        return a @ self.loop @ a.T + q              # broadcast over the three axes

    def attitude_gain(self, fix_attitude_std: np.ndarray, interval: float) -> np.ndarray:
        """(3,) one-step Kalman gain per NED axis of a fix attitude of standard deviations
        ``fix_attitude_std`` [rad] ``interval`` s after the last pull: P_ε⁻/(P_ε⁻ + σ²)."""
        prior = self._prior(interval)[:, 0, 0]
        return prior / (prior + np.square(fix_attitude_std))

    def attitude_fix(self, fix_attitude_std: np.ndarray, interval: float, alpha: np.ndarray | None = None) -> None:
        """The attitude was pulled towards a fix whose attitude has standard deviations
        ``fix_attitude_std`` [rad, NED], ``interval`` s after the previous pull, with the
        proportional gains ``alpha`` per axis (None: the PI's, :func:`pi_gains`)."""
        s2 = np.square(fix_attitude_std)
        if self.attitude_tau is None:               # held: the fix's attitude itself
            self.eps_var = s2.copy()
            return
        prior = self._prior(interval)
        k_p, k_i = pi_gains(interval, self.attitude_tau)
        alpha = np.broadcast_to(k_p if alpha is None else alpha, (3,))
        u = np.zeros((3, 3, 3))
        u[:, 0, 0], u[:, 1, 0], u[:, 1, 1], u[:, 2, 2] = 1.0 - alpha, k_i, 1.0, 1.0
        v = np.zeros((3, 3))
        v[:, 0], v[:, 1] = -alpha, k_i
        self.loop = u @ prior @ u.transpose(0, 2, 1) + s2[:, None, None] * v[:, :, None] * v[:, None, :]
        self.eps_var = 0.5 * (prior[:, 0, 0] + self.loop[:, 0, 0])

    def position_var(self, rot: np.ndarray) -> np.ndarray:
        """Variance of the COG output per NED axis [m²] (``rot`` the attitude R_nb used)."""
        if self.P is None:
            return np.zeros(3)
        c = skew(rot @ self.mean_arm)
        return np.diag(self.P)[:3] + np.einsum("ij,j,ij->i", c, self.eps_var, c)

    # ---- state -------------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"P": None if self.P is None else self.P.tolist(), "loop": self.loop.tolist(),
                "eps_var": self.eps_var.tolist(), "q_scale": self.q_scale.tolist()}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.P = None if s["P"] is None else np.array(s["P"], dtype=float)
        self.loop = np.array(s["loop"], dtype=float)
        self.eps_var = np.array(s["eps_var"], dtype=float)
        self.q_scale = np.array(s["q_scale"], dtype=float)
        self._scale_noise()
