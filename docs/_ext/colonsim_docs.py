"""Reference tables of the documentation site generated from the code, so that they cannot drift.

Directives (used in ``docs/reference/*.md``):

``colonsim-columns``
    The results table's columns, from :data:`colonsim.catalog.COLUMNS` (name, kind, unit,
    surrogate role, meaning).
``colonsim-parameters``
    Every field of :class:`colonsim.insertion.case.insertion_case.InsertionCase`: its default (read
    from the class), unit, whether it is a study input, a modelling **assumption** or a numerical
    setting, and its description (from the class docstring). A field without a classification
    below fails the build, so a new parameter cannot enter the reference unclassified.
``colonsim-constants``
    The model's fixed constants that are not case fields, read from the modules that define them.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import re

from docutils import nodes
from sphinx.errors import ExtensionError
from sphinx.util.docutils import SphinxDirective

INPUT, ASSUMPTION, NUMERICAL = "input", "assumption", "numerical"

# field -> (unit, flag). The unit is the user's unit at the command line and in sweep files.
PARAMETERS = {
    "segment": ("", INPUT),
    "centerline": ("CSV file", INPUT),
    "centerline_smoothing_mm": ("mm", ASSUMPTION),
    "scope": ("name or mm", INPUT),
    "diameter_mm": ("mm", INPUT),
    "angle_deg": ("deg", INPUT),
    "flexure_angle_deg": ("deg", ASSUMPTION),
    "friction": ("", INPUT),
    "wall_thickness_mm": ("mm", ASSUMPTION),
    "material": ("JSON file", INPUT),
    "element_size_mm": ("mm", NUMERICAL),
    "scope_spacing_mm": ("mm", NUMERICAL),
    "push_speed": ("m/s", NUMERICAL),
    "held_push_share": ("", NUMERICAL),
    "held_push_lead_mm": ("mm", NUMERICAL),
    "held_push_pace": ("", NUMERICAL),
    "straighten_speed_factor": ("", NUMERICAL),
    "ramp_s": ("s", NUMERICAL),
    "relax_s": ("s", NUMERICAL),
    "relax_max_s": ("s", NUMERICAL),
    "stop_distance_mm": ("mm", NUMERICAL),
    "settle_s": ("s", NUMERICAL),
    "settle_max_s": ("s", NUMERICAL),
    "settle_lateral_damping": ("1/s", NUMERICAL),
    "exit_length_mm": ("mm", ASSUMPTION),
    "distal_resistance_N": ("N", ASSUMPTION),
    "failure_stretch": ("", ASSUMPTION),
    "sheath_reserve_mm": ("mm", ASSUMPTION),
    "colon_damping": ("1/s", NUMERICAL),
    "scope_damping": ("1/s", NUMERICAL),
    "scope_lateral_damping": ("1/s", NUMERICAL),
    "scope_axial_damping_s": ("s", NUMERICAL),
    "record_interval_s": ("s", NUMERICAL),
    "time_step_factor": ("", NUMERICAL),
    "material_parameters": ("Pa", INPUT),
    "stiffness_factor": ("", INPUT),
    "time_step_estimate": ("", NUMERICAL),
    "contact_surface": ("", NUMERICAL),
    "contact_face_subdivision": ("", NUMERICAL),
}

# (module, name, unit, flag, meaning): constants of the model that no case field sets
CONSTANTS = (
    ("colonsim.catalog", "SCOPE_YOUNGS_MODULUS", "Pa", ASSUMPTION,
     "the scope's Young's modulus, from the flexural rigidity of a 3-point bending test"),
    ("colonsim.catalog", "SCOPE_DENSITY", "kg/m^3", ASSUMPTION, "the scope's density"),
    ("colonsim.insertion.case.scenario", "COLON_DENSITY", "kg/m^3", ASSUMPTION, "the colon wall's density"),
    ("colonsim.insertion.case.scenario", "DISTAL_RAMP", "m", ASSUMPTION,
     "length of exit over which the distal resistance engages"),
    ("colonsim.insertion.case.scenario", "DISTAL_CREEP_SHARE", "", NUMERICAL,
     "the distal resistance's regularisation speed, as a share of the held push's speed"),
    ("colonsim.catalog", "SMOKE_ELEMENT_MM", "mm", NUMERICAL,
     "wall mesh of the tests, the notebooks at reduced size and the smoke preset (not a result)"),
    ("colonsim.catalog", "SMOKE_SCOPE_SPACING_MM", "mm", NUMERICAL, "scope node spacing at the smoke size"),
    ("colonsim.catalog", "SMOKE_PUSH_SPEED", "m/s", NUMERICAL, "push speed at the smoke size"),
)


def _field_docs(cls) -> dict:
    """{field: description} from the ``Attributes`` section of a numpydoc class docstring."""
    doc = inspect.getdoc(cls) or ""
    section = doc.split("Attributes\n----------\n", 1)[-1]
    found, names, lines = {}, [], []
    for line in section.splitlines() + ["end : end"]:
        head = re.match(r"^([a-z_][a-zA-Z0-9_, ]*) : ", line)
        if head:
            for name in names:
                found[name] = " ".join(lines)
            names = [n.strip() for n in head.group(1).split(",")]
            lines = []
        elif names and line.strip():
            lines.append(line.strip())
    return {name: _plain(text) for name, text in found.items()}


def _plain(text) -> str:
    """Docstring markup as plain text: ``x`` and :role:`~a.b.x` become x, **x** stays x."""
    text = re.sub(r":[a-z]+:`~?([^`]+)`", r"\1", text)
    return text.replace("``", "").replace("**", "")


def _text(value) -> str:
    return "" if value is None else str(value)


def _table(header, rows, widths):
    """A docutils table: the first column as code, the others as text."""
    table = nodes.table()
    group = nodes.tgroup(cols=len(header))
    table += group
    for width in widths:
        group += nodes.colspec(colwidth=width)

    def row(cells, code_first):
        tr = nodes.row()
        for i, cell in enumerate(cells):
            entry = nodes.entry()
            paragraph = nodes.paragraph()
            paragraph += nodes.literal(text=cell) if (i == 0 and code_first and cell) else nodes.Text(cell)
            entry += paragraph
            tr += entry
        return tr

    thead = nodes.thead()
    thead += row(header, False)
    group += thead
    body = nodes.tbody()
    for cells in rows:
        body += row(cells, True)
    group += body
    return table


class ColumnsDirective(SphinxDirective):
    def run(self):
        from colonsim.catalog import COLUMNS

        rows = [(c.name, c.kind, c.unit, c.surrogate, c.description + (f" (set by {c.option})" if c.option else ""))
                for c in COLUMNS.values()]
        return [_table(("column", "kind", "unit", "surrogate role", "meaning"), rows, (22, 9, 6, 10, 53))]


def parameter_rows() -> list:
    """(field, default, unit, kind, description) of every InsertionCase field; an unclassified
    field, or a classification of a field that no longer exists, is an error naming the fix."""
    from colonsim.insertion.case.insertion_case import InsertionCase

    docs = _field_docs(InsertionCase)
    names = [f.name for f in dataclasses.fields(InsertionCase)]
    missing = [n for n in names if n not in PARAMETERS]
    if missing:
        raise ExtensionError(f"InsertionCase field(s) {missing} have no unit and kind in docs/_ext/colonsim_docs.py "
                             "PARAMETERS: classify each (input, assumption or numerical)")
    unknown = sorted(set(PARAMETERS) - set(names))
    if unknown:
        raise ExtensionError(f"docs/_ext/colonsim_docs.py PARAMETERS names fields InsertionCase does not have: {unknown}")
    rows = []
    for field in dataclasses.fields(InsertionCase):
        unit, flag = PARAMETERS[field.name]
        default = field.default if field.default is not dataclasses.MISSING else "(required)"
        rows.append((field.name, _text(default), unit, flag, docs.get(field.name, "")))
    return rows


class ParametersDirective(SphinxDirective):
    def run(self):
        return [_table(("parameter", "default", "unit", "kind", "meaning"), parameter_rows(), (20, 8, 8, 10, 54))]


class ConstantsDirective(SphinxDirective):
    def run(self):
        rows = []
        for module, name, unit, flag, meaning in CONSTANTS:
            value = getattr(importlib.import_module(module), name)
            rows.append((name, f"{value:g}" if isinstance(value, float) else str(value), unit, flag,
                         f"{meaning} ({module})"))
        return [_table(("constant", "value", "unit", "kind", "meaning"), rows, (22, 8, 8, 10, 52))]


def setup(app):
    app.add_directive("colonsim-columns", ColumnsDirective)
    app.add_directive("colonsim-parameters", ParametersDirective)
    app.add_directive("colonsim-constants", ConstantsDirective)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
