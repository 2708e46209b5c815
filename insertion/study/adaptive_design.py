"""The domain of an adaptive sweep and its candidate runs: the ``[lhs]`` ranges of a sweep TOML
crossed with its ``[[grid]]`` cases.

The first round is the spec's own Latin hypercube (``[lhs] samples`` points per grid case). Each
later round draws a fresh, seeded Latin hypercube of :data:`POOL` points in the same ranges,
rounded as the spec's hypercube is (:func:`colonsim.insertion.study.sweep_spec.lhs_values`),
crosses it with every grid case, and leaves the choice among these candidates to the surrogate
(:func:`colonsim.surrogate.acquisition.greedy_batch`).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.study.sweep import input_row
from colonsim.insertion.study.sweep_spec import SCOPE_DIAMETER, latin_hypercube, lhs_values
from colonsim.surrogate.table import INPUTS

# Candidate points drawn per grid case and round: the chosen point is the best of these, so a
# larger pool only refines where in a region of high variance the run lands (the variance is
# smooth over a length scale of a fraction of the range); 1000 points cost 0.1-0.3 s per round and grid
# case (drawn, validated and scored; measured on the 3-input RSJ domain of the tests).
POOL = 1000


class AdaptiveDesign:
    """The continuous ranges and the grid cases of an adaptive sweep.

    Parameters
    ----------
    spec : SweepSpec
        A parsed sweep with an ``[lhs]`` table (:func:`colonsim.insertion.study.sweep_spec.load_sweep`).
    """

    def __init__(self, spec):
        if not spec.lhs_ranges:
            raise ColonsimError(f"--adaptive needs an [lhs] table in the sweep TOML (the ranges to choose runs in, "
                                f"e.g. diameter_mm = [20, 40]); sweep {spec.name!r} has none")
        not_inputs = [key for key, _, _ in spec.lhs_ranges if key not in INPUTS]
        if not_inputs:
            raise ColonsimError(f"--adaptive: [lhs] {', '.join(not_inputs)} is not an input of the surrogate, which "
                                f"chooses the runs; vary only {', '.join(INPUTS)} in [lhs] and put the rest in "
                                "[fixed] or [[grid]]")
        self.spec = spec
        self.ranges = list(spec.lhs_ranges)
        self.fields = {"scope" if key == SCOPE_DIAMETER else key for key, _, _ in self.ranges}
        self.templates = self._templates(spec.cases)

    def _templates(self, cases):
        """One case per grid case (the first round's case with the first hypercube point)."""
        templates = {}
        for case in cases:
            grid = tuple(sorted((k, repr(v)) for k, v in case.to_dict().items() if k not in self.fields))
            templates.setdefault(grid, case)
        return list(templates.values())

    @property
    def first_round(self) -> list:
        """The spec's own cases: its Latin hypercube crossed with its grid."""
        return list(self.spec.cases)

    def candidates(self, round_index: int, exclude=(), size: int = POOL) -> list:
        """Valid candidate cases of round ``round_index`` (seeded by the sweep's seed and the round),
        none of whose keys is in ``exclude``; in a reproducible order."""
        seed = int(np.random.SeedSequence([self.spec.seed, round_index]).generate_state(1)[0])
        values = lhs_values(self.ranges, latin_hypercube(size, len(self.ranges), seed))
        exclude, found = set(exclude), {}
        for template in self.templates:
            for point in values:
                case = dataclasses.replace(template, **point)
                key = case.key()
                if key in exclude or key in found:
                    continue
                try:
                    case.validate()  # e.g. a scope that does not fit a narrow colon in a corner of the ranges
                except ColonsimError:
                    continue
                found[key] = case
        return list(found.values())

    def inputs(self, case) -> dict:
        """The ``[lhs]`` values of ``case`` in the spec's keys and units (for the round log)."""
        row = input_row(case)
        return {key: float(row[key]) for key, _, _ in self.ranges}


def input_matrix(cases, names) -> np.ndarray:
    """The surrogate inputs ``names`` (results-table columns) of ``cases``, (n, d)."""
    rows = [input_row(case) for case in cases]
    return np.array([[float(row[name]) for name in names] for row in rows], dtype=float).reshape(len(rows), len(names))


__all__ = ["AdaptiveDesign", "POOL", "input_matrix"]
