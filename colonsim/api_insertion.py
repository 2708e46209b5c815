"""The public Python API of one insertion run kept in memory with its shapes: :func:`simulate`.

Importable from the package itself (``colonsim.simulate(...)``), lazily like :mod:`colonsim.api`.
:func:`colonsim.insert` runs several scopes and writes their folders and a comparison;
:func:`simulate` runs one case and also keeps the wall's and the scope's positions during the run
(snapshots), for figures of the deformed colon at any moment. The example runs as a test
(``tests/test_api_calibration.py``) at the smoke size of :mod:`colonsim.catalog`.
"""

from __future__ import annotations

from pathlib import Path

from colonsim.errors import ColonsimError

__all__ = ["simulate"]


def simulate(segment="rsj", scope="sdc", *, snapshot_interval_s=None, out=None, centerline=None, max_steps=None,
             **inputs):
    """Run one insertion and return its result, with the positions stored during the run.

    Parameters
    ----------
    segment : str
        The colon model (``rsj``, ``rsf``, ``thf``, ``straight``; ``patient`` with ``centerline``).
    scope : str or float
        A named scope (``utc``, ``pdc``, ``sdc``) or an outer diameter in mm.
    snapshot_interval_s : float, optional
        Simulated seconds between stored positions (0.001-10; 0.01 gives about a hundred per
        second of push); None: no snapshots, only the final shape.
    out : path, optional
        Write the run's folder here (``summary.json``, ``timeseries.csv`` in cm/N/s,
        ``insertion.png``, the wall-stretch map), as :func:`colonsim.insert` writes each run's;
        None: write nothing.
    centerline : path, optional
        A patient's centerline CSV (then ``segment`` is ``patient``).
    max_steps : int, optional
        Refuse, before it starts, a run estimated to need more time steps (None: the command
        line's ``--max-steps`` default).
    **inputs
        Fields of :class:`colonsim.insertion.case.insertion_case.InsertionCase` (``diameter_mm``,
        ``angle_deg``, ``friction``, ``material``, ``element_size_mm``, ...; the reference's
        "Model parameters" lists them with their units). A run at the defaults takes minutes.

    Returns
    -------
    InsertionResult
        ``summary`` (the dict of ``summary.json``; deformations in cm, forces in N),
        ``timeseries`` (SI units: m, N, s), ``snapshots`` (a list of ``(time_s, wall node
        positions, scope node positions)``, positions in m), ``final_shape``, ``case`` and
        ``model`` (``model.shell.x0``: the wall's reference positions, m).

    Examples
    --------
    A straight tube at the smoke size with a snapshot every 0.05 s (seconds once the solver is
    compiled):

    >>> import colonsim
    >>> from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
    >>> run = colonsim.simulate("straight", "sdc", snapshot_interval_s=0.05, element_size_mm=SMOKE_ELEMENT_MM,
    ...                         scope_spacing_mm=SMOKE_SCOPE_SPACING_MM, push_speed=SMOKE_PUSH_SPEED)
    >>> time_s, wall, scope = run.snapshots[-1]
    >>> len(run.snapshots) > 2, wall.shape == run.model.shell.x0.shape, scope.shape[1]
    (True, True, 3)
    """
    from colonsim.files import check_output_folder, output_set
    from colonsim.insertion.case.results import write_insertion
    from colonsim.insertion.case.run_budget import DEFAULT_MAX_STEPS, check_run_budget
    from colonsim.insertion.case.scenario import run_insertion
    from colonsim.limits import OPTION_RANGES

    if snapshot_interval_s is not None:
        low, high, what = OPTION_RANGES["--snapshot-every"]
        if isinstance(snapshot_interval_s, bool) or not isinstance(snapshot_interval_s, (int, float)) or not (
                low <= snapshot_interval_s <= high):
            raise ColonsimError(f"snapshot_interval_s {snapshot_interval_s!r} is outside {low:g}-{high:g} ({what})")
    if not isinstance(scope, (str, int, float)):
        raise ColonsimError(f"scope {scope!r}: simulate runs one scope (utc, pdc, sdc or a diameter in mm); "
                            "colonsim.insert runs several")
    if out is not None:
        out = check_output_folder(Path(out))
    case, = insertion_cases(segment, [scope], centerline, inputs)
    check_run_budget(case, DEFAULT_MAX_STEPS if max_steps is None else max_steps, option="max_steps")
    result = run_insertion(case, snapshot_interval=snapshot_interval_s)
    if out is not None:
        with output_set(out) as stage:  # the folder's files replaced together when all are written
            write_insertion(result, stage)
    return result


def insertion_cases(segment, scopes, centerline, inputs) -> list:
    """The cases of ``scopes`` (names or diameters in mm) through ``segment`` (or a patient's
    ``centerline``) with the other ``inputs`` (InsertionCase's fields; ``segment``, ``scope`` and
    ``centerline`` among them are left out), as :func:`simulate` and :func:`colonsim.insert` take
    them; an unknown field is one line."""
    from colonsim.insertion.case.insertion_case import InsertionCase
    from colonsim.workflows import anatomy_inputs

    inputs = {k: v for k, v in inputs.items() if k not in ("segment", "scope", "centerline")}
    anatomy = anatomy_inputs(segment, None if centerline is None else Path(centerline),
                             inputs.pop("diameter_mm", None), inputs.pop("centerline_smoothing_mm", None))
    try:
        return [InsertionCase(**anatomy, scope=str(s), **inputs) for s in scopes]
    except TypeError as error:  # an unknown keyword
        raise ColonsimError(f"{error}; the inputs are InsertionCase's fields (docs: reference, model parameters)")
