"""Each format's material keyword for each law, and its strain-energy convention as the format's
manual writes it: the one table the card writers (:mod:`colonsim.identification.card_writers`) and
readers (:mod:`colonsim.identification.card_readers`) share.

colonsim's own conventions (:mod:`colonsim.identification.hyperelastic`): the invariant laws
``W = sum C_ij (I1 - 3)^i (I2 - 3)^j`` (C10, C01, C11, C20, C30 in Pa), Ogden
``W = sum_p mu_p / alpha_p (l1^alpha_p + l2^alpha_p + l3^alpha_p - 3)``. The Ogden constants are
where the codes differ: :data:`OGDEN_FACTOR` turns a format's two constants of a term into the
factor of ``(l1^a + l2^a + l3^a - 3)``.
"""

from __future__ import annotations

from dataclasses import dataclass

from colonsim.errors import ColonsimError
from colonsim.identification.hyperelastic import calibration_law

FORMATS = ("lsdyna", "abaqus", "ansys", "febio")
SUFFIX = {"lsdyna": "k", "abaqus": "inp", "ansys": "mac", "febio": "xml"}
COMMENT = {"lsdyna": "$", "abaqus": "**", "ansys": "!", "febio": ""}
MPA = 1e6
CARD_TITLE = "colonsim material card"
HEADER_WIDTH = 77  # LS-DYNA reads 80 columns; every format's comments keep to it


@dataclass(frozen=True)
class Keyword:
    """A format's material keyword for one law: as written, its strain energy as the format's
    manual writes it (bars and tildes: isochoric quantities), and how the bulk modulus is written."""

    name: str
    energy: str
    bulk: str


_LS_RUBBER = Keyword("*MAT_HYPERELASTIC_RUBBER (077-H)", "W = sum C_pq (J1 - 3)^p (J2 - 3)^q + W_H(J)", "PR, Poisson's ratio")
_LS_OGDEN = Keyword("*MAT_OGDEN_RUBBER (077-O)",
                    "W = sum_i sum_j mu_j / alpha_j (l_i^alpha_j - 1) + K (J - 1 - ln J)", "PR, Poisson's ratio")
_ABQ_POLY = "W = sum C_ij (I1b - 3)^i (I2b - 3)^j + sum 1/D_i (J - 1)^(2i)"
_ANSYS_POLY = "W = sum c_ij (I1b - 3)^i (I2b - 3)^j + sum 1/d_k (J - 1)^(2k)"
_OGDEN_TERMS = ("ogden_1", "ogden_2", "ogden_3")
# The keyword of every law a format holds; a law missing from a format's table is refused.
KEYWORDS = {
    "lsdyna": {**{n: _LS_RUBBER for n in ("mooney_rivlin_3", "mooney_rivlin_2", "neo_hookean", "yeoh")},
               **{n: _LS_OGDEN for n in _OGDEN_TERMS}},
    "abaqus": {"mooney_rivlin_3": Keyword("*HYPERELASTIC, POLYNOMIAL, N=2", _ABQ_POLY, "D1 = 2 / K"),
               "mooney_rivlin_2": Keyword("*HYPERELASTIC, MOONEY-RIVLIN", _ABQ_POLY, "D1 = 2 / K"),
               "neo_hookean": Keyword("*HYPERELASTIC, NEO HOOKE", _ABQ_POLY, "D1 = 2 / K"),
               "yeoh": Keyword("*HYPERELASTIC, YEOH", _ABQ_POLY, "D1 = 2 / K"),
               **{n: Keyword("*HYPERELASTIC, OGDEN", "W = sum 2 mu_i / alpha_i^2 (l1b^alpha_i + l2b^alpha_i + "
                             "l3b^alpha_i - 3) + sum 1/D_i (J - 1)^(2i)", "D1 = 2 / K") for n in _OGDEN_TERMS}},
    "ansys": {"mooney_rivlin_3": Keyword("TB,HYPER,,,3,MOONEY", _ANSYS_POLY, "d = 2 / K"),
              "mooney_rivlin_2": Keyword("TB,HYPER,,,2,MOONEY", _ANSYS_POLY, "d = 2 / K"),
              "neo_hookean": Keyword("TB,HYPER,,,,NEO", "W = mu/2 (I1b - 3) + 1/d (J - 1)^2", "d = 2 / K"),
              "yeoh": Keyword("TB,HYPER,,,3,YEOH", "W = sum c_i0 (I1b - 3)^i + sum 1/d_k (J - 1)^(2k)", "d = 2 / K"),
              **{n: Keyword("TB,HYPER,,,N,OGDEN", "W = sum mu_i / alpha_i (l1b^alpha_i + l2b^alpha_i + l3b^alpha_i - 3) "
                            "+ sum 1/d_k (J - 1)^(2k)", "d = 2 / K") for n in _OGDEN_TERMS}},
    "febio": {"mooney_rivlin_3": Keyword("polynomial", "W = sum c_ij (I1t - 3)^i (I2t - 3)^j + D1 (J - 1)^2 + "
                                         "D2 (J - 1)^4", "D1 = K / 2 (a stiffness)"),
              **{n: Keyword("Mooney-Rivlin", "W = c1 (I1t - 3) + c2 (I2t - 3) + k/2 (ln J)^2", "k, bulk modulus")
                 for n in ("mooney_rivlin_2", "neo_hookean")},
              "yeoh": Keyword("Yeoh", "W = sum_i c_i (I1t - 3)^i (i = 1..6) + k/2 (ln J)^2", "k, bulk modulus"),
              **{n: Keyword("Ogden", "W = sum c_i / m_i^2 (l1t^m_i + l2t^m_i + l3t^m_i - 3) + k/2 (ln J)^2",
                            "k, bulk modulus") for n in _OGDEN_TERMS}},
}
# The factor k of k (l1^a + l2^a + l3^a - 3) from a format's two constants (m, a) of an Ogden term.
OGDEN_FACTOR = {"lsdyna": lambda m, a: m / a, "abaqus": lambda m, a: 2.0 * m / a**2,
                "ansys": lambda m, a: m / a, "febio": lambda m, a: m / a**2}


def _check_format(fmt):
    if fmt not in FORMATS:
        raise ColonsimError(f"unknown export format {fmt!r}; use {', '.join(FORMATS)}")


def keyword(fmt, law_name) -> Keyword:
    """The keyword of ``law_name`` in ``fmt``, or one line naming the formats that hold it."""
    _check_format(fmt)
    law = calibration_law(law_name).name
    if law not in KEYWORDS[fmt]:
        others = [f for f in FORMATS if law in KEYWORDS[f]]
        raise ColonsimError(f"{fmt} cannot hold {law}: colonsim writes no {fmt} material for it; export it as "
                            f"{', '.join(others) or 'colonsim material.json only'} instead")
    return KEYWORDS[fmt][law]


def check_formats(formats, law_names):
    """Refuse, before anything is fitted or written, a format that cannot hold one of ``law_names``."""
    for law in law_names:
        for fmt in formats:
            keyword(fmt, law)
