"""The ``colonsim`` command line: thin wrappers that read options, run a workflow, print a report.

Every error a user can cause is a :class:`colonsim.errors.ColonsimError`: printed as one line,
exit code 2, no traceback.
"""

from __future__ import annotations

import _thread
import argparse
import contextlib
import sys
import threading
import warnings
from pathlib import Path

from colonsim import catalog, options
from colonsim.errors import ColonsimError, ColonsimWarning
from colonsim.files import os_failure
from colonsim.limits import MESH_MAX, POINTS_RANGE
from colonsim.options import bounded_int, finite_float, output_folder, positive_int, seed, worker_count

# The modules below the command line are imported by the command that needs them, not here: the
# insertion engine (Numba) takes a second or two to import, which `colonsim predict` never pays
# (tests/test_cli.py checks that the predict path leaves it unimported).


def _mesh(text):
    try:
        nl, nw = (int(v) for v in text.lower().split("x"))
        if nl < 1 or nw < 1:
            raise ValueError
    except ValueError:
        raise argparse.ArgumentTypeError(f"mesh must look like 8x3 (divisions along the length x half-width), got {text!r}")
    if nl > MESH_MAX[0] or nw > MESH_MAX[1]:
        raise argparse.ArgumentTypeError(f"{nl}x{nw} is finer than {MESH_MAX[0]}x{MESH_MAX[1]} (every objective "
                                         "evaluation solves this mesh; 8x3 is the default)")
    return nl, nw


def _add_calibrate(sub):
    from colonsim import cli_material

    p = sub.add_parser("calibrate", help="identify hyperelastic parameters from tensile test curves",
                       description="Fit a hyperelastic law to strip tensile curves (docs/model.md): Latin-hypercube "
                                   "sensitivity study -> CMA-ES -> Nelder-Mead on a scikit-fem model of the "
                                   "clamped specimen. Writes material.json (read by the insertion solver), "
                                   "CSV tables and figures.")
    src = p.add_argument_group("test data (default: the bundled synthetic data set)")
    src.add_argument("--manifest", type=Path,
                     help="CSV listing specimens: specimen,file,length_mm,width_mm,thickness_mm")
    src.add_argument("--curve", type=Path,
                     help="one force-displacement CSV or testing-machine export (geometry from --length, --width, "
                          "--thickness or the file's preamble)")
    src.add_argument("--length", type=finite_float, help="free length between the grips, mm (wins over the file's preamble)")
    src.add_argument("--width", type=finite_float, help="specimen width, mm (wins over the file's preamble)")
    src.add_argument("--thickness", type=finite_float, help="wall thickness, mm (wins over the file's preamble)")
    src.add_argument("--displacement-unit", help="unit of the displacement column if the header does not say (mm, m, cm, um, in)")
    src.add_argument("--force-unit", help="unit of the force column if the header does not say (N, mN, kN, gf, kgf, lbf)")
    fit = p.add_argument_group("fit")
    fit.add_argument("--per-specimen", action="store_true",
                     help="fit every specimen separately and report the population mean and spread "
                          "(default: fit the mean curve of all specimens, the source's way)")
    fit.add_argument("--law", help="mooney_rivlin_3 (default), mooney_rivlin_2, neo_hookean, yeoh; ogden_1..3 in multi-mode fits")
    fit.add_argument("--compare-laws", action="store_true",
                     help="fit every law (all of them run in the insertion solver), write laws.csv and laws.png, and material.json "
                          "for the law BIC chooses")
    fit.add_argument("--analytic", action="store_true",
                     help="fit the closed-form homogeneous uniaxial model instead of the clamped FE strip")
    fit.add_argument("--mesh", type=_mesh, default=(8, 3), help="FE divisions of the quarter strip, default 8x3")
    fit.add_argument("--points", type=bounded_int(*POINTS_RANGE), default=20,
                     help=f"simulation displacement points, {POINTS_RANGE[0]}-{POINTS_RANGE[1]} (default 20)")
    fit.add_argument("--quick", action="store_true",
                     help="reduced budget (40 designs, 100 CMA-ES, 160 Nelder-Mead evaluations) instead of 100/300/300")
    fit.add_argument("--seed", type=seed, default=1, help="seed of the Latin hypercube and CMA-ES (default 1)")
    fit.add_argument("--workers", type=worker_count, default=2, help="processes for --per-specimen (default 2)")
    cli_material.add_calibrate_options(p)
    p.add_argument("--out", type=output_folder, default="colonsim_results/calibration",
                   help="output folder (default colonsim_results/calibration)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_calibrate)


def cmd_calibrate(args):
    from colonsim import cli_material
    from colonsim.workflows import CalibrationRequest, calibrate

    if cli_material.wants_modes(args):
        return cli_material.cmd_calibrate_modes(args)

    request = CalibrationRequest(
        manifest=args.manifest, curve=args.curve, length_mm=args.length, width_mm=args.width,
        thickness_mm=args.thickness, displacement_unit=args.displacement_unit, force_unit=args.force_unit,
        per_specimen=args.per_specimen, law=args.law, compare_laws=args.compare_laws, analytic=args.analytic,
        mesh=args.mesh, points=args.points, quick=args.quick, seed=args.seed, workers=args.workers,
        show_progress=not args.no_progress, given_as="--{}", load_start=args.load_start, decimate=args.decimate)
    cli_material.check_export(args)
    calibrate(request, args.out)
    cli_material.export_after(args)


def cmd_demo(args):
    from colonsim.demo import DemoOptions, run_demo
    from colonsim.input_ranges import check_input_range
    from colonsim.insertion.case.insertion_case import InsertionCase

    check_input_range("element_size_mm", args.element_size, "--element-size: ")  # before the calibration runs
    # the case's own range checks, before the calibration runs
    for field, value in (("scope_spacing_mm", args.scope_spacing), ("push_speed", args.push_speed)):
        if value is not None:
            InsertionCase(**{field: value}).validate()

    run_demo(DemoOptions(out=args.out, element_size_mm=args.element_size, scope_spacing_mm=args.scope_spacing,
                         push_speed=args.push_speed, sweep=args.sweep, workers=args.workers,
                         show_progress=not args.no_progress, target=args.target))


def _add_insert(sub):
    from colonsim.insertion.case.insertion_case import TIME_STEP_ESTIMATES, InsertionCase
    from colonsim.insertion.case.run_budget import DEFAULT_MAX_STEPS
    from colonsim.insertion.engine.contact_points import WALL_SAMPLINGS

    p = sub.add_parser("insert", help="simulate a colonoscope insertion (explicit dynamics)",
                       description="Push a colonoscope through a colon model (docs/model.md) and record the colon "
                                   "deformation, contact and push forces, tip motion and energies. Writes "
                                   "timeseries.csv, summary.json, insertion.png and the wall-stretch map "
                                   "(stretch_map.npz/.png) per scope, a comparison table and figure, and optional "
                                   "movies (--animate) and VTU files for ParaView.")
    p.add_argument("--segment", default=None, help=f"colon model (default rsj): {options.segment_help()}")
    p.add_argument("--scope", nargs="+", default=["sdc"], help=f"{options.scope_help()}; several allowed (default sdc)")
    p.add_argument("--centerline", type=Path,
                   help="a patient's centerline CSV (x_mm, y_mm, z_mm, label fixed/mobile, optional diameter_mm "
                        "and name; docs/model.md); implies --segment patient")
    p.add_argument("--centerline-smoothing", type=finite_float, default=None,
                   help="RMS distance (mm) the smoothed centerline may keep from the file's points (default 1, "
                        "about a CT voxel)")
    p.add_argument("--diameter", type=finite_float, default=None,
                   help="colon inner diameter, mm (default 36; with --centerline, the median of the file's "
                        "diameter_mm column when it has one)")
    p.add_argument("--angle", type=finite_float, default=0.0, help=f"degrees (default 0): {options.angle_help()}")
    p.add_argument("--friction", type=finite_float, default=0.0, help="Coulomb friction scope/wall (default 0)")
    p.add_argument("--wall-thickness", type=finite_float, default=2.0, help="colon wall thickness, mm (default 2, an assumption)")
    p.add_argument("--element-size", type=finite_float, default=InsertionCase.element_size_mm,
                   help=f"wall triangle size, mm (default {InsertionCase.element_size_mm:g})")
    p.add_argument("--scope-spacing", type=finite_float, default=None,
                   help=f"scope node spacing, mm (default {InsertionCase.scope_spacing_mm:g}; coarser is faster, not "
                        "validated)")
    p.add_argument("--push-speed", type=finite_float, default=InsertionCase.push_speed,
                   help=f"plateau push speed, m/s (default {InsertionCase.push_speed:g}, quasi-static; the source "
                        "pushed at 0.6; half of it checks the rate: docs/model.md, \"Loading\")")
    p.add_argument("--time-step-estimate", choices=TIME_STEP_ESTIMATES, default=InsertionCase.time_step_estimate,
                   help="what the stable time step rests on: global (default), the coupled system's largest "
                        "frequency by power iteration (about 0.7 of the steps of bounds), or bounds, the element "
                        "bounds (docs/quasi_static.md)")
    p.add_argument("--contact-surface", choices=WALL_SAMPLINGS, default=InsertionCase.contact_surface,
                   help="where the contact samples the wall: its nodes (default) or points spread over its triangles, "
                        f"{InsertionCase.contact_face_subdivision ** 2} per triangle (the scope no longer rises and "
                        "sinks over the wall's nodes; docs/model.md, \"Contact\")")
    p.add_argument("--material", help="material JSON from colonsim calibrate (default: the source's parameters)")
    p.add_argument("--flexure-angle", type=finite_float, default=90.0,
                   help="turn of the splenic (RSF) or hepatic (THF) flexure, degrees (default 90, an assumption)")
    p.add_argument("--exit-length", type=finite_float, default=100.0,
                   help="mm of fixed colon after the last mobile piece (default 100, an assumption; in RSF/THF a "
                        "minimum: the exit is lengthened to take the whole scope)")
    p.add_argument("--distal-resistance", type=finite_float, default=5.0,
                   help="N the colon beyond the model opposes to the tip's advance once it is in the fixed exit "
                        "(default 5, the light level of 0/5/10/20; 0: none; docs/model.md, \"Loading\")")
    p.add_argument("--vtu", action="store_true", help="write deformed meshes for ParaView (needs meshio)")
    p.add_argument("--animate", action="store_true",
                   help="write insertion.gif per run (insertion.mp4 too when ffmpeg is on the path): the wall coloured "
                        "by displacement, the scope, the push force (docs/visualisation.md)")
    p.add_argument("--snapshot-every", type=options.ranged("--snapshot-every"), default=0.02,
                   help="simulated seconds between snapshots for --vtu and --animate (0.001-10, default 0.02)")
    p.add_argument("--stretch-threshold", type=finite_float, default=None,
                   help=f"stretch above which the wall counts as stretched in summary.json's "
                        f"{catalog.STRETCHED_WALL_COLUMN} (default {catalog.STRETCHED_WALL_THRESHOLD:g}, "
                        "{:g}-{:g}; an assumption)".format(*catalog.STRETCHED_WALL_THRESHOLD_RANGE))
    p.add_argument("--threads", type=int, default=None,
                   help="Numba threads (default: all cores). Use 1 when running several insertions side by side: "
                        "oversubscribed threads slow the kernels down by an order of magnitude")
    p.add_argument("--max-steps", type=positive_int, default=DEFAULT_MAX_STEPS,
                   help=f"refuse a run estimated to need more time steps (default {DEFAULT_MAX_STEPS:,}; "
                        "a stiff wall or a fine mesh needs many)")
    p.add_argument("--out", type=output_folder, default="colonsim_results/insertion", help="output folder")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_insert)


def cmd_insert(args):
    import numba

    from colonsim.insertion.case.scenario import InsertionCase

    if args.vtu:  # fails before the runs, not after them
        from colonsim.insertion.case.results import check_vtu_writer

        check_vtu_writer()
    if args.stretch_threshold is not None:
        from colonsim.insertion.case.stretch_map import check_threshold

        check_threshold(args.stretch_threshold)
    if args.threads is not None:
        if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
            raise ColonsimError(f"--threads {args.threads} must lie in 1-{numba.config.NUMBA_NUM_THREADS} (the cores Numba sees)")
        numba.set_num_threads(args.threads)

    from colonsim.workflows import anatomy_inputs

    anatomy = anatomy_inputs(args.segment, args.centerline, args.diameter, args.centerline_smoothing)
    cases = [InsertionCase(**anatomy, scope=scope, angle_deg=args.angle,
                           flexure_angle_deg=args.flexure_angle, friction=args.friction,
                           wall_thickness_mm=args.wall_thickness,
                           element_size_mm=args.element_size, material=args.material,
                           exit_length_mm=args.exit_length, distal_resistance_N=args.distal_resistance,
                           push_speed=args.push_speed, time_step_estimate=args.time_step_estimate,
                           contact_surface=args.contact_surface,
                           **({} if args.scope_spacing is None else {"scope_spacing_mm": args.scope_spacing}))
             for scope in args.scope]
    if args.material is not None:
        from colonsim.inputs import check_input
        from colonsim.insertion.engine.material import load_material

        load_material(check_input(args.material, "material file"))
    from colonsim.workflows import insert

    insert(cases, args.out, vtu=args.vtu, snapshot_every=args.snapshot_every, show=not args.no_progress,
           max_steps=args.max_steps, animate=args.animate, stretch_threshold=args.stretch_threshold)


class OneLineParser(argparse.ArgumentParser):
    """Option errors as one line, like every other error (exit code 2), instead of the usage text."""

    def error(self, message):
        raise ColonsimError(f"{message} (see '{self.prog} --help')")


def _add_demo(sub):
    from colonsim.insertion.case.insertion_case import InsertionCase

    demo = sub.add_parser("demo", help="run the workflows on the bundled data (about 2 minutes on 2 idle cores)",
                          description="Calibrate on the bundled synthetic tensile data (reduced budget), run one "
                                      "insertion with the calibrated material, ask the predictor shipped with colonsim "
                                      "about that material for two patients and rank the scopes, and set the live run "
                                      "beside the predictor's answer for the same case. Writes report.md.")
    demo.add_argument("--out", type=output_folder, default="colonsim_demo", help="output folder (default colonsim_demo)")
    demo.add_argument("--sweep", action="store_true",
                      help="also run a 12-run sweep of the demo's own (RSJ x 3 scopes x 2 diameters x 2 frictions, "
                           "4 replicates) and fit a surrogate on it: some minutes more")
    demo.add_argument("--element-size", type=finite_float, default=InsertionCase.element_size_mm,
                      help=f"wall mesh of the insertion and the sweep, mm (default {InsertionCase.element_size_mm:g}; "
                           "coarser is faster, not validated)")
    demo.add_argument("--scope-spacing", type=finite_float, default=None,
                      help=f"scope node spacing of the insertion and the sweep, mm (default "
                           f"{InsertionCase.scope_spacing_mm:g}; coarser is faster, not validated)")
    demo.add_argument("--push-speed", type=finite_float, default=None,
                      help=f"push speed of the insertion and the sweep, m/s (default {InsertionCase.push_speed:g}, "
                           "quasi-static; faster is cheaper and rings, not validated)")
    demo.add_argument("--workers", type=worker_count, default=None,
                      help="processes for the demo's sweep with --sweep (default: up to 2 cores)")
    demo.add_argument("--no-progress", action="store_true", help="no progress bar")
    demo.add_argument("--target", choices=("max_deformation_cm", "final_deformation_cm"), default=catalog.PAIN_PROXY,
                      help="deformation the summary and the rankings go by (default: the largest over the run)")
    demo.set_defaults(func=cmd_demo)


def _add_material(sub):
    from colonsim import cli_material

    cli_material.add_parsers(sub)


def _add_sweep(sub):
    from colonsim import cli_sweep

    cli_sweep.add_parser(sub)


def _add_surrogate(sub):
    from colonsim import cli_surrogate

    cli_surrogate.add_parsers(sub)


# command -> the function that adds its parser (with the others it shares a module with)
COMMANDS = {"calibrate": _add_calibrate, "insert": _add_insert, "material": _add_material, "sweep": _add_sweep,
            "surrogate": _add_surrogate, "predict": _add_surrogate, "recommend": _add_surrogate, "demo": _add_demo}


def command_of(argv):
    """The command ``argv`` names (its first word that is no option), or None."""
    return next((word for word in argv if not word.startswith("-")), None)


def build_parser(command=None):
    """The command line's parser: every command's (``command`` None, as for the site's reference
    and ``colonsim --help``), or only ``command``'s, which imports only the modules it needs."""
    from colonsim import __version__

    parser = OneLineParser(prog="colonsim", description="Colonoscope-colon interaction toolkit.")
    parser.add_argument("--version", action="version", version=f"colonsim {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    adders = ([COMMANDS[command]] if command in COMMANDS else
              list(dict.fromkeys(COMMANDS.values())))  # each module's adder once, in the order of COMMANDS
    for add in adders:
        add(sub)
    return parser


def _one_line(text) -> str:
    return " ".join(str(text).split())


@contextlib.contextmanager
def interrupts_not_dropped():
    """Deliver again a Ctrl-C that Python had to drop.

    A ``KeyboardInterrupt`` raised where no exception can propagate (a ctypes callback, as when
    Numba compiles a kernel; a ``__del__``) is printed as "Exception ignored" and lost: a sweep
    interrupted in its first moments then ran on. Here such an interrupt is delivered again to the
    main thread a moment later, once the callback has returned, and nothing is printed for it.
    """
    previous = sys.unraisablehook

    def hook(unraisable):
        if unraisable.exc_type is not None and issubclass(unraisable.exc_type, KeyboardInterrupt):
            again = threading.Timer(0.05, _thread.interrupt_main)
            again.daemon = True
            again.start()
        else:
            previous(unraisable)

    sys.unraisablehook = hook
    try:
        yield
    finally:
        sys.unraisablehook = previous


def main(argv=None):
    show, shown = warnings.showwarning, set()

    def show_warning(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, ColonsimWarning):
            show(message, category, filename, lineno, file, line)
        elif _one_line(message) not in shown:  # each distinct warning once (a material is read per run)
            shown.add(_one_line(message))
            print(f"colonsim: warning: {_one_line(message)}", file=sys.stderr)

    with warnings.catch_warnings(), interrupts_not_dropped():  # restore the filters, the display, the hook
        warnings.simplefilter("always", ColonsimWarning)
        warnings.showwarning = show_warning
        try:
            argv = sys.argv[1:] if argv is None else list(argv)
            args = build_parser(command_of(argv)).parse_args(argv)
            args.func(args)
        except ColonsimError as exc:
            print(f"colonsim: error: {_one_line(exc)}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print("colonsim: interrupted; files written so far are complete", file=sys.stderr)
            return 130
        except OSError as exc:  # a failure no writer or reader turned into its own line
            print(f"colonsim: error: {_one_line(os_failure(exc))}", file=sys.stderr)
            return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
