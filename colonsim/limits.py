"""The bounds of every size a user controls, checked before anything is allocated or run.

Each bound is documented here, once, with its reason; the command line and the workflows check
against these values (:func:`check_count`) so that a typo (``--points 1000000``, ``samples =
1000000000``) costs a one-line error instead of hours or gigabytes. docs/architecture.md
("Limits") lists them for users.
"""

from __future__ import annotations

import os

from colonsim.errors import ColonsimError

# -- input files --------------------------------------------------------------------------------
# A testing-machine export or a centerline CSV: an hour of a 1 kHz recording is ~100 MB of text;
# reading a file costs about 20 times its size in memory, so this keeps a read under ~1.3 GB.
TEXT_FILE_MAX_BYTES = 64 * 2**20
# A TOML sweep, a JSON material, presets or tissue file: hand-written documents.
DOCUMENT_MAX_BYTES = 16 * 2**20
# A query CSV of `colonsim predict --csv`: one patient a row, 13-21 bytes a row. Its cost is the
# prediction's, not the read's: 100,000 queries (1.3 MB) took 38 s and 460 MB (measured: scope,
# age and sex columns, one RSJ model of 30 runs, one core), about 2 KB a query; 32 MB holds
# 1.5-2.5 million queries, minutes and a few GB; a million (21 MB) is accepted.
QUERY_MAX_BYTES = 32 * 2**20
# A results table (Parquet or CSV) a surrogate is fitted on, and a surrogate's arrays (.npz):
# 20,000 runs (the largest sweep) take a few MB; this leaves room for hand-made tables.
TABLE_MAX_BYTES = 512 * 2**20

# -- sweeps ------------------------------------------------------------------------------------
# Runs of one sweep (grid x hypercube x materials) and of an adaptive sweep's budget: ~3 s to
# expand and validate; 28 hours of computing at the fastest runs measured.
MAX_RUNS = 20_000

# -- calibration --------------------------------------------------------------------------------
# FE divisions of the quarter strip (along the length, across the half-width): every objective
# evaluation solves this mesh at every displacement point, 600 evaluations per fit; 8x3 is the
# default, 32x12 already takes hours.
MESH_MAX = (64, 24)
# Evaluations of each stage of a search budget given through the Python API (designs, CMA-ES
# population and evaluations, Nelder-Mead evaluations): the largest default is the closed-form
# fits' 4,000; an evaluation of the 8x3 strip takes ~0.15 s, so 100,000 is already about 4 hours.
BUDGET_MAX = 100_000
# Simulated displacement points along a curve (default 20): each is a nonlinear solve per evaluation.
POINTS_RANGE = (5, 200)
# Specimen geometry in mm (free length, width, wall thickness): wide bounds that only keep the
# arithmetic finite (1e-300 mm underflows the strain); the reader's own checks say more about
# values inside them (a thickness typed in metres, a strip wider than long).
GEOMETRY_RANGES_MM = {"length": (1e-2, 1e4), "width": (1e-3, 1e4), "thickness": (1e-4, 1e3)}

# -- option values ------------------------------------------------------------------------------
# Numbers given on the command line whose range is not a physical input's (those are
# colonsim.input_ranges and InsertionCase.validate): (low, high, what the value is and why the
# bounds). Each is checked where the option is parsed (colonsim.options.ranged), whether or not
# the run uses it.
OPTION_RANGES = {
    # a snapshot per time step would fill memory and disk; one per 10 s is none in a run of seconds
    "--snapshot-every": (1e-3, 10.0, "simulated seconds between snapshots for --vtu and --animate"),
    # fewer points do not fix a law's curvature; more than a curve holds would invent points by
    # interpolation (checked per curve: colonsim.identification.cleanup.check_decimation)
    "--decimate": (5, 10_000, "points per curve, at most the curve's own"),
}

# -- processes ----------------------------------------------------------------------------------
# Local worker processes: each loads the solver (~300 MB); more than a few per core only costs memory.
WORKERS_PER_CORE = 4
# Random seeds: what numpy's and CMA-ES's generators accept.
SEED_RANGE = (0, 2**32 - 1)
# Seconds a Dask scheduler address may take to answer before a sweep gives up on it.
SCHEDULER_CHECK_S = 6.0


def max_workers() -> int:
    """The most local worker processes accepted: :data:`WORKERS_PER_CORE` per usable core."""
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        cores = os.cpu_count() or 1
    return WORKERS_PER_CORE * cores


def check_count(name, value, low, high, why=""):
    """Refuse ``value`` of the whole-number option ``name`` outside [``low``, ``high``] in one line."""
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise ColonsimError(f"{name} {value!r} is outside {low:,}-{high:,}{why}; give a whole number in that range")


def check_workers(name, value):
    """``value`` local processes: at least 1, at most :func:`max_workers`."""
    check_count(name, value, 1, max_workers(), f" ({WORKERS_PER_CORE} per core of this machine)")


def check_seed(name, value):
    check_count(name, value, *SEED_RANGE)


def check_mesh(name, mesh):
    """FE divisions (along, across) within :data:`MESH_MAX`."""
    along, across = mesh
    if not (1 <= along <= MESH_MAX[0] and 1 <= across <= MESH_MAX[1]):
        raise ColonsimError(f"{name} {along}x{across} is outside 1x1-{MESH_MAX[0]}x{MESH_MAX[1]} (each objective "
                            "evaluation solves this mesh; 8x3 is the default); give a smaller mesh")


def check_geometry_mm(quantity, value, given_as="{}"):
    """A specimen dimension ``quantity`` (length, width, thickness) in mm within :data:`GEOMETRY_RANGES_MM`."""
    low, high = GEOMETRY_RANGES_MM[quantity]
    if value > 0 and not low <= value <= high:  # zero and negative values: the reader says more
        raise ColonsimError(f"{given_as.format(quantity)} {value:g} mm is outside {low:g}-{high:g} mm; give the "
                            f"specimen's {quantity} in mm")
