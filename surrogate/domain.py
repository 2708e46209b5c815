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

from colonsim.catalog import TISSUE_STIFFNESS, WALL_C11, WALL_MU0, column_unit
from colonsim.input_ranges import INPUT_RANGES, check_input_range
from colonsim.errors import ColonsimError, ColonsimWarning
from colonsim.surrogate.table import INPUT_OPTIONS, INPUTS

# Relative slack of the bounds (a fraction of the range, or of the value for a fixed input), so
# that round-off in a query ("9.2" vs 9.200000001) is not "outside".
TOLERANCE = 1e-6
# Farther than this many training ranges outside the domain a query is no extrapolation but a slip
# (a unit, a typo): the GP's length scales are at most 100 ranges, so there it returns its prior
# whatever the value, and squared distances of ~1e154 ranges overflow to NaN.
FAR = 1e4
# beside every number answered outside the training domain
EXTRAPOLATED = "[EXTRAPOLATED]"


def _is_number(value) -> bool:
    try:
        float(np.nan if value is None else value)
    except (TypeError, ValueError):
        return False
    return True


class OutOfDomainWarning(ColonsimWarning):
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

    def _matrix(self, query: dict, n=None):
        """The model's input matrix (n, d) from ``query`` (input name -> float array, as
        :meth:`check` has read it with :meth:`numbers`).

        Inputs the model does not have are checked against their fixed value by :meth:`check`,
        not used here. A missing model input is an error naming it and its range."""
        missing = [name for name in self.inputs if query.get(name) is None]
        if missing:
            ranges = ", ".join(f"{m} ({self.low[self.inputs.index(m)]:g}-{self.high[self.inputs.index(m)]:g} in the runs; "
                               f"{INPUT_OPTIONS.get(m, m)} on the command line)" for m in missing)
            raise ColonsimError(f"segment {self.segment}: give {ranges}; the surrogate depends on it")
        cols = [query[name] for name in self.inputs]
        if n is None:
            n = max([len(c) for c in cols], default=1)
        X = np.empty((n, len(cols)))
        for j, c in enumerate(cols):
            X[:, j] = c  # a single value fills its column
        if np.isnan(X).any():
            i, j = np.argwhere(np.isnan(X))[0]
            raise ColonsimError(f"segment {self.segment}: query {i + 1} lacks {self.inputs[j]}; the surrogate depends on it")
        return X

    @property
    def _numeric(self):
        """The query's names :meth:`check` reads as numbers: ranged, candidate, model and fixed inputs."""
        return INPUT_RANGES.keys() | set(INPUTS) | set(self.inputs) | set(self.fixed)

    def numbers(self, values, name) -> np.ndarray:
        """``values`` of input ``name`` as a float array (NaN = not given); a text that is no number
        or an infinite value is an error naming the query and the input."""
        if isinstance(values, np.ndarray) and values.dtype == np.float64:
            raw, out = None, np.atleast_1d(values)
        elif isinstance(values, (float, int, np.floating, np.integer)):  # one query's value: no object array
            raw, out = None, np.array([float(values)])
        else:
            raw = np.atleast_1d(np.asarray(values, dtype=object))
            try:
                out = raw.astype(float)
            except (TypeError, ValueError):
                i = next(i for i, v in enumerate(raw) if not _is_number(v))
                raise ColonsimError(f"segment {self.segment}: query {i + 1} has {name} = {raw[i]!r}; "
                                    "give a number") from None
        infinite = np.isinf(out)
        if infinite.any():
            i = np.flatnonzero(infinite)[0]
            shown = float(out[i]) if raw is None else raw[i]
            raise ColonsimError(f"segment {self.segment}: query {i + 1} has {name} = {shown!r}; give a finite number")
        return out

    def _check_ranges(self, query: dict):
        """Refuse a query value no insertion accepts (a negative diameter, friction above 2, ...):
        the ranges of :data:`colonsim.input_ranges.INPUT_RANGES`, which ``colonsim insert`` applies too.
        ``query``: input name -> float array (:meth:`check` has read it)."""
        with np.errstate(invalid="ignore"):
            for name, numbers in query.items():
                if name in INPUT_RANGES and numbers is not None:
                    low, high, _ = INPUT_RANGES[name]
                    outside = (numbers < low) | (numbers > high)  # NaN (not given) is neither
                    if outside.any():  # the first one, in the words of colonsim insert
                        i = np.flatnonzero(outside)[0]
                        check_input_range(name, numbers[i], f"segment {self.segment}: query {i + 1}: ")

    def _unknown_inputs(self, query: dict) -> list:
        """Candidate inputs the query sets but the model has neither as an input nor as a fixed
        value (the results table had no such column): the model cannot answer for them.
        ``query``: input name -> float array (:meth:`check` has read it)."""
        return [name for name in INPUTS if name not in self.inputs and name not in self.fixed
                and query.get(name) is not None and not np.isnan(query[name]).all()]

    def check(self, query: dict, n=None, strict=False, warn=True):
        """The model's input matrix of ``query`` and the rows outside the domain.

        Returns (X, inside, reasons): the (n, d) inputs, a boolean array and, per row, a text naming
        the offending inputs ("" inside). Raises :class:`ColonsimError` with ``strict``; otherwise warns once
        (:class:`OutOfDomainWarning`) when ``warn``."""
        # each value a number once, not in every check below (a query's cost: measured)
        numeric = self._numeric
        query = {name: self.numbers(values, name) if values is not None and name in numeric else values
                 for name, values in query.items()}
        self._check_ranges(query)
        unknown = self._unknown_inputs(query)
        if unknown and TISSUE_STIFFNESS in self.inputs and set(unknown) <= {WALL_MU0, WALL_C11}:
            raise ColonsimError(f"segment {self.segment}: this model takes the tissue as its stiffness factor "
                                f"({TISSUE_STIFFNESS}), not as {', '.join(unknown)}; give --stiffness or --material FILE")
        if unknown:
            options = ", ".join(INPUT_OPTIONS.get(u, u) for u in unknown)
            raise ColonsimError(f"segment {self.segment}: the surrogate was fitted on a table without "
                                f"{', '.join(unknown)}, so it cannot take it into account; leave {options} out of the "
                                "query or refit on a results table with that column")
        X = self._matrix(query, n)
        reasons = [[] for _ in range(len(X))]
        span = np.maximum(self.high - self.low, 0.0)
        below = X < self.low - TOLERANCE * span
        above = X > self.high + TOLERANCE * span
        with np.errstate(over="ignore"):  # inf distance is as far as it gets
            distance = np.maximum(self.low - X, X - self.high) / np.where(span > 0, span, 1.0)
        if (distance > FAR).any():
            i, j = np.argwhere(distance > FAR)[0]
            raise ColonsimError(f"segment {self.segment}: query {i + 1} has {self.inputs[j]} = {X[i, j]:g}, more than "
                                f"{FAR:,.0f} times the training range ({self.low[j]:g}-{self.high[j]:g}) outside it; "
                                "check the value and its unit")
        outside = below | above
        for j in np.flatnonzero(outside.any(axis=0)):  # (the per-input loops cost a query's time)
            unit = column_unit(self.inputs[j])
            for i in np.flatnonzero(outside[:, j]):
                by, side = (self.low[j] - X[i, j], "below") if below[i, j] else (X[i, j] - self.high[j], "above")
                reasons[i].append(f"{self.inputs[j]} {X[i, j]:g} outside {self.low[j]:g}-{self.high[j]:g} "
                                  f"({by:.3g}{' ' + unit if unit else ''} {side})")
        for name, value in self.fixed.items():
            given = query.get(name)
            if given is None:
                continue
            arr = np.broadcast_to(given, (len(X),))
            off = np.abs(arr - value) > TOLERANCE * max(1.0, abs(value))  # NaN = not given: not off
            for i in np.flatnonzero(off) if off.any() else ():
                reasons[i].append(f"{name} {arr[i]:g} but every {self.segment} run used {value:g}")
        text = ["; ".join(r) for r in reasons]
        inside = np.array([not r for r in reasons], dtype=bool)
        if not inside.all():
            first = int(np.flatnonzero(~inside)[0])
            where = f"query {first + 1} of {len(X)}: " if len(X) > 1 else ""
            message = (f"{self.segment} {where}{text[first]} (outside the training domain; the prediction "
                       "extrapolates)")
            if strict:
                raise ColonsimError(message.replace("the prediction extrapolates", "not extrapolated; drop --strict, or give "
                                                                                  "--extrapolate, to answer anyway"))
            if warn:
                extra = f" and {int((~inside).sum()) - 1} more" if (~inside).sum() > 1 else ""
                warnings.warn(message + extra, OutOfDomainWarning, stacklevel=3)
        return X, inside, text
