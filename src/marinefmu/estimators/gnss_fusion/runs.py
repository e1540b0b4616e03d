"""Whole-record runs of the GNSS + accelerometer fusion (:mod:`.filter`, paper 001):
:func:`fuse` over arrays, with the RTS fixed-interval smoother for post-processing
(:func:`rts_smooth`), and :func:`fuse_receiver` for a data set with one receiver.

The smoother is hand-written because filterpy's ``rts_smoother`` has no control input, and
here x⁻_{k+1} = Φ x_k + G u_k.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ...errors import ShapeError
from .filter import GnssAccFusionParams, GnssAccFusion, transition


def fuse(acc: np.ndarray, dt: float, gnss: np.ndarray, gnss_new: np.ndarray, gyro: np.ndarray | None = None,
         params: GnssAccFusionParams | None = None, smooth: bool = False, gnss_valid: np.ndarray | None = None,
         euler: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Run :class:`~.filter.GnssAccFusion` over whole records, optionally with the RTS smoother.

    Parameters
    ----------
    acc : numpy.ndarray
        (N, 3) specific force [m/s², b] at t_k = (k + 1)·dt.
    dt : float
        Sample interval [s].
    gnss : numpy.ndarray
        (N, 12) antenna positions (ant1 n, e, d, ant2, …) [m], read where ``gnss_new``; with
        ``attitude="input"`` (N, 3) the receiver's (antenna 1).
    gnss_new : numpy.ndarray
        (N,) bool, True at the samples where a new epoch arrived.
    gnss_valid : numpy.ndarray, optional
        (N,) bool receiver validity (VesselMotion's ``gnss.valid``); epochs where it is False
        are not used (a receiver in dropout repeats its last fix).
    gyro : numpy.ndarray, optional
        (N, 3) angular rate [rad/s, b].
    params : GnssAccFusionParams, optional
    euler : numpy.ndarray, optional
        (N, 3) roll, pitch, yaw [rad] for ``attitude="input"`` (required then).
    smooth : bool
        Also return the RTS fixed-interval smoothed ``pos_smooth`` and ``vel_smooth``. Through
        a GNSS gap of up to ``max_coast`` s it does better than the real-time output (``make
        bench``, part ``dropout``); over a longer
        one, which ends in a re-initialisation that the smoother does not cross, and over a
        gap that ends the record, it is the real-time output (:func:`orphan_steps`).

    Returns
    -------
    dict of numpy.ndarray
        ``pos``, ``vel``, ``pos_std``, ``euler``, ``acc_n``, ``acc_bias`` (N, 3); ``valid`` (N,);
        ``fix`` (N,) str; with ``smooth``, ``pos_smooth`` and ``vel_smooth`` (N, 3).
    """
    acc = np.asarray(acc, dtype=float)
    n = len(acc)
    est = GnssAccFusion(params)
    one = est.params.attitude == "input"
    width = 3 if one else 12
    if acc.shape != (n, 3) or np.shape(gnss) != (n, width) or np.shape(gnss_new) != (n,):
        raise ShapeError(f"expected acc (N, 3), gnss (N, {width}), gnss_new (N,); got {acc.shape}, {np.shape(gnss)}, "
                         f"{np.shape(gnss_new)}")
    if one and np.shape(euler) != (n, 3):
        raise ShapeError(f"attitude = 'input': expected euler (N, 3) roll, pitch, yaw; got {np.shape(euler)}")
    out = {k: np.empty((n, 3)) for k in ("pos", "vel", "pos_std", "euler", "acc_n", "acc_bias")}
    out["valid"] = np.empty(n, dtype=bool)
    out["fix"] = np.empty(n, dtype=object)
    keep = smooth and n > 1
    nx = est.kf.dim_x
    xs = np.zeros((n, nx)) if keep else None
    ps = np.zeros((n, nx, nx)) if keep else None
    priors: list = [None] * n
    arms = np.zeros((n, 3))
    use = np.asarray(gnss_new, dtype=bool) & (True if gnss_valid is None else np.asarray(gnss_valid, dtype=bool))
    for k in range(n):
        r = est.step(acc[k], gnss[k] if use[k] else None, dt, None if gyro is None else gyro[k],
                     euler[k] if one else None)
        for key in ("pos", "vel", "pos_std", "euler", "acc_n", "acc_bias"):
            out[key][k] = getattr(r, key)
        out["valid"][k], out["fix"][k] = r.valid, r.fix
        if keep:
            xs[k], ps[k] = est.kf.x.ravel(), est.kf.P
            priors[k] = est.prior
            arms[k] = out["pos"][k] - est.kf.x.ravel()[:3] if est.initialised else 0.0
    if keep:
        f = transition(dt, est.params.bias_states)[0]
        sx, _ = rts_smooth(xs, ps, priors, f, hold=orphan_steps(priors, out["fix"] == "accepted"))
        out["pos_smooth"] = sx[:, :3] + arms
        out["vel_smooth"] = sx[:, 3:6] + (out["vel"] - xs[:, 3:6])
    return out


def fuse_receiver(f_n: np.ndarray, dt: float, pos: np.ndarray, pos_new: np.ndarray,
                  params: GnssAccFusionParams | None = None) -> dict[str, np.ndarray]:
    """The fusion filter on one GNSS receiver, with the attitude applied by the caller.

    For a data set with a single antenna (and a compass) instead of four: ``f_n`` is the
    specific force already rotated into NED by an external attitude (eqs. 25-26 done
    outside: f_n = R_nb f_b), ``pos`` the receiver's fixes of the accelerometer point. This is
    :class:`~.filter.GnssAccFusion` with ``attitude="input"`` (its module docstring, item 5)
    at zero angles, with the receiver and the accelerometer at the COG: the Kalman filter,
    gating, bias states, coasting and re-initialisation are the same code as the four-antenna
    estimator's.

    Parameters
    ----------
    f_n : numpy.ndarray
        (N, 3) specific force in NED [m/s²] at t_k = (k + 1)·dt.
    dt : float
        Sample interval [s].
    pos : numpy.ndarray
        (N, 3) receiver position of the accelerometer point, NED [m], read where ``pos_new``.
    pos_new : numpy.ndarray
        (N,) bool, True where a new fix arrived.
    params : GnssAccFusionParams, optional
        ``q``, ``q_down``, ``r``, ``gate``, ``bias_states`` … (its attitude, antenna 1 and lever
        arm are overridden as above). ``antenna_sigma_h`` and ``antenna_sigma_v`` are the
        receiver's noise, for ``pos_std``.

    Returns
    -------
    dict of numpy.ndarray
        As :func:`fuse`.
    """
    p = params or GnssAccFusionParams()
    p = replace(p, attitude="input", acc_lever_arm=(0.0, 0.0, 0.0), antennas=((0.0, 0.0, 0.0), *p.antennas[1:]))
    pos = np.asarray(pos, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ShapeError(f"expected pos (N, 3); got {pos.shape}")
    return fuse(f_n, dt, pos, pos_new, None, p, euler=np.zeros((len(pos), 3)))


def orphan_steps(priors: list, accepted: np.ndarray) -> np.ndarray:
    """(N,) bool: the steps after which the filter restarts (``priors`` None) before it takes
    another fix (``accepted``), or the record ends; the smoother has no later fix for them.

    Why: such a stretch is a GNSS gap that ended in a re-initialisation (longer than
    ``max_coast``) or ends the record, bridged by the wave coast's pseudo-fixes. There the
    filter's bias states follow g × the drifting tilt of its gyro-propagated attitude, far
    beyond their random walk, and the smoother, which takes the bias as nearly constant, would
    spread the late value back over the whole gap and before it, worse than the real-time
    output (docs/decisions/gnss-fusion-filter.md). :func:`fuse` keeps the filtered state over these steps (``hold`` of
    :func:`rts_smooth`). A step counts from the last fix before the restart on, since nothing
    after that fix reaches it.

    Examples
    --------
    >>> orphan_steps([None, 1, 1, 1, 1, None, 1], np.array([1, 0, 1, 0, 0, 1, 0], bool)).tolist()
    [False, False, True, True, True, True, True]
    """
    n = len(priors)
    accepted = np.asarray(accepted, dtype=bool)
    restart = np.array([k > 0 and pr is None for k, pr in enumerate(priors)] + [True])
    # index of the next restart (n: the end) and of the next accepted fix after each step
    idx = np.arange(n + 1)
    next_restart = np.minimum.accumulate(np.where(restart, idx, n + 1)[::-1])[::-1][1:]
    acc = np.append(accepted, False)
    next_fix = np.minimum.accumulate(np.where(acc, idx, n + 1)[::-1])[::-1][1:]
    return next_restart <= next_fix


def rts_smooth(xs: np.ndarray, ps: np.ndarray, priors: list, f: np.ndarray,
               hold: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Rauch–Tung–Striebel fixed-interval smoothing of a filtered run with a control input.

    ``xs``/``ps`` are the filtered x_k, P_k; ``priors[k]`` the (x⁻_k, P⁻_k) predicted into
    step k (None where the filter started or restarted: the recursion does not cross those).
    x^s_k = x_k + C_k (x^s_{k+1} − x⁻_{k+1}), C_k = P_k Φᵀ (P⁻_{k+1})⁻¹. Steps where ``hold``
    (N,) is True keep the filtered state, and the step before them smooths from it.
    """
    sx, sp = xs.copy(), ps.copy()
    for k in range(len(xs) - 2, -1, -1):
        prior = priors[k + 1]
        if prior is None or (hold is not None and hold[k]):
            continue
        xp, pp = prior[0].ravel(), prior[1]
        c = np.linalg.solve(pp.T, (ps[k] @ f.T).T).T
        sx[k] = xs[k] + c @ (sx[k + 1] - xp)
        sp[k] = ps[k] + c @ (sp[k + 1] - pp) @ c.T
    return sx, sp
