"""Write the sweep of a resistance sweep's runs that ring above the limit, at half the push speed.

The validation report judges each run of the ``resistance`` preset whose ringing ratio is above
the limit by the proposed bound (docs/notes/2026-11-model-studies.md, "Ringing that no push speed removes"): the same
run at half the push speed. Which runs ring depends on the engine that made the sweep, so the list
is written from the sweep's own table rather than kept by hand::

    python -m validation.ringing_half_speed /path/to/resistance_sweep
    colonsim sweep benchmarks/sweeps/ringing_half_speed.toml --workers 2 --out DIR
    python -m validation.report ... --resistance-sweep /path/to/resistance_sweep --ringing-half-sweep DIR

Each run is written as one ``[[grid]]`` block with every input that differs from the defaults and
``push_speed`` at the rate check's half speed, so its key is the one the report looks up.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

from colonsim.errors import ColonsimError
from colonsim.insertion.case.insertion_case import InsertionCase
from colonsim.insertion.case.ringing import RINGING_LIMIT
from colonsim.insertion.study.sweep_presets import HALF_SPEED
from colonsim.insertion.study.sweep_spec import parse_sweep
from .resistance import half_speed_twin, measured_ringing
from .sweeps import read_sweep

OUT = Path(__file__).resolve().parents[1] / "benchmarks" / "sweeps" / "ringing_half_speed.toml"


def ringing_cases(sweep) -> list:
    """The cases of ``sweep`` run at the default push speed whose ringing ratio is at or above the
    limit (the report's "above the limit"), in the sweep's order."""
    return [case for case, _, ratio in measured_ringing(sweep, InsertionCase().push_speed) if ratio >= RINGING_LIMIT]


def _toml_value(name, value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, (int, float)):
        return repr(value)
    raise ColonsimError(f"input {name} = {value!r} cannot be written to the half-speed sweep; "
                        "write that run's [[grid]] block by hand")


def half_speed_toml(cases, engine: str) -> str:
    """The sweep TOML of ``cases`` at half the push speed; ``engine``: the commit(s) that made the
    rows, named in the description."""
    defaults = InsertionCase()
    lines = ["[sweep]", 'name = "ringing_half_speed"',
             f'description = "The {len(cases)} runs of the resistance preset whose ringing ratio is above '
             f'{RINGING_LIMIT:g} (engine {engine}), at half the push speed: the proposed bound (docs/model.md, '
             '\\"Ringing that no push speed removes\\") asks that half the speed leave the ratio within 20 % and '
             'the rate pair pass"']
    for case in cases:
        twin = half_speed_twin(case)
        lines += ["", "[[grid]]"]
        for f in dataclasses.fields(InsertionCase):
            value = getattr(twin, f.name)
            if value != getattr(defaults, f.name) or f.name == "segment":
                lines.append(f"{f.name} = {_toml_value(f.name, value)}")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sweep", type=Path, help="folder of a finished `colonsim sweep --preset resistance`")
    parser.add_argument("--out", type=Path, default=OUT, help=f"TOML to write (default {OUT.name} in benchmarks/sweeps)")
    args = parser.parse_args(argv)
    try:
        sweep = read_sweep("resistance", args.sweep, optional=True)
        if not sweep.ran:
            raise ColonsimError(f"no results table in {args.sweep}; give the folder of a resistance sweep")
        cases = ringing_cases(sweep)
        if not cases:
            raise ColonsimError(f"no run of {args.sweep} rings above {RINGING_LIMIT:g}: the half-speed sweep would be empty")
        engine = ", ".join(str(c)[:7] for c in sorted(sweep.commits()))
        text = half_speed_toml(cases, engine)
        written = parse_sweep(text, origin=str(args.out)).cases  # what `colonsim sweep` will read back
        if [c.key() for c in written] != [half_speed_twin(c).key() for c in cases]:
            raise ColonsimError("the written sweep does not read back as the half-speed runs; report this as a bug")
    except ColonsimError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    args.out.write_text(text, encoding="utf-8")
    print(f"{len(cases)} runs above {RINGING_LIMIT:g} of {len(sweep.table)} in {args.sweep} -> {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
