"""BLAS on one thread for the small matrices of the per-step estimators (threadpoolctl)."""
from __future__ import annotations

from threadpoolctl import ThreadpoolController

_BLAS: ThreadpoolController | None = None


def one_blas_thread():
    """Context manager that runs BLAS/LAPACK on one thread (threadpoolctl), restoring the
    previous setting on exit.

    Used where an estimator multiplies small dense matrices every step or block: the
    decomposition of :mod:`.reconstruction` and the covariance of :mod:`.aided_band`. The
    decomposition's matrices are small (≈ 500 × 500 SVDs, 1000 × 120 least squares), and
    OpenBLAS's thread synchronisation costs more than it gains on them: measured 2026-11-22
    on this project's 2-core machine, one hour of 100 Hz three-axis acceleration took 14.9 s
    with OpenBLAS's default two threads and 6.7 s with one (same results to 1e-12 m).
    Running (segment, axis) fits in parallel Python threads instead gained nothing (7.7 s).
    The aided coast's 60-220-state covariance products (above OpenBLAS's 64³ threading
    threshold) took 190 µs per fusion step with one thread and 430-900 µs with two while
    another process used the second core (2026-11-22)."""
    global _BLAS
    if _BLAS is None:
        _BLAS = ThreadpoolController()
    return _BLAS.limit(limits=1, user_api="blas")
