"""Build every ``models/*.py`` into ``fmus/*.fmu`` and validate it.

Each FMU bundles ``src/marinefmu`` in its resources, so it runs without the source tree
(but note: FMUs in one process share one interpreter, so an already imported ``marinefmu``
is the one used). After pythonfmu writes the FMU, :mod:`marinefmu.fmu.units` adds units
and initial unknowns, :mod:`marinefmu.fmu.osp` writes ``<Model>_OspModelDescription.xml``
next to it, and ``fmpy.validation.validate_fmu`` and :func:`marinefmu.fmu.osp.check` must
report nothing.

A build is skipped when a stamp (hash of the model script, every file of the package and the
pythonfmu version) matches the previous build, so ``make test`` after ``make demo`` is quick.
"""
from __future__ import annotations

import hashlib
import importlib.util
import sys
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

import pythonfmu
from filelock import FileLock

from ..errors import MarineFmuError
from .units import postprocess_model_description
from . import osp

PACKAGE_DIR = Path(__file__).resolve().parents[1]


class BuildError(MarineFmuError, RuntimeError):
    """An FMU failed to build or to validate."""


@dataclass(frozen=True)
class BuildResult:
    """Outcome for one model: its FMU path and whether it was rebuilt."""

    fmu: Path
    rebuilt: bool


def repo_root() -> Path:
    """The source checkout holding ``models/`` (the package is installed in editable mode)."""
    root = PACKAGE_DIR.parents[1]
    if not (root / "models").is_dir():
        raise BuildError(f"cannot find models/ next to {PACKAGE_DIR}: build from a source checkout (pip install -e .)")
    return root


def _fingerprint(script: Path) -> str:
    h = hashlib.sha256()
    h.update(pythonfmu.__version__.encode())
    h.update(script.read_bytes())
    for f in sorted(PACKAGE_DIR.rglob("*")):
        if f.is_file() and "__pycache__" not in f.parts:
            h.update(str(f.relative_to(PACKAGE_DIR)).encode())
            h.update(f.read_bytes())
    return h.hexdigest()


def _slave_units(script: Path) -> dict[str, str]:
    """Instantiate the script's slave (its ``__init__`` is cheap) and read its unit table."""
    spec = importlib.util.spec_from_file_location(f"_marinefmu_build_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    cls = getattr(module, script.stem)
    return cls(instance_name="build", resources=str(script.parent)).io.units


def build_one(script: Path, dest: Path, force: bool = False) -> BuildResult:
    """Build ``script`` into ``dest/<stem>.fmu`` unless it is up to date, then validate it."""
    fmu = dest / f"{script.stem}.fmu"
    stamp = dest / ".build-stamps" / f"{script.stem}.sha256"
    fingerprint = _fingerprint(script)
    osp_file = dest / f"{script.stem}_OspModelDescription.xml"
    if not force and fmu.exists() and osp_file.exists() and stamp.exists() and stamp.read_text() == fingerprint:
        return BuildResult(fmu, False)
    from pythonfmu.builder import FmuBuilder

    dest.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        raw = Path(FmuBuilder.build_FMU(script, dest=tmp, project_files=[PACKAGE_DIR],
                                        canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        units = _slave_units(script)
        with zipfile.ZipFile(raw) as zin, zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as zout:
            for item in zin.infolist():
                data = zin.read(item.filename)
                if item.filename == "modelDescription.xml":
                    data = postprocess_model_description(data, units)
                zout.writestr(item, data)
    with zipfile.ZipFile(fmu) as z:
        md_xml = z.read("modelDescription.xml")
    osp.write(md_xml, osp_file)
    problems = validate(fmu) + osp.check(md_xml, osp_file.read_bytes())
    if problems:
        fmu.unlink()
        raise BuildError(f"{fmu.name} failed validation:\n  " + "\n  ".join(problems))
    stamp.parent.mkdir(exist_ok=True)
    stamp.write_text(fingerprint)
    return BuildResult(fmu, True)


def validate(fmu: Path) -> list[str]:
    """Problems reported by ``fmpy.validation.validate_fmu`` (empty when the FMU is valid)."""
    from fmpy.validation import validate_fmu

    return list(validate_fmu(str(fmu)))


def build_all(models: Path | None = None, dest: Path | None = None, force: bool = False,
              verbose: bool = True) -> list[BuildResult]:
    """Build every ``models/*.py`` into ``dest`` (default ``fmus/`` of the checkout)."""
    root = repo_root() if models is None or dest is None else None
    models = models or root / "models"
    dest = dest or root / "fmus"
    scripts = sorted(p for p in models.glob("*.py") if not p.name.startswith("_"))
    if not scripts:
        raise BuildError(f"no model scripts in {models}")
    dest.mkdir(parents=True, exist_ok=True)
    sys.path.insert(0, str(models))
    # One builder at a time per folder: parallel test workers (make test runs two) or two shells
    # would otherwise write the same .fmu at once, or one would read an FMU half written.
    try:
        with FileLock(dest / ".build.lock"):
            results = []
            for script in scripts:
                result = build_one(script, dest, force)
                if verbose:
                    print(f"{'built  ' if result.rebuilt else 'up to date'} {result.fmu}")
                results.append(result)
            return results
    finally:
        sys.path.remove(str(models))
