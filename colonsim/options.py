"""Value types of the command-line options (numbers that must be finite, outputs checked at once)
and the help texts that list the catalog's colon models, angles and scopes.

Each turns a bad value into an argparse error (one line, exit code 2, see
:class:`colonsim.cli.OneLineParser`) while the options are read, so that nothing starts on input
that would fail later; output paths are checked by :mod:`colonsim.files`.
"""

from __future__ import annotations

import argparse
import math

from colonsim import catalog
from colonsim.errors import ColonsimError
from colonsim.files import check_output_file, check_output_folder
from colonsim.limits import OPTION_RANGES, SEED_RANGE, WORKERS_PER_CORE, max_workers


def finite_float(text) -> float:
    """A finite number (``inf``, ``nan`` and overflowing values such as 1e999 are refused)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number")
    return value


def positive_int(text) -> int:
    """A whole number >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be at least 1")
    return value


def bounded_int(low, high):
    """A type for a whole number in [``low``, ``high``] (the bounds of :mod:`colonsim.limits`)."""
    def int_type(text):
        value = positive_int(text) if low >= 1 else _whole(text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{value} is outside {low:,}-{high:,}")
        return value

    int_type.__name__ = "whole number"
    return int_type


def _whole(text) -> int:
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None


def ranged(option):
    """A type for the number ``option`` takes, in its range of :data:`colonsim.limits.OPTION_RANGES`
    (a whole number when both bounds are)."""
    low, high, what = OPTION_RANGES[option]
    whole = isinstance(low, int) and isinstance(high, int)

    def value_type(text):
        value = _whole(text) if whole else finite_float(text)
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{value:g} is outside {low:,g}-{high:,g} ({what})")
        return value

    value_type.__name__ = "whole number" if whole else "number"
    return value_type


class StretchRange(argparse.Action):
    """``LOW HIGH`` stretches (``nargs=2``, finite numbers): from below 1 to above 1, checked when
    parsed, whether or not the run uses them."""

    def __call__(self, parser, namespace, values, option_string=None):
        low, high = values
        if not 0 < low < 1 < high:
            parser.error(f"argument {option_string}: {low:g} {high:g} must run from below 1 to above 1 (e.g. 0.5 4)")
        setattr(namespace, self.dest, (low, high))


def worker_count(text) -> int:
    """Local worker processes: 1 to :func:`colonsim.limits.max_workers` (a few per core)."""
    value = positive_int(text)
    if value > max_workers():
        raise argparse.ArgumentTypeError(f"{value} is more than the {max_workers()} processes this machine can use "
                                         f"({WORKERS_PER_CORE} per core)")
    return value


def seed(text) -> int:
    """A random seed, 0 to 2**32 - 1."""
    return bounded_int(*SEED_RANGE)(text)


def _checked(check, text, *args):
    try:
        return check(text, "", *args)
    except ColonsimError as exc:
        raise argparse.ArgumentTypeError(str(exc).strip()) from None


def output_folder(text):
    """A folder to write results into (new, or an earlier run's), checked before any work."""
    return _checked(check_output_folder, text)


def output_file(*suffixes):
    """A type for a file to write, checked before any work; ``suffixes`` (e.g. ".png") if given."""
    def file_type(text):
        return _checked(check_output_file, text, suffixes or None)

    file_type.__name__ = "output file"
    return file_type


def segment_help() -> str:
    """Help text of ``--segment``: each model with its title."""
    return ", ".join(f"{m.name} ({m.title})" for m in catalog.COLON_MODELS.values())


def angle_help() -> str:
    """Help text of ``--angle``: what the angle means in which model, and its limits."""
    parts = []
    for symbol in (catalog.ALPHA, catalog.BETA):
        models = [m for m in catalog.COLON_MODELS.values() if m.angle == symbol]
        if models:
            low, high = models[0].angle_limits_deg
            parts.append(f"{symbol} of {', '.join(m.name for m in models)} ({low:g}-{high:g} deg)")
    ignored = [m.name for m in catalog.COLON_MODELS.values() if m.angle == catalog.NO_ANGLE]
    return "; ".join(parts) + (f"; ignored by {', '.join(ignored)}" if ignored else "")


def scope_help() -> str:
    """Help text of ``--scope``: the named scopes with their diameters, or a diameter in mm."""
    low, high = catalog.SCOPE_DIAMETER_RANGE
    named = ", ".join(f"{s.name} ({s.title}, {s.diameter * 1e3:g} mm)" for s in catalog.NAMED_SCOPES.values())
    return f"{named}, or an outer diameter in mm ({low * 1e3:g}-{high * 1e3:g})"
