"""The command line, run as a user would (short durations)."""
import subprocess
import sys

import numpy as np
import pytest

from marinefmu.cli import main
from marinefmu.cosim.system import load_csv

pytestmark = pytest.mark.fmu


def test_simulate_default_writes_csv_plots_and_system_file(fmu_dir, tmp_path, capsys):
    assert main(["simulate", "default", "--duration", "20", "--out", str(tmp_path), "--fmus", str(fmu_dir), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "hs_realised_m" in out and "summary of vessel" in out
    r = load_csv(tmp_path / "results.csv")
    assert r["time"][-1] == pytest.approx(20.0) and r.size == 2001
    streamed = np.load(tmp_path / "results.npy")       # the same rows, streamed during the run
    np.testing.assert_allclose(streamed["vessel.truth.cog.d"], r["vessel.truth.cog.d"], rtol=1e-9)
    assert "engine fmpy" in out
    assert np.std(r["vessel.truth.cog.d"]) > 0.05
    for name in ("vessel_motion.png", "vessel_imu.png", "vessel_gnss.png", "SystemStructure.ssd"):
        assert (tmp_path / name).stat().st_size > 1000


def test_simulate_writes_an_ssp_package_that_simulate_runs_again(fmu_dir, tmp_path):
    """The whole-system scenario: its SSP package (with the FMUs inside) run on its own gives
    the same results, bit for bit; the OSP libcosim file and the HTML report are written beside it."""
    first, second = tmp_path / "a", tmp_path / "b"
    assert main(["simulate", "system", "--duration", "3", "--out", str(first), "--fmus", str(fmu_dir), "--no-progress"]) == 0
    assert (first / "OspSystemStructure.xml").stat().st_size > 5000
    assert main(["simulate", str(first / "system.ssp"), "--duration", "3", "--out", str(second), "--no-progress"]) == 0
    a, b = load_csv(first / "results.csv"), load_csv(second / "results.csv")
    # the scenario records time and its [record] list (65 variables); an .ssp has none: every output
    assert len(a.dtype.names) == 66 and set(a.dtype.names) < set(b.dtype.names)
    assert all(np.array_equal(a[f], b[f]) for f in a.dtype.names)
    assert np.std(a["fusion.pos.d"][100:]) > 0.01          # the estimators ran (GNSS fusion follows the heave)
    page = (first / "report.html").read_text()
    assert "Accuracy against the goals" in page and page.count("data:image/png;base64,") >= 4   # diagram + figures


def test_simulate_reports_a_bad_scenario_with_exit_code_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[scenario]\nduration = 5.0\n[components.v]\nfmu = "VesselMotion"\n[components.v.parameters]\n"sea.hs" = -2.0\n')
    assert main(["simulate", str(bad), "--out", str(tmp_path / "o"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert "sea.hs = -2.0 is out of range" in err


def test_simulate_reports_a_missing_ssp_package_with_exit_code_2(tmp_path, capsys):
    assert main(["simulate", str(tmp_path / "none.ssp"), "--out", str(tmp_path / "o"), "--no-progress"]) == 2
    assert "none.ssp: not a readable SSP package" in capsys.readouterr().err


def test_console_script_is_installed():
    out = subprocess.run([sys.executable, "-m", "marinefmu.cli", "--help"], capture_output=True, text=True, check=True).stdout
    assert "simulate" in out and "build" in out and "bench" in out


def test_simulate_in_process_engine(fmu_dir, tmp_path, capsys):
    assert main(["simulate", "default", "--duration", "2", "--out", str(tmp_path), "--fmus", str(fmu_dir),
                 "--no-progress", "--engine", "python"]) == 0
    assert "engine python" in capsys.readouterr().out
    assert np.load(tmp_path / "results.npy").size == 201
