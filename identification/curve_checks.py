"""Whether a test-mode curve can be what its header says, and whether a fitted law follows it.

Before a fit, a curve whose values cannot be a tension test of tissue or rubber is refused
(:func:`check_plausible`):

- a stretch beyond :data:`MAX_STRETCH`: no tissue or rubber test reaches it (Treloar's rubber
  breaks near 7.6, soft tissue below 3); per-cent strain under a plain ``strain`` header reads
  as stretch up to 101 and more;
- a stress of the wrong sign: the largest stress (in magnitude) is negative although the test
  is read as tension (a machine that records tension as negative, or compression);
- no load: the stress does not move from its first value by more than :data:`NO_LOAD_NOISE`
  times the curve's own noise.

After a fit, every curve gets the diagnostics of the single-curve path
(:mod:`colonsim.identification.diagnostics`): its residual RMS against the RMS its own noise
explains, and R^2; a curve whose residual exceeds :data:`FOLLOWS_LIMIT` times that is not
followed, and a warning names it (:func:`misfit_warnings`). The likely cause is named when the
data point to one: a curve whose stress is about a power of ten off the others' at the same
stretch (read through the neo-Hookean form of each mode, whose secant moduli agree within a
factor 1.4 on Treloar's three modes) is in the wrong unit; a curve given as strain may also mix
per cent and fraction.
"""

from __future__ import annotations

import math

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.identification.diagnostics import FOLLOWS_LIMIT, noise_sd, residual_against_noise
from colonsim.identification.hyperelastic import calibration_law

MAX_STRETCH = 10.0
# change of a loaded curve's stress in noise units: pure noise over 30 samples moves 1-3 sd (measured, 8 seeds)
NO_LOAD_NOISE = 5.0
# a curve's neo-Hookean secant modulus this close (in log10) to a power of ten times the other
# curves' median is read as a unit off by that power (a factor 2 either way)
UNIT_TOLERANCE = math.log10(2.0)


def check_plausible(curve):
    """Refuse, in one line, a curve whose values cannot be what its header says (see the module)."""
    where = curve.meta.get("path") or curve.name
    header = curve.meta.get("deformation")
    if curve.max_stretch > MAX_STRETCH:
        why = (" (per-cent strain under a plain 'strain' header? name the column 'strain [%]')" if header == "strain"
               else " (strain or per cent under a 'stretch' header? stretch is 1 + strain)" if header == "stretch" else "")
        raise ColonsimError(f"{curve.name}: stretch reaches {curve.max_stretch:g}, beyond any tissue or rubber test "
                            f"(at most {MAX_STRETCH:g}){why}; check the deformation column of {where}")
    stress = np.asarray(curve.stress, dtype=float)
    change = float(np.max(np.abs(stress - stress[0])))
    sd = noise_sd(curve.stretch, stress)
    if change <= NO_LOAD_NOISE * sd:
        raise ColonsimError(f"{curve.name}: the stress does not rise above its noise (change {change:.3g} Pa, noise "
                            f"{sd:.3g} Pa per sample): no load was recorded; check the stress column of {where}")
    peak = int(np.argmax(np.abs(stress)))
    if stress[peak] < 0:
        raise ColonsimError(f"{curve.name}: the stress is negative in tension ({stress[peak]:.4g} Pa at stretch "
                            f"{curve.stretch[peak]:.4g}); give tension as positive stress (the machine may record it "
                            f"as negative) in {where}")


def curve_misfit(curve, stretch, measured, fitted, n_parameters) -> dict:
    """R^2, RMS and the residual against the curve's own noise at ``stretch`` (Pa)."""
    r = np.asarray(measured, dtype=float) - np.asarray(fitted, dtype=float)
    ss_tot = float(np.sum((measured - np.mean(measured)) ** 2))
    sd, expected, ratio = residual_against_noise(curve.stretch, curve.stress, stretch, r, n_parameters)
    return {"r2": 1.0 - float(r @ r) / ss_tot if ss_tot > 0 else None, "rms_Pa": float(np.sqrt(np.mean(r**2))),
            "max_abs_Pa": float(np.max(np.abs(r))), "noise_sd_Pa": sd, "noise_rms_expected_Pa": expected,
            "rms_over_noise": ratio, "follows_curve": bool(ratio <= FOLLOWS_LIMIT)}


def secant_moduli(curves) -> dict:
    """Each curve's neo-Hookean secant modulus (Pa): the median of P / g(l) over the stretches all
    curves reach, g the neo-Hookean nominal stress of unit modulus in the curve's mode."""
    unit = calibration_law("neo_hookean")
    common = min(c.max_stretch for c in curves)
    moduli = {}
    for c in curves:
        keep = (c.stretch > 1.0 + 1e-6) & (c.stretch <= common * (1 + 1e-9))
        if keep.any():
            moduli[c.name] = float(np.median(c.stress[keep] / unit.nominal_stress(c.mode, c.stretch[keep], [0.5])))
    return moduli


def unit_suspects(curves) -> dict:
    """``{curve name: cause}`` for curves whose stress is about a power of ten off the others' at
    the same stretches: against the median of all curves with three or more (the odd one out),
    against each other with two (either may be the wrong one); empty with one curve."""
    moduli = {n: g for n, g in secant_moduli(curves).items() if g > 0}
    if len(moduli) < 2:
        return {}
    logs = {n: math.log10(g) for n, g in moduli.items()}
    if len(logs) == 2:
        (a, la), (b, lb) = logs.items()
        pairs = {a: (la - lb, f"{b}'s"), b: (lb - la, f"{a}'s")}
    else:
        middle = float(np.median(list(logs.values())))
        pairs = {n: (v - middle, "the other curves'") for n, v in logs.items()}
    suspects = {}
    for name, (ratio, others) in pairs.items():
        power = round(ratio)
        if power != 0 and abs(ratio - power) <= UNIT_TOLERANCE:
            suspects[name] = (f"its stress is about {10.0 ** power:g} times {others} at the same stretch: a unit off by "
                              f"{10.0 ** abs(power):g}? check the stress unit in its header")
    return suspects


def misfit_warnings(law, per_curve, curves, mu0=None) -> list:
    """One line per curve the law does not follow (its residual against its noise, R^2 and the
    likely cause), and one for a negative small-strain modulus ``mu0`` (Pa)."""
    suspects = unit_suspects(curves)
    by_name = {c.name: c for c in curves}
    lines = []
    for row in per_curve:
        if row["follows_curve"]:
            continue
        curve = by_name[row["curve"]]
        r2 = "-" if row["r2"] is None else f"{row['r2']:.3f}"
        cause = suspects.get(row["curve"])
        if cause is not None:
            if curve.meta.get("deformation") == "strain":
                cause += " (or per cent and fraction mixed in its strain column)"
        else:
            cause = "compare laws (--compare-laws), or check its columns and units"
        lines.append(f"{row['curve']} ({row['mode']}): {law} does not follow this curve: residual RMS "
                     f"{row['rms_Pa'] / 1e3:.3g} kPa is {row['rms_over_noise']:.1f} times what its noise explains, "
                     f"R^2 {r2}; {cause}")
    if mu0 is not None and mu0 <= 0:
        lines.append(f"{law}: the small-strain shear modulus is {mu0:.4g} Pa, not positive: the fit does not describe "
                     "a solid (the insertion solver refuses it); check the curves' units and signs, or compare laws")
    return lines
