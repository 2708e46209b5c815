"""``colonsim sweep``: run insertions over scopes and anatomies, locally or on a Dask cluster."""

from __future__ import annotations

from pathlib import Path

from colonsim.errors import ColonsimError
from colonsim.files import check_output_folder
from colonsim.limits import MAX_RUNS
from colonsim.options import bounded_int, finite_float, output_folder, positive_int, worker_count
from colonsim.insertion.case.run_budget import DEFAULT_MAX_STEPS
from colonsim.workflows import available_cores


def add_parser(sub):
    """Add the ``sweep`` subcommand to the subparsers ``sub`` of :func:`colonsim.cli.build_parser`."""
    p = sub.add_parser("sweep", help="run insertions over scopes, anatomies and friction (resumable)",
                       description="Run the insertion model over a grid and/or Latin hypercube of inputs "
                                   "(docs/sweeps.md), described in a TOML file (format: docs/sweeps.md) or a preset. "
                                   "Writes results.parquet (one row per run) and runs/<key>/ per run. Rerunning "
                                   "into the same --out skips the runs already finished.")
    p.add_argument("spec", nargs="?", type=Path, help="sweep TOML file")
    p.add_argument("--preset", help="thesis (the source's 39 insertions), validation (the validation report's "
                                    "24 extra runs), resistance (the distal resistance study, 136 runs), smoke "
                                    "(3 fast runs), patient_space (the shipped predictor's 708 runs: its "
                                    "fourteen presets patient_space_MODEL[_more|_more2|_heldout|_heldout2|_replicates], each "
                                    "into its own "
                                    "folder under --out)")
    p.add_argument("--workers", type=worker_count, default=None,
                   help=f"local worker processes, one Numba thread each (default: the cores, {available_cores()} here)")
    p.add_argument("--scheduler", metavar="ADDR",
                   help="run on a Dask distributed cluster, e.g. tcp://HOST:8786 (workers: dask worker ADDR --nthreads 1)")
    p.add_argument("--out", type=output_folder, help="output folder (default colonsim_results/sweep_NAME); "
                                                    "it holds one sweep, which a rerun resumes")
    p.add_argument("--retry-failed", action="store_true", help="run again the cases recorded as failed")
    p.add_argument("--dry-run", action="store_true", help="check and list the cases and which are done, run nothing")
    p.add_argument("--reuse", nargs="+", type=Path, metavar="FOLDER", default=(),
                   help="other sweep folders: their finished runs of the same cases (same inputs) are copied in, "
                        "not run again")
    p.add_argument("--max-steps", type=positive_int, default=DEFAULT_MAX_STEPS,
                   help=f"refuse the sweep if a run needs more time steps (default {DEFAULT_MAX_STEPS:,}; one run "
                        "per material file is estimated: a material in the wrong unit makes every run long)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    a = p.add_argument_group("adaptive sweeps (docs/sweeps.md, 'Adaptive sweeps')")
    a.add_argument("--adaptive", action="store_true",
                   help="choose the runs: the [lhs] hypercube first, then batches where the surrogate is least certain")
    a.add_argument("--budget", type=bounded_int(1, MAX_RUNS), metavar="N",
                   help=f"most runs in all, at most {MAX_RUNS:,} (with --adaptive; required)")
    a.add_argument("--target-rmse", type=finite_float, metavar="X",
                   help="stop when the leave-one-out RMSE of --target is at most X in every segment (its unit: cm "
                        "for deformations); default: run to the budget")
    a.add_argument("--batch", type=positive_int, metavar="B",
                   help="runs chosen per round (default: the workers, or 4 on a Dask cluster)")
    a.add_argument("--target", metavar="COLUMN", help="output that chooses the runs (default max_deformation_cm, the "
                                                      "pain proxy)")
    a.add_argument("--criterion", choices=("variance", "error"),
                   help="where a round runs: greatest posterior variance (default) or greatest expected squared "
                        "prediction error (the nearest run's leave-one-out error plus the variance)")
    p.set_defaults(func=cmd_sweep)
    return p


def _adaptive_settings(args, workers):
    """The adaptive settings of the command line, or None for a plain sweep; one-line errors."""
    from colonsim.insertion.study.adaptive_sweep import AdaptiveSettings

    given = [o for o, v in (("--budget", args.budget), ("--target-rmse", args.target_rmse), ("--batch", args.batch),
                            ("--target", args.target), ("--criterion", args.criterion)) if v is not None]
    if not args.adaptive:
        if given:
            raise ColonsimError(f"{', '.join(given)} belong(s) to adaptive sweeps; add --adaptive or drop them")
        return None
    if args.reuse:
        raise ColonsimError("--reuse is for sweeps of given cases; an adaptive sweep chooses its runs as results "
                            "come in: drop --reuse or --adaptive")
    if args.dry_run:
        raise ColonsimError("--dry-run cannot list an adaptive sweep's runs (they are chosen as results come in); "
                            "drop --adaptive to list the first round")
    if args.budget is None:
        raise ColonsimError("--adaptive needs --budget N, the most runs in all (the first round included)")
    batch = args.batch or (4 if args.scheduler else workers)
    return AdaptiveSettings(args.budget, args.target_rmse, batch, args.target or "final_deformation_cm",
                            args.criterion or "variance")


def _adaptive(args, spec, settings, out, workers, where):
    from colonsim.insertion.study.adaptive_sweep import FIGURE, ROUNDS, run_adaptive_sweep

    goal = f"LOO RMSE of {settings.target} <= {settings.target_rmse:g} in every segment" if settings.target_rmse else ""
    print(f"adaptive sweep {spec.name}: at most {settings.budget} runs{', until ' + goal if goal else ''}, "
          f"{settings.batch} per round, on {where} -> {out}/", flush=True)
    report = run_adaptive_sweep(spec, out, settings, workers=workers, scheduler=args.scheduler,
                                retry_failed=args.retry_failed, progress=not args.no_progress,
                                max_steps=args.max_steps)
    print(f"stopped: {report.stopped} after {len(report.rounds)} round(s), {report.runs} runs ({report.ran} run now)")
    print(f"results: {out / 'results.parquet'}; rounds: {out / ROUNDS}; figure: {out / FIGURE}")


def _dask_installed() -> bool:
    import importlib.util

    try:
        return importlib.util.find_spec("distributed") is not None
    except (ImportError, ValueError):  # a module set to None (blocked) or half imported
        return False


def cmd_sweep(args):
    if args.scheduler is not None and args.workers is not None:
        raise ColonsimError("--workers is for local runs; a Dask cluster (--scheduler) has its own workers")
    if args.scheduler is not None and not args.dry_run and _dask_installed():
        from colonsim.scheduler_address import check_scheduler

        # first, before the heavy imports: an address where no scheduler answers fails within seconds
        check_scheduler(args.scheduler)
    from colonsim.insertion.case.run_budget import check_sweep_budget
    from colonsim.insertion.study.adaptive_sweep import ROUNDS
    from colonsim.insertion.study.sweep_outcomes import dask_distributed
    from colonsim.insertion.study.sweep_presets import PRESET_GROUPS
    from colonsim.insertion.study.sweep_spec import load_sweep

    if args.scheduler is not None and not args.dry_run:
        dask_distributed()  # so does a missing dask, before the sweep is announced or anything written
    workers = available_cores() if args.workers is None else args.workers
    settings = _adaptive_settings(args, workers)
    where = f"Dask cluster {args.scheduler}" if args.scheduler else f"{workers} local process{'es' if workers > 1 else ''}"
    if args.spec is None and args.preset in PRESET_GROUPS:
        if settings is not None:
            raise ColonsimError(f"--preset {args.preset} runs {len(PRESET_GROUPS[args.preset])} presets as they "
                                "are; --adaptive takes one sweep")
        base = args.out or check_output_folder(Path("colonsim_results") / f"sweep_{args.preset}")
        names = PRESET_GROUPS[args.preset]
        specs = [load_sweep(None, name) for name in names]  # every preset checked before any runs
        for spec in specs:
            check_sweep_budget(spec.cases, args.max_steps)
        for spec in specs:
            _one_sweep(args, spec, check_output_folder(base / spec.name), workers, where)
        return
    spec = load_sweep(args.spec, args.preset)
    out = args.out or check_output_folder(Path("colonsim_results") / f"sweep_{spec.name}")
    if settings is not None:
        return _adaptive(args, spec, settings, out, workers, where)
    if (out / ROUNDS).is_file():
        raise ColonsimError(f"{out} holds an adaptive sweep; continue it with --adaptive --budget N, or give this "
                            "sweep another --out")
    _one_sweep(args, spec, out, workers, where)


def _one_sweep(args, spec, out, workers, where):
    """Run (or with --dry-run, list) the sweep ``spec`` into ``out`` and print its report."""
    from colonsim.insertion.case.run_budget import check_sweep_budget
    from colonsim.insertion.study.sweep import SweepStore, describe_cases, reusable_runs, run_sweep

    if args.dry_run:
        check_sweep_budget(spec.cases, args.max_steps)
        store = SweepStore(out)
        store.load()
        extends = store.check_same_sweep([c.key() for c in spec.cases], spec.source)
        if extends:
            print(extends)
        done = store.finished(args.retry_failed)
        pending = {c.key() for c in spec.cases} - done
        reused = len(reusable_runs(args.reuse, pending, out)) if args.reuse else 0
        print(describe_cases(spec.cases))
        print(f"sweep {spec.name}: {len(spec.cases)} runs, {len(spec.cases) - len(pending)} already in {out}/, "
              + (f"{reused} to copy from {', '.join(map(str, args.reuse))}, " if args.reuse else "")
              + f"{len(pending) - reused} to run on {where}")
        return
    print(f"sweep {spec.name}: {len(spec.cases)} runs on {where} -> {out}/", flush=True)
    report = run_sweep(spec.cases, out, workers=workers, scheduler=args.scheduler, retry_failed=args.retry_failed,
                       spec=spec, progress=not args.no_progress, max_steps=args.max_steps, reuse=args.reuse)
    rate = "" if report.ran == 0 else f" ({report.runs_per_hour:.0f} runs/hour)"
    print(f"{report.skipped} already finished (skipped), {report.ran} run in {report.wall_time_s:.1f} s{rate}: "
          f"{report.ok} ok, {report.failed} failed")
    failed = report.table[report.table["status"] == "failed"]
    for _, row in failed.head(10).iterrows():
        print(f"  failed {row['key']} ({row['segment']} {row['scope']} D {row['diameter_mm']:g} mm): {row['error']}")
    if len(failed):
        more = f" (+{len(failed) - 10} more)" if len(failed) > 10 else ""
        print(f"{len(failed)} failed run(s){more} are recorded; rerun with --retry-failed to try them again")
    print(f"results: {out / 'results.parquet'} ({len(report.table)} runs of this sweep), time series in {out / 'runs'}/")
