"""The training domain of a segment's model, and the check of a query against it.

A GP answers anywhere, but away from the runs it only returns its prior: the mean drifts back to
the average run and the interval widens. A query outside the box spanned by the runs, or one that
sets an input the sweep held fixed to another value, is therefore flagged: a warning by default,
an error with ``strict``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from colonsim.errors import ColonsimError
from surrogate.table import INPUT_OPTIONS

# Relative slack of the bounds (a fraction of the range, or of the value for a fixed input), so
# that round-off in a query ("9.2" vs 9.200000001) is not "outside".
TOLERANCE = 1e-6


class OutOfDomainWarning(UserWarning):
    """A query lies outside the inputs the surrogate was trained on: its prediction is an extrapolation."""


@dataclass
class SegmentDomain:
    """Inputs of one segment's model: the varying ones with their range, the fixed ones with their value."""

    segment: str
    inputs: list  # names of the model's inputs, in column order
    low: np.ndarray
    high: np.ndarray
    fixed: dict  # input -> the one value every run used
    n_runs: int
    scopes: dict = field(default_factory=dict)  # scope name -> diameter (mm) the runs used
    settings: dict = field(default_factory=dict)  # solver setting -> values the runs used

    def to_dict(self):
        return {"segment": self.segment, "n_runs": self.n_runs,
                "inputs": {n: [float(lo), float(hi)] for n, lo, hi in zip(self.inputs, self.low, self.high)},
                "fixed": self.fixed, "scopes_mm": self.scopes, "settings": self.settings}

    @classmethod
    def from_dict(cls, doc):
        names = list(doc["inputs"])
        bounds = np.array([doc["inputs"][n] for n in names], dtype=float).reshape(len(names), 2)
        return cls(doc["segment"], names, bounds[:, 0], bounds[:, 1], {k: float(v) for k, v in doc["fixed"].items()},
                   int(doc["n_runs"]), {k: float(v) for k, v in doc.get("scopes_mm", {}).items()}, doc.get("settings", {}))

    def describe(self):
        """One line: the model's inputs with their ranges and the fixed values."""
        parts = [f"{n} {lo:g}-{hi:g}" for n, lo, hi in zip(self.inputs, self.low, self.high)]
        parts += [f"{n} = {v:g} (fixed)" for n, v in self.fixed.items()]
        return f"{self.segment}: {self.n_runs} runs; " + ", ".join(parts)

    def matrix(self, query: dict, n=None):
        """The model's input matrix (n, d) from ``query`` (input name -> scalar or array).

        Inputs the model does not have are checked against their fixed value by :meth:`check`,
        not used here. A missing model input is an error naming it and its range."""
        missing = [name for name in self.inputs if query.get(name) is None]
        if missing:
            ranges = ", ".join(f"{m} ({self.low[self.inputs.index(m)]:g}-{self.high[self.inputs.index(m)]:g} in the runs; "
                               f"{INPUT_OPTIONS.get(m, m)} on the command line)" for m in missing)
            raise ColonsimError(f"segment {self.segment}: give {ranges}; the surrogate depends on it")
        cols = [np.atleast_1d(np.asarray(query[name], dtype=float)) for name in self.inputs]
        if n is None:
            n = max([len(c) for c in cols], default=1)
        X = np.column_stack([np.broadcast_to(c, (n,)) for c in cols]) if cols else np.zeros((n, 0))
        if np.isnan(X).any():
            i, j = np.argwhere(np.isnan(X))[0]
            raise ColonsimError(f"segment {self.segment}: query {i + 1} lacks {self.inputs[j]}; the surrogate depends on it")
        return X

    def check(self, query: dict, n=None, strict=False, warn=True):
        """The model's input matrix of ``query`` and the rows outside the domain.

        Returns (X, inside, reasons): the (n, d) inputs, a boolean array and, per row, a text naming
        the offending inputs ("" inside). Raises :class:`ColonsimError` with ``strict``; otherwise warns once
        (:class:`OutOfDomainWarning`) when ``warn``."""
        X = self.matrix(query, n)
        reasons = [[] for _ in range(len(X))]
        span = np.maximum(self.high - self.low, 0.0)
        below = X < self.low - TOLERANCE * span
        above = X > self.high + TOLERANCE * span
        for j, name in enumerate(self.inputs):
            for i in np.flatnonzero(below[:, j] | above[:, j]):
                reasons[i].append(f"{name} {X[i, j]:g} outside {self.low[j]:g}-{self.high[j]:g}")
        for name, value in self.fixed.items():
            given = query.get(name)
            if given is None:
                continue
            arr = np.broadcast_to(np.atleast_1d(np.asarray(given, dtype=float)), (len(X),))
            off = np.abs(arr - value) > TOLERANCE * max(1.0, abs(value))  # NaN = not given: not off
            for i in np.flatnonzero(off):
                reasons[i].append(f"{name} {arr[i]:g} but every {self.segment} run used {value:g}")
        text = ["; ".join(r) for r in reasons]
        inside = np.array([not r for r in reasons], dtype=bool)
        if not inside.all():
            first = int(np.flatnonzero(~inside)[0])
            where = f"query {first + 1} of {len(X)}: " if len(X) > 1 else ""
            message = (f"{self.segment} {where}{text[first]} (outside the training domain; the prediction "
                       "extrapolates)")
            if strict:
                raise ColonsimError(message.replace("the prediction extrapolates", "drop --strict to extrapolate anyway"))
            if warn:
                extra = f" and {int((~inside).sum()) - 1} more" if (~inside).sum() > 1 else ""
                warnings.warn(message + extra, OutOfDomainWarning, stacklevel=3)
        return X, inside, text
