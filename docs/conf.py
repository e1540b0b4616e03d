"""Sphinx configuration of the marinefmu documentation site (built by ``make docs``).

Pages are MyST Markdown; the API reference comes from the docstrings (autodoc + numpydoc); each
FMU page's interface table is read from the built FMU (``docs/_ext/fmu_interface.py``), so the
FMUs must be built first (``make docs`` depends on ``make fmus``). The build needs no network:
no intersphinx inventories are fetched.
"""
from __future__ import annotations

import importlib
import inspect
import re
import sys
import unicodedata
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT / "src"))  # document this checkout, whatever is installed
sys.path.insert(0, str(DOCS / "_ext"))

import marinefmu  # noqa: E402

project = "marinefmu"
author = "marinefmu developers"
copyright = "marinefmu developers, MIT licence"
version = release = marinefmu.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "numpydoc",
    "fmu_interface",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# Markdown files in docs/ that are not pages of the site.
exclude_patterns = ["_build", "_ext", "README.md", "**/README.md"]

# MyST: ::: fences, definition lists, $...$ and $$...$$ maths; anchors for headings up to level 3
# so that links like [text](concepts.md#frames-and-signs) resolve.
myst_enable_extensions = ["colon_fence", "deflist", "dollarmath"]
myst_heading_anchors = 3

# autodoc + numpydoc: members in source order; numpydoc lists no class members itself (autodoc's
# :members: does), so that no object is described twice.
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # the numpydoc Parameters sections carry the types
autodoc_default_options = {"members": True}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_attributes_as_param_list = True
numpydoc_xref_param_type = False

html_theme = "pydata_sphinx_theme"
html_title = f"marinefmu {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_static_path: list[str] = []
html_show_sourcelink = False


# The docstrings are written to read as plain text too: |x| is an absolute value or a norm, not a
# reST substitution reference, and an inline literal may touch a symbol (``acc_noise``²,
# ±``max_command``), which reST does not take as the literal's end or start. So in every docstring
# autodoc renders: bars are escaped outside inline literals and roles (``...``, :math:`...`), maths
# and literal blocks, doctests, line blocks and grid tables; and an escaped space (rendered as
# nothing) separates an inline literal from such a neighbour.
_INLINE = re.compile(r"(``[^`].*?``|(?<!`)`[^`]+`(?!`))")  # on one line; one across lines is left
_BEFORE_OK = set(" \t'\"([{<-/:")
_AFTER_OK = set(" \t'\")]}>-/:.,;!?\\")


def _delimits(ch: str, ok: set[str], categories: tuple[str, ...]) -> bool:
    return ch == "" or ch in ok or unicodedata.category(ch) in categories


def _plain_text_line(line: str) -> str:
    parts = _INLINE.split(line)
    out = []
    for i, part in enumerate(parts):
        if i % 2 == 0:
            out.append(part.replace("|", r"\|"))
            continue
        literal = part.startswith("``")  # else interpreted text: a role's `...` (its prefix before)
        if literal and not _delimits(parts[i - 1][-1:], _BEFORE_OK, ("Ps", "Pi", "Pf", "Pd", "Po")):
            part = "\\ " + part
        after = parts[i + 1][:1]
        if not (_delimits(after, _AFTER_OK, ("Pe", "Pi", "Pf", "Pd", "Po")) or after == "_" and not literal):
            part = part + "\\ "
        out.append(part)
    return "".join(out)


_VERBATIM = (".. math::", ".. code-block::", ".. code::", ".. sourcecode::")


def _plain_bars(app, what, name, obj, options, lines: list[str]) -> None:
    block = None     # indentation of the line that opened a verbatim block (maths, code, ``::``)
    doctest = False  # inside a >>> block, which runs to the next blank line
    opener = ""      # the last non-blank line
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if block is not None:
            if not stripped or indent > block:
                continue
            block = None
        if doctest:
            if stripped:
                continue
            doctest = False
        if not stripped:
            continue
        if opener.rstrip().endswith("::") and indent > len(opener) - len(opener.lstrip()):
            block = len(opener) - len(opener.lstrip())  # a literal block after "text::"
            continue
        opener = line
        if stripped.startswith(">>>"):
            doctest = True
        elif stripped.startswith(_VERBATIM):
            block = indent
        elif not (stripped == "|" or stripped.startswith(("| ", "+-", "+="))):  # not a line block or grid table
            lines[i] = _plain_text_line(line)


# Relative cross-references (:mod:`.filter`, :class:`~.wave_coast.WaveCoast`) are written as in
# Python: relative to the package of the module they sit in. Sphinx reads a leading dot as "the
# current class, then the current module, then any name ending so", which finds two modules
# named ``filter``. Each such reference is resolved here, against the current class, the current
# module, then its package, and written out with its canonical target and the title Sphinx would
# have shown; one that does not resolve is left to Sphinx.
_RELATIVE = re.compile(r":(mod|class|func|meth|data|attr|exc|obj|const):`(~?)\.([A-Za-z_][\w.]*)`")


def _find(path: str):
    """The object at the dotted ``path`` and its canonical dotted name, or ``None``."""
    parts = path.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ImportError:
            continue
        owner = None
        for part in parts[i:]:
            owner, obj = obj, getattr(obj, part, _MISSING)
            if obj is _MISSING:
                return None
        if inspect.ismodule(obj):
            return obj.__name__
        if (inspect.isclass(obj) or inspect.isfunction(obj)) and obj.__module__.startswith("marinefmu"):
            return f"{obj.__module__}.{obj.__qualname__}"
        if inspect.isclass(owner) and owner.__module__.startswith("marinefmu"):
            return f"{owner.__module__}.{owner.__qualname__}.{parts[-1]}"
        return path
    return None


_MISSING = object()


def _contexts(what: str, name: str, obj) -> list[str]:
    """Where a relative reference in the docstring of ``name`` is looked up, in order."""
    if what == "module":
        module = name
    else:
        module = getattr(obj, "__module__", None)
        if not isinstance(module, str) or not module.startswith("marinefmu"):
            module = name.rsplit(".", 1)[0]
            while module and module not in sys.modules:
                module = module.rpartition(".")[0]
    bases = []
    if what == "class":
        bases.append(_find(name))
    elif what in ("method", "attribute", "property"):
        bases.append(_find(name.rsplit(".", 1)[0]))
    package = module if hasattr(sys.modules.get(module), "__path__") else module.rpartition(".")[0]
    return [b for b in (*bases, module, package) if b]


def _relative_refs(app, what, name, obj, options, lines: list[str]) -> None:
    if not any("`." in line or "`~." in line for line in lines):
        return
    contexts = _contexts(what, name, obj)
    tables = _simple_table_lines(lines)  # a longer cell would break the table's columns

    def absolute(match: re.Match) -> str:
        role, tilde, target = match.groups()
        for base in contexts:
            found = _find(f"{base}.{target}")
            if found:
                title = target.rsplit(".", 1)[-1] if tilde else target
                if role in ("func", "meth") and app.config.add_function_parentheses:
                    title += "()"
                return f":{role}:`{title} <{found}>`"
        return match.group(0)

    for i, line in enumerate(lines):
        if ("`." in line or "`~." in line) and i not in tables:
            lines[i] = _RELATIVE.sub(absolute, line)


_BORDER = re.compile(r"\s*=+( +=+)+\s*")


def _simple_table_lines(lines: list[str]) -> set[int]:
    """Indices of the lines inside simple reST tables (from the top border to the bottom one,
    the border followed by a blank line or the end)."""
    inside, start = set(), None
    for i, line in enumerate(lines):
        if not _BORDER.fullmatch(line):
            continue
        if start is None:
            start = i
        elif i + 1 == len(lines) or not lines[i + 1].strip():
            inside.update(range(start, i + 1))
            start = None
    return inside


def setup(app):
    app.connect("autodoc-process-docstring", _relative_refs, priority=590)
    app.connect("autodoc-process-docstring", _plain_bars, priority=600)  # after numpydoc's (500)
