"""The demo's questions to the predictor shipped with colonsim: the calibrated material's patients,
the ranking of the scopes, and the live run beside the predictor's answer for the same case.

Nothing here is made up when no predictor ships: :func:`predictor_step` then says so in one line
and the demo goes on without predictions.
"""

from __future__ import annotations

from colonsim.errors import ColonsimError
from colonsim.surrogate.predictor import NOT_SHIPPED

# Two patients at opposite corners of the patient space of RSJ (presets of surrogate/patients.py).
PATIENTS = (
    {"label": "young African patient", "age": "young", "region": "african"},
    {"label": "older European patient (diverticular disease)", "age": "older", "region": "european"},
)
NO_PREDICTOR = f"{NOT_SHIPPED}; 'colonsim demo --sweep' fits a surrogate on a small sweep of its own instead"
# the outputs the live run is set beside the predictor's answer for
COMPARED = ("max_deformation_cm", "final_deformation_cm")
# run settings the predictor's runs hold fixed: a live run at others is not the case they answer
SETTINGS = ("element_size_mm", "scope_spacing_mm", "push_speed")


def material_factor(material) -> float:
    """The tissue stiffness factor of a calibrated ``material.json`` (its parameters' point
    estimate, the material the live run used; :mod:`colonsim.insertion.study.tissue_stiffness`)."""
    from colonsim.insertion.case.case_material import case_material
    from colonsim.insertion.study.tissue_stiffness import stiffness_factor

    wall = case_material(str(material))
    return float(stiffness_factor(wall.law, [wall.parameters])[0])


def settings_apart(model, case) -> list:
    """The run settings of ``case`` that the predictor's runs of its segment did not use, as
    phrases ("element_size_mm 5 (the predictor's runs: 3)")."""
    used = model.domains_[case.segment].settings
    apart = []
    for name in SETTINGS:
        values = used.get(name)
        value = float(getattr(case, name))
        if values and not any(isinstance(v, float) and abs(v - value) <= 1e-9 * max(1.0, abs(v)) for v in values):
            apart.append(f"{name} {value:g} (the predictor's runs: {', '.join(f'{v:g}' for v in values)})")
    return apart


def comparison(live_summary: dict, predicted, targets=COMPARED) -> list:
    """One row per output: the live run's value, the predictor's mean and 95 % interval for the
    same case (``predicted``: a row of :func:`colonsim.surrogate.predictor.predict_deformation`),
    and whether the live value lies inside (None where the predictor states no interval)."""
    rows = []
    for t in targets:
        low, high = float(predicted[t + "_low95"]), float(predicted[t + "_high95"])
        live = float(live_summary[t])
        known = low == low and high == high
        rows.append({"output": t, "live": live, "predicted": float(predicted[t]), "low95": low if known else None,
                     "high95": high if known else None, "inside": (low <= live <= high) if known else None})
    return rows


def comparison_line(row) -> str:
    if row["inside"] is None:
        return (f"{row['output']}: live {row['live']:.2f} cm, predicted {row['predicted']:.2f} cm (the predictor "
                "states no interval here)")
    where = "inside" if row["inside"] else "OUTSIDE"
    return (f"{row['output']}: live {row['live']:.2f} cm, predicted {row['predicted']:.2f} cm "
            f"(95 %: {row['low95']:.2f} to {row['high95']:.2f}): {where} the interval")


def patient_recommendations(model, segment: str, target: str, strict: bool = False) -> list:
    """The scopes ranked by ``target`` for each of the :data:`PATIENTS`, printed; a predictor's
    query takes colonsim insert's defaults for what the presets leave out (distal resistance)."""
    from colonsim.surrogate.patients import describe_patient, patient_inputs
    from colonsim.surrogate.predictor import query_defaults
    from colonsim.surrogate.recommend import format_recommendation, recommend

    recs = []
    for p in PATIENTS:
        inputs = patient_inputs(segment, age=p["age"], region=p["region"])
        inputs.update(query_defaults(model, segment, inputs))
        rec = recommend(model, segment, inputs, target=target, strict=strict)
        mapping = describe_patient(segment, age=p["age"], region=p["region"])
        if "distal_resistance_N" in inputs:
            mapping += f", distal resistance {inputs['distal_resistance_N']:g} N"
        rec["patient"] = {"label": p["label"], "age": p["age"], "region": p["region"], "mapping": mapping}
        recs.append(rec)
        print(f"{p['label']} ({mapping}):")
        print(format_recommendation(rec))
    return recs


def predictor_step(material, live, target: str, section) -> dict:
    """Ask the shipped predictor (or the model ``COLONSIM_PREDICTOR`` names) about the calibrated
    ``material``: each scope for the two :data:`PATIENTS`, ranked by ``target``, and the case of
    the ``live`` run (an :class:`InsertionResult`) at the material's stiffness factor. Returns
    what it answered, or ``{"no_predictions": why}`` (printed, one line) when no predictor ships
    or it does not answer for this material and these patients."""
    from colonsim.surrogate.predictor import check_material, load_shipped, predict_deformation, shipped_exists, with_material

    section("the predictor shipped with colonsim: the calibrated material's patients, the scopes ranked")
    if not shipped_exists():
        print(f"no predictions: {NO_PREDICTOR}")
        return {"no_predictions": NO_PREDICTOR}
    model = load_shipped()
    case = live.case
    try:
        tissue, note = with_material(model, material)
        check_material(tissue, case.segment)
        factor = material_factor(material)
        print(f"tissue: {note}")
        recs = patient_recommendations(tissue, case.segment, target, strict=True)
        same = predict_deformation(case.segment, case.scope, diameter_mm=case.diameter_mm, friction=case.friction,
                                   distal_resistance_N=case.distal_resistance_N, tissue_stiffness=factor,
                                   targets=COMPARED, model=model).iloc[0]
    except ColonsimError as exc:
        print(f"no predictions for this material: {exc}")
        return {"no_predictions": f"the predictor does not answer for this material and these patients: {exc}"}
    section(f"the live run beside the predictor's answer for the same case ({case.segment.upper()} "
            f"{case.scope.upper()}, D = {case.diameter_mm:g} mm, mu = {case.friction:g}, distal resistance "
            f"{case.distal_resistance_N:g} N, tissue stiffness {factor:.3g})")
    rows = comparison(live.summary, same)
    for row in rows:
        print(comparison_line(row))
    apart = settings_apart(model, case)
    if apart:
        print("the live run is not at the predictor's settings: " + "; ".join(apart)
              + ": the difference shows what those settings change, not the predictor's error")
    about = model.about_ or {}
    return {"recommendations": recs, "comparison": rows, "tissue_note": note, "stiffness_factor": factor,
            "settings_apart": apart, "sweeps": about.get("sweeps", []),
            "engine_commits": about.get("engine_commits", [])}
