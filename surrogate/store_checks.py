"""Checks of a surrogate's files as they are loaded: a tampered, foreign or damaged model is refused.

A model file is data from disk: a NaN noise level or an infinite output scale would print ``nan``
predictions, a negative signal variance a ``+- 0`` interval, and the arrays of another segment
stored under this segment's names (with the checksum updated) would answer silently for the
wrong colon. So every number of a model entry must be finite and in its domain (variances,
scales and length scales positive), every array must have the shape the segment's inputs and
run count give, the arrays must say which segment and output they belong to (an identity array
the writer stores beside them), and the arrays file must lie in the model's own folder.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError

IDENTITY = "belongs_to"  # per segment and output: the array ["segment", "output"] of the fit it came from


def arrays_path(json_path: Path, name) -> Path:
    """The arrays file ``name`` a model JSON names: a bare file name in the JSON's own folder."""
    if not isinstance(name, str) or not name or Path(name).name != name or name in (".", "..") or "\\" in name:
        raise ColonsimError(f"{json_path} names the arrays file {name!r}, outside the model's folder; a model's "
                            "arrays file lies beside its JSON (refit the surrogate, or restore the JSON)")
    return json_path.with_name(name)


def _positive(value, what, where):
    number = _finite(value, what, where)
    if number <= 0:
        raise ColonsimError(f"{where}: {what} = {number:g} must be positive; the model file is damaged or edited, "
                            "refit the surrogate")
    return number


def _finite(value, what, where):
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ColonsimError(f"{where}: {what} = {value!r} is not a number; refit the surrogate") from None
    if not math.isfinite(number):
        raise ColonsimError(f"{where}: {what} = {number} is not finite; the model file is damaged or edited, refit "
                            "the surrogate")
    return number


def check_domain(domain, where):
    """Finite bounds with low <= high and a positive run count."""
    bounds = np.concatenate([np.asarray(domain.low, dtype=float), np.asarray(domain.high, dtype=float)])
    if not np.isfinite(bounds).all() or (np.asarray(domain.low) > np.asarray(domain.high)).any():
        raise ColonsimError(f"{where}: the training domain has bounds that are not finite or not ordered; refit the "
                            "surrogate")
    if domain.n_runs < 1:
        raise ColonsimError(f"{where}: the training domain counts {domain.n_runs} runs; refit the surrogate")


def check_entry(segment, target, entry, domain, arrays, key, where):
    """One output's numbers (``entry`` of the JSON) and arrays (``key(name)`` in the npz ``arrays``).

    Raises
    ------
    ColonsimError
        A missing, non-finite or out-of-domain number, an array of the wrong shape, or arrays that
        belong to another segment or output.
    """
    where = f"{where}: segment {segment}, {target}"
    name = key(IDENTITY)
    if name not in arrays.files:
        raise ColonsimError(f"{where}: the arrays file does not say which fit its arrays belong to (a model from an "
                            "older colonsim, or edited); refit the surrogate")
    identity = [str(v) for v in np.asarray(arrays[name]).ravel()]
    if identity != [segment, target]:
        raise ColonsimError(f"{where}: the arrays stored under this name belong to {' '.join(identity)!r}, not to "
                            f"{segment} {target}; the files were mixed or edited, refit the surrogate")
    d = len(domain.inputs)
    _positive(entry["constant"], "the signal variance (constant)", where)
    _positive(entry["noise_level"], "the noise variance (noise_level)", where)
    _positive(entry["y_scale"], "the output scale (y_scale)", where)
    _finite(entry["y_mean"], "the output mean (y_mean)", where)
    for input_name in domain.inputs:
        _positive(entry["length_scale"][input_name], f"the length scale of {input_name}", where)
    for field in ("x_low", "x_span"):
        values = np.asarray(entry[field], dtype=float)
        if values.shape != (d,) or not np.isfinite(values).all() or (field == "x_span" and (values <= 0).any()):
            raise ColonsimError(f"{where}: {field} must hold {d} finite number(s){' > 0' if field == 'x_span' else ''} "
                                f"(one per input); refit the surrogate")
    n = entry.get("n_train")
    shapes = {"X_train": (n, d), "y_train": (n,), "alpha": (n,), "L": (n, n)}
    for array_name, shape in shapes.items():
        value = arrays[key(array_name)]
        if value.shape != shape or value.dtype.kind != "f" or not np.isfinite(value).all():
            raise ColonsimError(f"{where}: array {array_name} has shape {value.shape} ({value.dtype}), expected "
                                f"{shape} of finite numbers for {n} runs and {d} input(s); refit the surrogate")
    if not (np.diag(arrays[key("L")]) > 0).all():
        raise ColonsimError(f"{where}: the Cholesky factor L has a diagonal entry <= 0; refit the surrogate")


def check_draws(draws, n_inputs, where):
    """The stored draws of the log hyperparameters: finite, one column per hyperparameter."""
    draws = np.asarray(draws)
    if draws.ndim != 2 or draws.shape[1] != n_inputs + 2 or draws.dtype.kind != "f" or not np.isfinite(draws).all():
        raise ColonsimError(f"{where}: array draws has shape {draws.shape} ({draws.dtype}), expected (draws, "
                            f"{n_inputs + 2}) finite log hyperparameters; refit the surrogate")
    return draws


def check_held_out(held_out, where) -> dict:
    """The coverage of an output's intervals on held-out runs: a positive whole run count, coverages
    between 0 and 1 that are shares of it, the sweeps named (an edited count would vouch for
    intervals no run checked)."""
    try:
        runs = held_out["runs"]
        shares = {key: _finite(held_out[key], key, where) for key in ("coverage_95", "coverage_50")}
        sweeps = [str(s) for s in held_out["sweeps"]]
    except (KeyError, TypeError):
        raise ColonsimError(f"{where}: its held-out record lacks runs, coverage_95, coverage_50 or sweeps; "
                            "refit the surrogate") from None
    if not isinstance(runs, int) or runs < 1 or any(not 0 <= v <= 1 or abs(v * runs - round(v * runs)) > 1e-6
                                                    for v in shares.values()):
        raise ColonsimError(f"{where}: its held-out record ({runs!r} runs, coverages {list(shares.values())}) is not "
                            "a count of runs and shares of it; the model file is damaged or edited, refit the surrogate")
    return {"runs": runs, **shares, "sweeps": sweeps}
