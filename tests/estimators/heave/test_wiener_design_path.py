"""The Wiener design's fast path (the correlation sums by one inverse FFT on the folded
frequency grid, the block mean's response in closed form) against the straightforward
(K, L) tables of cosines and sines and the direct mean of exponentials."""
import math

import numpy as np
import pytest
from scipy.linalg import solve_toeplitz

from marinefmu.estimators.heave.wiener import block_mean_response, correlation_sums, wiener_taps


def table_sums(coef, w, taps, spacing):
    wt = np.outer(w, np.arange(taps) * spacing)
    return coef @ np.cos(wt) + 1j * (coef @ np.sin(wt))


def table_taps(omega, heave_density, dt, block, taps, lag, acc_noise, offset_noise, unwanted):
    """wiener_taps with its sums written as the tables of its docstring's equations."""
    memory = taps * block * dt
    top = float(np.max(omega[heave_density > 0.0], initial=omega[0]))
    top = max(top, min(float(np.max(omega[unwanted > 0.0], initial=omega[0])), 2.0 * math.pi / (block * dt)))
    d_omega = min(omega[1] - omega[0], math.pi / (2.0 * memory))
    w = np.arange(omega[0], top + d_omega, d_omega)
    s_z, extra = np.interp(w, omega, heave_density), np.interp(w, omega, unwanted)
    mean_response = np.exp(-1j * np.outer(w, np.arange(block) * dt)).mean(axis=1)
    b = -(w**2) * mean_response
    wt = np.outer(w, np.arange(taps) * block * dt)
    cos_wt, sin_wt = np.cos(wt), np.sin(wt)
    auto = (np.abs(mean_response) ** 2 * (s_z * w**4 + extra + offset_noise**2 / (math.pi * w**2)) * d_omega) @ cos_wt
    auto[0] += acc_noise**2 / (block * dt)
    cross = []
    for delay in (0.0, lag):
        beta = w * delay + np.angle(b)
        for weight, shift in ((s_z * np.abs(b) * d_omega, 0.0), (s_z * w * np.abs(b) * d_omega, 0.5 * math.pi)):
            cross.append((weight * np.cos(beta - shift)) @ cos_wt + (weight * np.sin(beta - shift)) @ sin_wt)
    solved = solve_toeplitz(auto, np.column_stack([*cross, np.ones(taps)]))
    weights, ones = solved[:, :4], solved[:, 4]
    weights -= np.outer(ones, weights.sum(axis=0) / ones.sum())
    return weights.T


@pytest.mark.parametrize("w0,d_omega,k,taps,spacing", [
    (2 * math.pi / 120.0, math.pi / (2 * 180.0), 1800, 450, 0.4),       # Δω = π/(2·memory): N = 4L
    (2 * math.pi / 900.0, 2 * math.pi / 900.0, 2400, 450, 0.4),        # the window's bin: p = M, N = n
    (0.0123, 0.00777, 700, 200, 0.4),                                   # any other grid: the table
])
def test_the_folded_sums_equal_the_tables(w0, d_omega, k, taps, spacing):
    rng = np.random.default_rng(5)
    w = np.arange(k) * d_omega + w0
    coef = rng.normal(size=(3, k)) + 1j * rng.normal(size=(3, k))
    got = correlation_sums(coef, w, taps, spacing)
    want = table_sums(coef, w, taps, spacing)
    scale = np.abs(coef).sum(axis=1, keepdims=True)
    assert np.max(np.abs(got - want) / scale) < 1e-13


def test_the_closed_form_block_mean_equals_the_mean_of_exponentials():
    w = np.linspace(1e-4, 2 * math.pi / 0.4, 3001)
    direct = np.exp(-1j * np.outer(w, np.arange(40) * 0.01)).mean(axis=1)
    np.testing.assert_allclose(block_mean_response(w, 40, 0.01), direct, rtol=0.0, atol=1e-15)


def test_the_taps_equal_the_table_design():
    """A two-peaked sea with noise and short waves above omega_max: the taps equal those of the
    table design to the rounding that the Toeplitz solve amplifies in either (1e-8 of the
    largest tap; the two differ by ~1e-10 on the system scenario's designs)."""
    n, dt = 60000, 0.01
    omega = 2 * math.pi * np.arange(1, n // 2 + 1) / (n * dt)
    sea = 0.5 * np.exp(-((omega - 0.7) / 0.08) ** 2) + 0.1 * np.exp(-((omega - 1.4) / 0.2) ** 2)
    sea[(omega < 0.25) | (omega > 6.0)] = 0.0
    unwanted = np.where(omega > 6.0, 1e-4 * np.exp(-(omega - 6.0)), 0.0)
    for taps in (300, 450):
        args = (omega, sea, dt, 40, taps, 5.0, 7e-4, 1e-4, unwanted)
        got, want = wiener_taps(*args), table_taps(*args)
        assert got.shape == (4, taps)
        assert np.max(np.abs(got - want)) < 1e-8 * np.max(np.abs(want))
