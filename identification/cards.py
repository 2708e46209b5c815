"""Material cards of a fitted law for other solvers: LS-DYNA, Abaqus, ANSYS (MAPDL) and FEBio.

Every format writes the same hyperelastic law with its own constants. Each format's documented
strain-energy convention is written down once, in :data:`CONVENTIONS`; the writers below turn
colonsim's parameters into it and :mod:`colonsim.identification.card_readers` turns a card back
into stresses with the same table.

colonsim's own conventions (:mod:`colonsim.identification.hyperelastic`): the invariant laws
``W = sum C_ij (I1 - 3)^i (I2 - 3)^j`` (C10, C01, C11, C20, C30 in Pa), Ogden
``W = sum_p mu_p / alpha_p (l1^alpha_p + l2^alpha_p + l3^alpha_p - 3)``.

Every card is in the unit system tonne, mm, s, N, MPa (stresses and moduli in MPa, density in
tonne/mm^3), stated in its comment lines. The solvers need a bulk term that colonsim's
incompressible fit does not have: every card takes ``K = 1000 mu0`` (Poisson's ratio 0.4995), a
common choice for rubber-like solids in explicit and implicit codes alike, and says so. The
density is the colon wall's 1040 kg/m^3 (docs/model.md) unless given.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.files import atomic_paths
from colonsim.identification.hyperelastic import calibration_law

FORMATS = ("lsdyna", "abaqus", "ansys", "febio")
SUFFIX = {"lsdyna": "k", "abaqus": "inp", "ansys": "mac", "febio": "xml"}
BULK_OVER_SHEAR = 1000.0
DENSITY = 1040.0  # kg/m^3, the colon wall's (docs/model.md)
MPA = 1e6

# The strain-energy convention of each format's hyperelastic material, as its manual writes it
# (bars: isochoric quantities; the volumetric term vanishes at J = 1). ``ogden`` gives the factor k
# of k (l1^a + l2^a + l3^a - 3) from the format's two constants of a term (m, a).
CONVENTIONS = {
    "lsdyna": {"invariant": "*MAT_HYPERELASTIC_RUBBER (077-H): W = sum C_pq (J1 - 3)^p (J2 - 3)^q + W_H(J)",
               "ogden": "*MAT_OGDEN_RUBBER (077-O): W = sum_i sum_j mu_j / alpha_j (l_i^alpha_j - 1) + K (J - 1 - ln J)",
               "ogden_factor": lambda m, a: m / a, "bulk": "PR, Poisson's ratio"},
    "abaqus": {"invariant": "*HYPERELASTIC, POLYNOMIAL / MOONEY-RIVLIN / NEO HOOKE / YEOH: "
                            "W = sum C_ij (I1b - 3)^i (I2b - 3)^j + sum 1/D_i (J - 1)^(2i)",
               "ogden": "*HYPERELASTIC, OGDEN: W = sum 2 mu_i / alpha_i^2 (l1b^alpha_i + l2b^alpha_i + l3b^alpha_i - 3) "
                        "+ sum 1/D_i (J - 1)^(2i)",
               "ogden_factor": lambda m, a: 2.0 * m / a**2, "bulk": "D1 = 2 / K"},
    "ansys": {"invariant": "TB,HYPER MOONEY (2 or 3 parameters) / NEO / YEOH: W = sum c_ij (I1b - 3)^i (I2b - 3)^j "
                           "+ sum 1/d_k (J - 1)^(2k); NEO: W = mu/2 (I1b - 3) + 1/d (J - 1)^2",
              "ogden": "TB,HYPER OGDEN: W = sum mu_i / alpha_i (l1b^alpha_i + l2b^alpha_i + l3b^alpha_i - 3) "
                       "+ sum 1/d_k (J - 1)^(2k)",
              "ogden_factor": lambda m, a: m / a, "bulk": "d = 2 / K"},
    "febio": {"invariant": "Mooney-Rivlin (uncoupled): W = c1 (I1t - 3) + c2 (I2t - 3) + k/2 (ln J)^2",
              "ogden": "Ogden (uncoupled): W = sum c_i / m_i^2 (l1t^m_i + l2t^m_i + l3t^m_i - 3) + k/2 (ln J)^2",
              "ogden_factor": lambda m, a: m / a**2, "bulk": "k, bulk modulus"},
}


def _g(v) -> str:
    """A number as the card writes it: shortest repr that reads back to the same float."""
    return repr(float(v))


def _header(fmt, law, params, comment="$"):
    mu0 = law.initial_shear_modulus(params)
    K = BULK_OVER_SHEAR * mu0
    kind = "ogden" if law.terms else "invariant"
    lines = [f"colonsim material card ({fmt}): law {law.name}, fitted by colonsim calibrate",
             "units: tonne, mm, s, N, MPa (stress and moduli in MPa, density in tonne/mm^3)",
             f"convention: {CONVENTIONS[fmt][kind]}",
             f"near-incompressibility: K = {BULK_OVER_SHEAR:g} mu0 = {_g(K / MPA)} MPa (mu0 = {_g(mu0 / MPA)} MPa, "
             f"Poisson's ratio {_poisson():.4f}), written as {CONVENTIONS[fmt]['bulk']}; colonsim's fit is incompressible",
             "colonsim parameters (Pa): " + ", ".join(f"{n}={_g(v)}" for n, v in zip(law.parameter_names, params))]
    return [f"{comment} {line}" for line in lines], mu0, K


def _poisson():
    r = BULK_OVER_SHEAR
    return (3 * r - 2) / (2 * (3 * r + 1))


def _refuse(fmt, law, what):
    raise ColonsimError(f"{fmt} cannot hold {law.name}: {what}; export it as "
                        f"{', '.join(f for f in FORMATS if f != fmt and _expressible(f, law))} instead")


def _expressible(fmt, law) -> bool:
    try:
        _check(fmt, law)
        return True
    except ColonsimError:
        return False


def _check(fmt, law):
    if fmt == "febio" and law.name in ("mooney_rivlin_3", "yeoh"):
        raise ColonsimError("FEBio's uncoupled Mooney-Rivlin has no C11 or higher-order I1 term")
    if law.terms and fmt == "lsdyna" and law.terms > 8:
        raise ColonsimError("LS-DYNA's Ogden rubber takes up to 8 terms")


def lsdyna(law, p, density):
    lines, mu0, K = _header("lsdyna", law, p)
    ro = density * 1e-12
    if law.terms:
        mus, alphas = p[0::2] / MPA, p[1::2]
        lines += ["*MAT_OGDEN_RUBBER", "$     MID        RO        PR         N        NV         G      SIGF       REF",
                  _row([1, ro, _poisson(), 0, 0, 0, 0, 0]), "$ MU1..MU8", _row(list(mus) + [0] * (8 - len(mus))),
                  "$ ALPHA1..ALPHA8", _row(list(alphas) + [0] * (8 - len(alphas)))]
    else:
        c = dict(zip(law.parameter_names, p / MPA))
        lines += ["*MAT_HYPERELASTIC_RUBBER", "$     MID        RO        PR         N        NV         G      SIGF       REF",
                  _row([1, ro, _poisson(), 0, 0, 0, 0, 0]), "$ C10 C01 C11 C20 C02 C30 THERML",
                  _row([c.get("C10", 0.0), c.get("C01", 0.0), c.get("C11", 0.0), c.get("C20", 0.0), 0.0, c.get("C30", 0.0), 0.0])]
    return "\n".join(lines + ["*END", ""])


def _row(values):
    # LS-DYNA free format: comma-separated fields (full precision, no 10-character limit)
    return ",".join(_g(v) if isinstance(v, (float, np.floating)) else str(v) for v in values)


def abaqus(law, p, density):
    lines, mu0, K = _header("abaqus", law, p, "**")
    d1 = 2.0 / (K / MPA)
    lines += ["*MATERIAL, NAME=COLONSIM", "*DENSITY", _g(density * 1e-12)]
    c = dict(zip(law.parameter_names, p / MPA))
    if law.terms:
        values = [v for i in range(law.terms) for v in (p[2 * i] * p[2 * i + 1] / 2 / MPA, p[2 * i + 1])]
        values += [d1] + [0.0] * (law.terms - 1)
        lines += [f"*HYPERELASTIC, OGDEN, N={law.terms}"] + [", ".join(_g(v) for v in values[i:i + 8]) for i in range(0, len(values), 8)]
    elif law.name == "mooney_rivlin_3":
        lines += ["*HYPERELASTIC, POLYNOMIAL, N=2", ", ".join(_g(v) for v in (c["C10"], c["C01"], 0.0, c["C11"], 0.0, d1, 0.0))]
    elif law.name == "mooney_rivlin_2":
        lines += ["*HYPERELASTIC, MOONEY-RIVLIN", ", ".join(_g(v) for v in (c["C10"], c["C01"], d1))]
    elif law.name == "neo_hookean":
        lines += ["*HYPERELASTIC, NEO HOOKE", ", ".join(_g(v) for v in (c["C10"], d1))]
    else:  # yeoh
        lines += ["*HYPERELASTIC, YEOH", ", ".join(_g(v) for v in (c["C10"], c["C20"], c["C30"], d1, 0.0, 0.0))]
    return "\n".join(lines + [""])


def ansys(law, p, density):
    lines, mu0, K = _header("ansys", law, p, "!")
    d = 2.0 / (K / MPA)
    c = dict(zip(law.parameter_names, p / MPA))
    lines += ["MAT,1", f"MP,DENS,1,{_g(density * 1e-12)}"]
    if law.terms:
        table, values = f"TB,HYPER,1,,{law.terms},OGDEN", [v for i in range(law.terms) for v in (p[2 * i] / MPA, p[2 * i + 1])]
        values += [d] + [0.0] * (law.terms - 1)
    elif law.name == "mooney_rivlin_3":
        table, values = "TB,HYPER,1,,3,MOONEY", [c["C10"], c["C01"], c["C11"], d]
    elif law.name == "mooney_rivlin_2":
        table, values = "TB,HYPER,1,,2,MOONEY", [c["C10"], c["C01"], d]
    elif law.name == "neo_hookean":
        table, values = "TB,HYPER,1,,,NEO", [2.0 * c["C10"], d]
    else:
        table, values = "TB,HYPER,1,,3,YEOH", [c["C10"], c["C20"], c["C30"], d, 0.0, 0.0]
    lines.append(table)
    lines += [f"TBDATA,{i + 1}," + ",".join(_g(v) for v in values[i:i + 6]) for i in range(0, len(values), 6)]
    return "\n".join(lines + [""])


def febio(law, p, density):
    comments, mu0, K = _header("febio", law, p, "")
    lines = ["<!--"] + [c.strip() for c in comments] + ["-->", "<Material>"]
    if law.terms:
        lines.append('\t<material id="1" name="colonsim" type="Ogden">')
        lines.append(f"\t\t<density>{_g(density * 1e-12)}</density>")
        lines.append(f"\t\t<k>{_g(K / MPA)}</k>")
        for i in range(law.terms):
            lines.append(f"\t\t<c{i + 1}>{_g(p[2 * i] * p[2 * i + 1] / MPA)}</c{i + 1}>")
            lines.append(f"\t\t<m{i + 1}>{_g(p[2 * i + 1])}</m{i + 1}>")
    else:
        c = dict(zip(law.parameter_names, p / MPA))
        lines += ['\t<material id="1" name="colonsim" type="Mooney-Rivlin">', f"\t\t<density>{_g(density * 1e-12)}</density>",
                  f"\t\t<c1>{_g(c['C10'])}</c1>", f"\t\t<c2>{_g(c.get('C01', 0.0))}</c2>", f"\t\t<k>{_g(K / MPA)}</k>"]
    lines += ["\t</material>", "</Material>", ""]
    return "\n".join(lines)


WRITERS = {"lsdyna": lsdyna, "abaqus": abaqus, "ansys": ansys, "febio": febio}


def card_text(fmt, law_name, parameters, density=DENSITY) -> str:
    """The card of ``law_name`` with ``parameters`` ({name: value} or sequence; Pa) in ``fmt``."""
    if fmt not in WRITERS:
        raise ColonsimError(f"unknown export format {fmt!r}; use {', '.join(FORMATS)}")
    law = calibration_law(law_name)
    p = law.values(parameters)
    try:
        _check(fmt, law)
    except ColonsimError as exc:
        _refuse(fmt, law, str(exc))
    if law.terms and np.any(p[1::2] == 0.0):
        raise ColonsimError(f"{law.name}: an Ogden exponent is 0, which no card can hold (mu/alpha); refit")
    return WRITERS[fmt](law, p, float(density))


def check_formats(formats, law_name):
    """Refuse, before anything is written, a format that cannot hold ``law_name``."""
    law = calibration_law(law_name)
    for fmt in formats:
        if fmt not in WRITERS:
            raise ColonsimError(f"unknown export format {fmt!r}; use {', '.join(FORMATS)}")
        try:
            _check(fmt, law)
        except ColonsimError as exc:
            _refuse(fmt, law, str(exc))


def write_cards(formats, law_name, parameters, out_dir, density=DENSITY) -> list[Path]:
    """Write ``material_<format>.<suffix>`` for each format into ``out_dir`` (all or none)."""
    check_formats(formats, law_name)
    texts = {fmt: card_text(fmt, law_name, parameters, density) for fmt in formats}
    paths = [Path(out_dir) / f"material_{fmt}.{SUFFIX[fmt]}" for fmt in texts]
    with atomic_paths(*paths) as temps:
        for tmp, text in zip(temps, texts.values()):
            Path(tmp).write_text(text)
    return paths
