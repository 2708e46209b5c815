"""Save a fitted surrogate to open files and load it back without pickle.

``MODEL.json`` (readable): format and version, the estimator's settings, per segment the training
domain, per output the kernel hyperparameters, scaling, cross-validation metrics (an output that is
the larger of two others: their names), the tissue distribution predictions average over, and the
name and SHA-256 of the arrays file. ``MODEL.npz`` (numpy arrays, read with
``allow_pickle=False``): per segment and output the scaled training inputs, the standardized
training outputs, ``alpha`` = K^-1 y and the lower Cholesky factor L of K. That is everything
prediction needs: loading neither refits nor imports scikit-learn.
"""

from __future__ import annotations

import datetime
import hashlib
import json
import zipfile
from pathlib import Path

import numpy as np

from colonsim import __version__
from colonsim.provenance import code_version
from colonsim.errors import ColonsimError
from colonsim.files import atomic_paths, json_text
from colonsim.inputs import check_input, read_input_text
from colonsim.limits import TABLE_MAX_BYTES
from colonsim.surrogate.domain import SegmentDomain
from colonsim.surrogate.gp import GaussianProcess
from colonsim.surrogate.larger import LargerOf
from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.store_checks import (IDENTITY, arrays_path, check_domain, check_draws, check_entry,
                                             check_held_out)
from colonsim.surrogate.tissue import TissueDistribution

FORMAT = "colonsim-surrogate"
# 1.2: the noise floor and scatter of replicate runs; the arrays say which segment and output they belong to
# 1.3: an output that is the larger of two others is stored as their names ("larger_of"), without arrays
# 1.4: the draws of the hyperparameters the prediction averages over ("draws", absent or empty: none)
# 1.5: the coverage of an output's intervals on held-out runs ("held_out", absent: not measured)
FORMAT_VERSION = "1.5"
ARRAYS = ("X_train", "y_train", "alpha", "L")
DRAWS = "draws"  # (draws, inputs + 2) log hyperparameters; the mixture is rebuilt from them on reading


def model_paths(path):
    """The JSON and NPZ paths of a model named ``path`` (``model``, ``model.json`` or ``model.npz``)."""
    path = Path(path)
    base = path.with_suffix("") if path.suffix.lower() in (".json", ".npz") else path
    return base.with_name(base.name + ".json"), base.with_name(base.name + ".npz")


def _key(segment, target, name):
    return f"{segment}__{target}__{name}"


def _sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def save_surrogate(model: SweepSurrogate, path, source=None, about=None):
    """Write ``model`` as ``<path>.json`` + ``<path>.npz``; returns the two paths. ``about``: a
    JSON-able description stored with it and read back as ``model.about_`` (the shipped
    predictor's sweeps, engine and domain: :mod:`colonsim.surrogate.predictor_fit`)."""
    json_path, npz_path = model_paths(path)
    arrays, segments = {}, {}
    for seg, domain in model.domains_.items():
        entries = {}
        for target, gp in model.models_[seg].items():
            if isinstance(gp, LargerOf):  # no arrays: predicted from its parts' models
                entries[target] = {"larger_of": list(gp.names), "n_train": gp.n_train,
                                   "cross_validation": model.cv_[seg][target], "scatter": model.scatter_[seg].get(target)}
                continue
            for name in (*ARRAYS, DRAWS):
                arrays[_key(seg, target, name)] = getattr(gp, name + "_")
            arrays[_key(seg, target, IDENTITY)] = np.array([seg, target])
            entries[target] = {
                "kernel": gp.kernel_description,
                "constant": gp.constant_, "noise_level": gp.noise_level_,
                "length_scale": dict(zip(domain.inputs, gp.length_scale_.tolist())),
                "x_low": gp.x_low_.tolist(), "x_span": gp.x_span_.tolist(),
                "y_mean": gp.y_mean_, "y_scale": gp.y_scale_, "noise_std": gp.noise_std,
                "log_marginal_likelihood": gp.log_marginal_likelihood_, "n_train": gp.n_train,
                "cross_validation": model.cv_[seg][target],
                "noise_floor_sd": gp.noise_floor_sd, "scatter": model.scatter_[seg].get(target),
            }
        for target, held in getattr(model, "held_out_", {}).get(seg, {}).items():
            entries[target]["held_out"] = held
        segments[seg] = {"domain": domain.to_dict(), "models": entries, "skipped": model.skipped_[seg]}
    doc = {"format": FORMAT, "format_version": FORMAT_VERSION, "colonsim_version": __version__,
           "git_commit": code_version()["git_commit"],
           "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
           "source": None if source is None else str(source), "about": about,
           "arrays": {"file": npz_path.name, "sha256": None},
           "estimator": {"targets": list(model.targets), "inputs": list(model.inputs),
                         "segments": None if model.segments is None else list(model.segments), "cv": model.cv,
                         "n_restarts": model.n_restarts, "min_runs": model.min_runs, "random_state": model.random_state,
                         "threads": model.threads, "hyperparameter_draws": model.hyperparameter_draws,
                         "tip_folded": model.tip_folded},
           "training": model.training_, "notes": model.notes_, "segments": segments,
           "tissue": None if model.tissue_ is None else model.tissue_.to_dict()}
    bad = next((k for k, a in arrays.items() if a.dtype.kind == "f" and not np.isfinite(a).all()), None)
    if bad is not None:
        raise ColonsimError(f"cannot save the surrogate: array {bad} is not finite; nothing was written")
    # Both files are complete and checked before either replaces an earlier model: a failure
    # leaves the earlier pair as it was (and no stray file), never a .npz of one fit beside the
    # .json of another.
    with atomic_paths(npz_path, json_path) as (npz_tmp, json_tmp):
        np.savez(npz_tmp, **arrays)
        doc["arrays"]["sha256"] = _sha256(npz_tmp)
        json_tmp.write_text(json_text(doc, json_path.name), encoding="utf-8")
        _read_pair(json.loads(json_tmp.read_text(encoding="utf-8")), json_tmp, npz_tmp)  # reads back as a model
    return json_path, npz_path


def load_surrogate(path) -> SweepSurrogate:
    """Read a surrogate written by :func:`save_surrogate` (no pickle, no refit)."""
    json_path, npz_path = model_paths(path)
    if not json_path.exists():
        raise ColonsimError(f"surrogate file {json_path} not found; write one with 'colonsim surrogate fit RESULTS -o MODEL'")
    try:
        doc = json.loads(read_input_text(json_path, "surrogate file"))
    except json.JSONDecodeError as exc:
        raise ColonsimError(f"{json_path} is not valid JSON ({exc}); refit the surrogate") from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise ColonsimError(f"{json_path} is not a colonsim surrogate (no 'format': '{FORMAT}')")
    if str(doc.get("format_version", "")).split(".")[0] != FORMAT_VERSION.split(".")[0]:
        raise ColonsimError(f"{json_path} has surrogate format {doc.get('format_version')}, this colonsim reads "
                            f"{FORMAT_VERSION}; refit it with this version")
    try:
        name = doc["arrays"]["file"]
    except (KeyError, TypeError):
        raise ColonsimError(f"{json_path} names no arrays file; refit the surrogate") from None
    npz_path = arrays_path(json_path, name)
    return _read_pair(doc, json_path, npz_path)


def _read_pair(doc, json_path, npz_path) -> SweepSurrogate:
    """The model of a JSON document ``doc`` (read from ``json_path``) and its arrays file."""
    if not npz_path.exists():
        raise ColonsimError(f"arrays file {npz_path} of {json_path} is missing; keep the .json and .npz together")
    check_input(npz_path, "arrays file", TABLE_MAX_BYTES)
    if _sha256(npz_path) != doc["arrays"].get("sha256"):
        raise ColonsimError(f"{npz_path} does not belong to {json_path} (checksum differs); copy both files of one fit")
    try:
        est = doc["estimator"]
        model = SweepSurrogate(targets=tuple(est["targets"]), inputs=tuple(est["inputs"]), segments=est["segments"],
                               cv=est["cv"], n_restarts=est["n_restarts"], min_runs=est["min_runs"],
                               random_state=est["random_state"], threads=est.get("threads", 1),
                               hyperparameter_draws=est.get("hyperparameter_draws"),
                               tip_folded=bool(est.get("tip_folded", False)))
        model.training_, model.notes_ = doc["training"], list(doc["notes"])
        model.about_ = doc.get("about")
        model.tissue_ = TissueDistribution.from_dict(doc.get("tissue"))  # files of format 1.0 hold none
        model.domains_, model.models_, model.cv_, model.skipped_, model.scatter_ = {}, {}, {}, {}, {}
        model.held_out_ = {}
        with np.load(npz_path, allow_pickle=False) as arrays:
            for seg, entry in doc["segments"].items():
                domain = SegmentDomain.from_dict(entry["domain"])
                check_domain(domain, json_path)
                model.domains_[seg] = domain
                model.models_[seg], model.cv_[seg], model.skipped_[seg] = {}, {}, dict(entry["skipped"])
                model.scatter_[seg] = {}
                larger = {t: m for t, m in entry["models"].items() if "larger_of" in m}
                for target, m in entry["models"].items():
                    if target in larger:
                        continue
                    check_entry(seg, target, m, domain, arrays, lambda name: _key(seg, target, name), json_path)
                    # files of format 1.0 and 1.1 hold no floor nor scatter
                    gp = GaussianProcess(input_range=(domain.low, domain.high),
                                         noise_floor_sd=float(m.get("noise_floor_sd", 0.0)))
                    gp.x_low_, gp.x_span_ = np.asarray(m["x_low"], dtype=float), np.asarray(m["x_span"], dtype=float)
                    gp.y_mean_, gp.y_scale_ = float(m["y_mean"]), float(m["y_scale"])
                    gp.constant_, gp.noise_level_ = float(m["constant"]), float(m["noise_level"])
                    gp.length_scale_ = np.array([m["length_scale"][n] for n in domain.inputs], dtype=float)
                    gp.log_marginal_likelihood_ = float(m["log_marginal_likelihood"])
                    for name in ARRAYS:
                        setattr(gp, name + "_", arrays[_key(seg, target, name)])
                    draws = _key(seg, target, DRAWS)  # files of format 1.3 and older hold none
                    gp.set_draws(check_draws(arrays[draws], len(domain.inputs), f"{json_path}: segment {seg}, {target}")
                                 if draws in arrays.files else np.zeros((0, len(domain.inputs) + 2)))
                    model.models_[seg][target] = gp
                    model.cv_[seg][target] = m["cross_validation"]
                    model.scatter_[seg][target] = m.get("scatter")
                for target, m in larger.items():
                    parts = [str(p) for p in m["larger_of"]]
                    if len(parts) != 2 or not all(isinstance(model.models_[seg].get(p), GaussianProcess) for p in parts):
                        raise ColonsimError(f"{json_path}: segment {seg}, {target} is the larger of {' and '.join(parts)}, "
                                            "which the file does not hold; refit the surrogate")
                    model.models_[seg][target] = LargerOf(parts, *(model.models_[seg][p] for p in parts))
                    model.cv_[seg][target] = m["cross_validation"]
                    model.scatter_[seg][target] = m.get("scatter")
                model.models_[seg] = {t: model.models_[seg][t] for t in entry["models"]}  # the fit's order
                model.held_out_[seg] = {t: check_held_out(m["held_out"], f"{json_path}: segment {seg}, {t}")
                                        for t, m in entry["models"].items() if m.get("held_out") is not None}
    except ColonsimError:
        raise
    except (KeyError, TypeError, ValueError, AttributeError, OSError, EOFError, zipfile.BadZipFile) as exc:
        raise ColonsimError(f"{json_path} or its arrays file is damaged ({type(exc).__name__}: {exc}); "
                            "refit the surrogate") from None
    return model
