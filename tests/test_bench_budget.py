"""benchmarks/bench_budget.py: a run's steps by phase, and the held push's steps where the tip kept
pace with the push (the upper bound of a push that speeds up there), counted both ways."""

import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from bench_budget import run_budget  # noqa: E402


def series(tip_share_in_held_push):
    """2 cm of push then 4 cm of held push, a sample per 0.1 mm, 10 steps a sample; in the held
    push the tip advances by ``tip_share_in_held_push`` of the push."""
    depth = np.arange(601) * 0.01  # cm
    held = depth > 2.0
    arc = np.where(held, 2.0 + tip_share_in_held_push * (depth - 2.0), depth)
    return pd.DataFrame({"time_s": depth / 15.0, "step": np.arange(601) * 10,
                         "phase": np.where(held, "held push", "push"), "depth_cm": depth, "tip_arc_cm": arc})


def test_steps_by_phase_add_up():
    budget = run_budget(series(1.0))
    assert budget["push"] == pytest.approx(2000) and budget["held push"] == pytest.approx(4000)
    assert budget["total"] == 6000 and budget["settle"] == 0.0


def test_a_tip_keeping_pace_counts_and_a_held_tip_does_not():
    pacing = run_budget(series(0.95))["held, keeping pace"]
    # the first centimetre of the held push still looks back into the push before it: counted too
    assert pacing == pytest.approx(4000)
    # a tip advancing at half the push: only the first 2 mm, whose centimetre still holds mostly free push
    assert run_budget(series(0.5))["held, keeping pace"] == pytest.approx(190)
