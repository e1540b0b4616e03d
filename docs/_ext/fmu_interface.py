"""Sphinx extension: the ``fmu-interface`` directive, an FMU's interface table read from the built FMU.

In a MyST page::

    ```{fmu-interface} HeaveObserver
    :causality: parameter
    ```

renders one row per ScalarVariable of ``fmus/HeaveObserver.fmu``'s modelDescription.xml (name,
causality, variability, type, unit, start, allowed range, description), read by
:func:`marinefmu.fmu.interface_table.interface_rows`. ``:causality:`` keeps only the given
causalities (a comma list, e.g. ``input,output``). The folder of the FMUs is the config value
``fmu_interface_dir`` (default: ``fmus/`` beside ``docs/``). A missing FMU stops the build.
"""
from __future__ import annotations

from pathlib import Path

from docutils import nodes
from docutils.parsers.rst import Directive
from sphinx.errors import ExtensionError

from marinefmu.fmu.interface_table import interface_rows

CAUSALITIES = ("parameter", "calculatedParameter", "input", "output", "local", "independent")

HEADERS = (  # (row key, column title, relative width)
    ("name", "Name", 14),
    ("causality", "Causality", 8),
    ("variability", "Variability", 8),
    ("type", "Type", 6),
    ("unit", "Unit", 7),
    ("start", "Start", 7),
    ("range", "Allowed range", 11),
    ("description", "Description", 39),
)


def _causalities(argument: str) -> list[str]:
    values = [v.strip() for v in argument.split(",") if v.strip()]
    unknown = [v for v in values if v not in CAUSALITIES]
    if not values or unknown:
        raise ValueError(f"causality must be a comma list of {', '.join(CAUSALITIES)}; got {argument!r}")
    return values


class FmuInterface(Directive):
    """``fmu-interface NAME``: the table of the variables of ``<fmu_interface_dir>/NAME.fmu``."""

    required_arguments = 1
    optional_arguments = 0
    has_content = False
    option_spec = {"causality": _causalities}

    def run(self) -> list[nodes.Node]:
        env = self.state.document.settings.env
        name = self.arguments[0]
        folder = Path(env.config.fmu_interface_dir or Path(env.srcdir).parent / "fmus")
        path = folder / f"{name}.fmu"
        if not path.is_file():
            raise ExtensionError(
                f"fmu-interface: {path} does not exist (page {env.docname}). Build the FMUs first: "
                "run `make fmus` (`make docs` does it)")
        env.note_dependency(str(path))
        rows = interface_rows(path)
        wanted = self.options.get("causality")
        if wanted:
            rows = [r for r in rows if r["causality"] in wanted]
        if not rows:
            return [self.state.document.reporter.warning(
                f"fmu-interface: {name} has no variable of causality {', '.join(wanted or [])}",
                line=self.lineno)]
        return [_table(rows)]


def _cell(text: str, literal: bool = False) -> nodes.entry:
    entry = nodes.entry()
    if text:
        entry += nodes.paragraph("", "", nodes.literal(text, text) if literal else nodes.Text(text))
    return entry


def _table(rows: list[dict[str, str]]) -> nodes.table:
    table = nodes.table(classes=["fmu-interface"])
    group = nodes.tgroup(cols=len(HEADERS))
    table += group
    for _, _, width in HEADERS:
        group += nodes.colspec(colwidth=width)
    head = nodes.thead()
    group += head
    header = nodes.row()
    for _, title, _ in HEADERS:
        header += _cell(title)
    head += header
    body = nodes.tbody()
    group += body
    for r in rows:
        shown = dict(r)
        if r["unit"] and r["description"].endswith(f" [{r['unit']}]"):  # the unit has its column
            shown["description"] = r["description"][: -len(r["unit"]) - 3]
        row = nodes.row()
        for key, _, _ in HEADERS:
            row += _cell(shown[key], literal=key in ("name", "start") and r[key] != "")
        body += row
    return table


def setup(app):
    app.add_config_value("fmu_interface_dir", None, "env")
    app.add_directive("fmu-interface", FmuInterface)
    return {"version": "1.0", "parallel_read_safe": True, "parallel_write_safe": True}
