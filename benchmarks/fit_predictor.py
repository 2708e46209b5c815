"""Fit the shipped pain predictor on the patient-space sweeps and write it into the package data.

    python benchmarks/fit_predictor.py                      # the committed records
    python benchmarks/fit_predictor.py --train /work/runs/patient_space_rsj /work/runs/patient_space_rsf ...

Reads the training sweeps' ``results.parquet`` (default: ``benchmarks/records/patient_space_{rsj,rsf,thf}``
and THF's further hypercubes ``patient_space_thf_more``, ``_more2``) and their replicate pairs (``..._replicates``, the noise floor),
fits :func:`colonsim.surrogate.predictor_fit.fit_predictor` (tip-folded runs left out and counted),
scores it on the held-out sweeps (``..._heldout`` and ``..._heldout2``, never fitted on) and stores their coverage in the
model, where it decides which outputs print intervals
(:func:`colonsim.surrogate.predictor_fit.vouch`), prints its report and writes
``data/predictor/patient_space.json`` + ``.npz`` (or ``--out``).
Print the held-out table with ``benchmarks/bench_predictor.py``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pandas as pd

from colonsim.errors import ColonsimError
from colonsim.insertion.study.sweep_presets import more_parts, patient_space_name
from colonsim.surrogate.predictor import SHIPPED
from colonsim.surrogate.predictor_fit import PATIENT_MODELS, fit_predictor, save_predictor, vouch
from colonsim.surrogate.table import read_results

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_predictor import RECORDS, predictor_table, records_of  # noqa: E402


def _tables(paths) -> dict:
    """Sweep name -> results table of sweep folders or tables."""
    return {(p.name if p.is_dir() else p.parent.name): read_results(p / "results.parquet" if p.is_dir() else p)
            for p in paths}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--train", type=Path, nargs="+",
                        default=[p for m in PATIENT_MODELS for part in ("", *more_parts(m))
                                 if (p := RECORDS / patient_space_name(m, part)).exists()],
                        help="training sweep folders (or results tables) of the patient models (default: the "
                             "committed records there are, patient_space_MODEL and its further hypercubes, "
                             "patient_space_MODEL_more, _more2)")
    parser.add_argument("--replicates", type=Path, nargs="*",
                        default=[p for m in PATIENT_MODELS if (p := RECORDS / f"patient_space_{m}_replicates").exists()],
                        help="replicate sweep folders (or tables): cases at two wall meshes, the noise floor")
    parser.add_argument("--heldout", type=Path, nargs="*", default=[p.parent for p in records_of("heldout")],
                        help="held-out sweep folders (or tables): scored, their coverage stored in the model")
    parser.add_argument("--out", type=Path, default=SHIPPED, help="model path (default: the package data)")
    args = parser.parse_args(argv)
    try:
        tables, replicates = _tables(args.train), _tables(args.replicates)
        held_out = _tables(args.heldout)
        model = fit_predictor(tables, held_out=list(held_out), replicates=replicates)
        if held_out:
            rows = predictor_table(model, pd.concat(held_out.values(), ignore_index=True),
                                   pd.concat(replicates.values(), ignore_index=True) if replicates else None)
            vouch(model, rows, held_out)
        json_path, npz_path = save_predictor(model, args.out)
    except ColonsimError as exc:
        print(f"fit_predictor: {exc}", file=sys.stderr)
        return 2
    print(model.report())
    print(f"predictor: {json_path} + {npz_path.name}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
