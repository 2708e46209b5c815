"""The command line of multi-mode fits and material cards: the ``calibrate`` options of
:mod:`colonsim.calibrate_modes` and ``--export``, which :mod:`colonsim.cli` adds to its ``calibrate``
parser, and ``colonsim material export`` for an existing material.json."""

from __future__ import annotations

from pathlib import Path

from colonsim.identification.cards import DENSITY, FORMATS
from colonsim.options import StretchRange, finite_float, output_folder, ranged


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
    g.add_argument("--stability-range", type=finite_float, nargs=2, metavar=("LOW", "HIGH"), action=StretchRange,
                   help="stretches over which a multi-mode fit's laws are checked for Drucker stability "
                        "(default 0.5 to twice the largest tested stretch; a strip fit always checks that default)")
    c = parser.add_argument_group("clean-up (recorded in material.json)")
    c.add_argument("--load-start", type=_load_start, default=None, metavar="detect|off|MM",
                   help="where the load starts: detect (slack or preload found in the data), off (raw curve), or the "
                        "displacement in mm; default: a slack region found is corrected and said so, a preload only reported")
    c.add_argument("--decimate", type=ranged("--decimate"), default=None, metavar="N",
                   help="resample every curve at N evenly spaced displacements (stretches) before fitting (5 to the "
                        "curve's own points)")
    parser.add_argument("--export", nargs="+", choices=FORMATS, metavar="FORMAT",
                        help=f"also write the fitted law as material cards: {', '.join(FORMATS)} (material_<format>.* in --out)")


def _load_start(text):
    import argparse

    if text in ("detect", "off"):
        return text
    try:
        return finite_float(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"--load-start {text!r}: give detect, off or a displacement in mm") from None


def add_parsers(sub):
    """``colonsim material export``."""
    p = sub.add_parser("material", help="material files: export a calibration's law as cards for other solvers")
    msub = p.add_subparsers(dest="material_command", required=True)
    e = msub.add_parser("export", help="write material.json's law as LS-DYNA, Abaqus, ANSYS or FEBio cards",
                        description="Write the law of a colonsim material.json as material cards (units tonne, mm, s, N, "
                                    "MPa; bulk modulus 1000 mu0; docs/calibration.md).")
    e.add_argument("material", type=Path, help="material.json written by colonsim calibrate")
    e.add_argument("--format", nargs="+", required=True, choices=FORMATS, help="one or more of " + ", ".join(FORMATS))
    e.add_argument("--out", type=output_folder, default=None, help="output folder (default: the material file's folder)")
    e.add_argument("--density", type=finite_float, default=DENSITY,
                   help=f"density written into the cards, kg/m^3 (default {DENSITY:g}, the colon wall's)")
    e.set_defaults(func=cmd_material_export)


def _law_and_parameters(path):
    from colonsim.errors import ColonsimError
    from colonsim.identification.hyperelastic import calibration_law
    from colonsim.insertion.engine.material import read_material_document
    from colonsim.schemas import check_material_document

    doc = read_material_document(path)
    law = doc.get("law")
    if not isinstance(law, str):
        raise ColonsimError(f"material file {path} has no law; pass a material.json of colonsim calibrate")
    return law, check_material_document(doc, path, calibration_law(law).parameter_names)


def cmd_material_export(args):
    from colonsim.identification.cards import write_cards

    law, params = _law_and_parameters(args.material)
    out = args.out if args.out is not None else args.material.parent
    for path in write_cards(args.format, law, params, out, args.density):
        print(f"{path}")


def check_export(args):
    """Before a calibration: refuse --export with --per-specimen, or a format that cannot hold --law."""
    from colonsim.errors import ColonsimError
    from colonsim.identification.cards import check_formats

    if not args.export:
        return
    if args.per_specimen:
        raise ColonsimError("--export writes one material's cards; fit the mean curve, or export a specimen's "
                            "material.json with colonsim material export")
    if args.law is not None:
        check_formats(args.export, args.law)


def export_after(args):
    """After a calibration: the cards of the material.json it wrote."""
    from colonsim.identification.cards import write_cards

    if args.export:
        law, params = _law_and_parameters(args.out / "material.json")
        paths = write_cards(args.export, law, params, args.out)
        print("material cards: " + ", ".join(str(p) for p in paths))


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
                          displacement_unit=args.displacement_unit, force_unit=args.force_unit,
                          load_start=args.load_start, decimate=args.decimate)
    check_export(args)
    calibrate_modes(request, args.out)
    export_after(args)

