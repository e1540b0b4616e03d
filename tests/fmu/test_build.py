"""The build's lean bundle (marinefmu.fmu.build): what each FMU carries of marinefmu, its
requirements.txt, how the set is found (a traced run, then the modules' import statements),
the stamp over the bundled files only, and the verification that refuses an FMU that does not
run from its own resources."""
from __future__ import annotations

import importlib.metadata
import json
import sys
import textwrap
import zipfile
from pathlib import Path

import pytest

from marinefmu.fmu import build
from marinefmu.fmu.build import Bundle, BuildError

ROOT = Path(__file__).resolve().parents[2]
MAX_FMU_BYTES = 1_000_000
#: Package parts no slave runs: they must stay out of every FMU.
NOT_RUN_BY_SLAVES = ("cli.py", "bench/", "campaign/", "analysis/", "papers/", "cosim/", "data/peer/", "data/scenarios/",
                     "fmu/build.py", "fmu/osp.py", "fmu/units.py", "fmu/interface_table.py", "ahc/design.py", "ahc/loop.py",
                     "sea/hydro/")


def _fmus(fmu_dir: Path) -> list[Path]:
    fmus = sorted(fmu_dir.glob("*.fmu"))
    assert len(fmus) >= 8
    return fmus


def _requirement_lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip() and not line.startswith("#")]


def test_every_fmu_carries_only_the_run_time_part_of_marinefmu(fmu_dir):
    """Lean: under 1 MB, every entry deflated, no command line, benchmarks, campaigns,
    analysis, papers, systems, scenario files or peer data; the same package files in every FMU
    (any may be the first loaded in a process), those recorded beside the stamps."""
    recorded = json.loads((fmu_dir / ".build-stamps" / "bundle.json").read_text())
    for fmu in _fmus(fmu_dir):
        assert fmu.stat().st_size <= MAX_FMU_BYTES, (fmu.name, fmu.stat().st_size)
        with zipfile.ZipFile(fmu) as z:
            infos = z.infolist()
        assert all(i.compress_type == zipfile.ZIP_DEFLATED for i in infos), fmu.name
        names = {i.filename for i in infos}
        package = sorted(n[len("resources/marinefmu/"):] for n in names if n.startswith("resources/marinefmu/"))
        assert package == recorded["files"], fmu.name
        assert {"__init__.py", "fmu/__init__.py", "fmu/slave.py", "fmu/tables.py", "sea/motion_model.py",
                "estimators/heave/observer.py"} <= set(package)
        assert not [f for f in package if f.startswith(NOT_RUN_BY_SLAVES)], fmu.name
        assert not any("__pycache__" in n for n in names)
        assert {f"resources/{fmu.stem}.py", "resources/requirements.txt", "resources/pythonfmu/fmi2slave.py"} <= names
        # every folder of modules the FMU carries has its __init__.py (data folders need none)
        folders = {str(Path(f).parent) for f in package if f.endswith(".py")} - {"."}
        assert all(f"{d}/__init__.py" in package for d in folders), fmu.name


def test_requirements_txt_bounds_each_import_by_the_tested_release(fmu_dir):
    """requirements.txt names the distributions the bundled modules import, each ``>=`` the
    minor release installed here, after a ``# tested with name==version`` line; pythonfmu (in
    resources/) and FMPy (a host's) are not in it. Every FMU has the same requirements."""
    from packaging.requirements import Requirement

    seen = set()
    for fmu in _fmus(fmu_dir):
        with zipfile.ZipFile(fmu) as z:
            text = z.read("resources/requirements.txt").decode()
        lines = text.splitlines()
        reqs = [Requirement(line) for line in _requirement_lines(text)]
        names = {r.name for r in reqs}
        assert {"numpy", "scipy", "filterpy", "control", "threadpoolctl"} == names, (fmu.name, text)
        for r in reqs:
            installed = importlib.metadata.version(r.name)
            assert str(r.specifier) == f">={'.'.join(installed.split('.')[:2])}", r
            assert r.specifier.contains(installed)
            assert lines[lines.index(str(r)) - 1] == f"# tested with {r.name}=={installed}"
        assert f"pythonfmu deploy -f {fmu.stem}.fmu" in text
        seen.add(tuple(_requirement_lines(text)))
    assert len(seen) == 1


def test_pythonfmu_deploy_installs_the_fmus_requirements(fmu_dir, monkeypatch):
    """``pythonfmu deploy -f X.fmu`` finds resources/requirements.txt and runs pip on it with
    the host's Python (pip itself is not run here: the clean-environment test installs it)."""
    from pythonfmu import deploy

    calls = []

    def fake_run(cmd, **kwargs):
        calls.append((cmd, Path(cmd[cmd.index("-r") + 1]).read_text()))

    monkeypatch.setattr(deploy.subprocess, "run", fake_run)
    fmu = fmu_dir / "HeaveObserver.fmu"
    deploy.deploy(fmu)
    with zipfile.ZipFile(fmu) as z:
        expected = z.read("resources/requirements.txt").decode()
    [(cmd, text)] = calls
    assert cmd[:4] == [sys.executable, "-m", "pip", "install"] and text == expected


@pytest.fixture
def fake_package(tmp_path, monkeypatch) -> Path:
    """An empty package folder named marinefmu, set as the build's package folder."""
    package = tmp_path / "fake" / "marinefmu"
    package.mkdir(parents=True)
    monkeypatch.setattr(build, "PACKAGE_DIR", package)
    return package


def _write(package: Path, files: dict[str, str]) -> None:
    for rel, text in files.items():
        (package / rel).parent.mkdir(parents=True, exist_ok=True)
        (package / rel).write_text(textwrap.dedent(text))


def test_imports_of_resolves_relative_function_level_lazy_and_optional_imports(fake_package):
    _write(fake_package, {
        "__init__.py": "", "a/__init__.py": "", "a/c.py": "", "a/g.py": "", "d.py": "", "e.py": "",
        "data/tables/one.csv": "1\n", "data/tables/two.json": "{}", "data/other/three.csv": "3\n",
        "estimators/__init__.py": "", "estimators/protocol.py": "",
        "a/b.py": """
            from __future__ import annotations
            import json
            from pathlib import Path
            from typing import TYPE_CHECKING
            import numpy as np
            from . import c
            from ..d import thing
            if TYPE_CHECKING:
                from ..e import Heavy
                import fmpy
            else:
                import scipy.linalg


            def table(name):
                return Path(__file__).parent.parent / "data" / "tables" / f"{name}.csv"   # a data folder, by name


            def f():
                from .g import h
                from marinefmu import Estimator   # the lazy public API: a name, not a module
                import pythonfmu
                try:
                    import pyarrow.parquet
                except ImportError:
                    pass
            """})
    files, third, optional = build.imports_of("a/b.py")
    assert files == {"__init__.py", "a/__init__.py", "a/c.py", "a/g.py", "d.py", "estimators/__init__.py",
                     "estimators/protocol.py", "data/tables/one.csv", "data/tables/two.json"}   # not e.py, data/other/
    assert third == {"numpy", "scipy"}            # not json (standard library), fmpy (TYPE_CHECKING), pythonfmu
    assert optional == {"pyarrow"}


def test_trace_records_the_modules_and_data_files_a_slave_uses(fake_package, tmp_path):
    """The traced run finds a module imported by string and a data file read at the first step
    (neither is in an import statement), and records a slave that refuses its parameters."""
    _write(fake_package, {
        "__init__.py": "", "lazy.py": "VALUE = 1.5\n", "unused.py": "", "data/table.csv": "1.5\n",
        "reader.py": """
            import importlib
            from pathlib import Path


            def read():
                importlib.import_module("marinefmu.lazy")
                return float((Path(__file__).parent / "data" / "table.csv").read_text())
            """})
    models = tmp_path / "models"
    _write(models, {
        "Reads.py": """
            from pythonfmu import Fmi2Slave
            from marinefmu import reader


            class Reads(Fmi2Slave):
                def do_step(self, current_time, step_size):
                    return reader.read() == 1.5
            """,
        "Refuses.py": """
            from pythonfmu import Fmi2Slave
            from pythonfmu.enums import Fmi2Status


            class Refuses(Fmi2Slave):
                def exit_initialization_mode(self):
                    self.log(f"{self.instance_name}: invalid parameter", Fmi2Status.error)

                def do_step(self, current_time, step_size):
                    return False
            """})
    files, behaviour = build.trace([models / "Reads.py", models / "Refuses.py"])
    assert files == {"__init__.py", "reader.py", "lazy.py", "data/table.csv"}
    assert behaviour["Reads"] == {"ok": [True] * (2 * build.STEPS), "errors": []}
    assert behaviour["Refuses"] == {"ok": [False] * (2 * build.STEPS), "errors": ["build-check: invalid parameter"]}


def test_the_stamp_covers_the_bundled_files_and_nothing_else(fake_package, tmp_path):
    _write(fake_package, {"__init__.py": "", "run.py": "x = 1\n", "cli.py": "y = 1\n"})
    script = tmp_path / "Model.py"
    script.write_text("# a model\n")
    bundle = Bundle(("__init__.py", "run.py"), ("numpy",))
    first = build._fingerprint(script, bundle)
    (fake_package / "cli.py").write_text("y = 2\n")
    assert build._fingerprint(script, bundle) == first
    (fake_package / "run.py").write_text("x = 2\n")
    assert build._fingerprint(script, bundle) != first
    assert build._fingerprint(script, Bundle(("__init__.py", "run.py"), ("numpy", "scipy"))) != build._fingerprint(
        script, bundle)
    assert build._fingerprint(script, Bundle(bundle.files, ("no-such-distribution",))) is None   # stale: rebuild


def test_an_fmu_missing_a_module_it_runs_is_refused(tmp_path):
    """The relay FMU built with a bundle that lacks marinefmu/variables.py: the verification
    (FMPy, the build's own marinefmu hidden) fails to instantiate it, the FMU is deleted and no
    stamp is written."""
    relay = ROOT / "tests" / "models" / "MfTestRelay.py"
    bad = Bundle(("__init__.py", "errors.py", "fmu/__init__.py", "fmu/host_exit.py", "fmu/slave.py"), ("numpy",),
                 behaviour={"MfTestRelay": {"ok": [True] * (2 * build.STEPS), "errors": []}})
    sys.path.insert(0, str(relay.parent))
    try:
        with pytest.raises(BuildError, match=r"MfTestRelay.fmu failed to run from its own resources(.|\n)*"
                                             r"marinefmu\.variables"):
            build.build_one(relay, tmp_path, bundle=bad)
    finally:
        sys.path.remove(str(relay.parent))
    assert not (tmp_path / "MfTestRelay.fmu").exists()
    assert not (tmp_path / ".build-stamps" / "MfTestRelay.sha256").exists()
