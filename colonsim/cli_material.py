"""The ``calibrate`` options of multi-mode fits (the command line's share of
:mod:`colonsim.calibrate_modes`); :mod:`colonsim.cli` adds them to its ``calibrate`` parser."""

from __future__ import annotations

from colonsim.options import finite_float


def add_calibrate_options(parser):
    """The multi-mode options of ``colonsim calibrate``."""
    g = parser.add_argument_group("test modes (a stress-stretch --curve with --mode, or a manifest with a mode column)")
    g.add_argument("--mode", choices=("uniaxial", "equibiaxial", "planar"),
                   help="test mode of a stress-stretch --curve (columns stretch or strain, nominal_stress [MPa|kPa|Pa|kgf/cm2])")
    g.add_argument("--stress-measure", choices=("nominal", "cauchy"),
                   help="measure of a stress column named only 'stress' (never guessed)")
    g.add_argument("--residuals", choices=("relative", "absolute"), default="relative",
                   help="joint-fit residuals per curve: relative (default; floor 10%% of the curve's peak) or "
                        "absolute in units of the curve's peak")
    g.add_argument("--stability-range", type=finite_float, nargs=2, metavar=("LOW", "HIGH"),
                   help="stretches over which every fitted law is checked for Drucker stability "
                        "(default 0.5 to twice the largest tested stretch)")


def wants_modes(args) -> bool:
    from colonsim.calibrate_modes import wants_modes as wanted

    return wanted(args.manifest, args.curve, args.mode)


def cmd_calibrate_modes(args):
    from colonsim.calibrate_modes import ModeRequest, calibrate_modes
    from colonsim.errors import ColonsimError

    if args.per_specimen:
        raise ColonsimError("--per-specimen fits strips one by one; a joint fit takes every curve of the manifest together")
    if any(v is not None for v in (args.length, args.width, args.thickness)):
        raise ColonsimError("--length/--width/--thickness go with a force-displacement --curve; a stress-stretch curve has none")
    request = ModeRequest(manifest=args.manifest, curve=args.curve, mode=args.mode, stress_measure=args.stress_measure,
                          law=args.law, compare_laws=args.compare_laws, residuals=args.residuals,
                          stability_range=tuple(args.stability_range) if args.stability_range else None,
                          analytic=args.analytic, mesh=args.mesh, quick=args.quick, seed=args.seed,
                          displacement_unit=args.displacement_unit, force_unit=args.force_unit)
    calibrate_modes(request, args.out)

