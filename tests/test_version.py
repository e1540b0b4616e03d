"""One version everywhere: pyproject.toml, ``marinefmu.__version__``, the newest entry of
CHANGELOG.md and the ``version`` of every built FMU's modelDescription.xml."""
import re
import tomllib
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

import marinefmu

ROOT = Path(__file__).resolve().parents[1]
SEMVER = re.compile(r"\d+\.\d+\.\d+")


def project_version() -> str:
    with open(ROOT / "pyproject.toml", "rb") as f:
        return tomllib.load(f)["project"]["version"]


def test_package_version_is_the_projects():
    assert SEMVER.fullmatch(project_version())
    assert marinefmu.__version__ == project_version()


def test_newest_changelog_entry_is_the_projects_version():
    """The first ``## X.Y.Z`` heading is the newest; versions go down from there."""
    text = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    versions = re.findall(r"^##\s+\[?(\d+\.\d+\.\d+)\b", text, flags=re.MULTILINE)
    assert versions, "CHANGELOG.md has no '## X.Y.Z' heading"
    assert versions[0] == project_version()
    as_tuples = [tuple(int(n) for n in v.split(".")) for v in versions]
    assert as_tuples == sorted(set(as_tuples), reverse=True), versions


@pytest.mark.fmu
def test_every_built_fmu_carries_the_projects_version(fmu_dir):
    names = sorted(p.stem for p in (ROOT / "models").glob("*.py"))
    assert names
    for name in names:
        with zipfile.ZipFile(fmu_dir / f"{name}.fmu") as z:
            root = ET.fromstring(z.read("modelDescription.xml"))
        assert root.get("version") == project_version(), name
