"""The quasi-static checks of the validation report on any sweeps: the mesh pair, the rate check
and the two smoothness checks, for a setting the report's own sweeps do not use.

The report judges its main sweep (the ``thesis`` preset) against its validation sweep and reads
the smoothness and surrogate sweeps (``benchmarks/sweeps/smoothness.toml``, ``gp_train.toml``,
``gp_test.toml``). Given other folders, this prints the same sections with the same columns and
verdicts (its own functions): e.g. everything stepped by the global time-step estimate (docs/model.md,
"The global time-step estimate")::

    export NUMBA_NUM_THREADS=1
    colonsim sweep benchmarks/sweeps/checks_global_base.toml --out BASE
    colonsim sweep benchmarks/sweeps/checks_global_variants.toml --out VARIANTS
    colonsim sweep benchmarks/sweeps/smoothness_global.toml --out SMOOTH
    colonsim sweep benchmarks/sweeps/gp_train_global.toml --out TRAIN
    colonsim sweep benchmarks/sweeps/gp_test_global.toml --out TEST
    python benchmarks/quasi_static_checks.py --base BASE --variants VARIANTS --smoothness SMOOTH \\
        --gp-train TRAIN --gp-test TEST --figures DIR

A variant pairs with the base run it differs from in its push speed or wall mesh alone. The runs
are only read; the smoothness figure is written into ``--figures`` (default: the smoothness
folder).
"""

import argparse
import sys
from pathlib import Path

import validation_smoothness as smoothness
from validation_markdown import mesh_pair, rate_check
from validation_markdown import smoothness as smoothness_section
from validation_report import pair_section, rate_section
from validation_sweeps import TABLE, read_sweep

FOLDERS = ("base", "variants", "smoothness", "gp_train", "gp_test")


def _missing(args):
    """The first given folder without a results table, or why the folders given do not make a check."""
    for name in FOLDERS:
        folder = getattr(args, name)
        if folder is not None and not (Path(folder) / TABLE).is_file():
            return (f"no {TABLE} in {folder}; run `colonsim sweep SWEEP.toml --out {folder}` first "
                    "(python benchmarks/quasi_static_checks.py --help)")
    pairs = (args.base, args.variants), (args.gp_train, args.gp_test)
    if any((a is None) != (b is None) for a, b in pairs):
        return "give --base with --variants and --gp-train with --gp-test"
    if all(getattr(args, name) is None for name in FOLDERS):
        return "give the sweeps to check: --base and --variants, --smoothness, --gp-train and --gp-test"
    return None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--base", help="sweep of base runs (default settings otherwise)")
    parser.add_argument("--variants", help="sweep of their variants: half the push speed, 2 mm wall triangles")
    parser.add_argument("--smoothness", help="sweep of RSJ D36 mu 0 over scope diameters")
    parser.add_argument("--gp-train", help="sweep the surrogate is fitted on")
    parser.add_argument("--gp-test", help="held-out sweep it predicts")
    parser.add_argument("--figures", help="folder for the smoothness figure (default: the smoothness folder)")
    args = parser.parse_args(argv)
    why = _missing(args)
    if why:
        print(f"error: {why}", file=sys.stderr)
        return 2
    print("; ".join(f"{name}: {getattr(args, name)}" for name in FOLDERS if getattr(args, name)) + "\n")
    if args.base:
        base, variants = read_sweep("main", args.base), read_sweep("validation", args.variants)
        print("\n".join(mesh_pair(pair_section(variants, base, "mesh"))))
        print("\n".join(rate_check(rate_section(variants, base))))
    if args.smoothness or args.gp_train:
        smooth = read_sweep("smoothness", args.smoothness, optional=True)
        train = read_sweep("gp_train", args.gp_train, optional=True)
        test = read_sweep("gp_test", args.gp_test, optional=True)
        figure = Path(args.figures or args.smoothness or ".") / "smoothness.png"
        figure.parent.mkdir(parents=True, exist_ok=True)
        print("\n".join(smoothness_section(smoothness.section(smooth, train, test, figure, str(figure)))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
