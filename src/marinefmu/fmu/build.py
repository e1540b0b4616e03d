"""Build every ``models/*.py`` into ``fmus/*.fmu``, lean and self-describing, and validate it.

**What an FMU carries.** pythonfmu's builder puts the model script and pythonfmu's own Python
part into ``resources/``; the build adds the part of :mod:`marinefmu` the slaves run and
``resources/requirements.txt``, and stores every entry deflated. The command line, the
benchmarks, the campaigns, the analysis, the papers' reproductions and the peer data stay out,
as does every module only a build or a host uses (:mod:`.build`, :mod:`.osp`, :mod:`.units`,
:mod:`marinefmu.cosim`).

**Which modules** (:func:`collect_bundle`). Each script is run in a fresh interpreter as a host
runs it: imported, instantiated, initialised, stepped with its inputs at their start values,
its state got, serialised, read back and set, stepped again and terminated. The ``marinefmu``
modules then in ``sys.modules`` and every other file of the package the slave opened (an
audit hook on ``open``: data files) are its run-time set. To that the build adds what the
import statements of those modules name (read with :mod:`ast`, function-level imports
included, ``if TYPE_CHECKING:`` blocks not), so a branch the run did not take (another
parameter choice) finds its module too; the files of every folder under ``data/`` those
modules name in their string constants (``"data", "hydro"``: the BEM presets' RAO tables,
read only when ``vessel.preset`` selects one); and the ``__init__.py`` of every parent
package.
A module's static imports alone would not do: ``marinefmu/__init__.py``'s names load by
string on first use.

**One set for every FMU of a checkout.** FMUs in one process share one interpreter, and the
``marinefmu`` package the first FMU imports, from its own folder, resolves the imports of every
later FMU (its ``__path__`` is that folder). Were each FMU to carry only its own modules,
VesselMotion loaded before HeaveObserver would leave ``marinefmu.estimators.heave.observer``
unimportable. So every FMU bundles the union of the run-time sets of all the scripts it is
built with and of the checkout's ``models/`` (:func:`bundle_scripts`): any of them can be the
first loaded. The per-script sets differ by a few modules anyway, since every slave imports
:mod:`marinefmu.fmu.tables`, which imports every model's parameters.

**requirements.txt** (:meth:`Bundle.requirements`) lists the distributions of the third-party
top-level modules the bundled files import (their import statements; the standard library,
``marinefmu`` and pythonfmu, which is bundled, excluded), mapped with
:func:`importlib.metadata.packages_distributions`; their own dependencies (matplotlib through
filterpy and python-control) are theirs to declare. Each is bounded below by the minor release
the build ran with, ``numpy>=2.4``, after a comment ``# tested with numpy==2.4.6``: the
packages go into the host's own Python, shared with the host tool and every other FMU in the
process, where exact pins from each FMU would conflict with one another, while an older
release than the one tested is refused. There is no upper bound: which future release breaks
an FMU cannot be known when it is built, and the comment says what did work. ``pythonfmu
deploy -f X.fmu`` finds the file there and runs ``pip install -r`` with the host's Python.

**After pythonfmu writes the FMU**, :mod:`marinefmu.fmu.units` adds units and initial
unknowns, :mod:`marinefmu.fmu.osp` writes ``<Model>_OspModelDescription.xml`` next to it,
``fmpy.validation.validate_fmu`` and :func:`marinefmu.fmu.osp.check` must report nothing, and
:func:`verify_runs` must find that the FMU runs under FMPy in a fresh interpreter that cannot
import the ``marinefmu`` the build used: only the FMU's own resources serve it. A failing FMU
is deleted and the build raises :class:`BuildError`.

**Stamps.** A build is skipped when a stamp (a hash of the model script, the bundled files, the
requirements with the installed versions, this module with :mod:`.units` and :mod:`.osp`, and
the pythonfmu version) matches the previous build, so ``make test`` after ``make demo`` is
quick. The bundle's file list is kept beside the stamps (``.build-stamps/bundle.json``): a
change to a module that no FMU runs rebuilds nothing, and a change that makes an FMU import a
new module changes a bundled file, so the scripts are traced again.

Note: FMUs in one process share one interpreter, so an already imported ``marinefmu`` is the one
used (the FMU contract, "Several FMUs in one process"): FMUs from different checkouts or
versions should not share a process.
"""
from __future__ import annotations

import ast
import hashlib
import importlib
import importlib.metadata
import importlib.util
import json
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import pythonfmu
from filelock import FileLock

from ..errors import MarineFmuError
from . import osp, units

PACKAGE_DIR = Path(__file__).resolve().parents[1]
PACKAGE = "marinefmu"
DATA = "data"              # the package's data folder
#: The files that shape an FMU besides its bundle: a change to them rebuilds every FMU.
BUILD_FILES = (Path(__file__).resolve(), Path(units.__file__).resolve(), Path(osp.__file__).resolve())
INSTANCE = "build-check"   # instance name of the traced and the verification runs (it is in their messages)
STEPS = 5                  # doStep calls of the traced and the verification runs, before and after the state round trip
STEP = 0.05                # s, communication step of both
SUBPROCESS_TIMEOUT = 300.0  # s, per trace or verification run (each takes a few seconds)
#: Top-level modules never listed in requirements.txt: pythonfmu's builder bundles pythonfmu.
BUNDLED_BY_PYTHONFMU = frozenset({"pythonfmu"})


class BuildError(MarineFmuError, RuntimeError):
    """An FMU failed to build or to validate."""


@dataclass(frozen=True)
class BuildResult:
    """Outcome for one model: its FMU path and whether it was rebuilt."""

    fmu: Path
    rebuilt: bool


@dataclass(frozen=True)
class Bundle:
    """What every FMU of one build carries of marinefmu (:func:`collect_bundle`).

    Attributes
    ----------
    files : tuple of str
        Files of the package, as posix paths relative to its folder (``sea/waves.py``).
    distributions : tuple of str
        Distributions of the third-party modules those files import (``numpy``).
    optional : tuple of str
        Third-party modules imported only under ``try: ... except ImportError`` (``pyarrow``):
        named in a comment of requirements.txt, not required.
    behaviour : dict
        Per script name, what its traced run gave: ``ok`` (doStep's result, step by step) and
        ``errors`` (the messages it logged with status error or worse); the FMU must do the
        same from its own resources (:func:`verify_runs`). Not kept in the bundle's record
        beside the stamps: the scripts are traced again whenever an FMU is rebuilt.
    """

    files: tuple[str, ...]
    distributions: tuple[str, ...]
    optional: tuple[str, ...] = ()
    behaviour: dict = field(default_factory=dict, compare=False)

    def requirements(self, model: str) -> str:
        """The text of ``resources/requirements.txt`` for ``model``, with the installed versions
        (the module doc says why the bounds are what they are).

        Raises
        ------
        importlib.metadata.PackageNotFoundError
            A distribution is not installed (any more).
        """
        from .. import __version__

        py = ".".join(map(str, sys.version_info[:3]))
        lines = [f"# Run-time requirements of the {model} FMU (marinefmu {__version__}), for the host's Python",
                 f"# 3.11 or later (tested with Python {py}). `pythonfmu deploy -f {model}.fmu` installs them",
                 "# into the Python that runs it (pip install -r); pythonfmu's Python part is in resources/.",
                 "# Each is bounded below by the minor release the FMU was built and tested with."]
        if self.optional:
            lines.append(f"# Optional, used when importable, not installed by this file: {', '.join(self.optional)}.")
        for dist in self.distributions:
            version = importlib.metadata.version(dist)
            release = version.split("+")[0].split(".")
            lines += [f"# tested with {dist}=={version}", f"{dist}>={'.'.join(release[:2])}"]
        return "\n".join(lines) + "\n"


def repo_root() -> Path:
    """The source checkout holding ``models/`` (the package is installed in editable mode)."""
    root = PACKAGE_DIR.parents[1]
    if not (root / "models").is_dir():
        raise BuildError(f"cannot find models/ next to {PACKAGE_DIR}: build from a source checkout (pip install -e .)")
    return root


# --- which files: a traced run of each script, then its modules' own imports ------------------

_TRACE = r"""
import importlib.util, json, os, sys
from pathlib import Path

package, steps, dt, instance = Path(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
opened = set()


def audit(event, args):
    if event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
        opened.add(os.path.abspath(os.fsdecode(args[0])))


sys.addaudithook(audit)
ok = {}
for script in map(Path, sys.argv[5:]):
    sys.path.insert(0, str(script.parent))
    spec = importlib.util.spec_from_file_location(script.stem, script)
    module = importlib.util.module_from_spec(spec)
    sys.modules[script.stem] = module
    spec.loader.exec_module(module)
    slave = getattr(module, script.stem)(instance_name=instance, resources=str(script.parent))
    slave.setup_experiment(0.0, None, None)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    done = [slave.do_step(k * dt, dt) for k in range(steps)]
    state = slave._fmu_state_from_bytes(slave._fmu_state_to_bytes(slave._get_fmu_state()))
    slave._set_fmu_state(state)
    done += [slave.do_step(k * dt, dt) for k in range(steps, 2 * steps)]
    slave.terminate()
    ok[script.stem] = {"ok": done, "errors": [m.msg for m in slave.log_queue if int(m.status) >= 3]}
modules = {name: getattr(m, "__file__", None) for name, m in list(sys.modules.items())
           if name == "marinefmu" or name.startswith("marinefmu.")}
print(json.dumps({"modules": modules, "opened": sorted(p for p in opened if p.startswith(str(package) + os.sep)),
                  "behaviour": ok}))
"""


def _subprocess_env() -> dict[str, str]:
    """This process's environment with the package's folder first on PYTHONPATH, so a child
    interpreter imports the same marinefmu."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(PACKAGE_DIR.parent), env.get("PYTHONPATH")) if p)
    return env


def _last_json(done: subprocess.CompletedProcess, what: str) -> dict:
    try:
        result = json.loads(done.stdout.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        result = None
    if done.returncode != 0 or not isinstance(result, dict):
        raise BuildError(f"{what} failed (exit code {done.returncode}):\n{done.stdout[-2000:]}\n{done.stderr[-3000:]}")
    return result


def trace(scripts: list[Path]) -> tuple[set[str], dict]:
    """Run the slave of each of ``scripts`` as a host would (the module doc), one after the other
    in one fresh interpreter; the package files they used (the ``marinefmu`` modules imported,
    the data files opened; relative to the package folder) and each one's behaviour (see
    :class:`Bundle`).

    A slave that refuses its default parameters (a file to play back that is not set) logs the
    refusal and discards its steps; that is recorded, not an error: its modules' imports are
    still followed (:func:`collect_bundle`), and its FMU must refuse them the same way.
    """
    names = ", ".join(s.name for s in scripts)
    with tempfile.TemporaryDirectory() as tmp:
        try:
            done = subprocess.run([sys.executable, "-c", _TRACE, str(PACKAGE_DIR), str(STEPS), str(STEP),
                                   INSTANCE, *(str(s.resolve()) for s in scripts)], capture_output=True, text=True,
                                  cwd=tmp, env=_subprocess_env(), timeout=SUBPROCESS_TIMEOUT)
        except subprocess.TimeoutExpired as exc:
            raise BuildError(f"tracing {names}: no answer within {SUBPROCESS_TIMEOUT:.0f} s") from exc
    result = _last_json(done, f"tracing {names}")
    files = set()
    for name, file in result["modules"].items():
        path = Path(file).resolve() if file else None
        if path is None or not path.is_relative_to(PACKAGE_DIR):
            raise BuildError(f"tracing {names}: module {name} came from {file}, not from {PACKAGE_DIR}")
        files.add(path.relative_to(PACKAGE_DIR).as_posix())
    for file in result["opened"]:
        path = Path(file)
        if path.suffix not in (".py", ".pyc") and "__pycache__" not in path.parts and path.is_file():
            files.add(path.relative_to(PACKAGE_DIR).as_posix())
    return files, result["behaviour"]


def _module_file(module: str) -> str | None:
    """``marinefmu.a.b`` -> ``a/b.py`` or ``a/b/__init__.py`` (relative), if that file exists."""
    parts = module.split(".")[1:]
    for rel in (Path(*parts).with_suffix(".py") if parts else None, Path(*parts, "__init__.py")):
        if rel is not None and (PACKAGE_DIR / rel).is_file():
            return rel.as_posix()
    return None


def _with_parents(module: str) -> set[str]:
    """The files of ``module`` and of every package above it (those that exist)."""
    parts = module.split(".")
    return {f for i in range(1, len(parts) + 1) if (f := _module_file(".".join(parts[:i])))}


def _module_name(rel: str) -> tuple[str, bool]:
    """``a/b.py`` -> (``marinefmu.a.b``, False); ``a/__init__.py`` -> (``marinefmu.a``, True)."""
    parts = list(Path(rel).with_suffix("").parts)
    package = parts[-1] == "__init__"
    return ".".join([PACKAGE, *(parts[:-1] if package else parts)]), package


def _is_type_checking(test: ast.expr) -> bool:
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _catches_import_error(handler: ast.ExceptHandler) -> bool:
    names = handler.type.elts if isinstance(handler.type, ast.Tuple) else [handler.type]
    return any(isinstance(n, ast.Name) and n.id in ("ImportError", "ModuleNotFoundError") for n in names)


def _import_nodes(tree: ast.AST):
    """Every Import and ImportFrom node, at any depth, outside ``if TYPE_CHECKING:`` bodies, with
    whether it is optional (in the body of a ``try`` that catches ImportError)."""
    stack = [(tree, False)]
    while stack:
        node, optional = stack.pop()
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node, optional
        elif isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend((n, optional) for n in node.orelse)
        elif isinstance(node, ast.Try) and any(_catches_import_error(h) for h in node.handlers):
            stack.extend((n, True) for n in node.body)
            stack.extend((n, optional) for n in (*node.handlers, *node.orelse, *node.finalbody))
        else:
            stack.extend((n, optional) for n in ast.iter_child_nodes(node))


def _data_folders() -> list[str]:
    """Every folder below the package's ``data/`` (``data/hydro``), relative, posix."""
    data = PACKAGE_DIR / DATA
    return sorted(p.relative_to(PACKAGE_DIR).as_posix() for p in data.rglob("*")
                  if p.is_dir() and p.name != "__pycache__") if data.is_dir() else []


def _data_named(tree: ast.AST) -> set[str]:
    """The files of every data folder a module names in its string constants: the folder's
    path (``"data/hydro"``) in one of them, or each of its parts (``"data"``, ``"hydro"``) as
    one, as ``Path(__file__).parent / "data" / "hydro" / f"{name}.csv"`` does."""
    consts = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
    files: set[str] = set()
    for folder in _data_folders():
        if any(folder in c for c in consts) or all(part in consts for part in folder.split("/")):
            files |= {f.relative_to(PACKAGE_DIR).as_posix() for f in (PACKAGE_DIR / folder).iterdir() if f.is_file()}
    return files


def imports_of(rel: str) -> tuple[set[str], set[str], set[str]]:
    """What the package file ``rel`` needs: (package files, third-party top-level modules,
    third-party top-level modules imported only where an ImportError is caught).

    Relative and absolute imports of ``marinefmu`` modules are resolved to their files; a name
    imported from ``marinefmu`` itself that is no module (the lazy public API) is resolved to
    the module defining it. The standard library and pythonfmu are left out. The package files
    include the data folders the module names (:func:`_data_named`): a file read only for a
    parameter value the traced run did not use (a BEM preset's RAO table) is then bundled too.
    """
    if not rel.endswith(".py"):
        return set(), set(), set()
    module, is_package = _module_name(rel)
    own_package = module if is_package else module.rpartition(".")[0]
    files: set[str] = set()
    third: set[str] = set()
    optional: set[str] = set()
    tree = ast.parse((PACKAGE_DIR / rel).read_bytes(), filename=rel)
    files |= _data_named(tree)
    for node, guarded in _import_nodes(tree):
        if isinstance(node, ast.Import):
            targets = [(alias.name, ()) for alias in node.names]
        elif node.level:
            base = own_package.rsplit(".", node.level - 1)[0] if node.level > 1 else own_package
            targets = [(f"{base}.{node.module}" if node.module else base, [a.name for a in node.names])]
        else:
            targets = [(node.module, [a.name for a in node.names])]
        for target, names in targets:
            top = target.split(".")[0]
            if top != PACKAGE:
                if top not in sys.stdlib_module_names and top not in BUNDLED_BY_PYTHONFMU and top != "__future__":
                    (optional if guarded else third).add(top)
                continue
            files |= _with_parents(target)
            for name in names:
                if _module_file(f"{target}.{name}"):
                    files |= _with_parents(f"{target}.{name}")
                elif target == PACKAGE and name != "*":
                    defined_in = getattr(getattr(importlib.import_module(PACKAGE), name, None), "__module__", None)
                    if isinstance(defined_in, str) and defined_in.split(".")[0] == PACKAGE:
                        files |= _with_parents(defined_in)
    return files, third, optional - third


def _parents(rel: str) -> set[str]:
    """The ``__init__.py`` of every package above the package file ``rel`` (that exists)."""
    parts = Path(rel).parts[:-1]
    inits = (Path(*parts[:i], "__init__.py").as_posix() for i in range(len(parts) + 1))
    return {f for f in inits if (PACKAGE_DIR / f).is_file()}


def bundle_scripts(scripts: list[Path]) -> list[Path]:
    """``scripts`` and, when the package is a source checkout's, the other scripts of its
    ``models/`` (a script of the same name in ``scripts`` takes the place of the checkout's)."""
    try:
        checkout = sorted(p for p in (repo_root() / "models").glob("*.py") if not p.name.startswith("_"))
    except BuildError:
        checkout = []
    given = {s.stem for s in scripts}
    return [*scripts, *(s for s in checkout if s.stem not in given)]


def collect_bundle(scripts: list[Path]) -> Bundle:
    """The :class:`Bundle` of ``scripts`` (:func:`bundle_scripts` adds the checkout's models):
    the files of their traced runs (:func:`trace`), closed under the import statements of its
    modules, with every parent package's ``__init__.py``, and the distributions those modules
    import."""
    files, behaviour = trace(bundle_scripts(scripts))
    third: set[str] = set()
    optional: set[str] = set()
    todo = sorted(files)
    while todo:
        rel = todo.pop()
        more, top, maybe = imports_of(rel)
        third |= top
        optional |= maybe
        for f in more | _parents(rel):
            if f not in files:
                files.add(f)
                todo.append(f)
    return Bundle(tuple(sorted(files)), _distributions(third), tuple(sorted(optional - third)), behaviour)


def _distributions(modules: set[str]) -> tuple[str, ...]:
    """Distribution names providing the top-level ``modules`` (BuildError if one has none)."""
    provided = importlib.metadata.packages_distributions()
    dists = set()
    for module in sorted(modules):
        names = provided.get(module)
        if not names:
            raise BuildError(f"the bundled modules import {module!r}, which no installed distribution provides")
        dists.add(importlib.metadata.metadata(names[0])["Name"])
    return tuple(sorted(dists, key=str.lower))


def _manifest(dest: Path) -> Path:
    return dest / ".build-stamps" / "bundle.json"


def _read_bundle(dest: Path) -> Bundle | None:
    """The bundle recorded by the previous build into ``dest``, or None if there is none, one of
    its files is gone, or a data folder it carries files of has a new one (a new BEM preset)."""
    try:
        data = json.loads(_manifest(dest).read_text())
        bundle = Bundle(tuple(data["files"]), tuple(data["distributions"]), tuple(data["optional"]))
    except (OSError, ValueError, KeyError, TypeError):
        return None
    files = set(bundle.files)
    folders = {Path(f).parent for f in files if f.startswith(f"{DATA}/")}
    if not all((PACKAGE_DIR / f).is_file() for f in files) or any(
            (p.relative_to(PACKAGE_DIR).as_posix() not in files) for folder in folders
            for p in (PACKAGE_DIR / folder).iterdir() if p.is_file()):
        return None
    return bundle


def _write_bundle(dest: Path, bundle: Bundle) -> None:
    _manifest(dest).parent.mkdir(parents=True, exist_ok=True)
    _manifest(dest).write_text(json.dumps({"files": bundle.files, "distributions": bundle.distributions,
                                           "optional": bundle.optional}, indent=1))


def _fingerprint(script: Path, bundle: Bundle) -> str | None:
    """The stamp of ``script`` built with ``bundle``; None if a requirement is not installed or
    a bundled file is gone (the bundle is stale)."""
    h = hashlib.sha256()
    try:
        requirements = bundle.requirements(script.stem)
        h.update(pythonfmu.__version__.encode())
        h.update(script.read_bytes())
        for f in BUILD_FILES:
            h.update(f.read_bytes())
        for rel in bundle.files:
            h.update(rel.encode())
            h.update((PACKAGE_DIR / rel).read_bytes())
    except (importlib.metadata.PackageNotFoundError, FileNotFoundError):
        return None
    h.update(requirements.encode())
    return h.hexdigest()


def repack(raw: Path, fmu: Path, unit_table: dict[str, str], extra: dict[str, str] | None = None) -> None:
    """Copy the FMU pythonfmu wrote (``raw``) into ``fmu``, every entry deflated (pythonfmu stores
    them uncompressed), with units and initial unknowns added to its modelDescription.xml
    (:func:`marinefmu.fmu.units.postprocess_model_description`) and the ``extra`` files (path in
    the FMU → text) added."""
    with zipfile.ZipFile(raw) as zin, zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                data = units.postprocess_model_description(data, unit_table)
            item.compress_type = zipfile.ZIP_DEFLATED
            zout.writestr(item, data)
        for name, text in (extra or {}).items():
            zout.writestr(name, text)


def check_and_describe(fmu: Path, osp_file: Path) -> None:
    """Write the OSP model description of ``fmu`` to ``osp_file``, then validate both
    (``fmpy.validation.validate_fmu`` and :func:`marinefmu.fmu.osp.check`); an FMU with problems is
    deleted and refused."""
    with zipfile.ZipFile(fmu) as z:
        md_xml = z.read("modelDescription.xml")
    osp.write(md_xml, osp_file)
    problems = validate(fmu) + osp.check(md_xml, osp_file.read_bytes())
    if problems:
        fmu.unlink()
        raise BuildError(f"{fmu.name} failed validation:\n  " + "\n  ".join(problems))


def slave_units(script: Path) -> dict[str, str]:
    """Instantiate the script's slave (its ``__init__`` is cheap) and read its unit table."""
    spec = importlib.util.spec_from_file_location(f"_marinefmu_build_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    cls = getattr(module, script.stem)
    return cls(instance_name="build", resources=str(script.parent)).io.units


def _up_to_date(script: Path, dest: Path, bundle: Bundle | None) -> bool:
    fmu = dest / f"{script.stem}.fmu"
    stamp = dest / ".build-stamps" / f"{script.stem}.sha256"
    osp_file = dest / f"{script.stem}_OspModelDescription.xml"
    if bundle is None or not (fmu.exists() and osp_file.exists() and stamp.exists()):
        return False
    return stamp.read_text() == _fingerprint(script, bundle)


def _build(script: Path, dest: Path, bundle: Bundle) -> str:
    """Write ``dest/<stem>.fmu`` and its OSP model description and validate them; the FMU's
    fingerprint (written as its stamp once the FMU is verified)."""
    from pythonfmu.builder import FmuBuilder

    fmu = dest / f"{script.stem}.fmu"
    osp_file = dest / f"{script.stem}_OspModelDescription.xml"
    fingerprint = _fingerprint(script, bundle)
    if fingerprint is None:
        raise BuildError(f"{script.stem}: a file of the bundle or a requirement went away while building; build again")
    requirements = bundle.requirements(script.stem)
    dest.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        stage = Path(tmp) / "stage" / PACKAGE
        for rel in bundle.files:
            (stage / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(PACKAGE_DIR / rel, stage / rel)
        raw = Path(FmuBuilder.build_FMU(script, dest=Path(tmp) / "raw", project_files=[stage],
                                        canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        repack(raw, fmu, slave_units(script), {"resources/requirements.txt": requirements})
    check_and_describe(fmu, osp_file)
    return fingerprint


def _verified(built: dict[Path, str], dest: Path, bundle: Bundle) -> None:
    """Run every FMU of ``built`` (FMU -> fingerprint) from its own resources; write the stamps
    of those that pass, delete those that fail and raise BuildError naming them."""
    problems = verify_runs(list(built), bundle.behaviour)
    failed = {fmu: p for fmu, p in problems.items() if p}
    stamps = dest / ".build-stamps"
    stamps.mkdir(parents=True, exist_ok=True)
    for fmu, fingerprint in built.items():
        if fmu in failed:
            fmu.unlink()
        else:
            (stamps / f"{fmu.stem}.sha256").write_text(fingerprint)
    if failed:
        raise BuildError("\n".join(f"{fmu.name} failed to run from its own resources:\n  " + "\n  ".join(p)
                                   for fmu, p in failed.items()))


def build_one(script: Path, dest: Path, force: bool = False, bundle: Bundle | None = None) -> BuildResult:
    """Build ``script`` into ``dest/<stem>.fmu`` unless it is up to date, then validate and
    verify it (:func:`verify_runs`).

    ``bundle`` is what it carries of marinefmu (default: :func:`collect_bundle` of this script;
    :func:`build_all` passes the bundle of the whole folder).
    """
    bundle = collect_bundle([script]) if bundle is None else bundle
    fmu = dest / f"{script.stem}.fmu"
    if not force and _up_to_date(script, dest, bundle):
        return BuildResult(fmu, False)
    _verified({fmu: _build(script, dest, bundle)}, dest, bundle)
    return BuildResult(fmu, True)


def validate(fmu: Path) -> list[str]:
    """Problems reported by ``fmpy.validation.validate_fmu`` (empty when the FMU is valid)."""
    from fmpy.validation import validate_fmu

    return list(validate_fmu(str(fmu)))


_VERIFY = r"""
import importlib.machinery, json, math, os, sys
from pathlib import Path

hidden, work, steps, dt, instance = Path(sys.argv[1]), Path(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4]), sys.argv[5]


class HideBuildCopy:
    # The marinefmu the build used (an editable install's src/ or site-packages) cannot be
    # imported: only an FMU's resources may provide it.
    @staticmethod
    def find_spec(name, path=None, target=None):
        if name != "marinefmu":
            return None
        where = [p for p in sys.path if not (os.path.isdir(p) and Path(p).resolve() == hidden)]
        spec = importlib.machinery.PathFinder.find_spec(name, where)
        if spec is None:
            raise ModuleNotFoundError("No module named 'marinefmu' (the build's copy is hidden)", name=name)
        return spec


sys.meta_path.insert(0, HideBuildCopy)
from ctypes import byref
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
from fmpy.logging import addLoggerProxy


def ours(name):
    return name == "marinefmu" or name.startswith("marinefmu.")


def step(fmu, k):
    try:
        fmu.doStep(currentCommunicationPoint=k * dt, communicationStepSize=dt)
        return True
    except FMICallException:
        return False


for i, fmu_path in enumerate(sys.argv[6:]):
    md = read_model_description(fmu_path)
    # each FMU imports its own copy: forget the previous FMU's (numpy and the rest stay loaded)
    for name in [n for n in sys.modules if ours(n) or n == md.coSimulation.modelIdentifier]:
        del sys.modules[name]
    unzip = str(work / f"{i}")
    extract(fmu_path, unzipdir=unzip)
    messages = []

    def log(env, name, status, category, message, messages=messages):
        messages.append((int(status), message.decode(errors="replace") if message else ""))

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(log)
    addLoggerProxy(byref(callbacks))
    outputs = {t: [v.valueReference for v in md.modelVariables if v.causality == "output" and v.type == t]
               for t in ("Real", "Integer", "Boolean")}
    result = {"fmu": fmu_path, "error": None, "ok": []}
    try:
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName=instance)
        fmu.instantiate(loggingOn=True, callbacks=callbacks)
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        result["ok"] += [step(fmu, k) for k in range(steps)]
        state = fmu.getFMUstate()
        copy = fmu.deSerializeFMUstate(fmu.serializeFMUstate(state))
        fmu.setFMUstate(copy)
        fmu.freeFMUstate(copy)
        fmu.freeFMUstate(state)
        result["ok"] += [step(fmu, k) for k in range(steps, 2 * steps)]
        values = fmu.getReal(outputs["Real"]) if outputs["Real"] else []
        result["finite"] = all(math.isfinite(x) for x in values)
        if outputs["Integer"]:
            fmu.getInteger(outputs["Integer"])
        if outputs["Boolean"]:
            fmu.getBoolean(outputs["Boolean"])
        fmu.terminate()
        fmu.freeInstance()
    except Exception as exc:   # FMPy's FMICallException, or "Failed to instantiate FMU"
        result["error"] = f"{type(exc).__name__}: {exc}"
    result["errors"] = [m for s, m in messages if s >= 3]
    result["messages"] = [m for s, m in messages][-5:]
    result["outside"] = sorted(f"{name} from {getattr(m, '__file__', None)}" for name, m in list(sys.modules.items())
                               if ours(name) and not str(getattr(m, "__file__", "") or "").startswith(unzip + os.sep))
    result["loaded"] = "marinefmu" in sys.modules
    print(json.dumps(result), flush=True)
"""


def verify_runs(fmus: list[Path], expected: dict[str, dict] | None = None) -> dict[Path, list[str]]:
    """Problems found running each FMU of ``fmus`` under FMPy from its own resources (an empty
    list for one that runs).

    One fresh interpreter runs them one after the other. The ``marinefmu`` this build uses
    cannot be imported there, and before each FMU the previous one's ``marinefmu`` modules are
    dropped from ``sys.modules``, so each FMU imports its own (numpy and the other libraries
    stay loaded: a few seconds for all). Each is instantiated, initialised with its start
    values, stepped, its state got, serialised, read back and set, stepped again and
    terminated. Every FMI call but doStep must succeed (the outputs of every type are read), the
    real outputs be finite, every ``marinefmu`` module come from the FMU's own folder, and the
    steps' results and the messages logged with status error be those of the slave's traced run
    from the source tree (``expected``: :attr:`Bundle.behaviour`; without it, every step must
    succeed and nothing be logged as an error).
    """
    if not fmus:
        return {}
    what = "running it from its own resources"
    with tempfile.TemporaryDirectory() as tmp:
        try:
            done = subprocess.run([sys.executable, "-c", _VERIFY, str(PACKAGE_DIR.parent.resolve()), tmp,
                                   str(STEPS), str(STEP), INSTANCE, *(str(f.resolve()) for f in fmus)],
                                  capture_output=True, text=True, cwd=tmp, timeout=SUBPROCESS_TIMEOUT)
        except subprocess.TimeoutExpired:
            return {fmu: [f"{what}: no answer within {SUBPROCESS_TIMEOUT:.0f} s"] for fmu in fmus}
    results = {}
    for line in done.stdout.splitlines():
        try:
            r = json.loads(line)
        except json.JSONDecodeError:
            continue
        if isinstance(r, dict) and "fmu" in r:
            results[Path(r["fmu"])] = r
    problems: dict[Path, list[str]] = {}
    for fmu in fmus:
        r = results.get(fmu.resolve())
        if r is None:
            problems[fmu] = [f"{what}: the process ended (exit code {done.returncode}) before its result:\n"
                             f"{done.stderr[-3000:]}"]
            continue
        want = (expected or {}).get(fmu.stem, {"ok": [True] * (2 * STEPS), "errors": []})
        p = [f"{what}: {r['error']}; its last messages: {r['messages']}; stderr:\n{done.stderr[-2000:]}"] if r["error"] else []
        if not r["error"] and (r["ok"] != want["ok"] or r["errors"] != want["errors"]):
            p.append(f"{what}, its steps returned {r['ok']} and it logged {r['errors']}; from the source tree: "
                     f"{want['ok']} and {want['errors']}")
        if r["outside"]:
            p.append(f"{what}: modules from elsewhere: " + ", ".join(r["outside"]))
        if not r["loaded"]:
            p.append(f"{what}: marinefmu was never imported")
        if not r["error"] and not r.get("finite"):
            p.append(f"{what}: a real output is not finite")
        problems[fmu] = p
    if done.returncode != 0 and all(fmu.resolve() in results for fmu in fmus):
        for fmu in fmus:   # every run ended, but the process did not exit cleanly
            problems[fmu].append(f"{what}: the process exited with code {done.returncode}\n{done.stderr[-2000:]}")
    return problems


def build_all(models: Path | None = None, dest: Path | None = None, force: bool = False,
              verbose: bool = True) -> list[BuildResult]:
    """Build every ``models/*.py`` into ``dest`` (default ``fmus/`` of the checkout), each with
    the bundle of them all (the module doc)."""
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
            bundle = _read_bundle(dest)
            stale = [s for s in scripts if force or not _up_to_date(s, dest, bundle)]
            if stale:
                bundle = collect_bundle(scripts)
                _write_bundle(dest, bundle)
                stale = [s for s in stale if force or not _up_to_date(s, dest, bundle)]
            built = {dest / f"{s.stem}.fmu": _build(s, dest, bundle) for s in stale}
            _verified(built, dest, bundle)
            results = [BuildResult(dest / f"{s.stem}.fmu", s in stale) for s in scripts]
            if verbose:
                for result in results:
                    size = result.fmu.stat().st_size / 1e6
                    print(f"{'built  ' if result.rebuilt else 'up to date'} {result.fmu} ({size:.2f} MB)")
            return results
    finally:
        sys.path.remove(str(models))
