"""The runs a sweep animates (``animate`` in a sweep file's ``[sweep]`` table, docs/sweeps.md):
the worker runs them with snapshots and makes their movie where the run's model is, so the
sweep's run folder gets ``insertion.gif`` beside its other files (docs/visualisation.md)."""

from __future__ import annotations

from dataclasses import dataclass

SNAPSHOT_S = 0.02  # simulated seconds between the snapshots of an animated run (insert's default)


@dataclass(frozen=True)
class AnimatedRuns:
    """A sweep's runner (:func:`colonsim.insertion.study.sweep.run_sweep`): every case runs as by
    default, those whose keys are in ``keys`` with snapshots, and their result carries its GIF
    (``animation_gif``, bytes) to the sweep's store."""

    keys: frozenset

    def __call__(self, case):
        from colonsim.insertion.case.animation import animation_frames, gif_bytes
        from colonsim.insertion.case.results import run_title
        from colonsim.insertion.case.scenario import run_insertion

        animated = case.key() in self.keys
        result = run_insertion(case, snapshot_interval=SNAPSHOT_S if animated else None)
        if animated:
            result.animation_gif = gif_bytes(list(animation_frames(result, title=run_title(result))))
        return result


def animated_keys(selectors, cases, coerce) -> frozenset:
    """Keys of the ``cases`` a sweep file's ``animate`` chooses: ``true`` (every case), or a list
    of tables of case inputs, each choosing the cases that have all of its values (``coerce(key,
    value)`` checks an input and returns it as the grid reads it: (field, value)). A table that chooses no case
    is refused: it names an input or a value the sweep does not run."""
    if selectors is True or selectors is False:
        return frozenset(c.key() for c in cases) if selectors else frozenset()
    from colonsim.errors import ColonsimError

    if not isinstance(selectors, list) or not all(isinstance(s, dict) and s for s in selectors):
        raise ColonsimError(f"[sweep] animate = {selectors!r}; give true, or a list of tables of inputs such as "
                            '[{scope = "sdc", diameter_mm = 36}] (the runs whose inputs all match one table)')
    keys = set()
    for selector in selectors:
        wanted = dict(coerce(k, v) for k, v in selector.items())
        chosen = [c.key() for c in cases if all(getattr(c, k) == v for k, v in wanted.items())]
        if not chosen:
            shown = ", ".join(f"{k} = {v!r}" for k, v in selector.items())
            raise ColonsimError(f"[sweep] animate: no run of the sweep has {shown}; choose inputs among the sweep's "
                                "values (`colonsim sweep FILE --dry-run` lists them)")
        keys.update(chosen)
    return frozenset(keys)
