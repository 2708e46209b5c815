"""Reading a written material card back, and the stress its own format's convention gives.

Each reader parses what :mod:`colonsim.identification.cards` writes and returns the card's law in
the format's terms, converted to one of two neutral forms (Pa):

- ``{"polynomial": {(i, j): C_ij}}``: ``W = sum C_ij (I1 - 3)^i (I2 - 3)^j``;
- ``{"ogden": [(k, a), ...]}``: ``W = sum k (l1^a + l2^a + l3^a - 3)``, k from the format's two
  constants of a term by :data:`colonsim.identification.cards.CONVENTIONS` (``ogden_factor``).

:func:`nominal_stress` evaluates either form in the three test modes (incompressible: the
volumetric term vanishes at J = 1), by its own arithmetic, not colonsim's law code, so a test can
compare the two.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.identification.cards import CONVENTIONS, MPA

_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def _numbers(line):
    return [float(v) for v in re.findall(_NUMBER, line)]


def _data_lines(text, comment):
    return [l.strip() for l in text.splitlines() if l.strip() and not l.strip().startswith(comment)]


def _ogden(fmt, pairs):
    factor = CONVENTIONS[fmt]["ogden_factor"]
    return {"ogden": [(factor(m * MPA, a), a) for m, a in pairs if a != 0.0 or m != 0.0]}


def read_lsdyna(text):
    lines = _data_lines(text, "$")
    key = lines[0].upper()
    if key.startswith("*MAT_OGDEN_RUBBER"):
        mus, alphas = _numbers(lines[2]), _numbers(lines[3])
        return _ogden("lsdyna", zip(mus, alphas))
    if key.startswith("*MAT_HYPERELASTIC_RUBBER"):
        c10, c01, c11, c20, c02, c30, _ = _numbers(lines[2])
        return {"polynomial": {(1, 0): c10 * MPA, (0, 1): c01 * MPA, (1, 1): c11 * MPA, (2, 0): c20 * MPA,
                               (0, 2): c02 * MPA, (3, 0): c30 * MPA}}
    raise ColonsimError(f"not a card colonsim writes for LS-DYNA: {lines[0]!r}")


def read_abaqus(text):
    lines = _data_lines(text, "**")
    i = next(k for k, l in enumerate(lines) if l.upper().startswith("*HYPERELASTIC"))
    option = lines[i].upper()
    values = [v for l in lines[i + 1:] if not l.startswith("*") for v in _numbers(l)]
    if "OGDEN" in option:
        n = int(re.search(r"N\s*=\s*(\d+)", option).group(1))
        return _ogden("abaqus", zip(values[0:2 * n:2], values[1:2 * n:2]))
    if "POLYNOMIAL" in option:  # N=2: C10, C01, C20, C11, C02, D1, D2
        keys = [(1, 0), (0, 1), (2, 0), (1, 1), (0, 2)]
    elif "MOONEY" in option:
        keys = [(1, 0), (0, 1)]
    elif "NEO" in option:
        keys = [(1, 0)]
    elif "YEOH" in option:
        keys = [(1, 0), (2, 0), (3, 0)]
    else:
        raise ColonsimError(f"not a card colonsim writes for Abaqus: {lines[i]!r}")
    return {"polynomial": {k: v * MPA for k, v in zip(keys, values)}}


def read_ansys(text):
    lines = _data_lines(text, "!")
    table = next(l for l in lines if l.upper().startswith("TB,HYPER"))
    fields = [f.strip().upper() for f in table.split(",")]
    values = [v for l in lines if l.upper().startswith("TBDATA") for v in _numbers(l.split(",", 2)[2])]
    kind = fields[5]
    if kind == "OGDEN":
        n = int(fields[4])
        return _ogden("ansys", zip(values[0:2 * n:2], values[1:2 * n:2]))
    if kind == "NEO":  # W = mu/2 (I1 - 3)
        return {"polynomial": {(1, 0): values[0] / 2 * MPA}}
    if kind == "MOONEY":
        keys = [(1, 0), (0, 1), (1, 1)][: int(fields[4]) if fields[4] else 2]
    elif kind == "YEOH":
        keys = [(1, 0), (2, 0), (3, 0)]
    else:
        raise ColonsimError(f"not a card colonsim writes for ANSYS: {table!r}")
    return {"polynomial": {k: v * MPA for k, v in zip(keys, values)}}


def read_febio(text):
    kind = re.search(r'type="([^"]+)"', text).group(1)
    tags = {k: float(v) for k, v in re.findall(r"<(\w+)>\s*(" + _NUMBER + r")\s*</\1>", text)}
    if kind == "Ogden":
        n = sum(1 for k in tags if re.fullmatch(r"m\d", k))
        return _ogden("febio", [(tags[f"c{i}"], tags[f"m{i}"]) for i in range(1, n + 1)])
    if kind == "Mooney-Rivlin":
        return {"polynomial": {(1, 0): tags["c1"] * MPA, (0, 1): tags["c2"] * MPA}}
    raise ColonsimError(f"not a card colonsim writes for FEBio: type {kind!r}")


READERS = {"lsdyna": read_lsdyna, "abaqus": read_abaqus, "ansys": read_ansys, "febio": read_febio}


def read_card(fmt, path_or_text):
    text = Path(path_or_text).read_text() if isinstance(path_or_text, Path) else str(path_or_text)
    return READERS[fmt](text)


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
