"""The centerlines of the study's colon models (docs/model.md, "Colon models"), built from the
pieces of :mod:`colonsim.insertion.anatomy.centerline`.

The builders (:func:`rsj_centerline`, :func:`rsf_centerline`, :func:`thf_centerline`,
:func:`thf_fixed_centerline`) are planar in the x-y plane, start at the origin heading ``+y`` with
``n = -x`` (positive turns are counter-clockwise seen from ``+z``). Readings of the source
(**assumptions**) are in their docstrings.
"""

from __future__ import annotations

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline import FILLET_RADIUS, FLEXURE_RADIUS, Arc, Centerline, Kink, Straight, check_length


def _check_angle(what, value, low, high, why):
    if not (np.isfinite(value) and low <= value <= high):
        raise ColonsimError(f"{what} = {value!r} deg is outside {low:g}-{high:g} deg ({why}); choose an angle in range.")


EXIT_LENGTH = 0.10  # m, assumption: the fixed colon every model continues into after its last mobile piece
FLEXURE_ANGLE_DEG = 90.0  # assumption: turn of the splenic and hepatic flexures


def exit_pieces(exit_length, name, fold_after=None):
    """The fixed exit a model continues into: one straight piece of ``exit_length`` m (none at 0).

    With ``fold_after`` (m) shorter than ``exit_length``, the exit runs straight for ``fold_after``,
    then folds out of the model's plane (towards ``+z``) by a quarter turn of the flexure radius and
    runs on straight, ``exit_length`` long in all (**assumption**, docs/model.md "Colon models": an
    exit lengthened to take the scope's whole available length after a flexure turned far enough
    would run back across the colon it came from; the fixed colon beyond the model leaves its
    plane instead). Every piece is fixed and carries ``name``."""
    if exit_length == 0.0:
        return []
    if fold_after is None or exit_length <= fold_after:
        return [Straight(exit_length, "fixed", name)]
    turn = 0.5 * np.pi * FLEXURE_RADIUS
    pieces = [Straight(fold_after, "fixed", name), Arc(FLEXURE_RADIUS, 0.5 * np.pi, "fixed", name, roll=0.5 * np.pi)]
    if exit_length > fold_after + turn:
        pieces.append(Straight(exit_length - fold_after - turn, "fixed", name))
    return pieces


def rsj_centerline(rectum_length=0.04, sigmoid_radius=FLEXURE_RADIUS, sigmoid_angle_deg=180.0,
                   exit_length=EXIT_LENGTH):
    """Rectosigmoid junction: a straight fixed rectum, the mobile sigmoid as one arc, a fixed exit.

    Parameters
    ----------
    rectum_length : float
        m (4 cm).
    sigmoid_radius : float
        m (5 cm).
    sigmoid_angle_deg : float
        Turning angle of the sigmoid arc, deg (180); 0 < angle <= 180, beyond 180 the arc would
        head back towards the anus.
    exit_length : float
        m, length of the fixed straight ``"descending"`` piece after the sigmoid (**assumption**
        10 cm: the sigmoid-descending junction), so the scope is held at both ends of the mobile
        arc and its tip enters fixed colon instead of leaving the tube; 0 ends the tube at the
        sigmoid (the end ring is then the only hold at the far end).
    """
    _check_angle("sigmoid angle", sigmoid_angle_deg, 1e-9, 180.0, "the arc of the junction")
    pieces = [Straight(rectum_length, "fixed", "rectum"),
              Arc(sigmoid_radius, np.radians(sigmoid_angle_deg), "mobile", "sigmoid")]
    if exit_length != 0.0:
        pieces.append(Straight(exit_length, "fixed", "descending"))
    return Centerline(pieces)


def rsf_centerline(alpha_deg=0.0, rectum_length=0.04, sigmoid_length=0.20, descending_length=0.10,
                   flexure_radius=FLEXURE_RADIUS, flexure_angle_deg=FLEXURE_ANGLE_DEG, fillet_radius=FILLET_RADIUS,
                   exit_length=EXIT_LENGTH, exit_fold_after=None):
    """Rectum to splenic flexure with the sigmoid tilted by ``alpha_deg``, then a fixed exit.

    Reading of "tilted by alpha" (**assumption**): rectum and descending colon are parallel (the
    body's long axis, ``+y``); the straight sigmoid between them makes the angle alpha with that
    axis, leaning to the patient's left (``-n``, i.e. ``+x``) where the descending colon lies, so
    the descending colon is shifted laterally by about ``L sin(alpha)``. The splenic flexure then
    turns medially (``+n``) by ``flexure_angle_deg`` into a fixed straight ``"transverse"`` exit
    (the start of the transverse colon). alpha = 0 makes rectum, sigmoid and descending colon one
    straight line. Both kinks get fillets; the largest alpha is set by the fillet fitting on the
    rectum (``R_f tan(alpha/2) <= rectum``: 77 deg with the defaults).

    Parameters
    ----------
    alpha_deg : float
        Sigmoid tilt, deg, 0 <= alpha < 90 (0, 30, 45 in the study).
    rectum_length, sigmoid_length, descending_length : float
        m (assumption 4 cm as in RSJ; 20 cm; 10 cm).
    flexure_radius : float
        m (5 cm).
    flexure_angle_deg : float
        Turn of the splenic flexure, deg (assumption 90: the transverse colon runs across).
    fillet_radius : float
        m (assumption 5 cm).
    exit_length : float
        m, fixed straight after the flexure (assumption 10 cm; 0: the tube ends at the flexure).
    exit_fold_after : float or None
        m of exit after which a longer exit folds out of the plane (:func:`exit_pieces`; None: straight).
    """
    if not (np.isfinite(alpha_deg) and 0.0 <= alpha_deg < 90.0):
        raise ColonsimError(f"alpha = {alpha_deg!r} deg is outside 0 <= alpha < 90 deg (the sigmoid must climb "
                            "from the rectum to the descending colon); choose an angle in range.")
    _check_angle("splenic flexure angle", flexure_angle_deg, 1e-9, 180.0, "a flexure turns by at most 180 deg")
    a = np.radians(alpha_deg)
    pieces = [Straight(rectum_length, "fixed", "rectum"),
              Kink(-a),
              Straight(sigmoid_length, "mobile", "sigmoid"),
              Kink(a),
              Straight(descending_length, "fixed", "descending"),
              Arc(flexure_radius, np.radians(flexure_angle_deg), "fixed", "splenic flexure")]
    pieces += exit_pieces(exit_length, "transverse", exit_fold_after)
    return Centerline(pieces, fillet_radius=fillet_radius)


def thf_centerline(beta_deg=0.0, span=0.20, flexure_radius=FLEXURE_RADIUS, flexure_angle_deg=FLEXURE_ANGLE_DEG,
                   fillet_radius=FILLET_RADIUS, exit_length=EXIT_LENGTH, fixed_transverse=False, exit_fold_after=None):
    """Transverse colon drooping as a V of angle ``beta_deg``, hepatic flexure, ascending colon.

    Reading (**assumptions**): the scope enters the transverse colon directly at its splenic end
    (the model holds no splenic flexure; the entry ring is held); the transverse colon is two
    straight arms at beta below and above the line joining its ends, each ``span / (2 cos beta)``
    long, so its ends are ``span`` apart (the straight-line distance) and the unrounded V sinks
    ``span tan(beta) / 2`` (longer and deeper with beta); a fillet rounds the V bottom; the
    hepatic flexure turns by ``flexure_angle_deg`` the other way from the V's bottom, into the
    fixed ascending colon (the exit). beta = 0 makes the transverse colon one straight piece.

    Parameters
    ----------
    beta_deg : float
        Droop angle, deg, 0 <= beta <= 60 (0, 30, 45 in the study).
    span : float
        Straight-line distance between the ends of the transverse colon, m (20 cm).
    flexure_radius, fillet_radius : float
        m (5 cm; assumption 5 cm).
    flexure_angle_deg : float
        Turn of the hepatic flexure, deg (assumption 90).
    exit_length : float
        Length of the fixed ascending colon, m (10 cm; 0: the tube ends at the flexure).
    fixed_transverse : bool
        True for the fixed THF model (no mobile part).
    exit_fold_after : float or None
        m of exit after which a longer exit folds out of the plane (:func:`exit_pieces`; None: straight).
    """
    _check_angle("beta", beta_deg, 0.0, 60.0, "a steeper V is not a transverse colon")
    _check_angle("hepatic flexure angle", flexure_angle_deg, 1e-9, 180.0, "a flexure turns by at most 180 deg")
    check_length("span", span)
    b = np.radians(beta_deg)
    tag = "fixed" if fixed_transverse else "mobile"
    arm = 0.5 * span / np.cos(b)
    pieces = [Straight(arm, tag, "transverse"),
              Kink(-2.0 * b),
              Straight(arm, tag, "transverse"),
              Arc(flexure_radius, np.radians(flexure_angle_deg), "fixed", "hepatic flexure")]
    pieces += exit_pieces(exit_length, "ascending", exit_fold_after)
    return Centerline(pieces, fillet_radius=fillet_radius)


def thf_fixed_centerline(beta_deg=0.0, **kwargs):
    """Fixed THF: :func:`thf_centerline` with the transverse colon fixed too."""
    return thf_centerline(beta_deg, fixed_transverse=True, **kwargs)
