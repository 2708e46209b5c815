"""Surrogate of an insertion sweep: Gaussian-process regression of the scalar outcomes.

Data flow: results table (one row per run) -> :class:`SweepSurrogate` (one GP per segment and
output, cross-validated at fit time) -> JSON + NPZ files (:func:`save_surrogate`,
:func:`load_surrogate`, no pickle) -> predictions with uncertainty, patient presets and scope
recommendations, with the spread split into tissue and surrogate parts when the sweep drew wall
materials (:mod:`colonsim.surrogate.tissue`). See docs/surrogate.md.
"""

from colonsim.surrogate.domain import OutOfDomainWarning, SegmentDomain
from colonsim.surrogate.gp import GaussianProcess
from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.table import INPUTS, SEGMENTS, TARGETS, read_results
from colonsim.surrogate.tissue import TissueDistribution

__all__ = ["GaussianProcess", "INPUTS", "OutOfDomainWarning", "SEGMENTS", "SegmentDomain", "SweepSurrogate",
           "TARGETS", "TissueDistribution", "read_results"]
