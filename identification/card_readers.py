"""Reading a written material card back, and the stress its own format's convention gives.

Each reader parses what :mod:`colonsim.identification.card_writers` writes, the way the solver
reads it (LS-DYNA: fixed columns of 10 characters, nothing past column 80, or comma-separated
free format), and returns the card's law in the format's terms converted to one of two neutral
forms (Pa):

- ``{"polynomial": {(i, j): C_ij}}``: ``W = sum C_ij (I1 - 3)^i (I2 - 3)^j``;
- ``{"ogden": [(k, a), ...]}``: ``W = sum k (l1^a + l2^a + l3^a - 3)``, k from the format's two
  constants of a term by :data:`colonsim.identification.card_conventions.OGDEN_FACTOR`;

plus ``bulk_modulus`` (Pa), ``density`` (kg/m^3) and ``material_id``. A file that is not such a
card is refused in one line (:class:`colonsim.errors.ColonsimError`).

:func:`nominal_stress` evaluates either form in the three test modes (incompressible: the
volumetric term vanishes at J = 1), by its own arithmetic, not colonsim's law code, so a test can
compare the two.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.identification.card_conventions import FORMATS, MPA, OGDEN_FACTOR
from colonsim.identification.card_numbers import FIELD_WIDTH, fixed_fields
from colonsim.identification.card_options import bulk_ratio_from_poisson

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def _numbers(text):
    return [float(v) for v in re.findall(_NUMBER, text)]


def _data_lines(text, comment):
    return [l for l in text.splitlines() if l.strip() and not l.strip().startswith(comment)]


def initial_shear_modulus(form) -> float:
    """mu0 of a neutral form, Pa: 2 (C10 + C01), or 1/2 sum k a^2 for Ogden."""
    if "ogden" in form:
        return 0.5 * sum(k * a * a for k, a in form["ogden"])
    return 2.0 * (form["polynomial"].get((1, 0), 0.0) + form["polynomial"].get((0, 1), 0.0))


def _ogden(fmt, pairs):
    factor = OGDEN_FACTOR[fmt]
    return {"ogden": [(factor(m * MPA, a), a) for m, a in pairs if a != 0.0 or m != 0.0]}


def _polynomial(keys, values):
    return {"polynomial": {k: v * MPA for k, v in zip(keys, values, strict=True)}}


def _lsdyna_values(line):
    """The values of one LS-DYNA data line: free format if it holds a comma, else fixed columns;
    as LS-DYNA reads them, a free-format value may not be wider than its fixed field."""
    cells = [c.strip() for c in line.split(",")] if "," in line else fixed_fields(line)
    wide = next((c for c in cells if len(c) > FIELD_WIDTH), None)
    if wide is not None:
        raise ColonsimError(f"LS-DYNA field {wide!r} is wider than {FIELD_WIDTH} characters, which LS-DYNA cuts; "
                            "write the card again with colonsim material export")
    return [float(c) if c else 0.0 for c in cells]


def read_lsdyna(text):
    lines = [l for l in _data_lines(text, "$") if l.strip().upper() not in ("*KEYWORD", "*END")]
    key = lines[0].strip().upper()
    card1 = _lsdyna_values(lines[1])
    if key.startswith("*MAT_OGDEN_RUBBER"):
        form = _ogden("lsdyna", zip(_lsdyna_values(lines[2]), _lsdyna_values(lines[3])))
    elif key.startswith("*MAT_HYPERELASTIC_RUBBER"):
        c10, c01, c11, c20, c02, c30 = _lsdyna_values(lines[2])[:6]
        form = _polynomial([(1, 0), (0, 1), (1, 1), (2, 0), (0, 2), (3, 0)], [c10, c01, c11, c20, c02, c30])
    else:
        raise ColonsimError(f"not a card colonsim writes for LS-DYNA: {lines[0].strip()!r}")
    ratio = bulk_ratio_from_poisson(card1[2])
    return {**form, "bulk_modulus": ratio * initial_shear_modulus(form), "density": card1[1] * 1e12,
            "material_id": int(card1[0])}


def read_abaqus(text):
    lines = [l.strip() for l in _data_lines(text, "**")]
    i = next((k for k, l in enumerate(lines) if l.upper().startswith("*HYPERELASTIC")), None)
    if i is None:
        raise ColonsimError("no *HYPERELASTIC line: not a card colonsim writes for Abaqus")
    option = lines[i].upper()
    values = [v for l in lines[i + 1:] if not l.startswith("*") for v in _numbers(l)]
    if "OGDEN" in option:
        n = int(re.search(r"N\s*=\s*(\d+)", option).group(1))
        form, d1 = _ogden("abaqus", zip(values[0:2 * n:2], values[1:2 * n:2])), values[2 * n]
    else:
        keys = {"POLYNOMIAL": [(1, 0), (0, 1), (2, 0), (1, 1), (0, 2)], "MOONEY": [(1, 0), (0, 1)],
                "NEO": [(1, 0)], "YEOH": [(1, 0), (2, 0), (3, 0)]}
        kind = next((k for k in keys if k in option), None)
        if kind is None:
            raise ColonsimError(f"not a card colonsim writes for Abaqus: {lines[i]!r}")
        form, d1 = _polynomial(keys[kind], values[:len(keys[kind])]), values[len(keys[kind])]
    name = re.search(r"NAME\s*=\s*COLONSIM_(\d+)", text, re.IGNORECASE)
    density = lines[lines.index("*DENSITY") + 1]
    return {**form, "bulk_modulus": 2.0 / d1 * MPA, "density": float(density.split(",")[0]) * 1e12,
            "material_id": int(name.group(1))}


def read_ansys(text):
    lines = [l.strip() for l in _data_lines(text, "!")]
    table = next((l for l in lines if l.upper().startswith("TB,HYPER")), None)
    if table is None:
        raise ColonsimError("no TB,HYPER command: not a card colonsim writes for ANSYS")
    fields = [f.strip().upper() for f in table.split(",")]
    values = [v for l in lines if l.upper().startswith("TBDATA") for v in _numbers(l.split(",", 2)[2])]
    kind = fields[5]
    if kind == "OGDEN":
        n = int(fields[4])
        form, d = _ogden("ansys", zip(values[0:2 * n:2], values[1:2 * n:2])), values[2 * n]
    elif kind == "NEO":  # W = mu/2 (I1 - 3)
        form, d = {"polynomial": {(1, 0): values[0] / 2 * MPA}}, values[1]
    elif kind in ("MOONEY", "YEOH"):
        keys = [(1, 0), (0, 1), (1, 1)][: int(fields[4])] if kind == "MOONEY" else [(1, 0), (2, 0), (3, 0)]
        form, d = _polynomial(keys, values[:len(keys)]), values[len(keys)]
    else:
        raise ColonsimError(f"not a card colonsim writes for ANSYS: {table!r}")
    dens = next(l for l in lines if l.upper().startswith("MP,DENS")).split(",")
    return {**form, "bulk_modulus": 2.0 / d * MPA, "density": float(dens[3]) * 1e12, "material_id": int(fields[2])}


def read_febio(text):
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as exc:
        raise ColonsimError(f"not well-formed XML ({exc}): not a card colonsim writes for FEBio") from None
    material = root if root.tag == "material" else root.find(".//material")
    if material is None:
        raise ColonsimError("no <material> element: not a card colonsim writes for FEBio")
    kind = material.get("type")
    tags = {child.tag: float(child.text) for child in material}
    if kind == "Ogden":
        n = sum(1 for k in tags if re.fullmatch(r"m\d", k))
        form = _ogden("febio", [(tags[f"c{i}"], tags[f"m{i}"]) for i in range(1, n + 1)])
    elif kind == "Mooney-Rivlin":
        form = _polynomial([(1, 0), (0, 1)], [tags["c1"], tags["c2"]])
    elif kind == "Yeoh":
        found = [i for i in range(1, 7) if f"c{i}" in tags]
        form = _polynomial([(i, 0) for i in found], [tags[f"c{i}"] for i in found])
    elif kind == "polynomial":  # W = sum c_ij (I1 - 3)^i (I2 - 3)^j + D1 (J - 1)^2: K = 2 D1
        found = [(int(k[1]), int(k[2])) for k in tags if re.fullmatch(r"c[0-2][0-2]", k)]
        form = _polynomial(found, [tags[f"c{i}{j}"] for i, j in found])
        tags["k"] = 2.0 * tags["D1"]
    else:
        raise ColonsimError(f"not a card colonsim writes for FEBio: type {kind!r}")
    return {**form, "bulk_modulus": tags["k"] * MPA, "density": tags["density"] * 1e12,
            "material_id": int(material.get("id"))}


READERS = {"lsdyna": read_lsdyna, "abaqus": read_abaqus, "ansys": read_ansys, "febio": read_febio}


def read_card(fmt, path_or_text):
    """The neutral form of a card (text, or a :class:`~pathlib.Path` to read) written in ``fmt``."""
    if fmt not in READERS:
        raise ColonsimError(f"unknown card format {fmt!r}; use {', '.join(FORMATS)}")
    text = Path(path_or_text).read_text(encoding="utf-8") if isinstance(path_or_text, Path) else str(path_or_text)
    try:
        return READERS[fmt](text)
    except ColonsimError:
        raise
    except (StopIteration, IndexError, KeyError, ValueError, TypeError, AttributeError, ZeroDivisionError) as exc:
        raise ColonsimError(f"not a {fmt} card colonsim writes, or an edited one ({type(exc).__name__}: {exc}); "
                            "write it again with colonsim material export") from None


_MODE_STRETCHES = {"uniaxial": lambda l: (l, l**-0.5, l**-0.5), "equibiaxial": lambda l: (l, l, l**-2.0),
                   "planar": lambda l: (l, 1.0 + 0.0 * l, 1.0 / l)}


def nominal_stress(form, mode, stretch):
    """Nominal stress (Pa) of a card's law in ``mode``: (sigma_1 - sigma_3) / l1, J = 1."""
    l1, l2, l3 = _MODE_STRETCHES[mode](np.asarray(stretch, dtype=float))
    if "ogden" in form:
        t1 = sum(k * a * (l1**a - l3**a) for k, a in form["ogden"])
    else:
        a = l1**2 + l2**2 + l3**2 - 3.0
        b = l1**-2 + l2**-2 + l3**-2 - 3.0
        W1 = sum(c * i * a ** (i - 1) * b**j for (i, j), c in form["polynomial"].items() if i > 0)
        W2 = sum(c * j * a**i * b ** (j - 1) for (i, j), c in form["polynomial"].items() if j > 0)
        t1 = 2.0 * W1 * (l1**2 - l3**2) - 2.0 * W2 * (l1**-2 - l3**-2)
    return t1 / l1
