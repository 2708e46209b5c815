"""How far a fit can be trusted: the curve's own noise, whether the law follows the curve, and
words that say no more than the numbers.

The noise is estimated from the curve alone, with the difference-based estimator of Gasser,
Sroka and Jennen-Steinmetz (Biometrika 73, 1986): each sample against the straight line through
its two neighbours removes any smooth trend (exactly for a linear one, to O(h^2) for a curved
one), so what is left is the sample-to-sample scatter of the load cell. It assumes independent
noise; a machine that filters its signal looks quieter than it is, which errs towards warning.
"""

from __future__ import annotations

import numpy as np

# RMS / noise above which a law does not follow the curve. A law that does leaves a residual
# sum of squares ~ chi-square(n - p) in noise units: with n >= 10 points RMS / noise stays below
# 1.55 with probability 0.999; 2 leaves room for a noise estimate that is itself tens of % off.
FOLLOWS_LIMIT = 2.0
# Relative standard deviation of mu0 up to which it is called well (moderately) identified.
WELL_IDENTIFIED = 0.05
MODERATELY_IDENTIFIED = 0.25
# |correlation| of C10 and C01 beyond which uniaxial data do not separate them.
SPLIT_CORRELATION = 0.95
# No load cell resolves a force to better than this fraction of its peak: the floor of the noise
# estimate, so noise-free (synthetic) curves are not judged against zero.
RESOLUTION = 1e-6


def noise_sd(displacement, force) -> float:
    """Standard deviation of the force noise of one sample, N (pseudo-residual estimator)."""
    x, y = np.asarray(displacement, dtype=float), np.asarray(force, dtype=float)
    if x.size < 3:
        return float("nan")
    h1, h2 = x[1:-1] - x[:-2], x[2:] - x[1:-1]
    a, b = h2 / (h1 + h2), h1 / (h1 + h2)
    pseudo = a * y[:-2] + b * y[2:] - y[1:-1]
    sd = float(np.sqrt(np.mean(pseudo**2 / (a**2 + b**2 + 1.0))))
    return max(sd, RESOLUTION * float(np.abs(y).max()))


def interpolation_variance(sample_points, points) -> np.ndarray:
    """Noise variance (in units of one sample's) of the curve linearly interpolated at ``points``:
    (1 - t)^2 + t^2 between two samples, 1 on a sample."""
    x = np.asarray(sample_points, dtype=float)
    p = np.asarray(points, dtype=float)
    i = np.clip(np.searchsorted(x, p, side="right") - 1, 0, x.size - 2)
    t = np.clip((p - x[i]) / (x[i + 1] - x[i]), 0.0, 1.0)
    return (1.0 - t) ** 2 + t**2


def fit_against_noise(curve, points, residuals, n_parameters) -> dict:
    """The residual of a fit at ``points`` (m) measured in the curve's noise.

    ``noise_rms_expected_N`` is the RMS a law that follows the curve leaves on average (the
    noise at the interpolated points, less the p degrees of freedom the fit absorbs).
    """
    sd, expected, ratio = residual_against_noise(curve.displacement, curve.force, points, residuals, n_parameters)
    return {"noise_sd_N": sd, "noise_rms_expected_N": expected, "rms_over_noise": ratio,
            "follows_curve": bool(ratio <= FOLLOWS_LIMIT), "noise_method": NOISE_METHOD}


NOISE_METHOD = "pseudo-residuals of neighbouring samples (Gasser et al. 1986), independent noise assumed"


def residual_against_noise(x, y, points, residuals, n_parameters) -> tuple[float, float, float]:
    """(noise sd of one sample of the curve ``y(x)``, the RMS a law that follows it leaves at
    ``points``, the residuals' RMS over that): the measure of :func:`fit_against_noise`."""
    sd = noise_sd(x, y)
    n = len(residuals)
    expected = sd * float(np.sqrt(np.mean(interpolation_variance(x, points)) * max(n - n_parameters, 1) / n))
    rms = float(np.sqrt(np.mean(np.square(residuals))))
    return sd, expected, rms / expected if expected > 0 else float("inf")


def shear_modulus_weights(law, n_parameters) -> np.ndarray:
    """mu0 = w . theta: the small-strain shear modulus is linear in every law's parameters."""
    return np.array([law.initial_shear_modulus(e) for e in np.eye(n_parameters)])


def shear_modulus(result) -> tuple[float, float]:
    """mu0 of a calibration and its standard deviation from the noise (Pa)."""
    from colonsim.laws import get_law

    w = shear_modulus_weights(get_law(result.model["law"]), len(result.names))
    return float(w @ result.parameters), result.uncertainty.linear_combination_std(w)


def identification_words(mu0, mu0_sd, follows_curve) -> str:
    """How well mu0 is known, in words the numbers support."""
    if not follows_curve:
        return "its sd reflects the noise only and understates the error: the law does not follow the curve"
    if not np.isfinite(mu0_sd):
        return "not identified: the data do not fix it (a combination of the parameters it depends on is free)"
    rel = mu0_sd / abs(mu0) if mu0 else float("inf")
    if rel <= WELL_IDENTIFIED:
        quality = "well identified"
    elif rel <= MODERATELY_IDENTIFIED:
        quality = "moderately identified"
    else:
        quality = "poorly identified"
    return f"{quality} (sd {100 * rel:.1f} % of the value)"


def split_unidentified(result) -> float | None:
    """The C10/C01 correlation when uniaxial data do not separate the two (else None)."""
    names = list(result.names)
    if "C10" not in names or "C01" not in names:
        return None
    c = float(result.uncertainty.correlation[names.index("C10"), names.index("C01")])
    return c if abs(c) >= SPLIT_CORRELATION else None


def parameters_at_bounds(result) -> list[str]:
    """'C01 at its upper bound 60000 Pa'-style notes for parameters the fit pressed against a bound."""
    notes = []
    for name, value in zip(result.names, result.parameters):
        lo, hi = result.settings["bounds_Pa"][name]
        for side, bound in (("lower", lo), ("upper", hi)):
            if abs(value - bound) <= 1e-6 * (hi - lo):
                notes.append(f"{name} at its {side} bound {bound:g} Pa")
    return notes


def misfit_warning(result) -> str | None:
    """A one-line warning when the law does not follow the curve, else None."""
    fit = result.fit
    if fit["follows_curve"]:
        return None
    bounds = parameters_at_bounds(result)
    at_bounds = f" ({', '.join(bounds)}: the optimum may lie outside the bounds, or the search stopped short)" if bounds else ""
    return (f"{result.curve.name}: the fit residual (RMS {fit['rms_N']:.3g} N) is {fit['rms_over_noise']:.1f} times what "
            f"the curve's noise ({fit['noise_sd_N']:.3g} N per sample) explains{at_bounds}: {result.model['law']} does not "
            "follow this curve as fitted and its uncertainties understate the error; compare laws (--compare-laws), "
            "or try another --seed or the full budget")
