"""Property-based tests of the curve reader: any input either reads to finite values (a curve a
fit can use) or raises the project's one-line error; nothing else escapes."""

import tempfile
import warnings
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from colonsim.errors import ColonsimError
from colonsim.identification.testdata import CurveWarning, read_curve

DISPLACEMENTS = ["displacement", "Extension", "Standard travel", "Axial Displacement ", "Stroke", "Position", "Weg"]
FORCES = ["force", "Load", "Standard force", "Kraft", "Axial Force "]
OTHERS = ["Time", "Strain", "Load cell", "x", "", "Crosshead speed", "Grip to grip separation"]
LENGTH_UNITS = ["mm", "µm", "in", "cm"]
FORCE_UNITS = ["N", "kN", "lbf", "mN"]
WRONG_UNITS = ["", "furlong", "%", "N", "mm"]
KEYS = ["Width", "Width (mm)", "Thickness", "Specimen thickness [mm]", "Gauge length (mm)", "Grip separation",
        "Probenbreite", "Rate", "Specimen", "Date", "Specimen : Width", "Clamping length"]
SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
WORDS = st.text(alphabet="abcdefgXYZ 0123456789.,:;-_()[]%µä", max_size=12)
# Mostly plausible forces, sometimes values that must be refused or that overflow a unit conversion.
forces = st.integers(0, 9).flatmap(lambda k: st.floats(0.0, 100.0) if k else st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([1e306, 1.7e308, -1e306, 0.0, -1.0, 5e-324])))


def mostly(usual, unusual):
    """``usual`` four times in five, else ``unusual``."""
    return st.integers(0, 4).flatmap(lambda k: unusual if k == 0 else usual)


def spelled(value, decimal):
    text = repr(value)
    return text.replace(".", ",") if decimal == "," else text


@st.composite
def cells(draw):
    """A stray cell: a number, a unit, text or nothing."""
    return draw(st.one_of(st.builds(repr, forces), st.sampled_from(["(mm)", "(N)", "mm", "kN", "sec", "%", ""]), WORDS))


@st.composite
def exports(draw):
    """Export-like text: preamble, header with units in it or in a units row, data rows, trailing rows."""
    delimiter = draw(st.sampled_from([",", ";", "\t"]))
    decimal = "," if delimiter != "," and draw(st.booleans()) else "."
    quote = draw(st.sampled_from(["", '"']))

    def row(values):
        return delimiter.join(f"{quote}{v}{quote}" for v in values)

    lines = [row([draw(st.sampled_from(KEYS)), spelled(draw(st.floats(0.0, 200.0)), decimal),
                  draw(st.sampled_from(["", "mm", "in", "%", "cm"]))]) for _ in range(draw(st.integers(0, 4)))]
    if lines and draw(st.booleans()):
        lines.append("")
    names = [draw(st.sampled_from(DISPLACEMENTS)), draw(st.sampled_from(FORCES))]
    names += [draw(st.sampled_from(OTHERS)) for _ in range(draw(st.integers(0, 2)))]
    units = [draw(mostly(st.sampled_from(LENGTH_UNITS), st.sampled_from(WRONG_UNITS))),
             draw(mostly(st.sampled_from(FORCE_UNITS), st.sampled_from(WRONG_UNITS)))] + ["s"] * (len(names) - 2)
    order = draw(st.permutations(range(len(names))))
    d_col = order.index(0)
    style = draw(mostly(st.sampled_from(["[{}]", "({})", "_{}", "units row"]), st.just("none")))
    if style in ("units row", "none"):
        lines.append(row([names[i] for i in order]))
        if style == "units row":
            lines.append(row([f"({units[i]})" if units[i] else "" for i in order]))
    else:
        lines.append(row([f"{names[i]} {style.format(units[i])}".replace(" _", "_") if units[i] else names[i]
                          for i in order]))
    start = draw(st.floats(0.0, 10.0))
    step = draw(mostly(st.floats(1e-3, 2.0), st.sampled_from([0.0, -0.5, 1e-300, 1e300])))
    for i in range(draw(mostly(st.integers(3, 12), st.integers(0, 2)))):
        if draw(st.integers(0, 29)) == 0:
            lines.append(row([draw(cells()) for _ in range(draw(st.integers(1, len(names) + 1)))]))
        else:
            values = [start + i * step if c == d_col else draw(forces) for c in range(len(names))]
            lines.append(row([spelled(v, decimal) for v in values]))
    lines += [row([draw(cells()) for _ in names]) for _ in range(draw(st.integers(0, 2)))]
    return "\n".join(lines)


def read(data, geometry):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "curve.csv"
        path.write_bytes(data)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", CurveWarning)  # a flag disagreeing with the preamble: reported, fine
                curve = read_curve(path, **geometry)
        except ColonsimError as exc:
            assert "\n" not in str(exc)
            return None
    d, f = curve.displacement, curve.force
    assert d.size >= 3 and np.all(np.isfinite(d)) and np.all(np.isfinite(f)) and np.all(np.diff(d) > 0)
    assert all(np.isfinite(v) and v > 0 for v in (curve.length, curve.width, curve.thickness))
    return curve


geometries = st.one_of(st.just({"length": 0.1, "width": 0.025, "thickness": 0.002}), st.fixed_dictionaries(
    {}, optional={"length": st.just(0.1), "width": st.just(0.025), "thickness": st.sampled_from([0.002, 1e-300, 1e300])}))


@SETTINGS
@given(exports(), st.sampled_from(["utf-8", "utf-8-sig", "cp1252", "utf-16"]), geometries)
def test_export_like_text_reads_or_fails_cleanly(text, encoding, geometry):
    read(text.encode(encoding, errors="replace"), geometry)


@SETTINGS
@given(st.binary(max_size=300), geometries)
def test_arbitrary_bytes_read_or_fail_cleanly(data, geometry):
    read(data, geometry)


@SETTINGS
@given(st.text(max_size=300), geometries)
def test_arbitrary_text_reads_or_fails_cleanly(text, geometry):
    read(text.encode("utf-8"), geometry)
