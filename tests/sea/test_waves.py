"""Wave spectra and realisations: moments, peaks, Hs of a 3-hour record, seeds, bad input."""
import math

import numpy as np
import pytest

from marinefmu.errors import ParameterError, ParameterTypeError
from marinefmu.sea.waves import SeaState, jonswap, pierson_moskowitz, realise, spectral_moment, spreading_pdf

W = np.linspace(1e-3, 30.0, 300001)


@pytest.mark.parametrize("hs,tp", [(1.0, 5.0), (2.5, 9.0), (6.0, 14.0)])
def test_pierson_moskowitz_m0_is_hs2_over_16_and_peak_at_wp(hs, tp):
    s = pierson_moskowitz(W, hs, tp)
    # closed form: m0 = Hs²/16 exactly; the tail beyond 30 rad/s is < 1e-6 of m0
    assert spectral_moment(W, s, 0) == pytest.approx(hs**2 / 16, rel=1e-5)
    assert W[np.argmax(s)] == pytest.approx(2 * math.pi / tp, abs=2e-4)


@pytest.mark.parametrize("gamma", [1.0, 2.0, 3.3, 7.0])
def test_jonswap_m0_is_hs2_over_16_for_any_gamma(gamma):
    s = jonswap(W, 3.0, 10.0, gamma)
    assert spectral_moment(W, s, 0) == pytest.approx(9.0 / 16, rel=1e-5)
    assert W[np.argmax(s)] == pytest.approx(2 * math.pi / 10.0, abs=2e-4)


def test_jonswap_with_gamma_one_is_pierson_moskowitz():
    np.testing.assert_allclose(jonswap(W, 2.0, 8.0, 1.0), pierson_moskowitz(W, 2.0, 8.0), rtol=1e-9, atol=1e-15)


def test_jonswap_mean_period_matches_dnv():
    # DNV-RP-C205 eq. 3.5.5.6: T1 = 2π m0/m1 = Tp (0.7303 + 0.04936γ − 0.006556γ² + 0.0003610γ³), accurate to ~1 %
    g, tp = 3.3, 10.0
    s = jonswap(W, 2.0, tp, g)
    t1 = 2 * math.pi * spectral_moment(W, s, 0) / spectral_moment(W, s, 1)
    assert t1 == pytest.approx(tp * (0.7303 + 0.04936 * g - 0.006556 * g**2 + 0.0003610 * g**3), rel=0.01)


def test_spreading_pdf_integrates_to_one():
    th = np.linspace(-math.pi, math.pi, 200001)
    for s in (1.0, 4.0, 15.0):
        assert np.trapezoid(spreading_pdf(th, s), th) == pytest.approx(1.0, rel=1e-8)


@pytest.mark.parametrize("spreading", [0.0, 4.0])
def test_three_hour_record_hs_within_two_percent(spreading):
    sea = SeaState(hs=2.5, tp=9.0, spreading=spreading, seed=11)
    t = np.arange(0.0, 3 * 3600.0, 0.25)
    eta = realise(sea).elevation(t)
    assert 4 * eta.std() == pytest.approx(2.5, rel=0.02)


def test_short_crested_directions_follow_the_mean_heading():
    wf = realise(SeaState(heading=1.0, spreading=4.0, n_components=2000))
    mean = math.atan2(np.sin(wf.direction).mean(), np.cos(wf.direction).mean())
    assert mean == pytest.approx(1.0, abs=0.05)
    # cos-2s with s = 4: circular std of ~0.45 rad (Longuet-Higgins): spread, not a single direction
    assert 0.3 < np.std(wf.direction - 1.0) < 0.7


def test_same_seed_same_sea_other_seed_other_sea():
    a, b, c = realise(SeaState(seed=5)), realise(SeaState(seed=5)), realise(SeaState(seed=6))
    np.testing.assert_array_equal(a.phase, b.phase)
    np.testing.assert_array_equal(a.omega, b.omega)
    assert not np.allclose(a.phase, c.phase)


def test_encounter_frequency_head_and_following_seas():
    wf = realise(SeaState(heading=math.pi))
    np.testing.assert_allclose(wf.encounter_frequency(5.0), wf.omega + wf.omega**2 / 9.80665 * 5.0, rtol=1e-12)
    wf0 = realise(SeaState(heading=0.0))
    np.testing.assert_allclose(wf0.encounter_frequency(5.0), wf0.omega - wf0.omega**2 / 9.80665 * 5.0, rtol=1e-12)


@pytest.mark.parametrize(
    "kwargs,match",
    [
        ({"hs": 0.0}, r"sea\.hs = 0\.0 is out of range: must be in \(0\.0, 30\.0\] \[m\]"),
        ({"hs": -1.0}, r"sea\.hs"),
        ({"tp": 0.0}, r"sea\.tp = 0\.0 is out of range"),
        ({"tp": -3.0}, r"sea\.tp"),
        ({"hs": float("nan")}, r"sea\.hs = nan is not finite"),
        ({"tp": float("inf")}, r"sea\.tp = inf is not finite"),
        ({"gamma": 0.5}, r"sea\.gamma"),
        ({"spectrum": "jonswapp"}, r"sea\.spectrum = 'jonswapp' is not allowed: must be one of 'jonswap', 'pierson-moskowitz'"),
        ({"spreading": 0.5}, r"sea\.spreading"),
        ({"n_components": 3}, r"sea\.components = 3 is out of range"),
        ({"omega_min": 2.0, "omega_max": 1.0}, r"sea\.omega_max = 1\.0 is out of range: must be > sea\.omega_min"),
    ],
)
def test_bad_sea_state_is_refused_with_its_name_and_range(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        SeaState(**kwargs)


def test_non_number_is_a_type_error():
    with pytest.raises(ParameterTypeError, match="sea.hs must be a real number"):
        SeaState(hs="2.5")
