"""The pain predictor that ships with colonsim: a surrogate of the patient-space sweeps, asked
without a model file of the user's.

``load_shipped()`` reads it from the package data (``colonsim/data/predictor/``, the project's own
JSON + NPZ format, checked on load like any model); ``predict_deformation(...)`` answers one
patient. Outside its training domain it refuses, naming the input and by how much, unless asked to
extrapolate. A calibrated ``material.json`` enters as the tissue stiffness factor it maps to
(:mod:`colonsim.insertion.study.tissue_stiffness`), its parameter uncertainty as the tissue part
of the interval (:mod:`colonsim.surrogate.tissue`).

The environment variable ``COLONSIM_PREDICTOR`` (a model path) puts another model in the shipped
one's place for every caller (``colonsim predict``, ``recommend``, ``demo``, the Python API): a
predictor fitted with ``benchmarks/fit_predictor.py --out`` before it is committed, for example.

Example (the shipped model; a model fitted on any patient-space table answers the same way)::

    from colonsim.surrogate.predictor import predict_deformation
    table = predict_deformation("rsf", "utc", angle_deg=45, diameter_mm=36, friction=0.05,
                                distal_resistance_N=5)
    table[["scope", "max_deformation_cm", "max_deformation_cm_low95", "max_deformation_cm_high95"]]
"""

from __future__ import annotations

import copy
import os
from pathlib import Path

import numpy as np
import pandas as pd

from colonsim.catalog import TISSUE_STIFFNESS
from colonsim.data import data_path
from colonsim.errors import ColonsimError
from colonsim.insertion.case.case_material import case_material
from colonsim.insertion.study.tissue_stiffness import MISMATCH_NOTE, shape_mismatch
from colonsim.surrogate.recommend import default_scopes
from colonsim.surrogate.store import load_surrogate, model_paths
from colonsim.surrogate.table import INPUT_OPTIONS
from colonsim.surrogate.tissue import TissueDistribution

SHIPPED = data_path("predictor", "patient_space")  # .json + .npz
# a model path (without suffix, or its .json) answering in place of the shipped one: a predictor
# fitted by benchmarks/fit_predictor.py --out before it is committed, or a test's
OVERRIDE = "COLONSIM_PREDICTOR"
# a predictor's query that leaves these inputs out takes colonsim insert's defaults (the insertion
# case's, which tests/test_predictor.py checks these are), and says so
QUERY_DEFAULTS = {"friction": 0.0, "distal_resistance_N": 5.0}
# the outputs the predictor answers by default: the pain proxy and the final deformation
DEFORMATIONS = ("max_deformation_cm", "final_deformation_cm")
NOT_SHIPPED = "this colonsim ships no fitted predictor (its package data lack predictor/patient_space.json)"
NO_SHIPPED = (f"{NOT_SHIPPED}; give a model file, fitted with 'colonsim sweep --preset patient_space_rsj --out PS' "
              "and 'colonsim surrogate fit PS/results.parquet -o MODEL'")


def shipped_path(path=None) -> Path:
    """Where the predictor is read: ``path``, else the environment variable ``COLONSIM_PREDICTOR``
    (:data:`OVERRIDE`; a model path, ``.json`` or none), else the package data (:data:`SHIPPED`)."""
    if path is not None:
        return Path(path)
    given = os.environ.get(OVERRIDE, "").strip()
    return Path(given).with_suffix("") if given.endswith(".json") else Path(given) if given else SHIPPED


def shipped_exists(path=None) -> bool:
    """Whether this colonsim holds a shipped predictor (both of its files, where :func:`shipped_path` says)."""
    return all(p.is_file() for p in model_paths(shipped_path(path)))


def load_shipped(path=None):
    """The shipped predictor (:class:`colonsim.surrogate.model.SweepSurrogate`); ``model.about_``
    names its sweeps, engine commits and domain.

    Raises
    ------
    ColonsimError
        None is shipped (one line saying how to fit one), or its files fail the load checks.
    """
    where = shipped_path(path)
    if not shipped_exists(where):
        if path is None and where != SHIPPED:
            raise ColonsimError(f"{OVERRIDE}={os.environ[OVERRIDE]}: no model there ({where}.json and .npz, written "
                                "by 'colonsim surrogate fit' or benchmarks/fit_predictor.py); unset it to use the "
                                "predictor shipped with colonsim")
        raise ColonsimError(NO_SHIPPED)
    return load_surrogate(where)


def query_defaults(model, segment, query) -> dict:
    """The inputs of :data:`QUERY_DEFAULTS` that ``segment``'s model takes and ``query`` (a mapping,
    or a frame's columns) leaves out, with their default; none for a model that is no predictor
    (no ``about_``), whose user names every input."""
    domain = model.domains_.get(str(segment).lower())
    if getattr(model, "about_", None) is None or domain is None:
        return {}
    return {k: v for k, v in QUERY_DEFAULTS.items() if k in domain.inputs and query.get(k) is None}


def defaults_note(defaults) -> str:
    """One phrase naming the defaults a query took ("" for none)."""
    if not defaults:
        return ""
    return (", ".join(f"{k} {v:g}" for k, v in defaults.items()) + " (colonsim insert's defaults; give "
            + " / ".join(INPUT_OPTIONS[k] for k in defaults) + " for the patient's)")


def joined_notes(*notes) -> str:
    """The non-empty ``notes`` joined by "; " (a query's tissue note and its defaults' phrase, a row's
    domain note and why it extrapolates)."""
    return "; ".join(filter(None, notes))


def with_material(model, material):
    """A copy of ``model`` whose tissue is the calibration ``material`` (a path), and a note: the
    stiffness factor it maps to (mean and sd over its distribution) and, where its curve has
    another shape than the reference wall's, by how much."""
    distribution = TissueDistribution.from_file(material)
    wall = case_material(str(material))
    mismatch = float(shape_mismatch(wall.law, [wall.parameters])[0])
    factors = distribution.draws()[TISSUE_STIFFNESS]
    note = f"{Path(material).name} maps to tissue stiffness {np.mean(factors):.3g} (sd {np.std(factors):.2g})"
    if mismatch > MISMATCH_NOTE:
        note += (f"; its stress curve departs from the reference wall's shape by {100 * mismatch:.0f} % (RMS): the "
                 "stiffness factor carries its level, not its shape")
    model = copy.copy(model)
    model.tissue_ = distribution
    return model, note


def check_material(model, segment, strict=True) -> str:
    """Refuse (``strict``) a model whose tissue distribution's mean stiffness lies outside the
    segment's training range, naming the material and by how much; else return that phrase for
    the answers to mark (:func:`mark_extrapolated`), "" when the mean is inside or the segment's
    model does not take the stiffness."""
    domain = model.domains_.get(str(segment).lower())
    if domain is None or TISSUE_STIFFNESS not in domain.inputs or model.tissue_ is None:
        return ""
    mean = float(np.mean(model.tissue_.draws()[TISSUE_STIFFNESS]))
    j = domain.inputs.index(TISSUE_STIFFNESS)
    low, high = float(domain.low[j]), float(domain.high[j])
    if low <= mean <= high:
        return ""
    by, side = (low - mean, "below") if mean < low else (mean - high, "above")
    outside = (f"{model.tissue_.description}: tissue stiffness {mean:.3g} outside {low:g}-{high:g} of the "
               f"{domain.segment} runs ({by:.3g} {side})")
    if strict:
        raise ColonsimError(f"{outside}; the predictor does not extrapolate unless asked (--extrapolate)")
    return outside


def mark_extrapolated(answer, outside: str, segment=None):
    """Mark as outside the training domain, for the reason ``outside`` (from :func:`check_material`;
    "" marks nothing), the rows of ``segment`` of a prediction frame (every row: None) or every
    scope of a recommendation (a dict), so that each of their printed numbers says so."""
    if not outside:
        return answer
    if isinstance(answer, dict):
        answer["in_domain"] = False
        for s in answer["scopes"]:
            s["in_domain"] = False
            s["domain_note"] = joined_notes(s["domain_note"], outside)
        return answer
    rows = answer.index if segment is None else answer.index[answer["segment"] == str(segment).lower()]
    answer.loc[rows, "in_domain"] = False
    answer.loc[rows, "domain_note"] = [joined_notes(note, outside)
                                       for note in answer.loc[rows, "domain_note"]]
    return answer


def predict_deformation(segment, scope=None, *, scope_diameter_mm=None, angle_deg=None, diameter_mm=None,
                        friction=None, distal_resistance_N=None, tissue_stiffness=None, material=None,
                        targets=DEFORMATIONS, extrapolate=False, model=None) -> pd.DataFrame:
    """Predicted colon deformation of one patient, per scope, with intervals.

    Parameters
    ----------
    segment : str
        ``rsj``, ``rsf`` or ``thf``.
    scope : str, sequence of str or None
        Named scopes or diameters in mm (None: the scopes the sweep ran); or ``scope_diameter_mm``.
    angle_deg, diameter_mm, friction, distal_resistance_N : float or None
        The patient (alpha of RSF, beta of THF; colon diameter in mm; Coulomb friction; the force
        in N that the colon beyond the model opposes to the tip). Friction and distal resistance
        left out take colonsim insert's defaults (:data:`QUERY_DEFAULTS`), said in ``tissue_note``.
    tissue_stiffness : float or None
        The wall as a factor on the reference law; or ``material``, a calibrated ``material.json``
        mapped to it (its parameter uncertainty in the interval). Neither: the model's own tissue.
    extrapolate : bool
        Answer outside the training domain (the rows say so: ``in_domain``, ``domain_note``);
        without it such a query is a :class:`ColonsimError` naming the input and by how much.
    model : SweepSurrogate or None
        None: the shipped predictor (:func:`load_shipped`).

    Returns
    -------
    DataFrame
        One row per scope: the inputs, per target its mean, sd, 95 % interval and sd parts
        (:meth:`SweepSurrogate.predict_frame`), ``in_domain``, ``domain_note``, ``tissue_note``.
    """
    model = load_shipped() if model is None else model
    if material is not None and tissue_stiffness is not None:
        raise ColonsimError("give the tissue as a stiffness factor or as a material file, not both")
    note, outside = "", ""
    if material is not None:
        model, note = with_material(model, material)
        outside = check_material(model, segment, strict=not extrapolate)
    values = {"scope_diameter_mm": scope_diameter_mm, "angle_deg": angle_deg, "diameter_mm": diameter_mm,
              "friction": friction, "distal_resistance_N": distal_resistance_N, TISSUE_STIFFNESS: tissue_stiffness}
    base = {"segment": str(segment).lower(), **{k: v for k, v in values.items() if v is not None}}
    defaults = query_defaults(model, segment, base)
    base.update(defaults)
    note = joined_notes(note, defaults_note(defaults))
    scopes = [scope] if isinstance(scope, (str, int, float)) else scope
    if scopes is None and scope_diameter_mm is None and base["segment"] in model.domains_:
        scopes = default_scopes(model.domains_[base["segment"]])
    frame = pd.DataFrame([{**base, "scope": str(s)} for s in scopes] if scopes else [base])
    out = model.predict_frame(frame, targets=list(targets), strict=not extrapolate)
    if note:
        out["tissue_note"] = out["tissue_note"] + "; " + note
    return mark_extrapolated(out, outside)
