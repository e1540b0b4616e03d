"""The design's import rules, read from the source with ``ast`` (every import statement counts,
also one inside a function or under ``TYPE_CHECKING``):

- nothing in ``sea/`` imports an estimator;
- nothing in ``sea/`` or ``estimators/`` imports FMPy or pythonfmu, nor the packages that make
  FMUs, run systems or use the models (``fmu``, ``cosim``, ``analysis``, ``bench``, ``campaign``,
  ``papers``, ``cli``), so that a model can be used, tested and benchmarked without them;
- an estimator package imports only the shared modules (``frames``, ``errors``,
  ``estimators.numerics``, ``.samples``, ``.protocol``, ``.noise_meter``) and itself; the GNSS fusion's wave coast
  (``estimators.gnss_fusion.wave_coast`` and its band observer ``.aided_band``) may also use
  paper 003's observer and its oscillator bank (``estimators.heave``), which it runs on the
  fusion's own acceleration during a GNSS dropout; the motion reference unit (``estimators.mru``)
  composes the attitude estimator and paper 003's Wiener axis filter, as one FMU;
- the heave compensation's winch, controller and design import only estimators, sea and the shared
  modules (``ahc.loop`` runs systems);
- no module uses another module's private name (``from x import _y`` or ``x._y``).
"""
from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

import pytest

import marinefmu

SRC = Path(marinefmu.__file__).resolve().parent
PACKAGE = "marinefmu"

SHARED = ("marinefmu.frames", "marinefmu.errors", "marinefmu.estimators.numerics", "marinefmu.estimators.samples",
          "marinefmu.estimators.protocol", "marinefmu.estimators.noise_meter")
ESTIMATOR_PACKAGES = ("attitude", "reconstruction", "gnss_fusion", "centre_of_rotation", "heave", "mru")
# module -> packages it may import beyond the shared modules and its own package
ALLOWED_BEYOND = {"marinefmu.estimators.gnss_fusion.wave_coast": ("marinefmu.estimators.heave",),
                  "marinefmu.estimators.gnss_fusion.aided_band": ("marinefmu.estimators.heave",),
                  "marinefmu.estimators.mru.params": ("marinefmu.estimators.attitude", "marinefmu.estimators.heave"),
                  "marinefmu.estimators.mru.unit": ("marinefmu.estimators.attitude", "marinefmu.estimators.heave")}
USERS_OF_MODELS = tuple(f"marinefmu.{p}" for p in ("fmu", "cosim", "analysis", "bench", "campaign", "papers", "cli"))
FMI_LIBRARIES = ("fmpy", "pythonfmu")


@dataclass(frozen=True)
class Import:
    module: str   # the importing module
    target: str   # the module imported (absolute; a name from a module resolves to the module)
    name: str     # the name taken from it ("" for ``import x``)
    line: int

    def __str__(self) -> str:
        what = f"from {self.target} import {self.name}" if self.name else f"import {self.target}"
        return f"{self.module}:{self.line}: {what}"


def module_name(path: Path) -> str:
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join([PACKAGE, *parts])


def is_module(name: str) -> bool:
    """Whether ``name`` (absolute) is a module or package of marinefmu."""
    if name != PACKAGE and not name.startswith(PACKAGE + "."):
        return False
    rel = Path(*name.split(".")[1:]) if "." in name else Path()
    return (SRC / rel).with_suffix(".py").is_file() or (SRC / rel / "__init__.py").is_file()


def public_home(name: str) -> str:
    """Where ``from marinefmu import <name>`` really comes from (the lazy public API)."""
    value = getattr(marinefmu, name, None)
    home = getattr(value, "__module__", None)
    return home if isinstance(home, str) and home.startswith(PACKAGE + ".") else PACKAGE


def package_of(path: Path) -> str:
    """The package a relative import in ``path`` starts from."""
    module = module_name(path)
    return module if path.name == "__init__.py" else module.rpartition(".")[0]


def resolve(path: Path, node: ast.Import | ast.ImportFrom) -> list[Import]:
    """One statement's imports, absolute, one per name: ``from pkg import sub`` resolves to the
    module ``pkg.sub`` if there is one, ``from marinefmu import Name`` to the module defining it."""
    module = module_name(path)
    if isinstance(node, ast.Import):
        return [Import(module, a.name, "", node.lineno) for a in node.names]
    if node.level:
        up = package_of(path).split(".")
        base_parts = up[: len(up) - (node.level - 1)]
        assert base_parts, f"{module}:{node.lineno}: relative import beyond the package"
        base = ".".join(base_parts + ([node.module] if node.module else []))
    else:
        base = node.module
    found = []
    for a in node.names:
        if is_module(f"{base}.{a.name}"):
            found.append(Import(module, f"{base}.{a.name}", "", node.lineno))
        elif base == PACKAGE:
            found.append(Import(module, public_home(a.name), a.name, node.lineno))
        else:
            found.append(Import(module, base, a.name, node.lineno))
    return found


def imports_of(path: Path) -> list[Import]:
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    return [i for node in ast.walk(tree) if isinstance(node, (ast.Import, ast.ImportFrom)) for i in resolve(path, node)]


def private_attributes_of(path: Path) -> list[str]:
    """``alias._name`` where ``alias`` is bound to a marinefmu module by an import in this file."""
    module = module_name(path)
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    aliases: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.asname and within(a.name, (PACKAGE,)):
                    aliases.add(a.asname)
                elif not a.asname and a.name.split(".")[0] == PACKAGE:
                    aliases.add(PACKAGE)
        elif isinstance(node, ast.ImportFrom):
            for imp, a in zip(resolve(path, node), node.names):
                if imp.name == "" and within(imp.target, (PACKAGE,)) and imp.target != module:
                    aliases.add(a.asname or a.name)
    return [f"{module}:{node.lineno}: {node.value.id}.{node.attr}" for node in ast.walk(tree)
            if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in aliases
            and is_private(node.attr)]


def is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def within(target: str, packages) -> bool:
    return any(target == p or target.startswith(p + ".") for p in packages)


MODULES = sorted(SRC.rglob("*.py"))
IMPORTS = {module_name(p): imports_of(p) for p in MODULES}


def in_package(prefix: str) -> dict[str, list[Import]]:
    return {m: imps for m, imps in IMPORTS.items() if within(m, (prefix,))}


def test_the_source_tree_is_read():
    names = set(IMPORTS)
    assert {"marinefmu.sea.motion_model", "marinefmu.estimators.heave.observer", "marinefmu.fmu.tables"} <= names
    assert sum(len(v) for v in IMPORTS.values()) > 200


def test_relative_imports_resolve_to_modules_of_the_package():
    """Every marinefmu import names a module that exists (the resolution the rules rely on)."""
    bad = [str(i) for imps in IMPORTS.values() for i in imps
           if within(i.target, (PACKAGE,)) and not is_module(i.target)]
    assert not bad, "\n".join(bad)


def test_sea_imports_no_estimator():
    bad = [str(i) for imps in in_package("marinefmu.sea").values() for i in imps
           if within(i.target, ("marinefmu.estimators",))]
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("package", ["marinefmu.sea", "marinefmu.estimators"])
def test_models_import_no_fmi_library_and_nothing_that_uses_them(package):
    bad = [str(i) for imps in in_package(package).values() for i in imps
           if within(i.target, FMI_LIBRARIES + USERS_OF_MODELS)]
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("name", ESTIMATOR_PACKAGES)
def test_an_estimator_package_imports_only_the_shared_modules_and_itself(name):
    own = f"marinefmu.estimators.{name}"
    modules = in_package(own)
    assert modules, own
    bad = [str(i) for m, imps in modules.items() for i in imps
           if within(i.target, (PACKAGE,)) and not within(i.target, (own, *SHARED, *ALLOWED_BEYOND.get(m, ())))]
    assert not bad, "\n".join(bad)


@pytest.mark.parametrize("module", ["marinefmu.ahc.winch", "marinefmu.ahc.controller", "marinefmu.ahc.design"])
def test_the_heave_compensation_physics_and_design_use_only_estimators_sea_and_shared(module):
    """The winch, the controller and their design are models: they run without FMI or a system
    runner (only ``ahc.loop`` runs systems)."""
    allowed = ("marinefmu.ahc", "marinefmu.estimators", "marinefmu.sea", "marinefmu.frames", "marinefmu.errors")
    bad = [str(i) for i in IMPORTS[module] if within(i.target, (PACKAGE,)) and not within(i.target, allowed)]
    bad += [str(i) for i in IMPORTS[module] if within(i.target, FMI_LIBRARIES)]
    assert not bad, "\n".join(bad)


def test_the_shared_estimator_modules_import_no_estimator():
    shared = [m for m in SHARED if m.startswith("marinefmu.estimators.")] + ["marinefmu.estimators"]
    bad = [str(i) for m in shared for i in IMPORTS[m]
           if within(i.target, tuple(f"marinefmu.estimators.{p}" for p in ESTIMATOR_PACKAGES))]
    assert not bad, "\n".join(bad)


def test_the_allowed_exception_is_still_needed():
    """An exception to the rules that the code no longer uses is removed from the rules."""
    for module, packages in ALLOWED_BEYOND.items():
        for package in packages:
            assert any(within(i.target, (package,)) for i in IMPORTS[module]), (module, package)


def test_no_module_imports_a_private_name_from_another():
    bad = [str(i) for m, imps in IMPORTS.items() for i in imps
           if within(i.target, (PACKAGE,)) and i.target != m and is_private(i.name)]
    bad += [str(i) for imps in IMPORTS.values() for i in imps
            if within(i.target, (PACKAGE,)) and any(is_private(p) for p in i.target.split("."))]
    assert not bad, "\n".join(bad)


def test_no_module_reads_a_private_name_of_another_through_its_module():
    bad = [b for p in MODULES for b in private_attributes_of(p)]
    assert not bad, "\n".join(bad)
