"""The command line of multi-mode fits and material cards: the ``calibrate`` options of
:mod:`colonsim.calibrate_modes` and ``--export``, which :mod:`colonsim.cli` adds to its ``calibrate``
parser, and ``colonsim material export`` for an existing material.json."""

from __future__ import annotations

import argparse
from pathlib import Path

from colonsim.identification.card_options import (BULK_RATIO_DEFAULT, BULK_RATIO_RANGE, DENSITY_DEFAULT, DENSITY_RANGE,
                                                  MATERIAL_ID_RANGE, check_bulk_ratio, check_density, check_material_id,
                                                  check_poisson, poisson_from_bulk_ratio)
from colonsim.identification.cards import FORMATS, SUFFIX
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
    cards = parser.add_argument_group("material cards (docs/cards.md; the options below go with --export)")
    cards.add_argument("--export", nargs="+", choices=FORMATS, metavar="FORMAT",
                       help=f"also write the fitted law as material cards: {', '.join(FORMATS)} (material_<format>.* in --out)")
    add_card_options(cards, given_only=True)


def _typed(check, convert=float):
    def value_type(text):
        from colonsim.errors import ColonsimError

        try:
            return check(convert(text))
        except ValueError as exc:  # ColonsimError is one
            kind = "a whole number" if convert is int else "a number"
            message = str(exc) if isinstance(exc, ColonsimError) else f"{text!r} is not {kind}"
            raise argparse.ArgumentTypeError(message) from None

    value_type.__name__ = "number"
    return value_type


def add_card_options(group, given_only=False):
    """The options of the cards: material id, density, bulk modulus, deck or include. With
    ``given_only`` their defaults are None, so that a value given without --export is noticed."""
    def default(value):
        return None if given_only else value

    low, high = BULK_RATIO_RANGE
    group.add_argument("--material-id", type=_typed(check_material_id, int), default=default(1), metavar="N",
                       help=f"material number in the cards (LS-DYNA MID, ANSYS material, FEBio id, Abaqus name "
                            f"COLONSIM_N), {MATERIAL_ID_RANGE[0]}-{MATERIAL_ID_RANGE[1]:,} (default 1)")
    group.add_argument("--density", type=_typed(check_density), default=default(DENSITY_DEFAULT), metavar="KG_M3",
                       help=f"density, kg/m^3, {DENSITY_RANGE[0]:g}-{DENSITY_RANGE[1]:g} (default {DENSITY_DEFAULT:g}, "
                            "the colon wall's; rubber 900-2000)")
    bulk = group.add_mutually_exclusive_group() if hasattr(group, "add_mutually_exclusive_group") else group
    bulk.add_argument("--bulk-ratio", type=_typed(check_bulk_ratio), default=None, metavar="K_MU0",
                      help=f"bulk modulus as K/mu0, {low:g}-{high:g} (default {BULK_RATIO_DEFAULT:g}, Poisson's ratio "
                           f"{poisson_from_bulk_ratio(BULK_RATIO_DEFAULT):.4f}; docs/cards.md: larger follows the "
                           "incompressible fit more closely and shortens an explicit solver's stable step)")
    bulk.add_argument("--poisson", type=_typed(check_poisson), default=None, metavar="NU",
                      help=f"bulk modulus as the small-strain Poisson's ratio, {poisson_from_bulk_ratio(low):.4f}-"
                           f"{poisson_from_bulk_ratio(high):.6f} (instead of --bulk-ratio)")
    group.add_argument("--deck", action="store_true", default=None if given_only else False,
                       help="write stand-alone files (LS-DYNA *KEYWORD ... *END, ANSYS /PREP7 ... FINISH, FEBio "
                            "<febio_spec>) instead of include files (default)")


CARD_OPTIONS = ("material_id", "density", "bulk_ratio", "poisson", "deck")


def card_options(args):
    """The CardOptions of the parsed options (defaults for those not given)."""
    from colonsim.identification.card_options import CardOptions

    given = {}
    if args.bulk_ratio is not None:
        given = dict(bulk_ratio=args.bulk_ratio, bulk_given=f"bulk-ratio {args.bulk_ratio:g} given")
    elif args.poisson is not None:  # check_poisson turned it into K/mu0
        given = dict(bulk_ratio=args.poisson,
                     bulk_given=f"poisson {poisson_from_bulk_ratio(args.poisson):.6g} given")
    return CardOptions(material_id=args.material_id or 1,
                       density=DENSITY_DEFAULT if args.density is None else args.density,
                       deck=bool(args.deck), **given)


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
                                    "MPa; docs/cards.md). Cards already in the output folder that were written from "
                                    "another material are rewritten with them; a folder whose material.json holds "
                                    "another material is refused.")
    e.add_argument("material", type=Path, help="material.json written by colonsim calibrate")
    e.add_argument("--format", nargs="+", required=True, choices=FORMATS, help="one or more of " + ", ".join(FORMATS))
    e.add_argument("--out", type=output_folder, default=None, help="output folder (default: the material file's folder)")
    add_card_options(e)
    e.set_defaults(func=cmd_material_export)


def _written(paths, asked):
    for path in paths:
        stale = path.name not in {f"material_{f}.{SUFFIX[f]}" for f in asked}
        print(f"{path}" + ("  (rewritten: it held another material's card)" if stale else ""))


def cmd_material_export(args):
    from colonsim.identification.cards import read_material, write_cards

    options = card_options(args)
    law, params = read_material(args.material)
    out = args.out if args.out is not None else args.material.parent
    _written(write_cards(args.format, law, params, out, options, source=args.material), args.format)


def _fitted_laws(args):
    """The laws a calibration may write: --law, every law with --compare-laws, else the default."""
    from colonsim.calibrate_modes import wants_modes as modes
    from colonsim.identification.hyperelastic import CALIBRATION_LAWS
    from colonsim.laws import DEFAULT_LAW, LAWS

    if args.compare_laws:
        return list(CALIBRATION_LAWS if modes(args.manifest, args.curve, args.mode) else LAWS)
    return [args.law or DEFAULT_LAW]


def check_export(args):
    """Before a calibration, before anything is fitted or written: refuse --export with
    --per-specimen, a format that cannot hold the law (whichever law the fit will write), card
    options without --export, and cards in --out that the new material.json would leave stale."""
    from colonsim.errors import ColonsimError
    from colonsim.identification.cards import FORMATS as ALL, card_path, check_formats

    given = [f"--{o.replace('_', '-')}" for o in CARD_OPTIONS if getattr(args, o) is not None]
    if not args.export:
        if given:
            raise ColonsimError(f"{given[0]} sets the material cards; add --export FORMAT, or drop it")
        held = [card_path(args.out, f).name for f in ALL if card_path(args.out, f).is_file()]
        if held and not args.per_specimen:  # --per-specimen leaves the folder's material.json alone
            raise ColonsimError(f"{args.out} holds material cards of the earlier fit ({', '.join(held)}), which the new "
                                "material.json would leave stale; add --export with their formats to rewrite them, "
                                "or choose another --out")
        return
    if args.per_specimen:
        raise ColonsimError("--export writes one material's cards; fit the mean curve, or export a specimen's "
                            "material.json with colonsim material export")
    held = [f for f in ALL if card_path(args.out, f).is_file()]
    check_formats(list(dict.fromkeys([*args.export, *held])), _fitted_laws(args))
    card_options(args)


def export_after(args):
    """After a calibration: the cards of the material.json it wrote (and the folder's earlier
    cards, rewritten from it)."""
    from colonsim.identification.cards import read_material, write_cards

    if args.export:
        material = args.out / "material.json"
        law, params = read_material(material)
        paths = write_cards(args.export, law, params, args.out, card_options(args), source=material)
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

