"""Fit the shipped pain predictor on the patient-space sweeps and write it into the package data.

    python benchmarks/fit_predictor.py                      # the committed records
    python benchmarks/fit_predictor.py --train /work/runs/patient_space_rsj /work/runs/patient_space_rsf ...

Reads the training sweeps' ``results.parquet`` (default: ``benchmarks/records/patient_space_{rsj,rsf,thf}``)
and their replicate pairs (``..._replicates``, the noise floor),
fits :func:`colonsim.surrogate.predictor_fit.fit_predictor` (tip-folded runs left out and counted),
prints its report and writes ``data/predictor/patient_space.json`` + ``.npz`` (or ``--out``).
Score it on the held-out sweeps with ``benchmarks/bench_predictor.py``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from colonsim.errors import ColonsimError
from colonsim.surrogate.predictor import SHIPPED
from colonsim.surrogate.predictor_fit import PATIENT_MODELS, fit_predictor, save_predictor
from colonsim.surrogate.table import read_results

RECORDS = Path(__file__).resolve().parent / "records"


def _tables(paths) -> dict:
    """Sweep name -> results table of sweep folders or tables."""
    return {(p.name if p.is_dir() else p.parent.name): read_results(p / "results.parquet" if p.is_dir() else p)
            for p in paths}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--train", type=Path, nargs="+",
                        default=[RECORDS / f"patient_space_{m}" for m in PATIENT_MODELS],
                        help="training sweep folders (or results tables), one per patient model")
    parser.add_argument("--replicates", type=Path, nargs="*",
                        default=[p for m in PATIENT_MODELS if (p := RECORDS / f"patient_space_{m}_replicates").exists()],
                        help="replicate sweep folders (or tables): cases at two wall meshes, the noise floor")
    parser.add_argument("--out", type=Path, default=SHIPPED, help="model path (default: the package data)")
    args = parser.parse_args(argv)
    try:
        tables, replicates = _tables(args.train), _tables(args.replicates)
        held_out = [f"{name}_heldout" for name in tables]
        model = fit_predictor(tables, held_out=held_out, replicates=replicates)
        json_path, npz_path = save_predictor(model, args.out)
    except ColonsimError as exc:
        print(f"fit_predictor: {exc}", file=sys.stderr)
        return 2
    print(model.report())
    print(f"predictor: {json_path} + {npz_path.name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
