"""Heave compensation closed around the estimators in co-simulation: the built-in scenario
``ahc`` (VesselMotion → AttitudeEstimator → HeaveObserver → AhcController → AhcWinch, beside the
truth-fed, classical-fed and uncompensated winches) against the project's goals
(docs/heave_compensation.md), the design loop (identify, tune, verify, write), and the same
system under FMPy, in-process and OSP libcosim."""
import tomllib
from dataclasses import replace

import numpy as np
import pytest
from tests.conftest import LibcosimBeside

from marinefmu.ahc.winch import AhcWinchParams
from marinefmu.ahc.design import design, fit_feedforward, identify_response, predicted_residual
from marinefmu.ahc.loop import find_loop, subsystem, write_gains
from marinefmu.errors import ParameterError
from marinefmu.cosim.scenarios import load_scenario

DT = 0.01


def _sea(seconds=1200.0, seed=4):
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, seconds, DT)
    w = rng.uniform(0.45, 1.0, 40)
    amp, ph = rng.rayleigh(0.15, 40), rng.uniform(0, 2 * np.pi, 40)
    x = (amp[:, None] * np.sin(w[:, None] * t + ph[:, None])).sum(0)
    v = (amp[:, None] * w[:, None] * np.cos(w[:, None] * t + ph[:, None])).sum(0)
    return t, x, v, w, amp, ph


def test_identification_recovers_a_known_estimator():
    """An estimate 1.02 × the truth 50 ms late with white noise, and a rate 0.98 × the true
    rate, on time: the fitted models are those numbers (tolerances: Welch's bias over 100 s
    segments, measured ≤ 1e-4 in gain and 0.3 ms in delay)."""
    t, x, v, w, amp, ph = _sea()
    rng = np.random.default_rng(5)
    late = (amp[:, None] * np.sin(w[:, None] * (t - 0.05) + ph[:, None])).sum(0)
    r = identify_response(x, 1.02 * late + 0.01 * rng.standard_normal(len(t)), 0.98 * v, DT)
    assert r.heave_model[0] == pytest.approx(1.02, abs=2e-3) and r.heave_model[1] == pytest.approx(0.05, abs=1e-3)
    assert r.rate_model[0] == pytest.approx(0.98, abs=2e-3) and abs(r.rate_model[1]) < 1e-3
    band = r.band()
    assert np.all(r.coherence[band] > 0.9) and np.all(r.rate_noise[band] < 1e-3 * r.spectrum[band] * r.omega[band] ** 2)
    # the white noise found again (without the delay, whose window bias leaves ~1e-5 of S_xx):
    # one-sided 2σ²Δt per Hz, /2π per rad/s (Welch scatter ±30 %)
    r = identify_response(x, 1.02 * x + 0.01 * rng.standard_normal(len(t)), 0.98 * v, DT)
    np.testing.assert_allclose(np.mean(r.heave_noise[band]), 2 * 0.01 ** 2 * DT / (2 * np.pi), rtol=0.3)
    with pytest.raises(ParameterError, match="NaN"):
        identify_response(np.append(x[:-1], np.nan), x, v, DT)
    with pytest.raises(ParameterError, match=r"segment = 100\.0 is out of range"):
        identify_response(x[:10000], x[:10000], v[:10000], DT)


def test_the_fitted_feedforward_gain_is_the_best_one():
    """fit_feedforward's closed form is the minimum of predicted_residual: a step of ±0.01 in
    k_ff either way predicts more residual (for an estimator that overestimates by 2 %)."""
    t, x, v, *_ = _sea()
    r = identify_response(x, 1.02 * x, 1.02 * v, DT)
    winch = AhcWinchParams(max_speed=3.0, max_acc=3.0)
    best = fit_feedforward(r, winch, design(winch).controller, DT)
    truth = fit_feedforward(identify_response(x, x, v, DT), winch, design(winch).controller, DT)
    assert best.k_ff == pytest.approx(truth.k_ff / 1.02, rel=1e-3)   # the loop's own optimum (0.985), scaled
    at = predicted_residual(r, winch, best, DT)
    for dk in (-0.01, 0.01):
        assert predicted_residual(r, winch, replace(best, k_ff=best.k_ff + dk), DT) > at


def test_gains_are_written_into_the_scenario_file_keeping_the_rest(tmp_path):
    from importlib import resources

    path = tmp_path / "ahc.toml"
    path.write_text(resources.files("marinefmu").joinpath("data/scenarios/ahc.toml").read_text(encoding="utf-8"))
    before = path.read_text()
    write_gains(path, "ctrl_observer", {"k_p": 3.5, "k_ff": 0.97})
    write_gains(path, "winch_none", {"mass": 5000.0})                 # a new key in an existing table
    text = path.read_text()
    comments = [ln for ln in before.splitlines() if ln.lstrip().startswith("#")]
    assert comments == [ln for ln in text.splitlines() if ln.lstrip().startswith("#")]
    sc = load_scenario(path)
    assert sc.system.component("ctrl_observer").parameters["k_p"] == 3.5
    assert sc.system.component("ctrl_observer").parameters["k_ff"] == 0.97
    assert sc.system.component("ctrl_ideal").parameters == load_scenario("ahc").system.component("ctrl_ideal").parameters
    assert sc.system.component("winch_none").parameters["mass"] == 5000.0
    with pytest.raises(ParameterError, match=r"no \[components.nope\] table"):
        write_gains(path, "nope", {"k_p": 1.0})


def test_a_loop_with_a_missing_piece_is_refused_by_name():
    system = load_scenario("ahc").system
    parts = find_loop(system, "ctrl_observer")
    assert (parts.estimator, parts.winch, parts.tip) == ("heave", "winch_observer", "vessel.truth.point.d")
    with pytest.raises(ParameterError, match="'att' is not an AhcController .* ctrl_ideal, ctrl_classic, ctrl_observer"):
        find_loop(system, "att")
    cut = replace(system, connections=tuple(c for c in system.connections if c.end_var != "heave_rate"))
    with pytest.raises(ParameterError, match="heave_rate input is not connected"):
        find_loop(cut, "ctrl_observer")
    assert {c.name for c in subsystem(system, {"vessel", "att", "heave"}).components} == {"vessel", "att", "heave"}


#: The four-way run of the test: the scenario's 418 s start-up and 10 of its 31 scored minutes
#: (the bench's part ahc runs all 38 minutes and reports the residuals and limit times).
FOUR_WAYS_S = 1020.0


@pytest.mark.fmu
def test_four_ways_to_drive_the_winch_against_the_goals(fmu_dir):
    """The built-in scenario ``ahc`` at Hs 3 m, Tp 9 s under the FMPy runner, its first 17 min
    (10 scored). Measured: the load's heave (periods < 31 s) is 100.5 % of the tip's with no
    compensation, 1.03 % fed the truth, 4.50 % fed the classical filter (at its best cutoff),
    1.28 % fed our observer; over all frequencies the observer-fed load moves 2.11 % (the
    AttitudeEstimator's slow error times the 45 m lever arm). The linear model of the design
    predicts the two loops from this run's identified observer to 15 % (predicted 1.27 % and
    1.03 %). Over the whole 38 min (31 scored): 100.5, 1.02, 4.63, 1.15 and 1.97 %, predicted
    1.16 and 1.03 %. The first 10 scored minutes are harder on the observer (its spectrum window
    still growing: 1.24 × the ideal against 1.12 over 31 min; 1.23 and 1.15 with sea and sensor
    seed 2), so each goal below holds with room over the shorter run too: the nearest, the
    observer at ≤ 1.5 × the ideal, by 17 %."""
    from marinefmu.cosim.system import SystemRunner
    from marinefmu.analysis.scoring import score

    sc = load_scenario("ahc")
    r = SystemRunner(sc.system, fmu_dir).run(FOUR_WAYS_S, record=sc.record, progress=False)
    s = score(r, sc.system, "vessel")
    none, ideal, classic, obs = (s[f"winch_{n}"] for n in ("none", "ideal", "classic", "observer"))
    assert obs["scored_s"] >= 600.0
    assert 99.0 < none["residual_pct"] < 102.0                        # the wire alone: the load follows the tip
    assert obs["residual_pct"] <= 5.0                                 # goal: ≤ 5 % of the tip's heave
    assert obs["vs_ideal"] <= 1.5 and obs["vs_ideal"] == obs["residual_pct"] / ideal["residual_pct"]   # goal
    assert obs["vs_classical"] < 1.0 and classic["residual_pct"] > 2 * obs["residual_pct"]            # goal
    assert all(w["limited_pct"] <= 1.0 for w in (ideal, classic, obs))                                # goal
    assert obs["residual_total_pct"] <= 5.0                           # all frequencies too (measured 2.11 %)

    # the design's model against this run: predicted from the identified observer, both loops
    m = r["time"] >= 420.0
    resp = identify_response(r["vessel.truth.point.d"][m], r["heave.point.heave"][m], r["heave.point.heave_rate"][m], DT)
    comps = {c.name: c for c in sc.system.components}
    from marinefmu.fmu.tables import controller_params, winch_params

    winch, ctrl = winch_params(comps["winch_observer"].parameters), controller_params(comps["ctrl_observer"].parameters)
    assert 100 * predicted_residual(resp, winch, ctrl, DT) == pytest.approx(obs["residual_pct"], rel=0.15)
    assert 100 * predicted_residual(resp, winch, ctrl, DT, estimator=False) == pytest.approx(ideal["residual_pct"], rel=0.15)


@pytest.mark.fmu
def test_design_ahc_identifies_tunes_verifies_and_writes_the_gains(fmu_dir, tmp_path, capsys):
    """``marinefmu design-ahc`` on the built-in scenario with short runs: the length loop has its
    60° margin, the feedforward is fitted to the identified observer, the verification run's
    residual is within 30 % of the prediction (these short runs: predicted 1.14 %, measured
    1.05 %; the default runs: 1.12 % and 0.99 %), the plots exist and every controller of the
    copy in --out carries the gains."""
    from marinefmu.cli import main

    assert main(["design-ahc", "ahc", "--identify", "300", "--verify", "400", "--out", str(tmp_path),
                 "--fmus", str(fmu_dir), "--write", "--no-progress"]) == 0
    out = capsys.readouterr().out
    for png in ("ahc_loop_bode.png", "ahc_estimator_bode.png", "ahc_step.png"):
        assert (tmp_path / png).stat().st_size > 10_000
    predicted = float(out.split("predicted residual heave ")[1].split(" %")[0])
    measured = float(out.split("residual heave ")[2].split(" %")[0])
    assert measured <= 5.0 and measured == pytest.approx(predicted, rel=0.3), out
    assert "phase margin 60." in out
    written = tomllib.loads((tmp_path / "ahc.toml").read_text())["components"]
    gains = [(written[c]["parameters"]["k_p"], written[c]["parameters"]["k_ff"]) for c in
             ("ctrl_ideal", "ctrl_classic", "ctrl_observer")]
    assert len(set(gains)) == 1 and gains[0][0] == pytest.approx(design(AhcWinchParams()).controller.k_p, rel=1e-4)
    assert 0.9 < gains[0][1] < 1.1


@pytest.mark.fmu
@pytest.mark.libcosim
@pytest.mark.isolated(timeout=600)
def test_the_ahc_system_is_the_same_under_fmpy_in_process_and_libcosim(fmu_dir, tmp_path):
    """150 s of the ``ahc`` system (the observer valid from 120 s, the loops engaged): the FMPy
    runner and the in-process engine agree exactly; OSP libcosim (from the OSP file, in a
    second process) to rounding, sampled every second: relative 1e-9, or 1e-9 absolute for the
    winch's acceleration (u − v)/τ, a difference of near-equal speeds (measured 3e-11 m/s²;
    libcosim's time is integer nanoseconds, k·h to ~1 ulp)."""
    from marinefmu.cosim.system import SystemRunner

    sc = load_scenario("ahc")
    duration, sample = 150.0, 1.0
    record = list(sc.record)
    with LibcosimBeside("ahc", fmu_dir, tmp_path, duration, record, sample) as libcosim:
        fmpy = SystemRunner(sc.system, fmu_dir).run(duration, record=record, progress=False)
        python = SystemRunner(sc.system, fmu_dir, engine="python").run(duration, record=record, progress=False)
        lib = libcosim.result(timeout=500)
    for f in record:
        np.testing.assert_array_equal(python[f], fmpy[f], err_msg=f)
    assert fmpy["ctrl_observer.engagement"][-1] == 1.0 and abs(fmpy["winch_observer.speed"]).max() > 0.3
    every = int(round(sample / sc.step))
    for f in record:
        np.testing.assert_allclose(lib[f].astype(float), fmpy[every::every][f].astype(float), rtol=1e-9,
                                   atol=1e-9 if f.endswith(".acc") else 1e-12, err_msg=f)


@pytest.mark.fmu
def test_the_copyable_example_designs_and_writes(tmp_path, fmu_dir):
    """examples/ahc_design_loop.py (identification only, no verification run): three phase
    margins predicted, the best written into a copy of the scenario that loads."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "examples" / "ahc_design_loop.py"
    spec = importlib.util.spec_from_file_location("ahc_design_loop_example", path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    r = example.main(["--identify", "300", "--verify", "0", "--out", str(tmp_path)])
    assert r["margin"] in (45.0, 60.0, 75.0) and 0.3 < r["predicted_pct"] < 5.0 and r["measured"] == {}
    assert load_scenario(r["file"]).system.component("ctrl_observer").parameters["k_ff"] == round(r["controller"].k_ff, 6)


def test_design_ahc_refuses_a_bad_request_before_running_anything(tmp_path, capsys):
    from marinefmu.cli import main

    args = ["design-ahc", "ahc", "--fmus", str(tmp_path), "--out", str(tmp_path)]
    assert main(args + ["--controller", "att"]) == 2
    assert "'att' is not an AhcController of system 'ahc'" in capsys.readouterr().err
    assert main(args + ["--identify", "10"]) == 2
    assert "identify_s = 10.0 is out of range" in capsys.readouterr().err
    assert main(args + ["--phase-margin", "95"]) == 2
    assert "phase_margin = 95.0 is out of range" in capsys.readouterr().err
