"""Wall materials drawn for a sweep (the ``[material]`` section), and the material columns of a run.

Two sources of tissue variability, both files ``colonsim calibrate`` writes::

    [material]                       # a calibration's posterior
    file = "calibration/material.json"
    samples = 20                     # draws
    seed = 1                         # default: the [sweep] seed

    [material]                       # the population of a per-specimen calibration
    population = "calibration/population.json"
    samples = 5                      # optional: a seeded subset of the specimens (default: all)

- ``file``: draws from the calibration's linearised posterior, the multivariate normal with the
  file's ``parameters`` as mean and its ``covariance_Pa2`` (identification/uncertainty.py),
  truncated to non-negative parameters by rejection (the calibration's bounds; the law refuses
  negative parameters). A file without a covariance (the bundled reference material) is refused.
- ``population``: each specimen's own fitted parameters, every specimen once (or a seeded subset
  without repetition). Not a normal fitted to them: with the source's 8 specimens and 3 parameters
  whose C10/C01 correlation is near -1, a fitted covariance rests on 7 degrees of freedom, its
  tails are invented beyond anything measured, and its draws would need heavy truncation at
  C10 = 0. The specimens are what was measured.

Every case of the grid is crossed with every draw (N draws x M cases runs): the draws are the same
for all cases, so the sweep separates the tissue's effect from the others. A case carries its draw
in ``InsertionCase.material_parameters`` and the file in ``material`` (which sets the law).

:func:`material_columns` gives every results row its material's small-strain shear modulus and
C11 in kPa (:data:`colonsim.catalog.WALL_MU0`, :data:`colonsim.catalog.WALL_C11`), the default
material included; a law without a C11 term (neo-Hookean, two-parameter Mooney-Rivlin, Yeoh, Ogden)
gets NaN there, and the surrogate leaves an input that is NaN in every run out.
"""

from __future__ import annotations

import dataclasses
import difflib
import json
import math
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from colonsim.catalog import WALL_C11, WALL_MU0
from colonsim.errors import ColonsimError
from colonsim.inputs import check_input
from colonsim.laws import OgdenLaw, get_wall_law
from colonsim.insertion.case.case_material import case_material
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, read_material_document
from colonsim.insertion.study.tissue_stiffness import STIFFNESS, stiffness_factor

SECTION_KEYS = ("file", "population", "samples", "seed")
MATERIAL_PARAMETERS = "material_parameters"  # the InsertionCase field a draw sets
PARAMETER_DECIMALS = 3  # drawn parameters are rounded to 0.001 Pa, so that tables stay readable
MIN_ACCEPTANCE = 1e-3  # below this share of non-negative draws, rejection is no way to truncate


@dataclass(frozen=True)
class Posterior:
    """A calibration's posterior: normal around ``mean`` with ``covariance``, truncated at 0 (Pa)."""

    law: str
    names: tuple
    mean: np.ndarray
    covariance: np.ndarray
    path: str

    def draw(self, n: int, seed: int) -> np.ndarray:
        """``n`` draws (n, p) in Pa with no negative parameter (rejection), reproducible by ``seed``."""
        values, vectors = np.linalg.eigh(0.5 * (self.covariance + self.covariance.T))
        root = vectors * np.sqrt(np.clip(values, 0.0, None))
        rng = np.random.default_rng(seed)
        kept, tried = [], 0
        batch = max(4 * n, 1000)
        while sum(len(k) for k in kept) < n:
            x = self.mean + rng.standard_normal((batch, len(self.mean))) @ root.T
            kept.append(x[(x >= 0.0).all(axis=1)])
            tried += batch
            accepted = sum(len(k) for k in kept)
            if accepted < MIN_ACCEPTANCE * tried:
                raise ColonsimError(f"{self.path}: only {100 * accepted / tried:.2g} % of the posterior's draws have no "
                                    "negative parameter; it cannot be truncated by rejection: check the calibration")
        return np.concatenate(kept)[:n]


@dataclass(frozen=True)
class Population:
    """The specimens of a per-specimen calibration: their names and parameters (n, p) in Pa."""

    law: str
    names: tuple
    specimens: tuple
    values: np.ndarray
    path: str


def read_posterior(path) -> Posterior:
    """The posterior of a ``material.json``: its parameters and ``covariance_Pa2`` (law order)."""
    material = case_material(str(path))  # law, units and parameters checked as for a run
    doc = read_material_document(path)
    names = material.law_model.parameter_names
    cov = doc.get("covariance_Pa2")
    if cov is None:
        what = "a per-specimen population.json (use population = ...)" if "specimens" in doc else "a file"
        raise ColonsimError(f"{path} is {what} without covariance_Pa2, so there is no posterior to draw from; "
                            "calibrate with colonsim calibrate, which writes covariance_Pa2")
    free = (doc.get("uncertainty") or {}).get("unidentified") or []
    if free:
        combos = "; ".join(", ".join(f"{c:+.2f} {n}" for n, c in d["direction_in_bound_widths"].items() if abs(c) > 1e-3)
                           for d in free)
        raise ColonsimError(f"{path}: the calibration does not identify {combos} (in bound widths), so its posterior "
                            "is unbounded there and cannot be sampled; fix one of those parameters or calibrate on "
                            "data that load them differently")
    order = list((doc.get("correlation") or {}).get("names") or names)
    try:
        cov = np.array(cov, dtype=float)
    except (TypeError, ValueError):
        cov = None
    if cov is None or cov.shape != (len(names), len(names)) or sorted(order) != sorted(names) or not np.isfinite(cov).all():
        raise ColonsimError(f"{path}: covariance_Pa2 must be a finite {len(names)} x {len(names)} matrix over "
                            f"{', '.join(names)}; regenerate the file with colonsim calibrate")
    index = [order.index(n) for n in names]
    cov = cov[np.ix_(index, index)]
    eig = np.linalg.eigvalsh(0.5 * (cov + cov.T))
    if not np.allclose(cov, cov.T, rtol=1e-6, atol=0.0) or eig[0] < -1e-9 * max(eig[-1], 0.0):
        raise ColonsimError(f"{path}: covariance_Pa2 is not a symmetric positive semi-definite matrix; regenerate "
                            "the file with colonsim calibrate")
    return Posterior(material.law, names, np.array(material.parameters), cov, str(path))


def read_population(path) -> Population:
    """The specimens of a ``population.json`` (``colonsim calibrate --per-specimen``)."""
    material = case_material(str(path))
    doc = read_material_document(path)
    names = material.law_model.parameter_names
    rows = doc.get("specimens")
    if not isinstance(rows, list) or not rows:
        raise ColonsimError(f"{path} lists no specimens; give the population.json of colonsim calibrate --per-specimen")
    try:
        values = np.array([[float(r[f"{n}_Pa"]) for n in names] for r in rows])
        specimens = tuple(str(r.get("specimen", i + 1)) for i, r in enumerate(rows))
    except (KeyError, TypeError, ValueError) as exc:
        raise ColonsimError(f"{path}: a specimen lacks a number for {exc}; regenerate the file with colonsim "
                            "calibrate --per-specimen") from None
    for row in values:
        case_material(str(path), dict(zip(names, row)))  # each specimen is a valid material of the law
    return Population(material.law, names, specimens, values, str(path))


def tissue_columns(law: str, values) -> dict:
    """The surrogate's tissue inputs of parameter rows ``values`` (n, p) in Pa of ``law``: mu0 and
    C11 in kPa (C11 NaN for a law without it, Ogden's included) and the stiffness factor on the
    reference law (:mod:`colonsim.insertion.study.tissue_stiffness`)."""
    model = get_wall_law(law)
    p = np.atleast_2d(np.asarray(values, dtype=float))
    if isinstance(model, OgdenLaw):
        mu0 = np.array([model.initial_shear_modulus(row) for row in p]) / 1e3
    else:
        rest = np.full(len(p), 3.0)
        d = model.energy(rest, rest, tuple(p.T))  # (W, W1, W2, ...) at I1 = I2 = 3
        mu0 = 2.0 * (np.asarray(d[1]) + np.asarray(d[2])) / 1e3
    names = model.parameter_names
    c11 = p[:, names.index("C11")] / 1e3 if "C11" in names else np.full(len(p), np.nan)
    return {WALL_MU0: mu0, WALL_C11: c11, STIFFNESS: stiffness_factor(law, p)}


def material_columns(case) -> dict:
    """The material columns of ``case``'s results row: its drawn parameters as JSON text ("" for
    none) and its material's mu0 and C11 in kPa (NaN if its material cannot be read)."""
    params, factor = case.material_parameters, case.stiffness_factor
    text = "" if params is None else json.dumps(params)
    path = Path(case.material or REFERENCE_MATERIAL_PATH).absolute()
    try:
        stat = path.stat()
    except OSError:  # read as before: the material's own error, taken as "cannot be read" below
        return {MATERIAL_PARAMETERS: text, **_tissue_values(case.material, text, factor)}
    return {MATERIAL_PARAMETERS: text,
            **_tissue_values_of_file(str(path), stat.st_mtime_ns, stat.st_size, text, factor)}


@lru_cache(maxsize=256)
def _tissue_values_of_file(path, mtime_ns, size, parameters_text, factor):
    """:func:`_tissue_values`, cached per material file state (path, modification time, size),
    drawn parameters and stiffness factor: the adaptive sweep reads the columns of about a
    thousand candidates a round, which all share one or a few materials."""
    return _tissue_values(path, parameters_text, factor)


def _tissue_values(path, parameters_text, factor) -> dict:
    """mu0 and C11 (kPa) and the stiffness factor of the material at ``path`` with the drawn
    parameters given as JSON text ("" for none), scaled by ``factor``; NaN if it cannot be read."""
    try:
        material = case_material(path, json.loads(parameters_text) if parameters_text else None, factor)
    except ColonsimError:  # a failed run of a material that no longer reads: no values, not an error
        return {WALL_MU0: math.nan, WALL_C11: math.nan, STIFFNESS: math.nan}
    return {k: float(v[0]) for k, v in tissue_columns(material.law, [material.parameters]).items()}


def _resolve(value, key, base) -> Path:
    if not isinstance(value, str) or not value.strip():
        raise ColonsimError(f"[material] {key} = {value!r}; give the path of the file colonsim calibrate wrote")
    path = Path(value).expanduser()
    return check_input((base / path if base is not None and not path.is_absolute() else path).resolve(),
                       f"[material] {key}")


def _draws(section, base, seed, max_runs) -> tuple[Path, list]:
    """The file and the parameter dicts a ``[material]`` section asks for."""
    for key in section:
        if key not in SECTION_KEYS:
            close = difflib.get_close_matches(key, SECTION_KEYS, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise ColonsimError(f"unknown key {key!r} in [material]; {hint}use one of: {', '.join(SECTION_KEYS)}")
    if ("file" in section) == ("population" in section):
        raise ColonsimError("[material] needs file = \"material.json\" (draws from a calibration's posterior) or "
                            "population = \"population.json\" (the specimens of a per-specimen calibration), one of them")
    samples, seed = section.get("samples"), section.get("seed", seed)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ColonsimError(f"[material] seed = {seed!r}; give a non-negative integer")
    if samples is not None and (isinstance(samples, bool) or not isinstance(samples, int) or samples < 1):
        raise ColonsimError(f"[material] samples = {samples!r}; give the number of materials to draw, e.g. samples = 20")
    if samples is not None and samples > max_runs:  # before any draw is allocated
        raise ColonsimError(f"[material] samples = {samples:,}: more than the {max_runs:,} a sweep may hold (checked before "
                            "drawing); lower samples")
    if "file" in section:
        if samples is None:
            raise ColonsimError("[material] file = ... needs samples = N, the number of materials drawn from its posterior")
        path = _resolve(section["file"], "file", base)
        posterior = read_posterior(path)
        rows, names = posterior.draw(samples, seed), posterior.names
    else:
        path = _resolve(section["population"], "population", base)
        population = read_population(path)
        rows, names = population.values, population.names
        if samples is not None:
            if samples > len(rows):
                raise ColonsimError(f"[material] samples = {samples} but {path} holds {len(rows)} specimens; give at "
                                    f"most {len(rows)}, or leave samples out to use every specimen once")
            rows = rows[np.sort(np.random.default_rng(seed).choice(len(rows), samples, replace=False))]
    return path, [{n: round(float(v), PARAMETER_DECIMALS) for n, v in zip(names, row)} for row in rows]


def sample_materials(doc: dict, cases: list, base, seed: int, max_runs: int) -> list:
    """``cases`` crossed with the materials of the sweep document's ``[material]`` section (the
    cases unchanged without one). ``base``: folder of relative paths; ``seed``: the sweep's."""
    section = doc.get("material")
    if section is None:
        return cases
    if not isinstance(section, dict):
        raise ColonsimError("[material] must be a table: file = \"material.json\" and samples = N, or population = ...")
    grid = doc.get("grid", [])
    tables = [("fixed", doc.get("fixed")), ("lhs", doc.get("lhs")),
              *(("grid", b) for b in (grid if isinstance(grid, list) else [grid]))]
    for where, table in tables:
        if isinstance(table, dict) and "material" in table:
            raise ColonsimError(f"material is set in [{where}] and drawn by [material]; keep one of the two")
    path, draws = _draws(section, base, seed, max_runs)
    if len(cases) * len(draws) > max_runs:
        raise ColonsimError(f"[material] makes {len(cases):,} cases x {len(draws):,} materials = "
                            f"{len(cases) * len(draws):,} runs, more than the {max_runs:,} a sweep may hold; lower "
                            "samples or the grid")
    out, seen = [], set()
    for case in cases:
        for params in draws:
            drawn = dataclasses.replace(case, material=str(path), material_parameters=dict(params))
            if drawn.key() not in seen:
                seen.add(drawn.key())
                out.append(drawn)
    return out
