"""Property-based tests of the sweep-spec parser: whatever the text, it either parses to cases of
finite values or raises the project's one-line error (never another exception, never NaN/inf).

Documents are drawn in the format's shape: half with plausible keys and values only (most parse,
and their cases are checked), half where anything TOML can hold may appear anywhere: inf, nan,
integers beyond any float, text with control characters, booleans, unknown keys."""

import dataclasses
import json
import math

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from colonsim.errors import ColonsimError
from colonsim.catalog import segment_names
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.anatomy.scopes import colonoscope
from colonsim.insertion.study.sweep_spec import SCOPE_DIAMETER, parse_sweep

DEFAULTS = {f.name: f.default for f in dataclasses.fields(InsertionCase)}
TEXT = st.text(st.characters(blacklist_categories=("Cs",)), max_size=6)  # TOML text cannot hold lone surrogates
ANYTHING = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**400, 10**400), TEXT,
                     st.booleans())
NUMBER_KEYS = [k for k, v in DEFAULTS.items() if isinstance(v, float)] + [SCOPE_DIAMETER]


def plausible(key):
    """A value a user might mean for ``key``."""
    if key == "segment":
        return st.sampled_from(segment_names())
    if key == "scope":
        return st.sampled_from(["utc", "pdc", "sdc", "10.5", 9.5])
    if key == "material":
        return st.just("")
    if key == SCOPE_DIAMETER:
        return st.floats(8, 14)
    if key == "time_step_estimate":
        return st.sampled_from(["bounds", "global", "fast"])  # "fast": the one-line error
    if key == "contact_surface":
        return st.sampled_from(["nodes", "faces", "edges"])  # "edges": the one-line error
    if key == "contact_face_subdivision":
        return st.integers(0, 9)  # 0 and 9: the one-line error
    default = DEFAULTS[key]
    return st.floats(0.5 * default, 1.5 * default) if default else st.floats(0, 0.2)


def toml_value(v) -> str:
    """A Python value in TOML (floats as inf/nan where TOML spells them so)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)  # ASCII escapes would split astral characters into surrogates
    return str(v)


def table(header, entries):
    return [header] + [f"{toml_value(k)} = {toml_value(v)}" for k, v in entries.items()]


@st.composite
def sweep_documents(draw):
    """TOML documents of the sweep format's shape (see the module docstring)."""
    wild = draw(st.booleans())

    def pick(strategy):
        return draw(st.one_of(strategy, strategy, ANYTHING) if wild else strategy)

    known = st.sampled_from([*DEFAULTS, SCOPE_DIAMETER])
    keys = st.one_of(known, known, TEXT) if wild else known

    def entries(as_list, min_size=0):
        out = {}
        for k in draw(st.lists(keys, min_size=min_size, max_size=3, unique=True)):
            if k not in DEFAULTS and k != SCOPE_DIAMETER:
                out[k] = draw(ANYTHING)
            elif as_list and draw(st.booleans()):
                out[k] = [pick(plausible(k)) for _ in range(draw(st.integers(0 if wild else 1, 3)))]
            else:
                out[k] = pick(plausible(k))
        return out

    lines = []
    if draw(st.booleans()):
        lines += table("[sweep]", {"name": pick(st.just("s")), "seed": pick(st.integers(0, 9))})
    if draw(st.booleans()):
        lines += table("[fixed]", entries(False))
    blocks = draw(st.integers(0, 2))
    for _ in range(blocks):
        lines += table("[[grid]]", entries(True, min_size=1))
    if draw(st.booleans()) or not (blocks or wild):
        ranges = {k: sorted([pick(plausible(k)) for _ in range(2)], key=str)
                  for k in draw(st.lists(st.sampled_from(NUMBER_KEYS), min_size=1, max_size=2, unique=True))}
        samples = pick(st.one_of(st.integers(1, 6), st.integers(1, 6), st.integers(10**5, 10**500)))
        lines += table("[lhs]", {"samples": samples, **ranges})
    return "\n".join(lines) + "\n"


def check_parse(text):
    """``text`` parses to cases of finite values, or raises a one-line ColonsimError; returns which."""
    try:
        spec = parse_sweep(text)
    except ColonsimError as exc:
        assert str(exc) and "\n" not in str(exc)
        return "refused"
    assert spec.cases
    for case in spec.cases:
        for name, v in case.to_dict().items():
            assert not isinstance(v, float) or math.isfinite(v), (name, v)
        assert math.isfinite(colonoscope(case.scope).diameter)
        json.dumps(case.to_dict(), allow_nan=False)  # keys and the results table hold only finite numbers
    return "parsed"


@settings(max_examples=250, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(sweep_documents())
def test_any_sweep_document_parses_to_finite_cases_or_one_line_error(text):
    check_parse(text)


@settings(max_examples=100, deadline=None)
@given(st.text(max_size=120))
def test_any_text_parses_to_finite_cases_or_one_line_error(text):
    check_parse(text)
