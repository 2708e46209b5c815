"""Material cards of a fitted law for other solvers: LS-DYNA, Abaqus, ANSYS (MAPDL) and FEBio.

Every format writes the same hyperelastic law with its own constants:
:mod:`colonsim.identification.card_conventions` holds each format's keyword and strain-energy
convention, :mod:`colonsim.identification.card_writers` the text of each card,
:mod:`colonsim.identification.card_options` the material id, density, bulk modulus and deck or
include, and :mod:`colonsim.identification.card_readers` reads a card back. This module checks
what goes into a card and writes a folder's cards as one set.

Every card is in the unit system tonne, mm, s, N, MPa and says so in its comment lines, with the
bulk modulus chosen and colonsim's parameters, from which :func:`card_material` tells which
material a card was written from.

The cards in a folder and its ``material.json`` describe one material. An export into a folder
whose ``material.json`` holds another material is refused; colonsim cards already in the folder
that were written from another material are rewritten with the same set (all files replaced
together, or none).
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError, ColonsimWarning
from colonsim.files import atomic_paths
from colonsim.identification.card_conventions import CARD_TITLE, FORMATS, SUFFIX, check_formats, keyword
from colonsim.identification.card_options import CardOptions
from colonsim.identification.card_writers import WRITERS
from colonsim.identification.hyperelastic import CALIBRATION_LAWS, calibration_law
from colonsim.insertion.engine.material import read_material_document
from colonsim.schemas import check_material_document

LSDYNA_MIN_POISSON = 0.49  # *MAT_077's manual: smaller values may not work

__all__ = ["FORMATS", "SUFFIX", "CardOptions", "card_text", "check_formats", "write_cards", "read_material",
           "card_material", "card_path", "folder_card_formats"]


def check_parameters(law, p):
    """Refuse parameters no card should carry: non-finite ones, a zero Ogden exponent, an initial
    shear modulus that is not positive."""
    bad = [(n, float(v)) for n, v in zip(law.parameter_names, p) if not math.isfinite(v)]
    if bad:
        raise ColonsimError(f"{law.name}: parameter {bad[0][0]} is {bad[0][1]!r}; "
                            "a card needs finite numbers: refit, or fix material.json")
    if law.terms and np.any(p[1::2] == 0.0):
        raise ColonsimError(f"{law.name}: an Ogden exponent is 0, which no card can hold (mu/alpha); refit")
    mu0 = law.initial_shear_modulus(p)
    if not mu0 > 0:
        raise ColonsimError(f"{law.name}: initial shear modulus {mu0:.6g} Pa is not positive, so the material is "
                            "unstable at rest and no solver can use it; refit (fix the data's units or sign)")


def card_text(fmt, law_name, parameters, options: CardOptions | None = None) -> str:
    """The card of ``law_name`` with ``parameters`` ({name: value} or sequence; Pa) in ``fmt``."""
    keyword(fmt, law_name)
    law = calibration_law(law_name)
    try:
        p = law.values(parameters)
    except (KeyError, TypeError, ValueError) as exc:
        raise ColonsimError(f"{law.name} takes the numbers {', '.join(law.parameter_names)} (Pa); got {parameters!r} "
                            f"({type(exc).__name__}: {exc})") from None
    if p.size != len(law.parameter_names):
        raise ColonsimError(f"{law.name} takes {len(law.parameter_names)} parameters ({', '.join(law.parameter_names)}), "
                            f"got {p.size}")
    check_parameters(law, p)
    options = options or CardOptions()
    if fmt == "lsdyna" and options.poisson < LSDYNA_MIN_POISSON:
        warnings.warn(ColonsimWarning(
            f"LS-DYNA's manual recommends PR >= {LSDYNA_MIN_POISSON} for its rubber materials; the card's PR is "
            f"{options.poisson:.4f} (K/mu0 {options.bulk_ratio:g}); choose K/mu0 >= 50 unless you have checked it"))
    return WRITERS[fmt](law, p, options)


def card_path(out_dir, fmt) -> Path:
    return Path(out_dir) / f"material_{fmt}.{SUFFIX[fmt]}"


_PARAMETER = re.compile(r"\b(\w+)=([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def card_material(path):
    """(law, {name: value}) of the material a colonsim card at ``path`` was written from, read from
    its comment lines; None when the file is not a colonsim card."""
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    title = re.search(re.escape(CARD_TITLE) + r" \((\w+)\): law (\w+)", text)
    if title is None or title.group(2) not in CALIBRATION_LAWS:
        return None
    names = CALIBRATION_LAWS[title.group(2)].parameter_names
    start = text.find("colonsim parameters (Pa):")
    found = {k: float(v) for k, v in _PARAMETER.findall(text[start:]) if k in names} if start >= 0 else {}
    return title.group(2), found


def read_material(path):
    """(law, {name: value in Pa}) of a colonsim ``material.json``; one line if it is not one."""
    doc = read_material_document(path)
    law = doc.get("law")
    if not isinstance(law, str):
        raise ColonsimError(f"material file {path} has no law; pass a material.json of colonsim calibrate")
    return law, check_material_document(doc, path, calibration_law(law).parameter_names)


def _same(a, b) -> bool:
    return a[0] == b[0] and set(a[1]) == set(b[1]) and all(a[1][n] == b[1][n] for n in a[1])


def _stale(path, material) -> bool:
    found = card_material(path) if path.is_file() else None
    return found is not None and not _same(found, material)


def folder_card_formats(formats, law_name, parameters, out_dir, source=None) -> list[str]:
    """The formats an export of this material into ``out_dir`` writes: ``formats``, then every
    format whose colonsim card there was written from another material (so that the folder's
    cards stay one set). Refuses a folder whose ``material.json`` (other than ``source``) holds
    another material."""
    out_dir = Path(out_dir)
    law = calibration_law(law_name)
    material = (law.name, dict(zip(law.parameter_names, (float(v) for v in law.values(parameters)))))
    held = out_dir / "material.json"
    if held.is_file() and (source is None or Path(source).resolve() != held.resolve()):
        other = read_material(held)
        if not _same(other, material):
            raise ColonsimError(f"{out_dir} holds the material.json of another material (law {other[0]}); cards of "
                                f"this one there would disagree with it: export into another folder (--out)")
    stale = [f for f in FORMATS if f not in formats and _stale(card_path(out_dir, f), material)]
    return list(dict.fromkeys([*formats, *stale]))


def write_cards(formats, law_name, parameters, out_dir, options: CardOptions | None = None, source=None) -> list[Path]:
    """Write ``material_<format>.<suffix>`` for each format into ``out_dir``, with the cards there
    that :func:`folder_card_formats` finds stale, all replaced together or none."""
    formats = folder_card_formats(formats, law_name, parameters, out_dir, source)
    check_formats(formats, [law_name])
    texts = {fmt: card_text(fmt, law_name, parameters, options) for fmt in formats}
    paths = [card_path(out_dir, fmt) for fmt in texts]
    with atomic_paths(*paths) as temps:
        for tmp, text in zip(temps, texts.values()):
            Path(tmp).write_text(text, encoding="utf-8")
    return paths
