"""The loading-following held push (``InsertionCase.held_push_pace``; docs/model.md, "Distal resistance").

Behind a held tip the push goes on at ``held_push_share`` of its speed: a scope bowing into a loop
behind a tip that does not advance is the slowest motion of an insertion. Once the loop has
formed, the tip often slides on through the exit against the full resistance at the speed of the
push, and nothing behind it changes (RSF alpha 45, 13.3 mm, 5 N: the last 25 cm of push, at a
steady push force); half of all the steps of the `thesis` preset are held push
(docs/notes/2026-12-07-time-budget.md). With ``held_push_pace`` > 0 the held push returns to the
full push speed while the tip keeps that pace, and slows again when it falls behind:

- the pace: the tip's advance along the lumen over the last :data:`PACE_WINDOW` of push, over
  that push, read from the recorded samples after every chunk of push;
- only once the tip is wholly in the resisted exit over the whole window (the resistance fully
  engaged: a tip still running through free lumen keeps pace without being held);
- the push speeds up at a pace of ``held_push_pace`` or more and slows to the held speed again
  below ``held_push_pace - PACE_HYSTERESIS``; each change follows the profile's speed ramp.
"""

from __future__ import annotations

PACE_WINDOW = 0.01  # m of push over which the tip's pace is measured
PACE_HYSTERESIS = 0.2  # the pace at which the held push slows again lies this far below the one it speeds up at


def tip_pace(rows, window=PACE_WINDOW, resisted_from=None):
    """The tip's advance along the lumen over the last ``window`` (m) of push, over that push, from
    the recorder's samples ``rows`` (dicts with ``depth_m`` and ``tip_arc_m``); None while the
    samples span less push, or (with ``resisted_from``, m along the centerline) while the tip was
    short of it at the window's start."""
    if not rows:
        return None
    last = rows[-1]
    k = len(rows) - 1
    while k > 0 and rows[k]["depth_m"] > last["depth_m"] - window:
        k -= 1
    pushed = last["depth_m"] - rows[k]["depth_m"]
    if pushed < window or (resisted_from is not None and rows[k]["tip_arc_m"] < resisted_from):
        return None
    return (last["tip_arc_m"] - rows[k]["tip_arc_m"]) / pushed


def paced_speed(pace, threshold, current, full, held):
    """The held push's plateau speed (m/s) for the tip's ``pace`` (None: not measured, keep
    ``current``): ``full`` at ``threshold`` or above, ``held`` below ``threshold`` less
    :data:`PACE_HYSTERESIS`, else ``current``."""
    if pace is None:
        return current
    if pace >= threshold:
        return full
    if pace < threshold - PACE_HYSTERESIS:
        return held
    return current
