"""The public Python API of the calibration beyond :func:`colonsim.calibrate`: the clamped strip
with a chosen mesh and search budget, joint fits of several test modes, and material cards.

Importable from the package itself (``colonsim.calibrate_strip(...)``), lazily like
:mod:`colonsim.api`. Each function runs the code of a command line and writes the same files:

===========================  ========================================  ==========================
function                     what it does                              command line
===========================  ========================================  ==========================
:func:`calibrate_strip`      fit a law to strip tensile curves with    ``colonsim calibrate
                             the FE mesh and search budget given       --mesh``
:func:`calibrate_multimode`  fit laws to stress-stretch curves of      ``colonsim calibrate
                             several test modes jointly, Drucker-      --manifest`` (mode column)
                             checked
:func:`export_cards`         write a material.json's law as LS-DYNA,   ``colonsim material
                             Abaqus, ANSYS or FEBio cards              export``
===========================  ========================================  ==========================

The examples run as tests (``tests/test_api_calibration.py``) with reduced meshes and budgets,
whose numbers are not calibrations.
"""

from __future__ import annotations

from pathlib import Path

from colonsim.errors import ColonsimError

__all__ = ["calibrate_strip", "calibrate_multimode", "export_cards"]

_BUDGET_WORDS = ("full", "quick")


def _budget(spec):
    """The search budget ``spec`` names: None for "full" (the workflow's default), the quick one,
    or a mapping of :class:`colonsim.identification.search.Budget`'s fields."""
    from dataclasses import fields

    from colonsim.identification.search import Budget
    from colonsim.limits import BUDGET_MAX, check_count

    if isinstance(spec, str) and spec in _BUDGET_WORDS:
        return None if spec == "full" else Budget.quick()
    names = [f.name for f in fields(Budget)]
    if not isinstance(spec, dict):
        raise ColonsimError(f"budget {spec!r}: give 'full', 'quick' or a dict of some of {', '.join(names)}")
    unknown = sorted(set(spec) - set(names))
    if unknown:
        raise ColonsimError(f"budget key {unknown[0]!r} is unknown; the keys are {', '.join(names)}")
    for key, value in spec.items():
        if key != "cma_sigma0":
            check_count(f"budget {key}", value, 1, BUDGET_MAX)
        elif isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value <= 1:
            raise ColonsimError(f"budget cma_sigma0 {value!r}: give the step as a share of each range, in (0, 1]")
    return Budget(**spec)


def calibrate_strip(curve=None, manifest=None, *, length_mm=None, width_mm=None, thickness_mm=None, law=None,
                    mesh=(8, 3), budget="full", points=20, seed=1, out="colonsim_results/calibration",
                    show_progress=False) -> dict:
    """Fit a hyperelastic law to strip tensile curves on the clamped-strip FE model.

    The pipeline of :func:`colonsim.calibrate` (Latin-hypercube sensitivity study, CMA-ES,
    Nelder-Mead, the linearised uncertainty), with the specimen's finite-element mesh and the
    search budget in the caller's hands: a coarse mesh and a small budget for a quick look, the
    defaults for a calibration. One curve, or the mean curve of a manifest's specimens.

    Parameters
    ----------
    curve : path, optional
        One force-displacement file (force in N, displacement in mm unless its header says).
    manifest : path, optional
        A CSV of specimens with their geometry; neither: the bundled synthetic data set.
    length_mm, width_mm, thickness_mm : float, optional
        The strip's free length, width and thickness in mm, for ``curve`` (else its preamble).
    law : str, optional
        A law of :data:`colonsim.laws.LAWS`; None: three-parameter Mooney-Rivlin.
    mesh : (int, int)
        Quarter-strip P2 divisions along the length and across the half-width (8 x 3: the
        command line's default).
    budget : {"full", "quick"} or dict
        The search's evaluations: the full pipeline, the quick one, or a dict of some of
        ``designs``, ``cma_popsize``, ``cma_max_evaluations``, ``cma_sigma0``, ``nm_max_evaluations``
        (the rest at the full pipeline's values).
    points : int
        Displacement points of the objective (5 or more).
    seed : int
        Seeds the Latin hypercube and CMA-ES: the same seed gives the same result.
    out : path
        Output folder: ``material.json`` (parameters in Pa), ``fit.csv``, ``history.csv``,
        ``sensitivity.csv``, figures; replaced whole when done.

    Returns
    -------
    dict
        ``material``: the path of ``material.json``; ``result``: the
        :class:`colonsim.identification.pipeline.CalibrationResult` (``parameters`` in Pa,
        ``uncertainty``, ``fit``, ``history``, ``sensitivity``, ``stages``).

    Examples
    --------
    A 2 x 1 mesh and about 20 evaluations on the bundled data (seconds; not a calibration):

    >>> import colonsim
    >>> fit = colonsim.calibrate_strip(mesh=(2, 1), budget={"designs": 6, "cma_max_evaluations": 6,
    ...                                "nm_max_evaluations": 6}, out="strip_coarse")  # doctest: +ELLIPSIS
    fitting the mean curve of 8 specimens ...
    >>> fit["material"].name, fit["result"].names
    ('material.json', ('C10', 'C01', 'C11'))
    >>> fit["result"].fit["evaluations"] < 40
    True
    """
    from colonsim.workflows import CalibrationRequest, calibrate as run

    if isinstance(mesh, str) or len(mesh) != 2:
        raise ColonsimError(f"mesh {mesh!r}: give two whole numbers, divisions along the length and across the half-width")
    out = Path(out)
    request = CalibrationRequest(manifest=None if manifest is None else Path(manifest),
                                 curve=None if curve is None else Path(curve), length_mm=length_mm, width_mm=width_mm,
                                 thickness_mm=thickness_mm, law=law, mesh=tuple(mesh), points=points,
                                 budget=_budget(budget), seed=seed, workers=1, show_progress=show_progress)
    result, = run(request, out)
    return {"material": out / "material.json", "result": result}


def calibrate_multimode(manifest=None, *, curve=None, mode=None, modes=None, law=None, compare_laws=False,
                    residuals="relative", stability_range=None, budget="full", seed=1,
                    out="colonsim_results/calibration") -> dict:
    """Fit hyperelastic laws to stress-stretch curves of several test modes at once.

    Every curve (uniaxial, equibiaxial, planar tension; strips too) enters one objective, each
    weighing the same; the search is followed by a least-squares polish, and each fitted law is
    checked for Drucker stability along the three paths.

    Parameters
    ----------
    manifest : path, optional
        A CSV of curves with a ``mode`` column (the bundled Treloar set:
        ``colonsim.data.TRELOAR_MANIFEST``).
    curve, mode : path, str, optional
        One stress-stretch file and its test mode, instead of a manifest.
    modes : sequence of str, optional
        Fit only the manifest's curves of these modes (``("uniaxial",)``); None: every curve.
    law : str, optional
        A law of ``colonsim.identification.hyperelastic.CALIBRATION_LAWS`` (Ogden's included);
        None: three-parameter Mooney-Rivlin.
    compare_laws : bool
        Fit every law; the Drucker-stable one with the lowest BIC is written as ``material.json``.
    residuals : {"relative", "absolute"}
        Per-curve residuals: relative to the stress (floor a tenth of the curve's peak) or in
        units of the curve's peak.
    stability_range : (float, float), optional
        Stretches of the Drucker check; None: 0.5 to twice the largest tested stretch.
    budget : {"full", "quick"} or dict
        The search's evaluations, as for :func:`calibrate_strip` ("full": the command line's).
    seed : int
        Seeds the search.
    out : path
        Output folder: ``material.json`` (parameters in Pa), ``fit.csv``, ``curves.csv``,
        ``modes.png``; with ``compare_laws`` also ``laws.csv``, ``laws.png``, ``laws/<law>/``.

    Returns
    -------
    dict
        ``material``: the path of ``material.json``; ``fits``: {law: its
        :class:`colonsim.identification.joint.JointResult`} (``parameters`` in Pa and 1,
        ``per_curve`` R^2 and RMS, ``stability``); ``chosen``: the law written; ``table``: with
        ``compare_laws`` the laws ranked stable-first by BIC (a DataFrame), else None;
        ``reason``: why the chosen law won (None without ``compare_laws``).

    Examples
    --------
    Mooney-Rivlin fitted to Treloar's uniaxial test alone turns Drucker-unstable; Yeoh fitted to
    the three modes jointly stays stable and follows each (a reduced budget: seconds, not a
    calibration; ``compare_laws=True`` fits every law and ranks them in ``table``):

    >>> import colonsim
    >>> from colonsim.data import TRELOAR_MANIFEST
    >>> small = {"designs": 20, "cma_popsize": 8, "cma_max_evaluations": 100, "nm_max_evaluations": 100}
    >>> alone = colonsim.calibrate_multimode(TRELOAR_MANIFEST, modes=["uniaxial"], law="mooney_rivlin_2",
    ...                                      budget=small, out="uniaxial_mr2")  # doctest: +ELLIPSIS
    fitting 1 curve(s) jointly: treloar_uniaxial (uniaxial)
    ...
    >>> list(alone["fits"]["mooney_rivlin_2"].per_curve["mode"]), alone["fits"]["mooney_rivlin_2"].stability.is_stable
    (['uniaxial'], False)
    >>> joint = colonsim.calibrate_multimode(TRELOAR_MANIFEST, law="yeoh", budget=small,
    ...                                      out="treloar")  # doctest: +ELLIPSIS
    fitting 3 curve(s) jointly: ...
    >>> yeoh = joint["fits"]["yeoh"]
    >>> list(yeoh.per_curve["mode"]), yeoh.stability.is_stable, bool(yeoh.per_curve["r2"].min() > 0.9)
    (['uniaxial', 'equibiaxial', 'planar'], True, True)
    """
    from colonsim.calibrate_modes import ModeRequest, calibrate_modes as run
    from colonsim.identification.hyperelastic import MODES
    from colonsim.identification.joint_report import compare_joint

    if isinstance(modes, str):
        modes = [modes]
    if modes is not None:
        unknown = [m for m in modes if m not in MODES]
        if unknown or not modes:
            raise ColonsimError(f"modes {list(modes)!r}: give some of {', '.join(MODES)}")
        if curve is not None:
            raise ColonsimError("modes= selects a manifest's curves; a single curve has its mode in mode=")
    if residuals not in ("relative", "absolute"):
        raise ColonsimError(f"residuals {residuals!r}: give 'relative' or 'absolute'")
    out = Path(out)
    request = ModeRequest(manifest=None if manifest is None else Path(manifest),
                          curve=None if curve is None else Path(curve), mode=mode, modes=None if modes is None else tuple(modes),
                          law=law, compare_laws=compare_laws, residuals=residuals,
                          stability_range=None if stability_range is None else tuple(stability_range),
                          budget=_budget(budget), seed=seed)
    if request.manifest is None and request.curve is None:
        raise ColonsimError("give a mode manifest (e.g. colonsim.data.TRELOAR_MANIFEST) or curve= with mode=")
    fits = {r.law: r for r in run(request, out)}
    table, chosen, reason = compare_joint(fits) if compare_laws else (None, next(iter(fits)), None)
    return {"material": out / "material.json", "fits": fits, "chosen": chosen, "table": table, "reason": reason}


def export_cards(material, formats, out=None, *, material_id=1, density=None, bulk_ratio=None, poisson=None,
                 deck=False) -> list:
    """Write the law of a ``material.json`` as material cards for other solvers.

    The cards are in tonne, mm, s, N, MPa (each format's own convention for Ogden's constants).
    Cards already in ``out`` that were written from another material are rewritten with these,
    so that a folder's cards stay one set; a folder whose ``material.json`` holds another material
    is refused.

    Parameters
    ----------
    material : path
        A ``material.json`` written by a calibration.
    formats : str or sequence of str
        Some of ``lsdyna``, ``abaqus``, ``ansys``, ``febio``.
    out : path, optional
        Output folder; None: the material file's folder.
    material_id : int
        Material number in the cards (LS-DYNA MID, ANSYS material, FEBio id, Abaqus COLONSIM_N).
    density : float, optional
        kg/m^3; None: the colon wall's default.
    bulk_ratio, poisson : float, optional
        The bulk modulus as K/mu0, or as the small-strain Poisson's ratio (one of them); None:
        the default ratio.
    deck : bool
        Stand-alone files instead of include files.

    Returns
    -------
    list of Path
        The cards written (``material_<format>.<suffix>``).

    Examples
    --------
    The Treloar fit above as LS-DYNA and FEBio cards:

    >>> import colonsim
    >>> paths = colonsim.export_cards("treloar/material.json", ["lsdyna", "febio"])
    >>> [p.name for p in paths]
    ['material_lsdyna.k', 'material_febio.xml']
    """
    from colonsim.cli_material import card_options
    from colonsim.identification.card_options import DENSITY_DEFAULT, check_bulk_ratio, check_material_id, check_poisson
    from colonsim.identification.cards import FORMATS, read_material, write_cards

    formats = [formats] if isinstance(formats, str) else list(formats)
    unknown = [f for f in formats if f not in FORMATS]
    if unknown or not formats:
        raise ColonsimError(f"card format {unknown[0] if unknown else 'none'!r}: give some of {', '.join(FORMATS)}")
    if bulk_ratio is not None and poisson is not None:
        raise ColonsimError("give the bulk modulus once: bulk_ratio= or poisson=, not both")
    material = Path(material)
    options = card_options(_CardChoice(check_material_id(material_id), DENSITY_DEFAULT if density is None else density,
                                       None if bulk_ratio is None else check_bulk_ratio(bulk_ratio),
                                       None if poisson is None else check_poisson(poisson), deck))
    law, params = read_material(material)
    return write_cards(formats, law, params, material.parent if out is None else Path(out), options, source=material)


class _CardChoice:
    """The card options as the command line's parsed options carry them (K/mu0 for ``poisson``)."""

    def __init__(self, material_id, density, bulk_ratio, poisson, deck):
        self.material_id, self.density, self.bulk_ratio, self.poisson, self.deck = (material_id, density, bulk_ratio,
                                                                                   poisson, deck)
