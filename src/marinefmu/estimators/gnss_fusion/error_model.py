"""The error covariance of the GNSS + accelerometer fusion as it runs: ``pos_std`` between GNSS
fixes (beyond paper 001).

Why. The fusion filter's own covariance P is that of its model, q and r of eqs. 16-17. Those
set the blend (the gain depends on q/r only), not the size of the errors: on the paper-001
set-up (1 Hz RTK) P is several times the error the filter makes
(docs/decisions/gnss-fusion-pos-std.md). A ``pos_std`` that a user can weigh
needs the covariance of the error the filter actually makes. This module keeps it alongside
the filter, without changing the fused output:

One covariance over the filter's state error e (position, velocity, with ``bias_states`` the
bias) and the PI attitude loop's error states (ε, β, b) per NED axis (:func:`loop_transition`),
kept at the accelerometer rate:

1. **The state error of a suboptimal filter** (Gelb 1974, section 7.2; Simon 2006, section
   10.1): the filter's own gains K, but the sensors' noises. At each sample
   e ← Φ e + G (u − a) with eq. 16's Q for the accelerometer's noise density (``acc_noise``²,
   not q) and the filter's bias random walk; at each GNSS fix the Joseph form, valid for any
   gain, e ← (I − KH) e + K ν-terms, with the noise of the four antennas' centroid
   (``antenna_sigma_h``²/4, ``antenna_sigma_v``²/4).
2. **The attitude error**, states (ε, β, b) — the attitude error (true R = exp([ε]×) R̂), the
   gyro-bias error and the true Gauss-Markov bias (``gyro_bias_sigma``, ``gyro_bias_tau``) —
   driven by the gyro's angle random walk ``gyro_noise`` and pulled at each fix with the PI
   loop's gains (:func:`~.filter.pi_pull`) and the fix attitude's noise
   (:func:`~.antenna_attitude.antenna_attitude_std`).

   With ``propagation="hold"`` the attitude is the last fix's, and its error is that fix's
   attitude noise ε⁺ plus the vessel's rotation since: ε̇ = ω, with ω, the vessel's angular
   rate, a Gauss-Markov process of correlation time :data:`HOLD_RATE_TAU` in place of
   (β, b). Its covariance is measured from fix to fix (:meth:`FusionError.held_rotation`: the
   rotation between consecutive fixes' attitudes, less their noise). Each fix resets ε to ε⁺,
   which is also what the fix's accelerometer point carries over its arm (:meth:`FusionError.fix`),
   so the output's share of ε⁺ is over the short arm from the antennas' centroid. With ε⁺
   alone, held constant, ``pos_std`` is over-confident. :data:`HOLD_RATE_TAU` is a little
   longer than 1/ω_p of the paper-001 sea, so that it also serves longer seas near the roll
   resonance (docs/decisions/gnss-fusion-pos-std.md).
   Once a fix is overdue the fusion follows its coast's gyro attitude (:mod:`.filter`);
   this model still takes the attitude as held, so it is cautious then, and in a gap
   ``pos_std`` is the coast's anyway.
3. **How the two go together** (the reason for one covariance). An attitude error moves
   (a) the acceleration the filter integrates, u − a = (R̂ − R) f_b = [R̂ f_b]× ε ≈ −[g_n]× ε
   (east −g ε_N, north g ε_E; with ``attitude_correction`` only), (b) the accelerometer point
   of a fix, z = centroid + R̂ (l − c̄) (l the accelerometer's arm, c̄ the antennas' mean arm),
   by S ε with S = [R̂ (l − c̄)]×, so the innovation is ν = −H e + S ε + n_c, and (c) the COG
   output x − R̂ l by −[R̂ l]× ε. The filter follows (a) and (b), so the output's error is
   e_pos − [R̂ l]× ε with e_pos and ε correlated (on the paper-001 set-up the model's
   correlation of the east error with ε_N matches the simulation's). The attitude's share,
   ε × (R c̄), added to the position variance as independent would leave ``pos_std``
   cautious, most of all just after a gap (docs/decisions/gnss-fusion-pos-std.md).
4. **A consistency check** (covariance matching: Mehra 1972; Myers & Tapley 1976): at each fix
   the innovation's square over its predicted variance, r = ν²/(M P Mᵀ + R_t) with
   M = [−H, S, 0], is 1 on average when the model holds. Per axis the acceleration noise
   density is scaled by 1 + w (r − 1) at each fix (w = interval / :data:`NIS_MEMORY`), never
   below the sensor's: an acceleration worse than its datasheet (the uncorrected acceleration
   of the paper's "before" case) shows in the innovations, and the covariance follows.

How well ``pos_std`` is calibrated (error / ``pos_std``, 1 is calibrated) is measured by
``make bench``, part ``pos_std`` (the benchmarks page; the history in
docs/decisions/gnss-fusion-pos-std.md).
In a GNSS gap bridged by the wave coast ``pos_std`` is the coast's (:mod:`.filter`); this
covariance then follows the filter's (its correlation with the attitude dropped), and the
fixes after the gap bring it down again.

Hand-written (numpy): filterpy and python-control compute the
covariance of an optimal filter, not of one run with another model's gains.
"""
from __future__ import annotations

import math
import numpy as np

from ...frames import GRAVITY_N

#: Memory of the innovation consistency check [s] (step 4 of the module docstring).
NIS_MEMORY = 60.0
#: Largest scale of the acceleration noise density the consistency check may reach.
MAX_Q_SCALE = 1e8
#: Correlation time of the vessel's angular rate in the held attitude's model [s]
#: (``propagation="hold"``, :func:`loop_transition`).
HOLD_RATE_TAU = 2.0
#: Memory of the held attitude model's rate variance, measured from fix to fix [s]
#: (:meth:`FusionError.held_rotation`).
HOLD_RATE_MEMORY = 60.0


def pi_gains(interval: float, tau: float) -> tuple[float, float]:
    """Gains of the PI attitude loop (:func:`~.filter.pi_pull`) for a fix ``interval`` s
    after the previous one, time constant ``tau`` [s]: the proportional fraction k_p·Δt with
    k_p = 2/τ, at most 1, and the integral gain k_i·Δt = Δt/τ², capped at 1/Δt after a gap
    longer than τ: e/Δt is then the whole bias error that built the attitude error e (after a
    300 s gap at τ = 30 s the uncapped gain would correct it 100 times over)."""
    return min(1.0, 2.0 * interval / tau), interval / max(tau, interval) ** 2


def skew(r: np.ndarray) -> np.ndarray:
    """[r]×, the cross-product matrix: skew(r) @ v = r × v."""
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def held_rotation_var(interval: float, tau: float | None = None) -> float:
    """Variance of the rotation ∫ω dt over ``interval`` s per unit variance of a Gauss-Markov
    rate ω of correlation time ``tau`` [s] (None: :data:`HOLD_RATE_TAU`) [s²]:
    2τ²(x − 1 + e^(−x)), x = interval/τ (≈ interval² for interval ≪ τ)."""
    tau = HOLD_RATE_TAU if tau is None else tau
    x = interval / tau
    return 2.0 * tau * tau * (x - 1.0 + math.exp(-x))


def loop_transition(h: float, bias_sigma: float, bias_tau: float, gyro_noise: float, propagated: bool,
                    rate_var: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Transition and noise of the attitude loop's error states over one sample of ``h`` s
    (module docstring, step 2), ordered (ε (3), β (3), b (3)), per NED axis alike.

    ε [rad] is the true minus the propagated attitude (true R = exp([ε]×) R̂), β = b − b̂ [rad/s]
    the gyro-bias error, b the true Gauss-Markov bias: ε̇ = −β − n (n the gyro's white noise,
    density ``gyro_noise`` [rad/s/√Hz]), b_{k+1} = φ b_k + w, b̂ constant between fixes. Not
    ``propagated`` (``propagation="hold"``): the attitude is the last fix's, held, so ε grows
    by the vessel's rotation since: ε̇ = ω, the second three states are then the vessel's
    angular rate ω [rad/s, NED], Gauss-Markov with correlation time :data:`HOLD_RATE_TAU` and
    variance ``rate_var`` (None: not yet measured, ω held at zero), the last three unused.
    """
    if not propagated:
        phi = math.exp(-h / HOLD_RATE_TAU)
        a = np.kron(np.array([[1.0, HOLD_RATE_TAU * (1.0 - phi), 0.0], [0.0, phi, 0.0], [0.0, 0.0, 1.0]]), np.eye(3))
        q = np.zeros((9, 9))
        if rate_var is not None:
            val, vec = np.linalg.eigh(rate_var)     # the measured covariance's nearest PSD matrix
            q[3:6, 3:6] = (vec * np.maximum(val, 0.0)) @ vec.T * (1.0 - phi * phi)
        return a, q
    phi = math.exp(-h / bias_tau)
    a = np.array([[1.0, -h, 0.0], [0.0, 1.0, phi - 1.0], [0.0, 0.0, phi]])
    q = np.zeros((3, 3))
    q[0, 0] = gyro_noise ** 2 * h
    q[1:, 1:] = bias_sigma ** 2 * (1.0 - phi * phi)     # w moves b and so β alike
    i3 = np.eye(3)
    return np.kron(a, i3), np.kron(q, i3)


class FusionError:
    """Covariance of the fusion's position error as it runs (module docstring).

    One covariance over the filter's state error e (position, velocity and, with bias states,
    bias; the filter's order) and the attitude loop's (ε, β, b) per NED axis: ``P`` is its e
    block, ``joint`` the whole.

    Parameters
    ----------
    arms : numpy.ndarray
        (4, 3) antenna lever arms, body frame [m].
    acc_arm : numpy.ndarray
        (3,) the accelerometer's lever arm, body frame [m] (the output is the COG, the origin).
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
    corrected : bool
        The acceleration is turned by the attitude (``attitude_correction``), so errs by g·ε;
        False: the body-frame force is used as it is, and its tilt error is the consistency
        check's (step 4).
    """

    def __init__(self, arms: np.ndarray, acc_arm: np.ndarray, acc_noise: float, gyro_noise: float,
                 antenna_sigma: tuple[float, float], bias_sigma: float, bias_tau: float,
                 attitude_tau: float | None, corrected: bool = True) -> None:
        self.mean_arm = np.asarray(arms, dtype=float).mean(axis=0)
        self.acc_arm = np.asarray(acc_arm, dtype=float).reshape(3)
        self.q_true = acc_noise ** 2
        self.gyro_noise = gyro_noise
        sh, sv = antenna_sigma
        self.r_true = np.array([sh, sh, sv]) ** 2 / len(arms)     # the centroid's noise
        self.bias_sigma, self.bias_tau = bias_sigma, bias_tau
        self.attitude_tau = attitude_tau
        self.corrected = corrected
        self.reset()

    def reset(self) -> None:
        """Forget everything (no fix yet)."""
        self.joint: np.ndarray | None = None        # covariance of (e, ε, β, b) [SI]
        self.q_scale = np.ones(3)                   # per axis, of the acceleration noise density
        self.model: tuple | None = None             # (Q_t's acceleration part, its bias part, the loop's noise)
        self.phi: np.ndarray | None = None          # the joint transition of one sample
        self.Q: np.ndarray | None = None            # the joint process noise of one sample
        self.rate_var: np.ndarray | None = None     # held attitude: the vessel's rate variance [rad²/s², NED]
        self.model_args: tuple | None = None        # set_model's arguments

    @property
    def P(self) -> np.ndarray | None:
        """The covariance of the filter's state error e (its first block of :attr:`joint`)."""
        return None if self.joint is None else self.joint[:-9, :-9]

    @property
    def eps_var(self) -> np.ndarray:
        """(3,) variance of the attitude error ε per NED axis [rad²]."""
        return np.zeros(3) if self.joint is None else np.diag(self.joint)[-9:-6].copy()

    def start(self, p: np.ndarray, fix_attitude_std: np.ndarray, rot: np.ndarray) -> None:
        """The filter (re)started on a fix with covariance ``p``, its accelerometer point taken
        through the fix's attitude ``rot`` (R_nb), whose standard deviations per NED axis are
        ``fix_attitude_std`` [rad]: that point carries the attitude error over the arm from
        the antennas' centroid (:meth:`fix`)."""
        nx = len(p)
        s2 = np.square(fix_attitude_std)
        b2 = self.bias_sigma ** 2
        j = np.zeros((nx + 9, nx + 9))
        j[:nx, :nx] = p
        j[nx:nx + 3, nx:nx + 3] = np.diag(s2)
        j[nx + 3:, nx + 3:] = np.kron(np.ones((2, 2)), b2 * np.eye(3))   # b̂ kept, b unknown: β and b alike
        sa = self._fix_arm(rot)
        c = sa * s2                                 # cov(e_pos, ε) = S Σ_ε
        j[:3, nx:nx + 3] = c
        j[nx:nx + 3, :3] = c.T
        j[:3, :3] += c @ sa.T
        self.joint = j

    def follow(self, p: np.ndarray) -> None:
        """Take the filter's own covariance (a pseudo-fix of the wave coast: its errors are one
        slowly growing error, which step 1 cannot model); its correlation with the attitude
        error is dropped."""
        if self.joint is None:
            return
        nx = len(p)
        self.joint[:nx, :nx] = p
        self.joint[:nx, nx:] = 0.0
        self.joint[nx:, :nx] = 0.0

    def set_model(self, f: np.ndarray, g: np.ndarray, q_acc: np.ndarray, q_bias: np.ndarray, dt: float) -> None:
        """The model for the step size ``dt`` [s] in use: the filter's Φ ``f`` and input matrix
        ``g`` (eq. 15), ``q_acc`` eq. 16's Q with the density :attr:`q_true`
        (:func:`~.filter.process_noise`), which the consistency check scales per axis, and
        ``q_bias`` the bias states' part."""
        self.model_args = (f, g, q_acc, q_bias, dt)
        a, q_loop = loop_transition(dt, self.bias_sigma, self.bias_tau, self.gyro_noise, self.attitude_tau is not None,
                                    self.rate_var)
        nx = len(f)
        phi = np.zeros((nx + 9, nx + 9))
        phi[:nx, :nx] = f
        if self.corrected:                          # u − a = (R̂ − R) f_b ≈ [R̂ f_b]× ε, R̂ f_b ≈ −g_n
            phi[:nx, nx:nx + 3] = g @ skew(-GRAVITY_N)
        phi[nx:, nx:] = a
        self.phi = phi
        self.model = (q_acc, q_bias, q_loop)
        self._scale_noise()

    def _scale_noise(self) -> None:
        if self.model is not None:
            q_acc, q_bias, q_loop = self.model
            nx = len(q_acc)
            s = np.ones(nx)
            s[0:3] = s[3:6] = np.sqrt(self.q_scale)
            q = np.zeros((nx + 9, nx + 9))
            q[:nx, :nx] = s[:, None] * q_acc * s + q_bias
            q[nx:, nx:] = q_loop
            self.Q = q

    def predict(self) -> None:
        """One sample: P ← Φ P Φᵀ + Q (:meth:`set_model`)."""
        if self.joint is not None:
            self.joint = self.phi @ self.joint @ self.phi.T + self.Q

    def _fix_arm(self, rot: np.ndarray) -> np.ndarray:
        """S = [R̂ (l − c̄)]×: a fix's accelerometer point errs by S ε (:meth:`fix`)."""
        return skew(rot @ (self.acc_arm - self.mean_arm))

    def held_rotation(self, change: np.ndarray, interval: float, fix_attitude_std: np.ndarray) -> None:
        """Held attitude (``attitude_tau`` None): measure the vessel's rate variance from the
        rotation ``change`` [rad, NED rotation vector] between two fixes' attitudes ``interval``
        s apart, each of standard deviations ``fix_attitude_std`` [rad]: E[change²] is the
        rotation's variance (:func:`held_rotation_var` times the rate variance) plus both fixes'
        noise. An exponential mean over :data:`HOLD_RATE_MEMORY` s; the model follows."""
        if self.attitude_tau is not None or not 0.0 < interval <= 10.0 * HOLD_RATE_TAU:
            return
        change = np.asarray(change, dtype=float)
        sample = (np.outer(change, change) - 2.0 * np.diag(np.square(fix_attitude_std))) / held_rotation_var(interval)
        w = min(1.0, interval / HOLD_RATE_MEMORY)
        self.rate_var = sample if self.rate_var is None else self.rate_var + w * (sample - self.rate_var)
        if self.model_args is not None:
            self.set_model(*self.model_args)

    def innovation_var(self, h: np.ndarray, rot: np.ndarray, held_std: np.ndarray | None = None) -> np.ndarray:
        """(3,) variance per NED axis of a fix's innovation z − H x⁻ [m²] as this covariance
        predicts it (:meth:`fix`: ν = −H e + S ε + n_c, or with a held attitude −H e + S ε⁺ +
        n_c); zeros before the first fix."""
        if self.joint is None:
            return np.zeros(3)
        nx = len(self.joint) - 9
        sa = self._fix_arm(rot)
        m = np.zeros((3, nx + 9))
        m[:, :nx] = -h
        s2 = np.zeros(3)
        if self.attitude_tau is None and held_std is not None:
            s2 = np.square(held_std)
        else:
            m[:, nx:nx + 3] = sa
        return np.einsum("ij,jk,ik->i", m, self.joint, m) + self.r_true + np.einsum("ij,j,ij->i", sa, s2, sa)

    def fix(self, innovation: np.ndarray, k: np.ndarray, h: np.ndarray, interval: float, rot: np.ndarray,
            held_std: np.ndarray | None = None, predicted: np.ndarray | None = None) -> None:
        """A GNSS fix was taken with gain ``k`` (observation matrix ``h``) and ``innovation``
        z − H x⁻ [m], ``interval`` s after the previous one, its accelerometer point z the
        centroid plus the arm turned by the propagated attitude ``rot``: the consistency check
        (step 4 of the module docstring), then the Joseph update.

        z − (true point) = n_c + (R̂ − R)(l − c̄) = n_c + S ε, so the innovation is
        ν = −H e + S ε + n_c and e ← (I − KH) e + K S ε + K n_c.

        Held attitude (``attitude_tau`` None): ``rot`` is this fix's own attitude. Its error ε⁺
        (standard deviations ``held_std`` [rad, NED]) is what the arm carries and what the held
        attitude errs by from now on: ν = −H e + S ε⁺ + n_c, e ← (I − KH) e + K S ε⁺ + K n_c
        and ε ← ε⁺ (so :meth:`attitude_fix` is not called for it). So the output's share
        of ε⁺ is (K S − [R̂ l]×) ε⁺, about −[R̂ c̄]× ε⁺ once K is near 1: the arm from the
        antennas' centroid, not the accelerometer's.

        ``predicted``: :meth:`innovation_var` for this fix, if the caller has it already (the
        fusion's gate does).
        """
        if self.joint is None:
            return
        nx = len(k)
        sa = self._fix_arm(rot)
        held = self.attitude_tau is None and held_std is not None
        s2 = np.square(held_std) if held else np.zeros(3)
        s = self.innovation_var(h, rot, held_std) if predicted is None else predicted
        w = min(1.0, interval / NIS_MEMORY)
        ratio = np.square(innovation) / s           # 1 on average when the model holds
        self.q_scale = np.clip(self.q_scale * (1.0 + w * (ratio - 1.0)), 1.0, MAX_Q_SCALE)
        self._scale_noise()
        u = np.eye(nx + 9)
        u[:nx, :nx] -= k @ h
        if held:
            u[nx:nx + 3, nx:nx + 3] = 0.0
            v = np.zeros((nx + 9, 3))
            v[:nx] = k @ sa
            v[nx:nx + 3] = np.eye(3)
            self.joint = u @ self.joint @ u.T + (v * s2) @ v.T
        else:
            u[:nx, nx:nx + 3] = k @ sa
            self.joint = u @ self.joint @ u.T
        self.joint[:nx, :nx] += (k * self.r_true) @ k.T

    def attitude_gain(self, fix_attitude_std: np.ndarray) -> np.ndarray:
        """(3,) one-step Kalman gain per NED axis of a fix attitude of standard deviations
        ``fix_attitude_std`` [rad] now: P_ε/(P_ε + σ²)."""
        prior = self.eps_var
        return prior / (prior + np.square(fix_attitude_std))

    def attitude_fix(self, fix_attitude_std: np.ndarray, interval: float, alpha: np.ndarray | None = None) -> None:
        """The attitude was pulled towards a fix whose attitude has standard deviations
        ``fix_attitude_std`` [rad, NED], ``interval`` s after the previous pull, with the
        proportional gains ``alpha`` per axis (None: the PI's, :func:`pi_gains`): with the fix's
        attitude error n, ε ← (1 − α) ε − α n and β ← β + k_i (ε + n); held
        (``attitude_tau`` None): ε ← −n (for a fix that :meth:`fix` took with its attitude std,
        which resets ε itself, not called)."""
        if self.joint is None:
            return
        nx = len(self.joint) - 9
        s2 = np.square(fix_attitude_std)
        if self.attitude_tau is None:
            k_i, alpha = 0.0, np.ones(3)
        else:
            k_p, k_i = pi_gains(interval, self.attitude_tau)
            alpha = np.broadcast_to(k_p if alpha is None else alpha, (3,))
        u = np.eye(nx + 9)
        u[nx:nx + 3, nx:nx + 3] = np.diag(1.0 - alpha)
        u[nx + 3:nx + 6, nx:nx + 3] = k_i * np.eye(3)
        v = np.zeros((nx + 9, 3))
        v[nx:nx + 3] = np.diag(-alpha)
        v[nx + 3:nx + 6] = k_i * np.eye(3)
        self.joint = u @ self.joint @ u.T + (v * s2) @ v.T

    def output_map(self, rot: np.ndarray) -> np.ndarray:
        """(3, n) M: the COG output's error is M times the joint state error (``rot`` the
        attitude R_nb used): the output x − R̂ l errs by e_pos − [R̂ l]× ε."""
        nx = len(self.joint) - 9
        m = np.zeros((3, nx + 9))
        m[:, :3] = np.eye(3)
        m[:, nx:nx + 3] = -skew(rot @ self.acc_arm)
        return m

    def position_var(self, rot: np.ndarray, arm_n: tuple[float, float, float] | None = None) -> tuple[float, float, float]:
        """Variance of the COG output per NED axis [m²] (``rot`` the attitude R_nb used;
        ``arm_n``: R̂ l [m, NED] when the caller has it).

        diag(M J Mᵀ) with M = [I 0 A 0] of :meth:`output_map`, A = −[R̂ l]×, written on the
        two 3 × 3 blocks M touches (position p and attitude ε): with r = R̂ l, row i of A is
        r × e_i, so var_i = J_pp,ii + 2 Σ_k A_ik J_pε,ik + Σ_jk A_ij J_εε,jk A_ik. Called
        every step, on Python floats: the nine products of a row are fewer operations than a
        numpy call's overhead (a test checks it against the full product)."""
        if self.joint is None:
            return (0.0, 0.0, 0.0)
        nx = len(self.joint) - 9
        j = self.joint
        r0, r1, r2 = (rot @ self.acc_arm).tolist() if arm_n is None else arm_n
        (c00, c01, c02), (c10, c11, c12), (c20, c21, c22) = j[:3, nx:nx + 3].tolist()       # J_pε
        (e00, e01, e02), (e10, e11, e12), (e20, e21, e22) = j[nx:nx + 3, nx:nx + 3].tolist()  # J_εε
        d0, d1, d2 = j.diagonal()[:3].tolist()
        # rows of A: (0, r2, −r1), (−r2, 0, r0), (r1, −r0, 0)
        var0 = d0 + 2.0 * (r2 * c01 - r1 * c02) + r2 * r2 * e11 - r2 * r1 * (e12 + e21) + r1 * r1 * e22
        var1 = d1 + 2.0 * (r0 * c12 - r2 * c10) + r2 * r2 * e00 - r2 * r0 * (e02 + e20) + r0 * r0 * e22
        var2 = d2 + 2.0 * (r1 * c20 - r0 * c21) + r1 * r1 * e00 - r1 * r0 * (e01 + e10) + r0 * r0 * e11
        return max(var0, 0.0), max(var1, 0.0), max(var2, 0.0)   # rounding: never negative

    # ---- state -------------------------------------------------------------------------------
    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"joint": None if self.joint is None else self.joint.tolist(), "q_scale": self.q_scale.tolist(),
                "rate_var": None if self.rate_var is None else self.rate_var.tolist()}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.joint = None if s["joint"] is None else np.array(s["joint"], dtype=float)
        self.q_scale = np.array(s["q_scale"], dtype=float)
        rate_var = s.get("rate_var")
        self.rate_var = None if rate_var is None else np.array(rate_var, dtype=float)
        if self.model_args is not None:             # the held attitude's model follows rate_var
            self.set_model(*self.model_args)
        else:
            self._scale_noise()
