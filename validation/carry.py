"""Sections of the validation report carried from the previous report when their sweep is not given.

The report's sweeps take about ten hours of two cores (the distal resistance sweep alone half of
that), more than one sitting of the machine that runs them. ``python -m validation.report --previous
OLD/report.json --carry`` regenerates what the given sweeps can give and takes every section whose
sweep was not given from OLD/report.json as it stands, instead of saying NOT RUN. A carried section
is marked with the report it comes from (date, commit) and the code that made its rows, and the
Markdown says so under its heading; carried again, it keeps its first mark. So the report can be
brought to a new engine one sweep at a time, each step landing, and every section says which engine
its numbers are from. The main sweep is always given: nothing read from it alone is carried.
"""

from __future__ import annotations

import copy

from .changes import section_at

# sweep label -> the report document's sections computed from that sweep (paths into the document)
SECTIONS = {
    "validation": (("header", "sweeps", "validation"), ("mesh_pair",), ("rate_check",), ("flexure_sensitivity",),
                   ("ringing", "sweeps", "validation"), ("run_ends", "validation")),
    "rate_angles": (("rate_check", "angles"),),
    "smoothness": (("smoothness", "cubic"),),
    "gp_train": (("smoothness", "surrogate"),),
    "gp_test": (("smoothness", "surrogate"),),
    "resistance": (("resistance",),),
}
# parts of a carried section that belong to another sweep and so stay as this report computed them
# (they are carried, or not, by that sweep's own entry above)
OWN_PARTS = {("rate_check",): ("angles",)}


def _mark(previous, label):
    """Where a section of ``previous`` was computed: its report's date and commit and, where that report
    described the sweep, the commits that made the sweep's rows."""
    header = previous.get("header", {})
    sweep = (header.get("sweeps") or {}).get(label) or {}
    return {"date": header.get("date"), "commit": header.get("commit"), "rows_code": sweep.get("code")}


def _ran(section):
    """Whether a section of a report was computed from a sweep that had run (not a NOT RUN section)."""
    return section.get("ran", (section.get("sweep") or {}).get("ran", True))


def carried_section(previous, label, path):
    """A copy of ``previous``'s section at ``path`` (computed from sweep ``label``), marked with where
    it was computed (a mark it already has is kept); None where ``previous`` has no such section or
    its sweep had not run there either."""
    old = section_at(previous, *path)
    if not isinstance(old, dict) or not _ran(old):
        return None
    section = copy.deepcopy(old)
    section.setdefault("carried_from", _mark(previous, label))
    return section


def carry(doc, previous, given):
    """Replace, in ``doc``, the sections of every sweep label whose ``given[label]`` is False by those of
    ``previous`` (both report documents as JSON holds them). Returns the labels carried, in order.
    A section ``previous`` does not have stays as ``doc`` has it (NOT RUN)."""
    carried = []
    for label, paths in SECTIONS.items():
        if given.get(label, True):
            continue
        for path in paths:
            section = carried_section(previous, label, path)
            if section is None:
                continue
            parent = section_at(doc, *path[:-1])
            for part in OWN_PARTS.get(path, ()):
                if part in parent[path[-1]]:
                    section[part] = parent[path[-1]][part]
            parent[path[-1]] = section
            if label not in carried:
                carried.append(label)
    return carried


def carried_lines(section) -> list:
    """The note under a carried section's heading; [] for a section this report computed."""
    mark = (section or {}).get("carried_from")
    if not mark:
        return []
    return [f"*Carried from the report of {mark.get('date')}: its sweep was not given to this report. Not "
            "recomputed by this report's code (the commits of that report and of the sweep's rows: "
            "`carried_from` in report.json).*", ""]
