"""The documentation site: the FMU interface tables read from the built FMUs, and the whole site
built with warnings as errors (what ``make docs`` runs)."""
from __future__ import annotations

import subprocess
import sys
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from marinefmu.fmu.interface_table import COLUMNS, allowed_range, interface_rows

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("description, unit, expected", [
    ("Significant wave height Hs, 0 < Hs <= 30 [m]", "m", "0 < Hs <= 30"),
    ("Forward speed (encounter frequency), 0..20 [m/s]", "m/s", "0..20"),
    ("Second-order damping ratio, (0, 10]", "", "(0, 10]"),
    ("Longest spectrum window: it grows (= window: the paper's fixed window), [window, 3600] [s]", "s",
     "[window, 3600]"),
    ("Sliding window length, >= 2/cutoff, <= 3600 [s]", "s", ">= 2/cutoff, <= 3600"),
    ("Feedforward gain on the estimated tip heave, [0, 2] (1: full compensation)", "", "[0, 2]"),
    ("Clip of the speed command (the winch's max_speed), > 0; no integration into the clip [m/s]", "m/s",
     "> 0"),
    ("Wave spectrum: one of jonswap, pierson-moskowitz", "", "one of jonswap, pierson-moskowitz"),
    ("Angle source: one of gyro_hp, input (high-pass integrated gyro, or the inputs)", "", "one of gyro_hp, input"),
    ("cos-2s spreading exponent s; 0 = long-crested, else 1..100", "", "0 = long-crested, else 1..100"),
    ("Monitoring point relative to the IMU, body frame, x [m]", "m", ""),
    ("Wire tension (>= 0: a wire cannot push) [N]", "N", ""),
])
def test_allowed_range_as_the_description_states_it(description, unit, expected):
    assert allowed_range(description, unit=unit) == expected


def test_allowed_range_from_min_and_max_first():
    assert allowed_range("Gain, (0, 10]", "0", "2") == "[0, 2]"
    assert allowed_range("Gain, (0, 10]", "0", None) == ">= 0"
    assert allowed_range("Gain, (0, 10]", None, "2") == "<= 2"


@pytest.mark.fmu
def test_interface_rows_are_every_scalar_variable_of_the_fmu(fmu_dir):
    path = fmu_dir / "HeaveObserver.fmu"
    rows = interface_rows(path)
    xml = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))
    variables = list(xml.iter("ScalarVariable"))
    assert len(rows) == len(variables)
    assert [r["name"] for r in rows] == [v.get("name") for v in variables]
    assert all(tuple(r) == COLUMNS for r in rows)
    by_name = {r["name"]: r for r in rows}
    point_x = by_name["point.x"]
    assert (point_x["causality"], point_x["variability"], point_x["type"], point_x["unit"]) == \
        ("parameter", "fixed", "Real", "m")
    assert float(point_x["start"]) == 0.0
    assert by_name["model"]["range"] == "one of band, peaks, highpass, wiener"
    assert by_name["model"]["type"] == "String"
    assert by_name["valid"]["causality"] == "output" and by_name["valid"]["type"] == "Boolean"


def test_interface_rows_of_a_missing_fmu(tmp_path):
    with pytest.raises(FileNotFoundError, match="no FMU at"):
        interface_rows(tmp_path / "Nothing.fmu")


def _sphinx(src: Path, out: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", *extra,
                           str(src), str(out)], capture_output=True, text=True, cwd=ROOT)


@pytest.mark.fmu
def test_fmu_interface_directive_renders_the_table(fmu_dir, tmp_path):
    src = tmp_path / "src"
    src.mkdir()
    (src / "conf.py").write_text(
        "import sys\n"
        f"sys.path.insert(0, {str(ROOT / 'docs' / '_ext')!r})\n"
        "extensions = ['myst_parser', 'fmu_interface']\n"
        f"fmu_interface_dir = {str(fmu_dir)!r}\n")
    (src / "index.md").write_text("# Heave\n\n```{fmu-interface} HeaveObserver\n:causality: parameter\n```\n")
    done = _sphinx(src, tmp_path / "html")
    assert done.returncode == 0, done.stdout + done.stderr
    page = (tmp_path / "html" / "index.html").read_text()
    assert "Allowed range" in page
    assert '<span class="pre">point.x</span>' in page
    assert "one of band, peaks, highpass, wiener" in page
    assert '<span class="pre">valid</span>' not in page  # an output: not of causality parameter

    (src / "index.md").write_text("# Nothing\n\n```{fmu-interface} NoSuchFmu\n```\n")
    done = _sphinx(src, tmp_path / "html2")
    assert done.returncode != 0
    assert "make fmus" in done.stdout + done.stderr


@pytest.mark.fmu
def test_the_documentation_site_builds_without_warnings(fmu_dir, tmp_path):
    """`make docs`: every page, the API reference from the docstrings and the FMU interface tables."""
    done = _sphinx(ROOT / "docs", tmp_path / "html", "-d", str(tmp_path / "doctrees"))
    assert done.returncode == 0, (done.stdout + done.stderr)[-6000:]
    html = tmp_path / "html"
    for page in ("index.html", "api/marinefmu.html", "changelog.html", "fmus/HeaveObserver.html"):
        assert (html / page).is_file(), page
    assert 'id="marinefmu.HeaveObserver"' in (html / "api" / "marinefmu.html").read_text()
