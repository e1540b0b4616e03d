"""VesselMotion's IMU grades (``imu.grade``): the table, the rule against the individual figures,
the figures' reaching the generated errors, the refusal of an unknown grade, the FMU parameter."""
import math

import numpy as np
import pytest

from marinefmu.errors import ParameterError
from marinefmu.sea.motion_model import PARAMETERS, VesselMotion, VesselMotionParams, simulate_record, stack
from marinefmu.sea.sensors import GRADE_FIGURES, IMU_GRADES, Imu, ImuParams

GRADES = tuple(IMU_GRADES)


def figures(obj):
    return {f: getattr(obj, f) for f in GRADE_FIGURES}


def test_mems_is_todays_default_error_model_exactly():
    assert GRADES == ("mems", "tactical", "mru")
    assert figures(IMU_GRADES["mems"]) == {"acc_noise": 7e-4, "acc_bias_instability": 5e-4, "gyro_noise": 5e-5,
                                           "gyro_bias_instability": 5e-5, "bias_tau": 50.0}
    assert ImuParams.from_grade("mems") == ImuParams() == VesselMotionParams.from_flat({}).imu
    defaults = {v.name: v.default for v in PARAMETERS}
    assert defaults["imu.grade"] == "mems"
    assert {f: defaults[f"imu.{f}"] for f in GRADE_FIGURES} == figures(IMU_GRADES["mems"])


def test_grades_improve_every_figure_and_keep_paper001s_tactical_gyro():
    from marinefmu.papers.paper001 import TACTICAL_GYRO

    for worse, better in zip(GRADES, GRADES[1:]):
        for f in GRADE_FIGURES[:4]:
            assert getattr(IMU_GRADES[better], f) < getattr(IMU_GRADES[worse], f), (better, f)
    assert TACTICAL_GYRO == (1e-5, 1.5e-5)
    mru = IMU_GRADES["mru"]    # the datasheet figures as the model's units
    assert math.degrees(mru.gyro_bias_instability) * 3600 == pytest.approx(0.05)       # °/h
    assert math.degrees(mru.gyro_noise) * 60 == pytest.approx(0.01)                    # °/√h
    assert mru.acc_noise / 9.80665e-6 == pytest.approx(15.0)                           # µg/√Hz
    assert all(g.source for g in IMU_GRADES.values())


@pytest.mark.parametrize("grade", GRADES)
def test_the_grade_sets_the_vessel_motion_error_model(grade):
    imu = VesselMotionParams.from_flat({"imu.grade": grade, "imu.x": 5.0, "imu.acc_bias.y": 0.01}).imu
    assert figures(imu) == figures(IMU_GRADES[grade])
    assert imu.lever_arm == (5.0, 0.0, 0.0) and imu.acc_bias == (0.0, 0.01, 0.0)   # not the grade's


def test_a_figure_set_to_other_than_its_default_replaces_the_grades():
    imu = VesselMotionParams.from_flat({"imu.grade": "mru", "imu.acc_noise": 0.0, "imu.bias_tau": 20.0}).imu
    expected = {**figures(IMU_GRADES["mru"]), "acc_noise": 0.0, "bias_tau": 20.0}
    assert figures(imu) == expected
    # the documented limit: a figure equal to its default (the mems one) cannot be told from unset
    kept = VesselMotionParams.from_flat({"imu.grade": "mru", "imu.gyro_noise": 5e-5}).imu
    assert kept.gyro_noise == IMU_GRADES["mru"].gyro_noise
    # under mems the individual figures are today's parameters, as before the grades
    assert VesselMotionParams.from_flat({"imu.gyro_noise": 1e-5}).imu.gyro_noise == 1e-5


@pytest.mark.parametrize("grade", ["navigation", "MRU", "", 3])
def test_an_unknown_grade_is_refused_naming_the_grades(grade):
    with pytest.raises(ParameterError, match=r"imu\.grade = .* is not allowed: must be one of 'mems', 'tactical', 'mru'"):
        VesselMotionParams.from_flat({"imu.grade": grade})
    with pytest.raises(ParameterError, match=r"imu\.grade"):
        ImuParams.from_grade(grade)


def test_measure_many_draws_the_same_numbers_as_measure():
    """The vectorised IMU (used by the tilt bound) equals step-by-step measurement, also when
    called in pieces, and leaves the same bias."""
    rng = np.random.default_rng(0)
    f, w = rng.normal(size=(300, 3)), rng.normal(size=(300, 3))
    for grade in GRADES:
        p = ImuParams.from_grade(grade, acc_bias=(0.1, 0.0, -0.2), gyro_bias=(0.0, 1e-3, 0.0))
        a, b = Imu(p, np.random.default_rng(7)), Imu(p, np.random.default_rng(7))
        seq = np.array([a.measure(f[k], list(w[k]), 0.02) for k in range(300)])
        vec = np.vstack([b.measure_many(f[:120], w[:120], 0.02), b.measure_many(f[120:], w[120:], 0.02)])
        np.testing.assert_allclose(vec, seq, rtol=0, atol=1e-15)
        np.testing.assert_allclose(b.gm_bias, a.gm_bias, rtol=0, atol=1e-18)


@pytest.mark.parametrize("grade", GRADES)
def test_white_noise_has_the_grades_density(grade):
    """Per-sample σ = N/√Δt: with 3 × 100,000 samples per sensor the sample std's standard error
    is 1/√(2·300,000) = 0.13 %, so 0.7 % is five of them."""
    g, dt, n = IMU_GRADES[grade], 0.01, 100_000
    p = ImuParams.from_grade(grade, acc_bias_instability=0.0, gyro_bias_instability=0.0)
    err = Imu(p, np.random.default_rng(11)).measure_many(np.zeros((n, 3)), np.zeros((n, 3)), dt)
    np.testing.assert_allclose(err[:, :3].std(), g.acc_noise / math.sqrt(dt), rtol=0.007)
    np.testing.assert_allclose(err[:, 3:].std(), g.gyro_noise / math.sqrt(dt), rtol=0.007)


@pytest.mark.parametrize("grade", GRADES)
def test_bias_instability_has_the_grades_spread_and_time_constant(grade):
    """Noise off, steps of τ/10: the one-step correlation is e^{−0.1} (standard error
    √((1 − φ²)/n) = 0.0013 per axis over n = 100,000 steps, 0.0008 for the mean of three;
    tolerance 0.004), and the innovations b_{k+1} − φ b_k have the std σ_b √(1 − φ²) of the
    exact discretisation (standard error 0.13 % over 3 × 100,000; tolerance 0.7 %)."""
    g = IMU_GRADES[grade]
    dt, n = g.bias_tau / 10, 100_000
    phi = math.exp(-0.1)
    b = Imu(ImuParams.from_grade(grade, acc_noise=0.0, gyro_noise=0.0),
            np.random.default_rng(5)).measure_many(np.zeros((n, 3)), np.zeros((n, 3)), dt)
    for cols, sigma in ((slice(0, 3), g.acc_bias_instability), (slice(3, 6), g.gyro_bias_instability)):
        x = b[:, cols]
        r = np.mean([np.corrcoef(x[:-1, i], x[1:, i])[0, 1] for i in range(3)])
        assert r == pytest.approx(phi, abs=0.004)
        np.testing.assert_allclose((x[1:] - phi * x[:-1]).std(), sigma * math.sqrt(1 - phi * phi), rtol=0.007)


def test_a_vessel_motion_record_carries_the_grades_noise():
    """Through the model: imu − truth − the true bias is the white noise, σ = N/√Δt (3 × 3,000
    samples: standard error 0.75 %, tolerance 4 %)."""
    dt = 0.01
    rec = simulate_record(VesselMotionParams.from_flat({"imu.grade": "mru", "sea.hs": 1.0, "sensors.seed": 2}), 30.0, dt)
    acc = stack(rec, "imu.acc") - stack(rec, "truth.imu_f") - stack(rec, "truth.acc_bias")
    gyro = stack(rec, "imu.gyro") - stack(rec, "truth.rate") - stack(rec, "truth.gyro_bias")
    np.testing.assert_allclose(acc.std(), IMU_GRADES["mru"].acc_noise / math.sqrt(dt), rtol=0.04)
    np.testing.assert_allclose(gyro.std(), IMU_GRADES["mru"].gyro_noise / math.sqrt(dt), rtol=0.04)
    assert np.abs(stack(rec, "truth.gyro_bias")).max() < 5 * IMU_GRADES["mru"].gyro_bias_instability


@pytest.mark.fmu
def test_the_fmu_has_the_grade_parameter_and_uses_it(fmu_dir, tmp_path):
    import xml.etree.ElementTree as ET
    import zipfile

    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    path = fmu_dir / "VesselMotion.fmu"
    with zipfile.ZipFile(path) as z:
        svs = {sv.get("name"): sv for sv in ET.fromstring(z.read("modelDescription.xml")).find("ModelVariables")}
    grade = svs["imu.grade"]
    assert grade.get("causality") == "parameter" and grade.find("String").get("start") == "mems"
    assert "mems, tactical, mru" in grade.get("description")
    md = read_model_description(str(path))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path), unzipdir=str(tmp_path / "vm")),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="vm")
    fmu.instantiate()
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.setString([vr["imu.grade"]], ["mru"])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        names = [f"imu.{s}.{a}" for s in ("acc", "gyro") for a in "xyz"]
        model = VesselMotion(VesselMotionParams.from_flat({"imu.grade": "mru"}))
        for k in range(50):
            fmu.doStep(currentCommunicationPoint=k * 0.01, communicationStepSize=0.01)
            y = model.step((k + 1) * 0.01, 0.01)
            assert fmu.getReal([vr[n] for n in names]) == pytest.approx(y[:6], abs=1e-12)
    finally:
        fmu.terminate()
        fmu.freeInstance()


@pytest.mark.fmu
def test_the_fmu_refuses_an_unknown_grade_naming_the_grades(fmu_dir):
    from marinefmu.cosim.ssp import Component, SystemDescription
    from marinefmu.cosim.system import SystemRunner
    from marinefmu.errors import SystemError_

    system = SystemDescription("bad", (Component("vessel", "VesselMotion.fmu", {"imu.grade": "navigation"}),),
                               (), 0.01, 1.0)
    with pytest.raises(SystemError_, match=r"imu\.grade = 'navigation' is not allowed: must be one of 'mems', 'tactical', 'mru'"):
        SystemRunner(system, fmu_dir).run(progress=False)
