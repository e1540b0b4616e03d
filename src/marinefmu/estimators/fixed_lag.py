"""Fixed-lag smoothing of linear outputs c x of a Kalman filter (the delayed heave of paper
003's observer, like the "delayed heave" of commercial motion reference units).

For the filter's prior error e⁻_k = x_k − x̂_{k|k−1} and innovation ε_k = y_k − C_k x̂_{k|k−1}
(variance S_k), the estimate of an earlier state x_s improves with each new innovation:

.. math::
    \\hat x_{s|k} = \\hat x_{s|k-1} + \\mathrm{Cov}(e^-_s, e^-_k)\\, C_k^T S_k^{-1} ε_k,\\qquad
    \\mathrm{Cov}(e^-_s, e^-_k) = P^-_s Φ_s^T \\cdots Φ_{k-1}^T,\\quad Φ_i = A_{i+1}(I − K_i C_i)

(Simon, *Optimal State Estimation*, 2006, section 9.2, in its innovation form). Only a few
output rows c_s are needed (heave, heave rate), so each pending time s carries the row block
W = c_s Cov(e⁻_s, e⁻_k) instead of a full covariance: O(lag·n²) per step, constant memory.
A coasted step (no measurement) has K = 0. When the model changes (the observer's mode set),
the pending times are frozen at their estimates so far (:meth:`FixedLagOutputs.freeze`): the
first innovations of a new model are not consistent with the old one's covariances, and
propagating them through the change (exact only for a consistent model) corrupted the delayed
heave by decimetres in tests with the paper's measurement model.

Why not filterpy: ``filterpy.kalman.FixedLagSmoother`` keeps every smoothed state ever computed
(memory grows without bound, filterpy issue #274), costs O(lag·n³) per step, and assumes a
fixed state dimension, while the observer's modes change. A test shows this module equals the
filterpy RTS smoother run on the data up to k, at s = k − lag.
"""
from __future__ import annotations

import numpy as np


class FixedLagOutputs:
    """Fixed-lag smoother of ``n_out`` linear outputs over ``lag`` steps.

    Parameters
    ----------
    lag : int
        Lag in steps (≥ 0; 0 gives the filtered output).
    n_out : int
        Number of output rows.
    n_aux : int
        Width of auxiliary values stored with each time and returned with its output (e.g.
        the angles needed to transfer the delayed heave to a point).
    """

    def __init__(self, lag: int, n_out: int, n_aux: int = 0) -> None:
        self.lag, self.n_out, self.n_aux = lag, n_out, n_aux
        self.reset()

    def reset(self) -> None:
        """Forget all pending times."""
        size = self.lag + 1
        self.rows: np.ndarray | None = None              # (size, n_out, n), ring buffer
        self.est = np.zeros((size, self.n_out))
        self.aux = np.zeros((size, self.n_aux))
        self.valid = np.zeros(size, dtype=bool)          # slot holds a pending time
        self.head = 0                                    # slot of the newest time

    def propagate(self, phi: np.ndarray) -> None:
        """Advance the pending rows by one step of the prior error: W ← W Φᵀ (Φ may change n)."""
        if self.rows is not None:
            self.rows = self.rows @ phi.T

    def freeze(self, n: int) -> None:
        """Stop correcting the pending times (they keep their estimates so far) and expect
        states of dimension ``n`` from now on. Used when the model changes: innovations of the
        new model, large while it settles, must not rewrite the estimates of the old one."""
        self.rows = np.zeros((self.lag + 1, self.n_out, n))

    def push(self, rows: np.ndarray, prior: np.ndarray, cov: np.ndarray, aux: np.ndarray | None = None) -> None:
        """Start smoothing the current time (the oldest pending time, if ``lag`` + 1 are
        pending, must have been taken by :meth:`pop`).

        Parameters
        ----------
        rows : numpy.ndarray
            (n_out, n) output rows c.
        prior : numpy.ndarray
            (n,) prior state x̂_{k|k−1}.
        cov : numpy.ndarray
            (n, n) prior covariance P⁻_k.
        aux : numpy.ndarray, optional
            (n_aux,) values to return with this time's output.
        """
        n = len(prior)
        if self.rows is None or self.rows.shape[2] != n:
            self.rows = np.zeros((self.lag + 1, self.n_out, n))
        self.head = (self.head + 1) % (self.lag + 1)
        self.rows[self.head] = rows @ cov
        self.est[self.head] = rows @ prior
        self.aux[self.head] = 0.0 if aux is None else aux
        self.valid[self.head] = True

    def correct(self, c: np.ndarray, innovation: float, s: float) -> None:
        """Apply the innovation ε_k (variance S_k) of the measurement row C_k to every pending time."""
        self.est += (self.rows @ c) * (innovation / s)

    def pop(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The output ``lag`` steps back and its aux values, once that many steps were seen."""
        oldest = (self.head + 1) % (self.lag + 1)
        if not self.valid[oldest]:
            return None
        self.valid[oldest] = False
        return self.est[oldest].copy(), self.aux[oldest].copy()

    def get_state(self) -> dict:
        """JSON-serialisable state."""
        return {"rows": None if self.rows is None else self.rows.tolist(), "est": self.est.tolist(),
                "aux": self.aux.tolist(), "valid": self.valid.tolist(), "head": self.head}

    def set_state(self, s: dict) -> None:
        """Restore from :meth:`get_state`."""
        self.rows = None if s["rows"] is None else np.array(s["rows"], dtype=float).reshape(self.lag + 1, self.n_out, -1)
        self.est = np.array(s["est"], dtype=float).reshape(self.lag + 1, self.n_out)
        self.aux = np.array(s["aux"], dtype=float).reshape(self.lag + 1, self.n_aux)
        self.valid = np.array(s["valid"], dtype=bool)
        self.head = int(s["head"])
