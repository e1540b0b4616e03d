"""The bench's memory figure for the whole system (bench.system.peak_rss_mb): a worker reports
its own peak, not the peak of the process that started it."""
import subprocess
import sys

import numpy as np
import pytest

from marinefmu.bench.system import peak_rss_mb


def test_a_worker_reports_its_own_peak_not_its_parents():
    """Linux keeps ``ru_maxrss`` across ``execve``: a worker started by a bench process holding
    300 MB read 300 MB or more, whatever it used itself (measured: 313 MB for every engine).
    VmHWM starts afresh at exec."""
    held = np.ones(300 * 2**20 // 8)                       # 300 MB resident in this process
    assert peak_rss_mb() > 300.0
    code = "from marinefmu.bench.system import peak_rss_mb; print(peak_rss_mb())"
    child = float(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout)
    assert 1.0 < child < 150.0, child                      # a bare interpreter and this module: ~20-80 MB
    assert held[-1] == 1.0


@pytest.mark.fmu
def test_idle_fmus_have_the_variables_of_the_real_ones_and_do_nothing(fmu_dir, tmp_path):
    """The master's floor (bench.system.master_floor) runs the system scenario on FMUs with the
    same variables whose doStep does nothing: they must load where the real ones do, be wired
    the same way, and hold their start values."""
    import zipfile

    from fmpy import read_model_description

    from marinefmu.bench.system import idle_fmus
    from marinefmu.cosim.ssp import Component, Connection, SystemDescription
    from marinefmu.cosim.system import SystemRunner

    idle = idle_fmus(fmu_dir, tmp_path / "idle", ("VesselMotion", "AttitudeEstimator"))
    for model in ("VesselMotion", "AttitudeEstimator"):
        real, fake = (read_model_description(str(d / f"{model}.fmu")) for d in (fmu_dir, idle))
        assert [(v.name, v.type, v.causality, v.variability, v.start) for v in fake.modelVariables] == \
               [(v.name, v.type, v.causality, v.variability, v.start) for v in real.modelVariables]
        assert zipfile.ZipFile(idle / f"{model}.fmu").namelist()     # a real FMU file
    sysd = SystemDescription("idle", (Component("vessel", "VesselMotion.fmu", {"sea.hs": 3.0}),
                                      Component("att", "AttitudeEstimator.fmu")),
                             (Connection.parse("vessel.imu.gyro.x", "att.gyro.x"),), 0.01, 0.5)
    r = SystemRunner(sysd, idle).run(record=["vessel.imu.gyro.x", "att.roll", "att.valid"], progress=False)
    assert r.size == 51
    assert np.all(r["vessel.imu.gyro.x"] == 0.0) and np.all(r["att.roll"] == 0.0) and not r["att.valid"].any()
    # libcosim's floor (master_floor(engine="libcosim")) reads the OSP model descriptions beside them
    assert all((idle / f"{m}_OspModelDescription.xml").exists() for m in ("VesselMotion", "AttitudeEstimator"))


@pytest.mark.fmu
@pytest.mark.libcosim
@pytest.mark.isolated
def test_the_idle_fmus_run_under_libcosim_as_run_libcosim_runs_them(fmu_dir, tmp_path):
    """libcosim's floor: the idle VesselMotion wired to the idle AttitudeEstimator under
    run_libcosim, 1 s sampled every 0.1 s, every output at its start value."""
    from marinefmu.bench.system import idle_fmus
    from marinefmu.cosim.libcosim import run_libcosim
    from marinefmu.cosim.ssp import Component, Connection, SystemDescription

    idle = idle_fmus(fmu_dir, tmp_path / "idle", ("VesselMotion", "AttitudeEstimator"))
    sysd = SystemDescription("idle", (Component("vessel", "VesselMotion.fmu", {"sea.hs": 3.0}),
                                      Component("att", "AttitudeEstimator.fmu")),
                             (Connection.parse("vessel.imu.gyro.x", "att.gyro.x"),), 0.01, 1.0)
    r = run_libcosim(sysd, idle, tmp_path, 1.0, ["vessel.imu.gyro.x", "att.roll", "att.valid"], 0.1)
    assert r.size == 10 and r["time"][-1] == pytest.approx(1.0)
    assert np.all(r["vessel.imu.gyro.x"] == 0.0) and np.all(r["att.roll"] == 0.0) and not r["att.valid"].any()


def test_the_speed_table_splits_each_base_step_into_components_and_the_rest():
    """Per component the in-process and FMI figures side by side; the master's row is the wall
    time per base step minus the components' own; the base step is 1e6 × wall / steps."""
    from marinefmu.bench.system import markdown, speed_table

    speed = {"fmpy": {"wall_s": 60.0, "duration_s": 600.0, "rtf": 10.0, "peak_rss_mb": 180.0,
                      "step_us": {"vessel": 400.0, "att": 300.0}},
             "python": {"wall_s": 48.0, "duration_s": 600.0, "rtf": 12.5, "peak_rss_mb": 170.0,
                        "step_us": {"vessel": 320.0, "att": 300.0}},
             "libcosim": {"wall_s": 100.0, "duration_s": 600.0, "rtf": 6.0, "peak_rss_mb": 190.0, "step_us": None},
             "idle_fmus": {"wall_s": 4.0, "duration_s": 600.0, "rtf": 150.0, "peak_rss_mb": 100.0}}
    rows = {r["component"]: r for r in speed_table(speed)}
    assert list(rows) == ["vessel", "att", "master and calls", "base step"]
    assert rows["vessel"]["fmi_over_in_process"] == pytest.approx(1.25)
    assert rows["base step"]["fmi_us"] == pytest.approx(1000.0) and rows["base step"]["in_process_us"] == pytest.approx(800.0)
    assert rows["master and calls"]["fmi_us"] == pytest.approx(300.0)
    assert rows["master and calls"]["in_process_us"] == pytest.approx(180.0)
    text = markdown({"speed": speed, "table": list(rows.values()),
                     "floor_over": {e: 150.0 / speed[e]["rtf"] for e in ("fmpy", "python", "libcosim")}})
    assert "| FMPy runner (FMI) | 60.0 s | 10.0 | 15.0 | 180 MB |" in text
    assert "| master and calls | 180 | 300 | 1.67 |" in text


def test_the_component_budget_is_the_goals_step_less_the_floors():
    """RTF 50 at a 10 ms step is 200 µs a base step; a floor of 153 (65.4 µs) leaves 134.6 µs
    for the components; a floor below the goal leaves nothing."""
    from marinefmu.bench.system import component_budget_us

    assert component_budget_us(50.0, 153.0) == pytest.approx(200.0 - 1e4 / 153.0)
    assert component_budget_us(50.0, 40.0) < 0
    with pytest.raises(ValueError, match="rtf_goal"):
        component_budget_us(0.0, 153.0)
