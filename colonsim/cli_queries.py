"""The queries of ``colonsim predict``, ``recommend`` and ``surrogate plot``: which model answers (a
file, or the predictor shipped with colonsim), the patient's inputs from presets and options, and
the predictions as text.
"""

from __future__ import annotations

from colonsim import catalog
from colonsim.errors import ColonsimError

# command-line option -> results-table column
RAW_OPTIONS = {"scope_diameter": "scope_diameter_mm", "diameter": "diameter_mm", "angle": "angle_deg",
               "friction": "friction", "wall_thickness": "wall_thickness_mm", "wall_mu0": catalog.WALL_MU0,
               "wall_c11": catalog.WALL_C11, "distal_resistance": "distal_resistance_N",
               "stiffness": catalog.TISSUE_STIFFNESS}


def load_model(args):
    """The model a query asks: ``args.model``, or the shipped predictor when none is given, with the
    tissue of --material if given; whether a query outside its domain is refused (--strict, or the
    shipped predictor without --extrapolate); and the note on the material ("" for none), which
    :func:`colonsim.surrogate.predictor.check_material` checks once the segment is known."""
    from colonsim.surrogate.predictor import load_shipped, with_material
    from colonsim.surrogate.store import load_surrogate

    shipped = args.model is None
    model = load_shipped() if shipped else load_surrogate(args.model)
    strict = args.strict or (shipped and not args.extrapolate)
    note = ""
    if args.material is not None:
        model, note = with_material(model, args.material)
    return model, strict, note


def raw_inputs(args):
    return {col: getattr(args, opt) for opt, col in RAW_OPTIONS.items() if getattr(args, opt, None) is not None}


def presets_of(args):
    from colonsim.surrogate.patients import PatientPresets

    return PatientPresets.from_json(args.presets) if args.presets else PatientPresets()


def segment_of(args, model):
    if args.segment:
        return args.segment.lower()
    if len(model.domains_) == 1:
        return next(iter(model.domains_))
    raise ColonsimError(f"give --segment ({', '.join(model.domains_)})")


def patient_query(model, segment, args, presets):
    """Model inputs from presets, then raw options on top, then a predictor's defaults for what
    both leave out; and the phrase naming those defaults ("" for none)."""
    from colonsim.surrogate.patients import patient_inputs
    from colonsim.surrogate.predictor import defaults_note, query_defaults

    query = {**patient_inputs(segment, args.sex, args.age, args.region, presets), **raw_inputs(args)}
    defaults = query_defaults(model, segment, query)
    return {**query, **defaults}, defaults_note(defaults)


def query_frame(args, model):
    """One row per query: from --csv (options fill its missing columns) or from the options, one per
    scope; and the phrase naming the defaults a predictor's query took ("" for none)."""
    import numpy as np
    import pandas as pd

    from colonsim.surrogate.patients import patient_inputs
    from colonsim.surrogate.predictor import query_defaults
    from colonsim.surrogate.recommend import default_scopes
    from colonsim.surrogate.table import read_query_file

    presets = presets_of(args)
    if args.csv:
        frame = read_query_file(args.csv)
        if args.segment:
            frame = frame.assign(segment=frame["segment"].fillna(args.segment) if "segment" in frame else args.segment)
        elif "segment" not in frame and len(model.domains_) == 1:
            frame["segment"] = next(iter(model.domains_))
        if "segment" not in frame:
            raise ColonsimError(f"{args.csv} has no segment column; add one or pass --segment")
        frame["segment"] = frame["segment"].astype(str).str.lower()
        for col, value in raw_inputs(args).items():
            frame[col] = frame[col].fillna(value) if col in frame else value
        if args.scope and len(args.scope) > 1:
            raise ColonsimError("with --csv give one --scope (or a scope column)")
        if args.scope:
            frame["scope"] = frame["scope"].fillna(args.scope[0]) if "scope" in frame else args.scope[0]
        for i, row in frame.iterrows():  # presets per row, where the row leaves the input empty
            p = patient_inputs(row["segment"], *(row.get(k) if isinstance(row.get(k), str) else getattr(args, k)
                                                  for k in ("sex", "age", "region")), presets=presets)
            p.update(query_defaults(model, row["segment"], {**p, **{k: v for k, v in row.items() if pd.notna(v)}}))
            for col, value in p.items():
                if col not in frame or pd.isna(frame.at[i, col]):
                    frame.loc[i, col] = value
        return frame.drop(columns=[c for c in ("sex", "age", "region") if c in frame]), ""
    segment = segment_of(args, model)
    query, note = patient_query(model, segment, args, presets)
    base = {"segment": segment, **query}
    scopes = args.scope
    if not scopes and "scope_diameter_mm" not in base and segment in model.domains_:
        domain = model.domains_[segment]
        scopes = default_scopes(domain) if "scope_diameter_mm" in domain.inputs else None
    rows = [{**base, "scope": s} for s in scopes] if scopes else [base]
    return pd.DataFrame(rows).replace({np.nan: None}), note


def records(frame):
    import numpy as np

    return [{k: (None if isinstance(v, float) and np.isnan(v) else v) for k, v in row.items()}
            for row in frame.to_dict(orient="records")]


def error_of(note, target):
    """The reason ``error_note`` gives for ``target``."""
    return next((part.split(": ", 1)[1] for part in note.split(". ") if part.startswith(target + ": ")), "")


def format_predictions(out, targets):
    from colonsim.surrogate.domain import EXTRAPOLATED
    from colonsim.surrogate.table import INPUTS, target_unit

    lines = []
    for _, row in out.iterrows():
        inputs = ", ".join(f"{c} {row[c]:g}" for c in INPUTS if c in row and row[c] is not None and row[c] == row[c])
        scope = f" {str(row['scope']).upper()}" if "scope" in row and isinstance(row["scope"], str) else ""
        outside = "" if row["in_domain"] else f"  [OUTSIDE the training domain: {row['domain_note']}]"
        lines.append(f"{row['segment'].upper()}{scope}: {inputs}{outside}")
        for t in targets:
            if row[t] == row[t]:
                unit = target_unit(t)
                split = ("" if row[t + "_std_tissue"] != row[t + "_std_tissue"] else
                         f"  sd: tissue {row[t + '_std_tissue']:.2g}, surrogate {row[t + '_std_surrogate']:.2g}")
                mark = "" if row["in_domain"] else f"  {EXTRAPOLATED}"
                if row[t + "_std"] != row[t + "_std"]:  # the model cannot vouch for a spread: no number
                    lines.append(f"  {t:<22} {row[t]:8.4g} {unit}  (no interval: {error_of(row['error_note'], t)})"
                                 + mark)
                    continue
                lines.append(f"  {t:<22} {row[t]:8.4g} +- {row[t + '_std']:.2g} {unit}  "
                             f"(95 %: {row[t + '_low95']:.4g} to {row[t + '_high95']:.4g}){split}{mark}")
        lines.append(f"  {row['tissue_note']}")
    lines.append("(+- one standard deviation of a new simulation result, tissue and surrogate parts added in "
                 "variance; the interval is mean +- 1.96 sd)")
    return "\n".join(lines)
