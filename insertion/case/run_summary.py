"""The summary of one insertion run (docs/model.md, "Outputs"): why and where it ended, its
scalar outcomes, and its quasi-static check.
"""

from __future__ import annotations

from colonsim.catalog import TIP_FOLDED, colon_model
from colonsim.insertion.anatomy.manoeuvre import SETTLE
from colonsim.insertion.case.outcomes import (JAM_FORCE, JAM_PROGRESS, JAM_PUSH, PEAK_WINDOW, REST_TOLERANCE,
                                              REST_WINDOW, TURNED_BACK_DEG, characteristic_points, peak_trend,
                                              quasi_static_fraction, rest_drift, turned_back)
from colonsim.insertion.case.ringing import (RINGING_FORCE_FLOOR_N, RINGING_LIMIT, RINGING_WINDOW, SNAP_DROP_N,
                                             SNAP_DROP_PUSH, SNAP_DROP_SHARE, SNAP_LEFT_OUT_LIMIT, SNAP_LEFT_OUT_PUSH,
                                             push_ringing, ringing_cause, ringing_holds)
from colonsim.insertion.case.stretch_map import wall_stretch_summary
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH
from colonsim.provenance import code_version

ENDINGS = {
    "tip_past_end": "the tip passed the fixed end",
    "far_end": "the tip reached the model's far end",
    "length_used": "the scope's available length was pushed in",
    "wall_stretch": "the wall's largest stretch passed the failure stretch",
    TIP_FOLDED: f"the tip folded back on itself (its last segment more than {TURNED_BACK_DEG:g} deg from the "
                  "lumen's direction): a real tip is steered, so the run ends there, outside the model",
    "jam": f"the tip jammed: under {JAM_PROGRESS * 1e3:g} mm of tip progress over {JAM_PUSH * 100:g} cm of push "
           f"under a push force of {JAM_FORCE:g} N or more",
}


def end_state(model, ts, ended_by) -> dict:
    """Where and under which forces a run ended (``ended_by`` explained, depth, tip, forces)."""
    last = ts.iloc[-1]
    reason = ENDINGS[ended_by]
    if ended_by == "length_used" and colon_model(model.case.segment).must_reach_end:
        reason += " before the tip passed the fixed end"
    return {"reason": reason, "depth_cm": float(last["depth_m"] * 100), "tip_arc_cm": float(last["tip_arc_m"] * 100),
            "push_force_N": float(last["push_force_N"]), "contact_force_N": float(last["contact_force_N"])}


def tip_passed_end(sample, model) -> bool:
    """Has the tip crossed the end plane, near the end of the colon (not beside its entry)?"""
    near = sample["tip_arc_m"] >= model.tip_end - 1e-3 * model.case.diameter_mm
    return bool(near and sample["tip_past_end_m"] >= 0.0)


def _finite(value):
    """``value``, or None where it is undefined (NaN): JSON holds no NaN."""
    return float(value) if value == value else None


def quasi_static_summary(ts, energy_fractions, sliding) -> dict:
    """The run's quasi-static check (docs/quasi_static.md): the ringing ratio of the push force over
    the push (the closing settle phase left out: the scope is held there) with the snap-throughs it
    leaves out, and the kinetic/internal energy fractions as information."""
    ring = push_ringing(ts["phase"], ts["depth_m"], ts["push_force_N"], ts["contact_nodes"])
    return {
        "criterion": f"ringing ratio below {RINGING_LIMIT:g}: RMS of the push force about its moving average over "
                     f"{RINGING_WINDOW * 100:g} cm of push, over max(its mean, {RINGING_FORCE_FLOOR_N:g} N), from the "
                     f"first contact to the end of the push, the {SNAP_LEFT_OUT_PUSH * 1e3:g} mm after each "
                     f"snap-through left out (at most {SNAP_LEFT_OUT_LIMIT:.0%} of the push)",
        "ringing_ratio": _finite(ring["ratio"]),
        "push_force_rms_N": _finite(ring["rms_N"]),
        "mean_push_force_N": _finite(ring["mean_N"]),
        "force_floor_N": RINGING_FORCE_FLOOR_N,
        "measured_push_cm": ring["push_cm"],
        "snap_throughs": {"count": len(ring["snap_throughs"]), "depths_cm": ring["snap_throughs"],
                          "left_out_share": ring["left_out_share"],
                          "rule": f"the push force falls by more than {SNAP_DROP_N:g} N and more than "
                                  f"{SNAP_DROP_SHARE:.0%} of the force before it within {SNAP_DROP_PUSH * 1e3:g} mm "
                                  "of push"},
        "holds": ringing_holds(ring),
        "cause": ringing_cause(ring),
        "energy": {"meaning": "kinetic / internal energy < 10 % on most (> 50 %) of the samples, per body, the scope's "
                              "kinetic energy taken less that of sliding along itself at the push speed; information, "
                              "not the criterion (it passed runs that rang)",
                   "fraction_below_10pct": {"colon": energy_fractions["colon"], "scope": sliding},
                   "holds": bool(energy_fractions["colon"] > 0.5 and sliding > 0.5)},
    }


def rest_summary(ts, hold_start) -> dict:
    """Whether the run came to rest in its closing hold before its final values were read
    (docs/model.md, "Loading"): ``came_to_rest``, the time held, and how far the colon deformation
    and the tip moved over the hold's last :data:`REST_WINDOW` (mm)."""
    out = {"criterion": f"the colon deformation and the tip each move less than {REST_TOLERANCE * 1e3:g} mm over the "
                        f"last {REST_WINDOW:g} s of the closing hold",
           "came_to_rest": False, "held_s": 0.0, "deformation_drift_mm": None, "tip_drift_mm": None}
    if hold_start is None or ts["time_s"].iloc[-1] < hold_start:
        return {**out, "meaning": "no closing hold: the run ended under its load (a jam, a fold or a tear) or without one"}
    hold = ts[ts["time_s"] >= hold_start - 1e-12]
    out["held_s"] = float(ts["time_s"].iloc[-1] - hold_start)
    drift = rest_drift(hold["time_s"], hold["deformation_m"], hold["tip_displacement_m"])
    if drift is None:
        return {**out, "meaning": f"held for less than {REST_WINDOW:g} s: too short to tell"}
    out.update(deformation_drift_mm=drift[0] * 1e3, tip_drift_mm=drift[1] * 1e3,
               came_to_rest=bool(max(drift) < REST_TOLERANCE))
    return out


def summarize(model, ts, wall_s, build_s) -> dict:
    """The summary of one run: deformation, points A/B/C, forces, energy check, sizes, inputs."""
    points = characteristic_points(ts["time_s"], ts["depth_m"], ts["deformation_m"])
    push = ts[ts["phase"] != SETTLE]
    qs = {body: quasi_static_fraction(ts[f"kinetic_{body}_J"], ts[f"internal_{body}_J"]) for body in ("colon", "scope")}
    sliding = quasi_static_fraction(ts["kinetic_scope_sliding_J"], ts["internal_scope_J"])
    g = model.geometry
    return {
        "inputs": model.case.to_dict(),
        "key": model.case.key(),
        "code": code_version(),
        "scope": {**model.scope.describe(), "length_cm": float(model.rod.rest_length.sum() * 100)},
        "pushed_depth_cm": float(ts["depth_m"].iloc[-1] * 100),
        "tip_end_cm": float(model.tip_end * 100),
        "final_deformation_cm": float(ts["deformation_m"].iloc[-1] * 100),
        "max_deformation_cm": float(ts["deformation_m"].max() * 100),
        "points_cm": {k: (None if v is None else {"deformation_cm": v["deformation_m"] * 100,
                                                    "depth_cm": v["depth_m"] * 100, "time_s": v["time_s"]})
                      for k, v in points.items()},
        "peak_contact_force_N": _finite(peak_trend(push["depth_m"], push["contact_force_N"])),
        "peak_push_force_N": _finite(peak_trend(push["depth_m"], push["push_force_N"])),
        "peak_forces_sampled_N": {"contact": float(ts["contact_force_N"].max()), "push": float(ts["push_force_N"].max()),
                                  "meaning": "largest recorded samples (every record_interval_s), before averaging "
                                             f"over {PEAK_WINDOW * 1e3:g} mm of push"},
        "max_wall_stretch": float(ts["max_stretch"].max()),
        "final_tip_arc_cm": float(ts["tip_arc_m"].iloc[-1] * 100),
        "max_lag_cm": float(ts["lag_m"].max() * 100),
        "final_lag_cm": float(ts["lag_m"].iloc[-1] * 100),
        "tip_turned_back_cm": (None if (back := turned_back(ts["depth_m"], ts["tip_heading_deg"])) is None
                               else back * 100),
        "max_tip_heading_deg": float(ts["tip_heading_deg"].max()),
        "distal_resistance": {"resistance_N": model.case.distal_resistance_N,
                              "exit_start_cm": None if g.exit_start is None else g.exit_start * 100,
                              "acting": model.resistance is not None,
                              "final_force_N": float(ts["distal_force_N"].iloc[-1]),
                              "max_force_N": float(ts["distal_force_N"].max())},
        "quasi_static": quasi_static_summary(ts, qs, sliding),
        "at_rest": rest_summary(ts, model.push.hold_start),
        "simulated_time_s": float(ts["time_s"].iloc[-1]),
        "steps": int(model.solver.step),
        "time_step_s": {"min": float(ts["dt_s"].min()), "max": float(ts["dt_s"].max())},
        "wall_time_s": float(wall_s),
        "build_time_s": float(build_s),
        "mesh": {**g.summary(), "scope_nodes": int(model.rod.n_nodes), "hinges": int(len(model.shell.hinges))},
        "material": {"law": model.shell.material.law, **model.shell.material.named_parameters,
                     "file": model.case.material or str(REFERENCE_MATERIAL_PATH)},
        **wall_stretch_summary(model, ts),  # where the wall is stretched (stretch_map.py)
    }
