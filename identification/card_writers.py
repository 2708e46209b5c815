"""The text of each format's material card (:mod:`colonsim.identification.card_conventions` has the
keywords and conventions; :mod:`colonsim.identification.card_options` the material id, density,
bulk modulus and deck-or-include choice).

Each writer takes a law, its parameters ``p`` (Pa, colonsim's order) and the options, and returns
the file's text: comment lines (:func:`header`), then the material
in the format's own constants (MPa). LS-DYNA's lines are fixed format, eight fields of 10
characters (:mod:`colonsim.identification.card_numbers`); the other formats take every number at
full precision (``repr``), within their line limits (Abaqus 256, ANSYS 640 characters).
"""

from __future__ import annotations

import math
import textwrap

from colonsim.identification.card_conventions import CARD_TITLE, COMMENT, HEADER_WIDTH, MPA, keyword
from colonsim.identification.card_numbers import FIELD_WIDTH, fixed_row
from colonsim.identification.card_options import HYBRID_POISSON, CardOptions

LSDYNA_OGDEN_TERMS = 8


def header(fmt, law, p, options: CardOptions) -> list[str]:
    """The comment lines every card starts with (without their comment marker): at most
    :data:`HEADER_WIDTH` wide, so that with the widest marker (``** ``) a line holds 80."""
    mu0 = law.initial_shear_modulus(p)
    K = options.bulk_ratio * mu0
    word = keyword(fmt, law.name)
    # no "--" here: an XML comment (FEBio's) may not hold it
    chosen = options.bulk_given or "the default; the bulk-ratio or poisson option chooses another"
    wave = math.sqrt((K + 4.0 / 3.0 * mu0) / options.density)
    implicit = (f"implicit solvers need hybrid (mixed u-p) elements above Poisson's ratio {HYBRID_POISSON}"
                if options.poisson > HYBRID_POISSON else f"below Poisson's ratio {HYBRID_POISSON} implicit solvers "
                "do not require hybrid elements")
    parts = [f"{CARD_TITLE} ({fmt}): law {law.name}, fitted by colonsim calibrate",
             "units: tonne, mm, s, N, MPa (stress and moduli in MPa, density in tonne/mm^3)",
             f"keyword: {word.name}; convention: {word.energy}",
             f"density: {options.density:g} kg/m^3",
             f"bulk modulus: K/mu0 = {options.bulk_ratio:.6g} ({chosen}): K = {K / MPA:.6g} MPa, mu0 = "
             f"{mu0 / MPA:.6g} MPa, Poisson's ratio {options.poisson:.6f}, written as {word.bulk}; the fit "
             "itself is incompressible",
             f"explicit solvers: dilatational wave speed {wave:.4g} m/s, stable step about {1e3 / wave:.3g} us "
             f"per mm of element size; {implicit}",
             "colonsim parameters (Pa): " + ", ".join(f"{n}={float(v)!r}" for n, v in zip(law.parameter_names, p))]
    return [line for part in parts for line in textwrap.wrap(part, width=HEADER_WIDTH, subsequent_indent="  ",
                                                            break_on_hyphens=False)]


def _g(v) -> str:
    """A number as the full-precision formats write it: the shortest text that reads back exactly."""
    return repr(float(v))


def _commented(fmt, lines):
    return [f"{COMMENT[fmt]} {line}" for line in lines]


def _bulk(law, p, options):
    """K in MPa."""
    return options.bulk_ratio * law.initial_shear_modulus(p) / MPA


def _names_row(names):
    """An LS-DYNA comment line naming the fields below it, each over its column."""
    return "$" + "".join(n.rjust(FIELD_WIDTH) for n in names)[1:]


def _invariants(law, p):
    """colonsim's invariant constants by name, MPa (absent ones 0)."""
    return {**dict.fromkeys(("C10", "C01", "C11", "C20", "C30"), 0.0), **dict(zip(law.parameter_names, p / MPA))}


def lsdyna(law, p, options):
    lines = ["*KEYWORD"] if options.deck else []
    lines += _commented("lsdyna", header("lsdyna", law, p, options))
    first = [options.material_id, options.density_tonne_per_mm3, options.poisson, 0, 0, 0.0, 0.0, 0.0]
    card1 = [_names_row(("MID", "RO", "PR", "N", "NV", "G", "SIGF", "REF")), fixed_row(first)]
    if law.terms:
        pad = [0.0] * (LSDYNA_OGDEN_TERMS - law.terms)
        lines += ["*MAT_OGDEN_RUBBER"] + card1
        lines += [_names_row([f"MU{i}" for i in range(1, 9)]), fixed_row(list(p[0::2] / MPA) + pad)]
        lines += [_names_row([f"ALPHA{i}" for i in range(1, 9)]), fixed_row(list(p[1::2]) + pad)]
    else:
        c = _invariants(law, p)
        lines += ["*MAT_HYPERELASTIC_RUBBER"] + card1
        lines += [_names_row(("C10", "C01", "C11", "C20", "C02", "C30", "THERML")),
                  fixed_row([c["C10"], c["C01"], c["C11"], c["C20"], 0.0, c["C30"], 0.0])]
    if options.deck:
        lines.append("*END")
    return "\n".join(lines + [""])


def abaqus(law, p, options):
    # Abaqus has no material-only deck: the same text is *INCLUDEd into the model data either way.
    lines = _commented("abaqus", header("abaqus", law, p, options))
    d1 = 2.0 / _bulk(law, p, options)
    lines += [f"*MATERIAL, NAME=COLONSIM_{options.material_id}", "*DENSITY", _g(options.density_tonne_per_mm3)]
    c = _invariants(law, p)
    if law.terms:
        values = [v for i in range(law.terms) for v in (p[2 * i] * p[2 * i + 1] / 2 / MPA, p[2 * i + 1])]
        values += [d1] + [0.0] * (law.terms - 1)
        option = f"*HYPERELASTIC, OGDEN, N={law.terms}"
    elif law.name == "mooney_rivlin_3":  # N=2: C10, C01, C20, C11, C02, D1, D2
        option, values = "*HYPERELASTIC, POLYNOMIAL, N=2", [c["C10"], c["C01"], 0.0, c["C11"], 0.0, d1, 0.0]
    elif law.name == "mooney_rivlin_2":
        option, values = "*HYPERELASTIC, MOONEY-RIVLIN", [c["C10"], c["C01"], d1]
    elif law.name == "neo_hookean":
        option, values = "*HYPERELASTIC, NEO HOOKE", [c["C10"], d1]
    else:  # yeoh: C10, C20, C30, D1, D2, D3
        option, values = "*HYPERELASTIC, YEOH", [c["C10"], c["C20"], c["C30"], d1, 0.0, 0.0]
    lines += [option] + [", ".join(_g(v) for v in values[i:i + 8]) for i in range(0, len(values), 8)]
    return "\n".join(lines + [""])


def ansys(law, p, options):
    lines = ["/PREP7"] if options.deck else []
    lines += _commented("ansys", header("ansys", law, p, options))
    d = 2.0 / _bulk(law, p, options)
    c = _invariants(law, p)
    mid = options.material_id
    if law.terms:
        table = f"TB,HYPER,{mid},,{law.terms},OGDEN"
        values = [v for i in range(law.terms) for v in (p[2 * i] / MPA, p[2 * i + 1])] + [d] + [0.0] * (law.terms - 1)
    elif law.name == "mooney_rivlin_3":
        table, values = f"TB,HYPER,{mid},,3,MOONEY", [c["C10"], c["C01"], c["C11"], d]
    elif law.name == "mooney_rivlin_2":
        table, values = f"TB,HYPER,{mid},,2,MOONEY", [c["C10"], c["C01"], d]
    elif law.name == "neo_hookean":
        table, values = f"TB,HYPER,{mid},,,NEO", [2.0 * c["C10"], d]
    else:
        table, values = f"TB,HYPER,{mid},,3,YEOH", [c["C10"], c["C20"], c["C30"], d, 0.0, 0.0]
    lines += [f"MP,DENS,{mid},{_g(options.density_tonne_per_mm3)}", table]
    lines += [f"TBDATA,{i + 1}," + ",".join(_g(v) for v in values[i:i + 6]) for i in range(0, len(values), 6)]
    if options.deck:
        lines.append("FINISH")
    return "\n".join(lines + [""])


def _febio_constants(law, p, options):
    """(FEBio material type, [(tag, value)]) of the law, MPa."""
    K = _bulk(law, p, options)
    c = _invariants(law, p)
    if law.terms:
        tags = [(t, v) for i in range(law.terms)
                for t, v in ((f"c{i + 1}", p[2 * i] * p[2 * i + 1] / MPA), (f"m{i + 1}", p[2 * i + 1]))]
        return "Ogden", tags + [("k", K)]
    if law.name == "mooney_rivlin_3":
        return "polynomial", [("c10", c["C10"]), ("c01", c["C01"]), ("c11", c["C11"]), ("D1", K / 2.0)]
    if law.name == "yeoh":
        return "Yeoh", [("c1", c["C10"]), ("c2", c["C20"]), ("c3", c["C30"]), ("k", K)]
    return "Mooney-Rivlin", [("c1", c["C10"]), ("c2", c["C01"]), ("k", K)]


def febio(law, p, options):
    kind, tags = _febio_constants(law, p, options)
    indent = "\t" if options.deck else ""
    lines = ['<?xml version="1.0" encoding="ISO-8859-1"?>'] if options.deck else []
    lines += ["<!--", *header("febio", law, p, options), "-->"]
    lines += ['<febio_spec version="4.0">'] if options.deck else []
    mid = options.material_id
    body = [f'\t<material id="{mid}" name="colonsim_{mid}" type="{kind}">',
            f"\t\t<density>{_g(options.density_tonne_per_mm3)}</density>"]
    body += [f"\t\t<{t}>{_g(v)}</{t}>" for t, v in tags] + ["\t</material>"]
    lines += [f"{indent}<Material>"] + [indent + b for b in body] + [f"{indent}</Material>"]
    lines += ["</febio_spec>"] if options.deck else []
    return "\n".join(lines + [""])


WRITERS = {"lsdyna": lsdyna, "abaqus": abaqus, "ansys": ansys, "febio": febio}
