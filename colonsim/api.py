"""The public Python API: colonsim's workflows as functions, the same that the command line runs.

Importable from the package itself (``import colonsim; colonsim.insert(...)``): ``colonsim``
re-exports these names lazily, so importing the package stays cheap. Every function checks its
inputs as the command line does (a bad input raises :class:`colonsim.ColonsimError` with one line
naming the problem and the fix) and writes its files into one folder, replaced whole when done.

=======================  ============================================  ============================
function                 what it does                                  command line
=======================  ============================================  ============================
:func:`calibrate`        fit a tissue law to strip tensile curves      ``colonsim calibrate``
:func:`insert`           push scopes through a colon model             ``colonsim insert``
:func:`sweep`            run a sweep of insertions, resumable          ``colonsim sweep``
:func:`fit_surrogate`    fit Gaussian processes on a sweep table       ``colonsim surrogate fit``
:func:`predict`          predict outputs with their uncertainty        ``colonsim predict``
:func:`recommend`        rank the scopes for a patient                 ``colonsim recommend``
=======================  ============================================  ============================

:func:`predict` and :func:`recommend` ask the predictor shipped with colonsim when no model is
given (docs/surrogate.md, "The predictor shipped with colonsim").

The examples run as tests (``tests/test_api.py``) at the smoke size of
:mod:`colonsim.catalog`: coarse meshes and a fast push, whose numbers are not results.
"""

from __future__ import annotations

from pathlib import Path

from colonsim.catalog import PAIN_PROXY
from colonsim.errors import ColonsimError

__all__ = ["calibrate", "insert", "sweep", "fit_surrogate", "predict", "recommend", "load_surrogate"]


def calibrate(curve=None, manifest=None, *, length_mm=None, width_mm=None, thickness_mm=None, law=None,
              compare_laws=False, per_specimen=False, analytic=False, quick=False, seed=1, workers=1,
              out="colonsim_results/calibration", show_progress=False) -> dict:
    """Fit a hyperelastic law to strip tensile curves and write ``material.json`` into ``out``.

    ``curve`` is one force-displacement file (geometry from ``length_mm``, ``width_mm``,
    ``thickness_mm`` in mm or the file's preamble), ``manifest`` a CSV of many; neither: the
    bundled synthetic data set. ``analytic`` uses the closed-form specimen instead of the clamped
    FE strip, ``quick`` a reduced optimizer budget; ``compare_laws`` fits every law and keeps the
    Drucker-stable one with the lowest BIC. Stress-stretch curves of several test modes are
    fitted by ``colonsim calibrate --manifest ... --mode`` (docs/how-to/multimode.md).

    Returns ``{"material": path of material.json (None with per_specimen), "results": [...]}``,
    the results being :class:`colonsim.identification.population.CalibrationResult` objects.

    Example (the closed form and a reduced budget on the bundled data, a few seconds):

    >>> import colonsim
    >>> fit = colonsim.calibrate(analytic=True, quick=True, out="calibration_quick")  # doctest: +ELLIPSIS
    fitting the mean curve of 8 specimens ...
    >>> fit["material"].name
    'material.json'
    >>> sorted(fit["results"][0].names)
    ['C01', 'C10', 'C11']
    """
    from colonsim.workflows import CalibrationRequest, calibrate as run

    out = Path(out)
    request = CalibrationRequest(manifest=None if manifest is None else Path(manifest),
                                 curve=None if curve is None else Path(curve), length_mm=length_mm,
                                 width_mm=width_mm, thickness_mm=thickness_mm, per_specimen=per_specimen, law=law,
                                 compare_laws=compare_laws, analytic=analytic, quick=quick, seed=seed,
                                 workers=workers, show_progress=show_progress)
    results = run(request, out)
    return {"material": None if per_specimen else out / "material.json", "results": results}


def insert(segment="rsj", scope="sdc", *, out="colonsim_results/insertion", centerline=None, vtu=False,
           show_progress=False, **inputs) -> list:
    """Push each scope through a colon model; write one folder per run and a comparison into ``out``.

    ``scope`` is a named scope (``utc``, ``pdc``, ``sdc``), an outer diameter in mm, or a list of
    them; ``centerline`` a patient's centerline CSV (then ``segment`` is ``patient``). Every other
    input is a field of :class:`colonsim.insertion.case.insertion_case.InsertionCase` with its
    default (``diameter_mm``, ``angle_deg``, ``friction``, ``material``, ``distal_resistance_N``,
    ``element_size_mm``, ...; the reference's "Model parameters" lists them). A run at the defaults
    takes minutes.

    Returns each run's :class:`~colonsim.insertion.case.scenario.InsertionResult`: ``summary`` (the
    dict written as ``summary.json``), ``timeseries`` (the DataFrame written as ``timeseries.csv``),
    ``final_shape`` (wall and scope node positions at the end, m), ``case`` and ``model``.

    Example (a straight tube at the smoke size, seconds once the solver is compiled):

    >>> import colonsim
    >>> from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
    >>> runs = colonsim.insert("straight", "sdc", element_size_mm=SMOKE_ELEMENT_MM,
    ...                        scope_spacing_mm=SMOKE_SCOPE_SPACING_MM, push_speed=SMOKE_PUSH_SPEED,
    ...                        out="straight_smoke")  # doctest: +ELLIPSIS
    STRAIGHT SDC: ...
    >>> len(runs), runs[0].summary["final_deformation_cm"] >= 0, "push_force_N" in runs[0].timeseries
    (1, True, True)
    """
    from colonsim.api_insertion import insertion_cases
    from colonsim.workflows import insert as run

    scopes = [scope] if isinstance(scope, (str, int, float)) else list(scope)
    if not scopes:
        raise ColonsimError("give at least one scope (utc, pdc, sdc or an outer diameter in mm)")
    return run(insertion_cases(segment, scopes, centerline, inputs), Path(out), vtu=vtu, show=show_progress)


def sweep(spec=None, *, preset=None, out=None, workers=1, retry_failed=False, show_progress=False):
    """Run every case of a sweep file (TOML) or preset not yet finished in ``out``; return its table.

    Finished runs are skipped, so a sweep killed or extended resumes where it stopped. Each run is
    a row of ``out/results.parquet`` (columns: the reference's "Results columns"), written after
    every run. ``out`` defaults to ``colonsim_results/sweep_NAME``.

    Example (one straight-tube run at the smoke size):

    >>> import colonsim
    >>> from pathlib import Path
    >>> _ = Path("tiny.toml").write_text('''
    ... [fixed]
    ... segment = "straight"
    ... element_size_mm = 5
    ... scope_spacing_mm = 10
    ... push_speed = 0.6
    ... [[grid]]
    ... scope = ["sdc"]
    ... ''')
    >>> table = colonsim.sweep("tiny.toml", out="tiny_sweep")  # doctest: +ELLIPSIS
    sweep ...
    >>> list(table["status"])
    ['ok']
    """
    from colonsim.files import check_output_folder
    from colonsim.insertion.study.sweep import run_sweep
    from colonsim.insertion.study.sweep_spec import load_sweep

    definition = load_sweep(None if spec is None else Path(spec), preset)
    out = check_output_folder(Path(out) if out is not None else Path("colonsim_results") / f"sweep_{definition.name}")
    print(f"sweep {definition.name}: {len(definition.cases)} runs -> {out}/", flush=True)
    report = run_sweep(definition.cases, out, workers=workers, retry_failed=retry_failed, spec=definition,
                       progress=show_progress)
    return report.table


def fit_surrogate(results, out=None, *, targets=None, replicates=None, seed=0, restarts=None):
    """Fit one Gaussian process per colon model and output on a sweep's results table.

    ``results`` is a ``results.parquet`` (or CSV) path or a DataFrame; ``replicates`` a table of
    training cases run again at another wall mesh, whose scatter floors each GP's noise. With
    ``out`` the model is saved as ``out.json`` + ``out.npz`` (no pickle). Returns the fitted
    :class:`colonsim.surrogate.SweepSurrogate`; ``model.report()`` gives its cross-validation.

    Example (a synthetic table, the project's grid run twice: regression machinery, not physics):

    >>> import colonsim
    >>> from colonsim.surrogate.synthetic import synthetic_sweep
    >>> model = colonsim.fit_surrogate(synthetic_sweep(design="grid", repeats=2), "model")
    >>> sorted(model.domains_)
    ['rsf', 'rsj']
    """
    import pandas as pd

    from colonsim.surrogate.model import SweepSurrogate
    from colonsim.surrogate.store import save_surrogate
    from colonsim.surrogate.table import TARGETS, read_results

    def table(source):
        return source if isinstance(source, pd.DataFrame) else read_results(Path(source))

    model = SweepSurrogate(targets=tuple(targets or TARGETS), n_restarts=restarts, random_state=seed,
                           replicates=None if replicates is None else table(replicates)).fit(table(results))
    if out is not None:
        save_surrogate(model, Path(out), source=None if isinstance(results, pd.DataFrame) else str(results))
    return model


def load_surrogate(path):
    """A surrogate saved by :func:`fit_surrogate` or ``colonsim surrogate fit`` (``MODEL.json``)."""
    from colonsim.surrogate.store import load_surrogate as load

    return load(Path(path))


def _model(model):
    """The model asked: a fitted surrogate, the path of its JSON file, or None for the predictor
    shipped with colonsim (:func:`colonsim.surrogate.predictor.load_shipped`)."""
    if model is None:
        from colonsim.surrogate.predictor import load_shipped

        return load_shipped()
    return load_surrogate(model) if isinstance(model, (str, Path)) else model


def _query(model, segment, query):
    """``query`` (a mapping or a frame) with a predictor's defaults for the inputs it leaves out
    (friction, distal resistance: colonsim insert's), and the tissue of ``material`` if given."""
    from colonsim.surrogate.predictor import query_defaults

    if segment is None:
        raise ColonsimError("give the colon model: segment='rsj', 'rsf', 'thf', ...")
    return query_defaults(model, segment, query)


def _with_material(model, segment, material, strict):
    """``model`` with the tissue of ``material`` (None: as it is), and why that material lies
    outside its domain ("" inside; refused with ``strict``)."""
    if material is None:
        return model, ""
    from colonsim.surrogate.predictor import check_material, with_material

    model, _ = with_material(model, material)
    return model, check_material(model, segment, strict=strict)


def predict(model=None, segment=None, *, targets=None, strict=None, material=None, **inputs):
    """Predict outputs at the given inputs: one row per combination of scopes given.

    ``model`` is a fitted surrogate, the path of its JSON file, or None: the predictor shipped
    with colonsim, over the patient space of the patient models it was fitted on (``colonsim
    surrogate info`` names them), whose friction and distal resistance default to ``colonsim
    insert``'s (0 and 5 N). ``inputs`` are the model's inputs
    (``scope`` or ``scope_diameter_mm``, ``diameter_mm``, ``angle_deg``, ``friction``,
    ``distal_resistance_N``, ``tissue_stiffness``, ...; a list for several queries);
    ``material``, a calibrated ``material.json``, gives the tissue (its stiffness factor, its
    parameter uncertainty in the interval). Each target gets its mean, sd and 95 % interval, NaN
    where the model has too few runs to know its error (``error_note`` says so); ``in_domain``
    flags extrapolation. ``strict``: refuse a query outside the training domain (default: yes for
    the shipped predictor, no for a model of your own, which warns).

    The shipped predictor, for an RSF patient with a 45 degree alpha angle and a 36 mm colon:

    >>> import colonsim
    >>> frame = colonsim.predict(segment="rsf", scope="pdc", angle_deg=45, diameter_mm=36)
    >>> frame[["scope", "friction", "distal_resistance_N"]].values.tolist()
    [['pdc', 0.0, 5.0]]
    >>> row = frame.iloc[0]
    >>> bool(row["max_deformation_cm_low95"] < row["max_deformation_cm"] < row["max_deformation_cm_high95"])
    True

    A model fitted on a sweep of your own (:func:`fit_surrogate`):

    >>> frame = colonsim.predict("model.json", "rsj", scope=["utc", "sdc"], diameter_mm=30, friction=0.05)
    >>> list(frame["scope"]), bool(frame["in_domain"].all())
    (['utc', 'sdc'], True)
    >>> bool((frame["max_deformation_cm"] > 0).all())
    True
    """
    import numpy as np
    import pandas as pd

    shipped, model = model is None, _model(model)
    strict = shipped if strict is None else strict
    columns = {k: (list(v) if isinstance(v, (list, tuple, np.ndarray)) else [v]) for k, v in inputs.items()}
    rows = max((len(v) for v in columns.values()), default=1)
    if any(len(v) not in (1, rows) for v in columns.values()):
        raise ColonsimError("give each input one value or as many as the others (one query per row)")
    frame = pd.DataFrame({k: v * rows if len(v) == 1 else v for k, v in columns.items()}, index=range(rows))
    frame = frame.assign(**_query(model, segment, frame))
    from colonsim.surrogate.predictor import mark_extrapolated

    model, outside = _with_material(model, segment, material, strict)
    return mark_extrapolated(model.predict_frame(frame, targets=targets, segment=segment, strict=strict), outside)


def recommend(model=None, segment=None, *, sex=None, age=None, region=None, scopes=None, target=PAIN_PROXY,
              strict=None, material=None, **inputs) -> dict:
    """Rank the scopes for a patient by the predicted ``target`` (the largest deformation by default).

    ``model``, ``material`` and ``strict`` as in :func:`predict` (None: the predictor shipped with
    colonsim). The patient is given by presets (``sex`` -> angle, ``age`` -> friction, ``region``
    -> colon diameter; docs/surrogate.md) and/or raw inputs, which win over the presets. Returns
    per scope the mean, sd and 95 % interval and, where the model can vouch for its error, the
    probability that it deforms the colon least and less than the standard scope (None where it
    cannot).

    >>> import colonsim
    >>> ranking = colonsim.recommend("model.json", "rsj", age="older", region="european")
    >>> [s["scope"] for s in sorted(ranking["scopes"], key=lambda s: s["rank"])]
    ['utc', 'pdc', 'sdc']
    """
    from colonsim.surrogate.patients import patient_inputs
    from colonsim.surrogate.recommend import recommend as rank

    shipped, model = model is None, _model(model)
    strict = shipped if strict is None else strict
    query = {**patient_inputs(segment, sex, age, region), **inputs}
    query.update(_query(model, segment, query))
    from colonsim.surrogate.predictor import mark_extrapolated

    model, outside = _with_material(model, segment, material, strict)
    return mark_extrapolated(rank(model, segment, query, scopes=scopes, target=target, strict=strict), outside)
