"""The joint motion filter: the IMU's real-time surge, sway and heave, and their rates, from the
past of all six IMU channels, a causal linear filter taught by the unit's own delayed outputs.

**Why.** One filter per level-frame axis (paper 003's observer generalised,
:class:`~marinefmu.estimators.heave.wiener.WienerAxis`) reads that axis's acceleration alone.
In a sea where one wave train drives all six motions, the other channels tell it much more: the
gyro's angles, precise at wave frequencies, predict the accelerations, and the vertical, which
the attitude's tilt error reaches only at second order, predicts the horizontal. The least-variance
causal linear estimate from all channels (:func:`marinefmu.papers.motion_bound.causal_motion_bound`)
lies 2-3 × below one filter per axis fed the *true* attitude; the per-axis filters also take the
AttitudeEstimator's in-band tilt error ε as motion (g·ε/ω² of displacement), which the joint
filter, reading the same specific force as a linear function of the tilt, does not.

**What it fits.** The rows are those of the bound (:meth:`JointMotion.features`): over the last
``memory`` seconds, block means (:func:`block_edges`: blocks a tenth of their age long, at most
:data:`LONGEST_BLOCK`) of nine channels, the Euler rates u = T(φ, θ)(ω − b̂) [rad/s], the level
frame's specific force linearised, a_h + g [θ, −φ, 0] [m/s²] (to first order the specific force
turned by the yaw alone, so that it is a linear function of the raw samples and the attitude's
tilt error cancels from it), and the Euler angles' change from each block to now (the trapezoidal
integral of u [rad]), then a constant. The targets are what the unit's three axis filters give
``lag`` s late, their fixed-lag (Wiener smoother) position and rate, which err 3-10 × less than
their real-time outputs: the rows at t − lag are regressed on the smoothed motion at t − lag, and
the fit applied to the rows at t. Least squares with a ridge ρ of the mean diagonal
(:data:`RIDGE`),

.. math::
    W = (N + ρ\\,\\overline{\\mathrm{diag}N}\\, I)^{-1} M,\\qquad
    N ← λN + X^T X,\\quad M ← λM + X^T Y,\\quad λ = e^{-T/τ},

over the rows of each refit interval T (:data:`REFIT`), forgotten with the time constant τ of the
axis filters' longest spectrum window (``window_max``), solved by Cholesky (``scipy.linalg``).
Where the smoother's error is not a linear function of the rows at t − lag (it depends on the
samples after it), the fit does better than its teacher; where it is (the attitude's tilt
error in the smoothed horizontal motion, an IMU far from the COG), the fit learns it too.

**Per step** the filter writes the channels' running sums to a ring and reads (wrapped) the
running sums at the block edges: the prediction is linear in them,
y = Σ_a S_{k−a} V_a + c, with V folded from W at each refit (:meth:`JointMotion._fold`), one
gather and one product. Until the first fit (:data:`WARMUP_RATIO` taught rows per weight) it
gives nothing and the unit keeps its axis filters' outputs; after it the unit moves its outputs
over to these in :data:`BLEND` s (:meth:`JointMotion.share`).

**Inputs outside its teaching.** The fit is taught in the sea at a steady heading and heel; a
heading change or a heel (a crane's load, ballast) puts into the rates, the angles and the
level specific force inputs it never saw, whose response the least squares leaves free. The
fit is held deaf to a constant offset of the horizontal level specific force over its memory
(:func:`slow_rows`), which is what a heel leaves once its memory has passed it. While a change
is within its memory the filter checks itself against the axis filters, which read the
acceleration in a level frame that a heel does not reach (:meth:`JointMotion.check`): beyond
:data:`GATE` × the two's running RMS difference it gives nothing (the unit uses the axis
filters' outputs) until its memory has passed the last such step, and then blends back in over
:data:`BLEND` s. It goes on learning meanwhile: the axis filters' delayed outputs, its teacher,
are right through a heel, and a lasting change of the vessel's state is learnt rather than
shut out.

Hand-written least squares (numpy and ``scipy.linalg.cho_factor``): neither scipy, filterpy nor
python-control fits a multichannel causal filter from data.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.linalg import LinAlgError, cho_factor, cho_solve

from ...frames import G
from ..numerics import one_blas_thread

#: Longest block of the rows [s]: a wave of 5 s or more is a smooth curve over it.
LONGEST_BLOCK = 2.0
#: Block length relative to its age (:func:`block_edges`).
RESOLUTION = 0.1
#: Shortest block after the newest sample [s]: 20 Hz resolves every wave and the vessel's
#: response to it, and fewer blocks cost less per step (:meth:`JointMotion.predict`).
SHORTEST_BLOCK = 0.05
#: Interval between taught rows [s].
STRIDE = 0.5
#: Interval between refits [s].
REFIT = 120.0
#: Taught rows per weight before the first fit: with fewer the fit follows the teacher's
#: errors (2 × 640 rows, 640 s at the defaults and 100 Hz: the first fit's errors are then those
#: of the later ones; after 300 s they were up to 1.9 × the axis filters' in heave).
WARMUP_RATIO = 2.0
#: After the first fit the unit's outputs move from the axis filters' to the joint filter's
#: linearly over BLEND s [s], so that the first fit does not step them (by a few centimetres,
#: which a heave compensator's feedforward would pass to its winch as a jerk).
BLEND = 10.0
#: Ridge, relative to the normal matrix's mean diagonal.
RIDGE = 1e-7
#: Number of channels: angle changes (3), Euler rates (3), specific force (3).
CHANNELS = 9
#: Number of targets: position (3) then rate (3), surge, sway, heave.
TARGETS = 6
#: Weight of the slow inputs' rows in the fit (:func:`slow_rows`), relative to the taught rows'
#: forgotten count: any weight from 10⁻³ on holds the response to nothing.
SLOW_WEIGHT = 1.0
#: The joint filter's output is distrusted when one of its six numbers (surge, sway, heave and
#: their rates) departs from the axis filters' by more than GATE × their running RMS
#: difference (:meth:`JointMotion.check`).
GATE = 6.0
#: Time constant of that running RMS [s], and the time it runs before the gate applies.
AGREEMENT_TAU = 300.0
AGREEMENT_SETTLE = 60.0
#: Interval of the agreement check [s]: the difference is smooth at wave frequencies.
CHECK_EVERY = 0.1


def block_edges(memory: float, dt: float, resolution: float = RESOLUTION, longest: float = LONGEST_BLOCK,
                shortest: float = 0.0) -> np.ndarray:
    """Ages [samples] of the block boundaries, 0 = now: block j holds the samples k − e_{j+1} < i ≤
    k − e_j of the row at sample k. The first block is the newest sample; each later one is
    ``resolution`` × its age long, at least ``shortest`` s (and one sample) and at most
    ``longest`` s, up to ``memory`` s."""
    edges, n_max = [0, 1], int(round(memory / dt))
    longest_n = max(1, int(round(longest / dt)))
    shortest_n = max(1, int(round(shortest / dt)))
    while edges[-1] < n_max:
        edges.append(min(n_max, edges[-1] + min(longest_n, max(shortest_n, int(resolution * edges[-1])))))
    return np.array(edges)


def slow_rows(edges: np.ndarray) -> np.ndarray:
    """(2, F) rows (:meth:`JointMotion.features`, the constant's column 0) of a unit constant in each
    horizontal level specific force over the memory of block ``edges``: what a heel (a crane's
    load, ballast) older than the memory leaves in the linearised force, g [θ, −φ, 0] more.
    A row is 1 at every block of its channel, so with zero targets it holds the sum of that
    channel's block weights, the fit's response to the offset, to nothing.

    The sea puts no such offset into the taught rows beyond their mean, so the least squares
    leaves that response free (decimetres of heave after a 2° heel); the axis filters reject
    below ``omega_min`` by design. The vertical force, which a heel does not reach, is left
    free, and so are a ramp in the forces and a constant in the rates (a heel still under way,
    a steady turn), which look too much like the waves over a 60 s memory: holding the fit to
    nothing there cost it up to 14 % of its accuracy in the sea (docs/decisions/mru-design.md);
    :meth:`JointMotion.check` deals with those."""
    blocks = len(edges) - 1
    rows = np.zeros((2, CHANNELS * blocks + 1))
    for row, channel in zip(rows, (6, 7)):         # the horizontal forces
        row[channel:-1:CHANNELS] = 1.0
    return rows


def linear_channels(gyro_unbiased: Any, roll: float, pitch: float, level_force: Any) -> tuple[float, ...]:
    """Euler rates u = T(φ, θ) ω [rad/s] from the bias-corrected body rate ω (3,), then the
    linearised level specific force a_h + g [θ, −φ, 0] [m/s²] from the level frame's
    acceleration ``level_force`` (3,) (surge, sway, heave axes; module docstring)."""
    p, q, r = gyro_unbiased
    sf, cf = math.sin(roll), math.cos(roll)
    qr = q * sf + r * cf
    return (p + qr * math.tan(pitch), q * cf - r * sf, qr / math.cos(pitch),
            level_force[0] + G * pitch, level_force[1] - G * roll, level_force[2])


class JointMotion:
    """The joint motion filter (module docstring).

    Parameters
    ----------
    memory : float
        Span of the rows [s].
    dt : float
        Sample interval [s].
    lag_steps : int
        Delay of the teacher's outputs [samples].
    forget : float
        Time constant of the fit's forgetting [s].
    slow : bool
        Hold the fit deaf to a constant horizontal force offset (:func:`slow_rows`); False for
        the bare least squares.
    """

    def __init__(self, memory: float, dt: float, lag_steps: int, forget: float, slow: bool = True) -> None:
        self.dt = dt
        self.lag = lag_steps
        self.edges = block_edges(memory, dt, shortest=SHORTEST_BLOCK)
        self.lengths = np.diff(self.edges).astype(float)
        self.blocks = len(self.lengths)
        self.n = int(self.edges[-1]) + lag_steps + 2          # ring rows: the memory and the lag
        self.ages = -self.edges                               # + the newest row, wrapped: the edges' rows
        self.features_count = CHANNELS * self.blocks + 1
        self.stride = max(1, int(round(STRIDE / dt)))
        self.refit_steps = max(1, int(round(REFIT / dt)))
        self.warmup_rows = WARMUP_RATIO * self.features_count
        self.decay = math.exp(-REFIT / forget)
        self.slow = slow_rows(self.edges) if slow else None
        self.check_steps = max(1, int(round(CHECK_EVERY / dt)))
        self.beta = 1.0 - math.exp(-self.check_steps * dt / AGREEMENT_TAU)
        self.settle_weight = 1.0 - math.exp(-AGREEMENT_SETTLE / AGREEMENT_TAU)
        self.reset()

    def reset(self) -> None:
        """Back to the initial state (nothing taught)."""
        self.k = 0
        self.ring = np.zeros((self.n, CHANNELS))
        self.until_row = self.stride                # samples to the next taught row
        self.totals = (0.0,) * CHANNELS            # the channels' running sums
        self.angles = (0.0, 0.0, 0.0)              # the Euler rates' integral [rad]
        self.last_channels: tuple[float, ...] = (0.0,) * 6     # the last good sample's (rates: the trapezoid's)
        self.last_bad = -1 << 40                  # the newest step with a bad sample
        self.batch: list[np.ndarray] = []
        self.batch_targets: list[np.ndarray] = []
        self.normal = np.zeros((self.features_count, self.features_count))
        self.moment = np.zeros((self.features_count, TARGETS))
        self.rows = 0.0                            # the forgotten count of taught rows
        self.taught = 0                            # every row taught
        self.weights: np.ndarray | None = None     # (features, 6) W
        self.fitted_at: int | None = None          # the sample count at the first fit
        self.blend_from: int | None = None         # the sample count the current blend began at
        self.agree_ms = np.zeros(TARGETS)          # running mean square of joint − axis outputs
        self.agree_weight = 0.0                    # its weight 1 − (1 − β)^n, for its start
        self.distrusted_until = 0                  # the sample count from which the output is trusted
        self.disagreed = False                     # this step's check found the two apart
        # [Vᵀ c]: the running sums' weights, then the constant, which meets the 1 at the end of
        # the gathered sums (rows contiguous)
        self.node_weights = np.zeros((TARGETS, len(self.edges) * CHANNELS + 1))
        self.index = np.zeros(len(self.edges), dtype=np.intp)
        self.flat_nodes = np.ones(len(self.edges) * CHANNELS + 1)      # the gathered sums, then 1
        self._link_nodes()
        self.blended = False                        # the joint filter's share has reached 1

    def __setstate__(self, state: dict) -> None:
        """Unpickled or deep-copied: ``nodes`` a view of ``flat_nodes`` again (a copy copies a
        view's data apart from its base, and the gather would land where the prediction does not
        read)."""
        self.__dict__.update(state)
        self._link_nodes()

    def _link_nodes(self) -> None:
        """``nodes``: a (blocks, channels) view of ``flat_nodes`` without its 1, where the gather
        lands."""
        self.nodes = self.flat_nodes[:-1].reshape(len(self.edges), CHANNELS)

    @property
    def ready(self) -> bool:
        """Whether a fit exists."""
        return self.weights is not None

    def push(self, channels: tuple[float, ...] | None) -> None:
        """One sample of the six linear channels (:func:`linear_channels`), or None for a bad
        sample: the last good one is held (as the attitude coasts on it), so that the angles'
        integral runs on rather than stopping, which would offset every later row spanning the
        gap by the angle turned in it (a 0.5 s gap in Hs 6 m: decimetres for the memory); no row
        spanning it is taught."""
        if channels is None:
            self.last_bad = self.k
            channels = self.last_channels
        previous = self.last_channels if self.k else channels     # the trapezoid's other end
        self.last_channels = channels
        u0, u1, u2, f0, f1, f2 = channels
        l0, l1, l2 = previous[0], previous[1], previous[2]
        h = 0.5 * self.dt
        a0, a1, a2 = self.angles
        a0 += h * (l0 + u0)
        a1 += h * (l1 + u1)
        a2 += h * (l2 + u2)
        self.angles = (a0, a1, a2)
        t0, t1, t2, t3, t4, t5, t6, t7, t8 = self.totals
        t = self.totals = (t0 + a0, t1 + a1, t2 + a2, t3 + u0, t4 + u1, t5 + u2, t6 + f0, t7 + f1, t8 + f2)
        self.ring[self.k % self.n] = t
        self.k += 1

    def step(self, channels: tuple[float, ...] | None, outputs: np.ndarray, valid: bool,
             compare: bool = True) -> np.ndarray | None:
        """:meth:`push`, :meth:`teach` and, once fitted, :meth:`predict` and, if ``compare``,
        :meth:`check` in one call (the unit's every step once its axis filters give outputs):
        the (2, 3) position [m] and rate [m/s] now, or None (no fit yet, or distrusted).
        ``compare`` false: the axis filters' outputs are not the motion's (after a gap they read
        its stand-ins for a while), and the filter keeps whatever trust it had."""
        self.disagreed = False
        self.push(channels)
        self.teach(outputs, valid)
        if self.weights is None:
            return None
        now = self.predict()
        if compare and (self.k % self.check_steps == 0 or self.k < self.distrusted_until):
            return self.check(now, outputs)
        return None if self.k < self.distrusted_until else now

    def check(self, now: np.ndarray, outputs: np.ndarray) -> np.ndarray | None:
        """``now`` (:meth:`predict`) if it agrees with the axis filters' real-time position and
        rate (``outputs`` (axes, 4), columns 0-1), else None (module docstring).

        Every :data:`CHECK_EVERY` s the difference d enters a running mean square per number
        (exponential, :data:`AGREEMENT_TAU`, corrected for its start; not while distrusted); from
        :data:`AGREEMENT_SETTLE` s on, |d| > :data:`GATE` × its RMS in any number distrusts the
        output until the rows no longer hold this step (the memory, :attr:`edges`) and sets
        :attr:`disagreed` on the step that starts it. Checked every step while distrusted, so
        that a continuing departure keeps it; after it the blend (:meth:`share`) starts
        again. The teaching goes on (module docstring)."""
        d = (now - outputs[:3, :2].T).ravel()
        weight = self.agree_weight
        if weight >= self.settle_weight and np.any(d * d > GATE * GATE * self.agree_ms / weight):
            self.disagreed = self.k >= self.distrusted_until
            self.distrusted_until = self.k + int(self.edges[-1])
            self.blended = False
            self.blend_from = None
            return None
        if self.k < self.distrusted_until:
            return None
        if self.blend_from is None:
            self.blend_from = self.k
        self.agree_ms += self.beta * (d * d - self.agree_ms)
        self.agree_weight = weight + self.beta * (1.0 - weight)
        return now

    def gather(self, age: int = 0) -> np.ndarray:
        """(B + 1, 9) running sums at the block edges of the row ``age`` samples before the
        newest, newest edge first."""
        return np.take(self.ring, self.ages + (self.k - 1 - age), axis=0, mode="wrap")

    def features(self, age: int = 0) -> np.ndarray:
        """(F,) row of the sample ``age`` samples before the newest: per block (newest first) the
        nine channels' means, the angles' less the angles now, then 1."""
        s = self.gather(age)
        means = (s[:-1] - s[1:]) / self.lengths[:, None]
        means[:, :3] -= means[0, :3]
        return np.append(means.ravel(), 1.0)

    def teach(self, outputs: np.ndarray, valid: bool) -> None:
        """After :meth:`push`: the axis filters' (axes, 4) outputs, whose rows 0-2, columns 2-3
        are the teacher, the position [m] and rate [m/s] of surge, sway and heave ``lag``
        samples before the newest, if ``valid``. A row is taught every :data:`STRIDE` s when its
        span holds no bad sample; every :data:`REFIT` s the rows are folded into the fit."""
        self.until_row -= 1
        if self.until_row:
            return
        self.until_row = self.stride
        k = self.k
        if valid and k - 1 - self.last_bad > self.lag + self.edges[-1] and k > self.lag + self.edges[-1] + 1:
            self.batch.append(self.features(self.lag))
            self.batch_targets.append(np.concatenate([outputs[:3, 2], outputs[:3, 3]]))
        if k % self.refit_steps < self.stride and self.batch:
            with one_blas_thread():               # (F × F) products and a Cholesky, F ≈ 600: below
                self._refit()                     # OpenBLAS's threads' pay-off (numerics.one_blas_thread)

    def _refit(self) -> None:
        """Fold the batch into N and M and solve for W (module docstring)."""
        x, y = np.array(self.batch), np.array(self.batch_targets)
        self.batch, self.batch_targets = [], []
        self.normal *= self.decay
        self.moment *= self.decay
        self.normal += x.T @ x
        self.moment += x.T @ y
        self.rows = self.decay * self.rows + len(x)
        self.taught += len(x)
        if self.taught < self.warmup_rows:
            return
        regular = self.normal.copy()
        if self.slow is not None:
            # the offsets at each force's RMS in the taught rows (its newest block, its samples),
            # weighted as the taught rows together
            scale = np.sqrt(np.diag(self.normal)[6:8] / self.rows)
            slow = self.slow * scale[:, None]
            regular += SLOW_WEIGHT * self.rows * (slow.T @ slow)
        regular.flat[::len(regular) + 1] += RIDGE * float(np.mean(np.diag(self.normal)))
        try:
            weights = cho_solve(cho_factor(regular, overwrite_a=True, check_finite=False), self.moment)
        except LinAlgError:
            return                                      # keep the last fit
        if np.all(np.isfinite(weights)):
            self.weights = weights
            self._fold()
            if self.fitted_at is None:
                self.fitted_at = self.blend_from = self.k

    def _fold(self) -> None:
        """V and c from W: the prediction as a product with the running sums at the edges.

        With S_a the running sums at age a and L_j the block lengths, block j's mean is
        (S_{e_j} − S_{e_{j+1}})/L_j and the angles now are block 0's mean (one sample), so
        Σ_j m_j W_j = Σ_j S_{e_j} (W_j/L_j − W_{j−1}/L_{j−1}) with the angle columns' weight
        sum moved to the first block."""
        w = self.weights[:-1].reshape(self.blocks, CHANNELS, TARGETS)
        scaled = w / self.lengths[:, None, None]
        v = np.zeros((self.blocks + 1, CHANNELS, TARGETS))
        v[:-1] += scaled
        v[1:] -= scaled
        angle_sum = w[:, :3].sum(axis=0) / self.lengths[0]
        v[0, :3] -= angle_sum
        v[1, :3] += angle_sum
        self.node_weights = np.ascontiguousarray(np.column_stack([v.reshape(-1, TARGETS).T, self.weights[-1]]))

    def share(self) -> float:
        """Weight of the joint filter in the unit's outputs, 0 … 1: 0 until the first fit (or
        while distrusted, :meth:`check`), then rising linearly to 1 over :data:`BLEND` s
        (``blended`` from then on)."""
        if self.blend_from is None:
            return 0.0
        share = min(1.0, (self.k - self.blend_from) * self.dt / BLEND)
        self.blended = share == 1.0
        return share

    def predict(self) -> np.ndarray:
        """(2, 3) position [m] and rate [m/s] of surge, sway, heave now (after :meth:`push`), a
        new array: one gather of the running sums at the edges into a kept buffer, one product
        (the arrays' own methods: numpy's module functions add about 0.7 µs of dispatch here)."""
        index = self.index
        np.add(self.ages, self.k - 1, index)
        self.ring.take(index, 0, self.nodes, "wrap")
        return self.node_weights.dot(self.flat_nodes).reshape(2, 3)

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"k": self.k, "ring": self.ring.tolist(), "totals": list(self.totals), "angles": list(self.angles),
                "last_channels": list(self.last_channels),
                "last_bad": self.last_bad, "batch": np.array(self.batch).tolist(),
                "batch_targets": np.array(self.batch_targets).tolist(), "normal": self.normal.tolist(),
                "moment": self.moment.tolist(), "rows": self.rows, "taught": self.taught, "fitted_at": self.fitted_at,
                "blend_from": self.blend_from, "agree_ms": self.agree_ms.tolist(),
                "agree_weight": self.agree_weight, "distrusted_until": self.distrusted_until,
                "until_row": self.until_row,
                "weights": None if self.weights is None else self.weights.tolist()}

    def set_state(self, s: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        self.reset()
        self.k, self.last_bad, self.rows = int(s["k"]), int(s["last_bad"]), float(s["rows"])
        self.taught = int(s["taught"])
        self.fitted_at = None if s["fitted_at"] is None else int(s["fitted_at"])
        self.blend_from = None if s.get("blend_from") is None else int(s["blend_from"])
        self.agree_ms = np.array(s.get("agree_ms", [0.0] * TARGETS), dtype=float)
        self.agree_weight = float(s.get("agree_weight", 0.0))
        self.distrusted_until = int(s.get("distrusted_until", 0))
        self.ring = np.array(s["ring"], dtype=float).reshape(self.n, CHANNELS)
        self.until_row = int(s["until_row"])
        self.totals = tuple(float(v) for v in s["totals"])
        self.angles = tuple(float(v) for v in s["angles"])
        self.last_channels = tuple(float(v) for v in s["last_channels"])
        self.batch = list(np.array(s["batch"], dtype=float).reshape(-1, self.features_count))
        self.batch_targets = list(np.array(s["batch_targets"], dtype=float).reshape(-1, TARGETS))
        self.normal = np.array(s["normal"], dtype=float)
        self.moment = np.array(s["moment"], dtype=float)
        if s["weights"] is not None:
            self.weights = np.array(s["weights"], dtype=float)
            self._fold()
