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
the pending times are frozen at their estimates so far (:meth:`FixedLagOutputs.set_model`): the
first innovations of a new model are not consistent with the old one's covariances, and
propagating them through the change (exact only for a consistent model) corrupts the delayed
heave by decimetres (seen in tests with the paper's measurement model).

Why not filterpy: ``filterpy.kalman.FixedLagSmoother`` keeps every smoothed state ever computed
(memory grows without bound, filterpy issue #274), costs O(lag·n³) per step, and assumes a
fixed state dimension, while the observer's modes change. A test shows this module equals the
filterpy RTS smoother run on the data up to k, at s = k − lag.

**Steady-state shortcut.** The observer runs a steady-state filter: while every step is a
measured one, Φ_i is the same closed-loop matrix F = A(I − KC) and every row block starts as
W₀ = c P⁻, so a time pushed j steps ago has W = W₀ (Fᵀ)^j. :meth:`FixedLagOutputs.set_model`
tabulates W₀ (Fᵀ)^j and its correction gains W C ᵀ for j = 0 … lag once per model, and each
step then costs O(lag·n_out) instead of O(lag·n_out·n²) (for the default 5 s lag at 100 Hz
and 72 states, a few µs per step instead of hundreds). A coasted step (Φ = A) turns the pending rows
explicit (from the table) and propagates them exactly; lag + 1 measured steps later every
pending time is again of the tabulated form and the rows return to the table.
"""
from __future__ import annotations

import numpy as np


class FixedLagOutputs:
    """Fixed-lag smoother of ``n_out`` linear outputs over ``lag`` steps of a steady-state
    Kalman filter (module docstring).

    Each step: :meth:`push` the prior, :meth:`correct` with the innovation (measured steps),
    :meth:`pop` the output ``lag`` steps back, :meth:`propagate`.

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
        self.out_rows: np.ndarray | None = None     # (n_out, n) output rows c
        self.phi: np.ndarray | None = None          # (n, n) closed-loop F of the steady filter
        self.c: np.ndarray | None = None            # (n,) measurement row C
        self.s = 1.0                                # innovation variance S
        self.table: np.ndarray | None = None        # (lag + 1, n_out, n): W₀ (Fᵀ)^j
        self.gain: np.ndarray | None = None         # (lag + 1, n_out): W₀ (Fᵀ)^j Cᵀ
        self.reset()

    def reset(self) -> None:
        """Forget all pending times (the model is kept)."""
        size = self.lag + 1
        self.est = np.zeros((size, self.n_out))
        self.aux = np.zeros((size, self.n_aux))
        self.valid = np.zeros(size, dtype=bool)          # slot holds a pending time
        self.live = np.zeros(size, dtype=bool)           # … that is still corrected
        self.head = 0                                    # slot of the newest time
        self.rows: np.ndarray | None = None              # explicit (size, n_out, n) rows, or None: the table
        self.steady = 0                                  # measured steps since the last coasted one

    def set_model(self, rows: np.ndarray, cov: np.ndarray, phi: np.ndarray, c: np.ndarray, s: float) -> None:
        """Use a new steady-state filter: output rows c (n_out, n), prior covariance P⁻ (n, n),
        closed-loop Φ = A(I − KC) (n, n), measurement row C (n,) and innovation variance S.

        Pending times are frozen at their estimates so far: innovations of a new model, large
        while it settles, must not rewrite the estimates of the old one (module docstring)."""
        self.out_rows, self.phi, self.c, self.s = np.asarray(rows), np.asarray(phi), np.asarray(c), float(s)
        table = np.empty((self.lag + 1, self.n_out, len(self.c)))
        table[0] = self.out_rows @ cov
        for j in range(1, self.lag + 1):
            table[j] = table[j - 1] @ self.phi.T
        self.table, self.gain = table, table @ self.c
        self.live[:] = False
        self.rows, self.steady = None, 0

    def _ages(self) -> np.ndarray:
        return (self.head - np.arange(self.lag + 1)) % (self.lag + 1)

    def push(self, prior: np.ndarray, aux: np.ndarray | None = None) -> None:
        """Start smoothing the current time from its prior state x̂_{k|k−1} (n,) (the oldest
        pending time, if ``lag`` + 1 are pending, must have been taken by :meth:`pop`);
        ``aux`` (n_aux,) is returned with its output."""
        self.head = (self.head + 1) % (self.lag + 1)
        self.est[self.head] = self.out_rows @ prior
        self.aux[self.head] = 0.0 if aux is None else aux
        self.valid[self.head] = self.live[self.head] = True
        if self.rows is not None:
            self.rows[self.head] = self.table[0]

    def correct(self, innovation: float) -> None:
        """Apply the innovation ε_k of this step's measurement to every pending time."""
        if self.rows is None:
            self.est += self.gain[self._ages()] * (self.live[:, None] * (innovation / self.s))
        else:
            self.est += (self.rows @ self.c) * (innovation / self.s)

    def propagate(self, phi: np.ndarray | None = None) -> None:
        """Advance the pending rows by one step of the prior error: W ← W Φᵀ, with the steady
        closed loop (``phi`` None: a measured step) or the given Φ (a coasted step, Φ = A)."""
        if phi is None:
            self.steady += 1
            if self.rows is not None:
                self.rows = self.rows @ self.phi.T
                if self.steady > self.lag:   # every pending time was pushed after the coast
                    self.rows = None
            return
        if self.rows is None:
            self.rows = self.table[self._ages()] * self.live[:, None, None]
        self.rows = self.rows @ np.asarray(phi).T
        self.steady = 0

    def pop(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The output ``lag`` steps back and its aux values, once that many steps were seen."""
        oldest = (self.head + 1) % (self.lag + 1)
        if not self.valid[oldest]:
            return None
        self.valid[oldest] = self.live[oldest] = False
        if self.rows is not None:
            self.rows[oldest] = 0.0
        return self.est[oldest].copy(), self.aux[oldest].copy()

    def get_state(self) -> dict:
        """JSON-serialisable state (the model is not in it: :meth:`set_model` first, then
        :meth:`set_state`)."""
        return {"rows": None if self.rows is None else self.rows.tolist(), "est": self.est.tolist(),
                "aux": self.aux.tolist(), "valid": self.valid.tolist(), "live": self.live.tolist(),
                "head": self.head, "steady": self.steady}

    def set_state(self, s: dict) -> None:
        """Restore from :meth:`get_state` (after :meth:`set_model` with the same model)."""
        self.rows = None if s["rows"] is None else np.array(s["rows"], dtype=float).reshape(self.lag + 1, self.n_out, -1)
        self.est = np.array(s["est"], dtype=float).reshape(self.lag + 1, self.n_out)
        self.aux = np.array(s["aux"], dtype=float).reshape(self.lag + 1, self.n_aux)
        self.valid = np.array(s["valid"], dtype=bool)
        self.live = np.array(s["live"], dtype=bool)
        self.head, self.steady = int(s["head"]), int(s["steady"])
