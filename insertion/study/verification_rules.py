"""How a row of the verification table is computed and judged: the memoised problem call, the
acceptance rules, the row itself and its verdict.

A problem that yields several compared quantities (the axial wave gives the wave speed and the
push force) runs once per process and argument set: every row that picks from it shares the run.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from colonsim.insertion.study.verification import Comparison

GROUPS = {"rod": "Rod (scope): beam theory, Euler buckling, axial waves",
          "shell": "Shell (colon wall): inflation against thin-wall theory, bending against plate theory",
          "energy": "Energy accounting of the explicit integrator",
          "damping": "Quasi-static devices: the scope's implicit damping, its push without drag, the sheath's lip",
          "resistance": "Distal resistance: the resisted tip against the Euler load of the free span, its creep",
          "contact": "Contact",
          "friction": "Regularised Coulomb friction",
          "law": "Every tissue law in the shell: homogeneous uniaxial tension and inflation in closed form",
          "specimen": "Calibration specimen model: homogeneous uniaxial tension, grips, mesh"}


@functools.cache
def _solved(problem, args):
    return problem(*args)


@dataclass(frozen=True)
class Run:
    """A call ``problem(*args)``, memoised per process; ``pick`` selects one comparison of a problem
    that returns several (an index or a key)."""

    problem: Callable[..., Any]
    args: tuple = ()
    pick: int | str | None = None

    def __call__(self) -> Comparison:
        result = _solved(self.problem, self.args)
        return result if self.pick is None else result[self.pick]

    def __str__(self) -> str:
        call = f"{self.problem.__name__}({', '.join(map(repr, self.args))})"
        return call if self.pick is None else f"{call}[{self.pick!r}]"


class Rule(Protocol):
    text: str

    def passed(self, c: Comparison) -> bool: ...


def _value(c: Comparison, of: str) -> float:
    return c.measured if of == "measured" else c.extra[of]


@dataclass(frozen=True)
class Relative:
    """|measured - analytic| <= tol |analytic|."""

    tol: float

    @property
    def text(self) -> str:
        return f"|rel. error| <= {self.tol:g}"

    def passed(self, c: Comparison) -> bool:
        return abs(c.relative_error) <= self.tol


@dataclass(frozen=True)
class Bound:
    """lower < value < upper (``<=`` if ``inclusive``) on the measured value or on a named extra."""

    lower: float | None = None
    upper: float | None = None
    of: str = "measured"
    inclusive: bool = False

    @property
    def text(self) -> str:
        op = "<=" if self.inclusive else "<"
        if self.upper is None:
            return f"{self.of} {'>=' if self.inclusive else '>'} {self.lower:g}"
        return (f"{self.lower:g} {op} " if self.lower is not None else "") + f"{self.of} {op} {self.upper:g}"

    def passed(self, c: Comparison) -> bool:
        v = _value(c, self.of)
        if self.inclusive:
            return (self.lower is None or v >= self.lower) and (self.upper is None or v <= self.upper)
        return (self.lower is None or v > self.lower) and (self.upper is None or v < self.upper)


@dataclass(frozen=True)
class Equal:
    """A named extra (a count, or work that must be exactly zero) equals ``value``."""

    of: str
    value: float

    @property
    def text(self) -> str:
        return f"{self.of} = {self.value:g}"

    def passed(self, c: Comparison) -> bool:
        return c.extra[self.of] == self.value


SAME = "same as full"


@dataclass(frozen=True)
class Check:
    """One verification row: what is compared, how it is computed at full size and in CI
    (``reduced``: ``SAME``, a smaller :class:`Run`, or None for full size only), the rules it must
    meet and why those tolerances hold."""

    id: str
    group: str
    quantity: str
    full: Run
    rules: tuple[Rule, ...]
    why: str
    reduced: Run | str | None = SAME

    @property
    def slow(self) -> bool:
        """Run at a reduced size in CI (the full problem takes too long there)."""
        return isinstance(self.reduced, Run)

    def run(self, full: bool) -> Run | None:
        return self.full if full or self.reduced == SAME else self.reduced

    def evaluate(self, full: bool) -> Verdict | None:
        """Solve and judge the row at full size or at the CI size; None if it has no CI size."""
        run = self.run(full)
        if run is None:
            return None
        c = run()
        return Verdict(self, c, tuple(r.text for r in self.rules if not r.passed(c)))


@dataclass(frozen=True)
class Verdict:
    check: Check
    comparison: Comparison
    broken: tuple[str, ...]  # the texts of the rules not met

    @property
    def passed(self) -> bool:
        return not self.broken

    def message(self) -> str:
        c = self.comparison
        return (f"{self.check.id}: measured {c.measured:.6g} {c.unit} against {c.analytic:.6g} "
                f"(extra {c.extra}) breaks {'; '.join(self.broken)}")

    def row(self) -> dict:
        """The row of the validation report."""
        c, check = self.comparison, self.check
        return {"id": check.id, "group": check.group, "quantity": check.quantity,
                "analytic": None if math.isnan(c.analytic) else c.analytic, "measured": c.measured, "unit": c.unit,
                "relative_error": c.relative_error, "rule": "; ".join(r.text for r in check.rules),
                "details": dict(c.extra), "why": check.why, "passed": self.passed}
