"""Where a screened reconstruction's error comes from: the motion its band leaves out, the
accelerometer's errors and the attitude's errors, each as the displacement it puts into the
band (beyond the papers; what :mod:`marinefmu.bench.defaults_reconstruction` measures, taken
apart).

Paper 000's reconstruction keeps the components of the tilt-corrected acceleration between the
screening frequency F (eq. 25) and the decimation's fmax and integrates them exactly (eqs.
26-31); the COG transfer (eq. 32) subtracts R_nb l. Its ideal counterpart is a band-pass double
integration of the same acceleration, non-causal, over the whole record:

    x̂_COG = F⁻¹[ (A(f) / (−(2πf)²) − L(f)) ] on F ≤ f ≤ fmax,
    A = F[ R̂_nb f_b + g ],   L = F[ R̂_nb l ],

(:func:`band_estimate`). Run three times, with the true specific force and attitude, with the
measured specific force and the true attitude, and with the measured specific force and the
attitude the reconstructor is fed, its differences split the ideal reconstruction's error
exactly into (:func:`band_budget`):

* ``screen``: the motion outside [F, fmax], which the band removes whatever the sensors;
* ``sensor``: the accelerometer's noise and bias, double-integrated in the band;
* ``attitude``: (R̂ − R) f_b ≈ g·ε horizontally for a tilt error ε, double-integrated in the
  band (g ε / (2πf)² per component at frequency f: 0.013° at 0.03 Hz is 6 cm), and
  (R̂ − R) l at the lever arm.

It is a budget, not a bound. The ``attitude`` term is slow and coherent, like the motion, and
a reconstruction cannot tell it from motion in the band (a test checks the
DisplacementReconstructor does not beat it on a sinusoidal tilt error); the ``sensor`` term is
broadband, and a fit with few components rejects part of it, so the measured error can lie
below ``ideal`` where the sensor term dominates.

The band-pass is the frequency-domain integration of paper 001 (eqs. 7-12,
:func:`~marinefmu.estimators.numerics.integrate_frequency`), on a record tapered to zero at its
ends outside the scored span (:func:`edge_taper`: without it the step between the record's ends
leaks into the band's lowest bins, where 1/(2πf)² weighs it most: 2.9 % of a motion entirely
in the band on a 550 s test record, 0.10 % with it). The score is that of
:mod:`marinefmu.bench.defaults_reconstruction`: over the span, each series about its mean, RMS
in % of the true COG motion's standard deviation per NED axis.

Frames: NED, FRD body, ZYX Euler angles [rad].
"""
from __future__ import annotations

import numpy as np

from ..errors import ShapeError, check_range, check_vector
from ..estimators.numerics import integrate_frequency
from ..estimators.reconstruction.decomposition import rotations, tilt_correct


def edge_taper(n: int, k0: int, k1: int) -> np.ndarray:
    """(n,) weights: 1 over the samples [k0 − g0/2, k1 + g1/2), g0 = k0 and g1 = n − k1 the
    gaps to the record's ends, and half-cosine ramps to 0 over the outer half of each gap."""
    w = np.ones(n)
    r0, r1 = k0 // 2, (n - k1) // 2
    if r0 > 0:
        w[:r0] = 0.5 - 0.5 * np.cos(np.pi * np.arange(r0) / r0)
    if r1 > 0:
        w[n - r1:] = (0.5 - 0.5 * np.cos(np.pi * np.arange(r1) / r1))[::-1]
    return w


def band_estimate(f_b: np.ndarray, euler: np.ndarray, dt: float, cutoff: float, fmax: float,
                  span: tuple[int, int], lever_arm: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
    """The ideal reconstruction of the COG screened to [``cutoff``, ``fmax``] (module docstring).

    Parameters
    ----------
    f_b : numpy.ndarray
        (N, 3) specific force at the IMU [m/s², body frame].
    euler : numpy.ndarray
        (N, 3) roll, pitch, yaw [rad], of the same length.
    dt : float
        Sample interval [s], > 0.
    cutoff, fmax : float
        The band kept [Hz], 0 < cutoff < fmax ≤ Nyquist.
    span : (int, int)
        Samples [k0, k1) that will be scored, inside the record: the taper leaves them whole.
        Keep them a few 1/cutoff from the record's ends.
    lever_arm : tuple of float
        IMU position relative to the COG, body frame [m].

    Returns
    -------
    numpy.ndarray
        (N, 3) COG displacement [m, NED], zero-mean in the band.
    """
    f_b, euler = np.asarray(f_b, dtype=float), np.asarray(euler, dtype=float)
    if not (f_b.ndim == 2 and f_b.shape[1] == 3 and euler.shape == f_b.shape):
        raise ShapeError(f"f_b and euler must be (N, 3) of one length, got {f_b.shape} and {euler.shape}")
    check_range("dt", dt, lo=0.0, lo_open=True, unit="s")
    check_range("cutoff", cutoff, lo=0.0, lo_open=True, unit="Hz")
    check_range("fmax", fmax, lo=cutoff, hi=0.5 / dt, lo_open=True, unit="Hz")
    check_vector("lever_arm", lever_arm, unit="m")
    k0, k1 = int(span[0]), int(span[1])
    if not 0 <= k0 < k1 <= len(f_b):
        raise ShapeError(f"span must lie in [0, {len(f_b)}] with span[0] < span[1], got {span}")
    taper = edge_taper(len(f_b), k0, k1)[:, None]
    arm = np.einsum("nij,j->ni", rotations(euler[:, 0], euler[:, 1], euler[:, 2]), np.asarray(lever_arm, float))
    _, disp = integrate_frequency(tilt_correct(f_b, euler) * taper, dt, band=(cutoff, fmax))
    # the arm band-passed alike: x = ∫∫a − R l, so a band-limited x needs a band-limited R l
    # (and a yaw that drifts, as a gyro-integrated one does, moves R l below the band)
    arm_band = np.fft.irfft(np.fft.rfft((arm - arm.mean(axis=0)) * taper, axis=0)
                            * _band_mask(len(f_b), dt, cutoff, fmax)[:, None], n=len(f_b), axis=0)
    return disp - arm_band


def _band_mask(n: int, dt: float, lo: float, hi: float) -> np.ndarray:
    """The bins of an n-point rfft that :func:`integrate_frequency` keeps for band (lo, hi)."""
    f = np.fft.rfftfreq(n, dt)
    return ((f >= lo - 1e-12) & (f <= hi + 1e-12) & (f > 0)).astype(float)


def _rms_pct(x: np.ndarray, truth: np.ndarray) -> list[float]:
    x = x - x.mean(axis=0)
    return (100.0 * np.sqrt(np.mean(x ** 2, axis=0)) / truth.std(axis=0)).tolist()


def band_budget(f_b: np.ndarray, f_true: np.ndarray, euler: np.ndarray, euler_true: np.ndarray, cog: np.ndarray,
                dt: float, cutoff: float, fmax: float, span: tuple[int, int],
                lever_arm: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> dict[str, list[float]]:
    """The ideal reconstruction's error over ``span`` and its three sources (module docstring).

    Parameters
    ----------
    f_b, f_true : numpy.ndarray
        (N, 3) measured and error-free specific force at the IMU [m/s², body frame].
    euler, euler_true : numpy.ndarray
        (N, 3) the attitude the reconstruction is fed and the true one [rad].
    cog : numpy.ndarray
        (N, 3) true COG position [m, NED].
    dt, cutoff, fmax, span, lever_arm
        As :func:`band_estimate`.

    Returns
    -------
    dict
        ``ideal``, ``screen``, ``sensor``, ``attitude``: [n, e, d] RMS over the span in % of the
        true COG motion's std; ``ideal`` is the error of the band-pass fed ``f_b`` and ``euler``;
        the other three are the differences that make it up (their squares need not add: the
        sources are not uncorrelated in a finite record).
    """
    cog = np.asarray(cog, dtype=float)
    if cog.shape != np.shape(f_b):
        raise ShapeError(f"cog must have the shape of f_b {np.shape(f_b)}, got {cog.shape}")
    clean, measured, fed = (band_estimate(f, e, dt, cutoff, fmax, span, lever_arm)
                            for f, e in ((f_true, euler_true), (f_b, euler_true), (f_b, euler)))
    s = slice(int(span[0]), int(span[1]))
    truth = cog[s]
    return {"ideal": _rms_pct(fed[s] - truth, truth), "screen": _rms_pct(clean[s] - truth, truth),
            "sensor": _rms_pct(measured[s] - clean[s], truth), "attitude": _rms_pct(fed[s] - measured[s], truth)}
