"""A sweep file's ``animate`` (colonsim.insertion.study.sweep_animation): which runs it chooses,
and the movie and the wall-stretch map in the sweep's run folders."""

import pytest
from PIL import Image

from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM, STRETCHED_WALL_COLUMN
from colonsim.errors import ColonsimError
from colonsim.insertion.case.stretch_map import read_stretch_map
from colonsim.insertion.study.sweep import run_sweep
from colonsim.insertion.study.sweep_spec import parse_sweep

GRID = """
[sweep]
name = "animated"
{animate}

[fixed]
segment = "straight"
element_size_mm = {element}
scope_spacing_mm = {spacing}
push_speed = {speed}

[[grid]]
scope = ["utc", "pdc"]
diameter_mm = [30, 36]
"""


def spec(animate):
    return parse_sweep(GRID.format(animate=animate, element=SMOKE_ELEMENT_MM, spacing=SMOKE_SCOPE_SPACING_MM,
                                   speed=SMOKE_PUSH_SPEED))


def test_animate_chooses_the_runs_whose_inputs_match():
    keys = lambda s, **inputs: {c.key() for c in s.cases if all(getattr(c, k) == v for k, v in inputs.items())}
    assert spec("").animated == frozenset()
    every = spec("animate = true")
    assert every.animated == {c.key() for c in every.cases} and len(every.cases) == 4
    one = spec('animate = [{scope = "UTC", diameter_mm = 36}]')  # read as the grid reads it: 36 is 36.0
    assert one.animated == keys(one, scope="utc", diameter_mm=36.0) and len(one.animated) == 1
    two = spec('animate = [{scope = "pdc"}, {diameter_mm = 30}]')
    assert two.animated == keys(two, scope="pdc") | keys(two, diameter_mm=30.0) and len(two.animated) == 3


@pytest.mark.parametrize("animate, message", [
    ('animate = [{scope = "sdc"}]', "no run of the sweep has scope = 'sdc'"),
    ('animate = [{diameter = 36}]', "unknown key 'diameter'"),
    ('animate = "utc"', "give true, or a list of tables"),
    ("animate = [{}]", "give true, or a list of tables"),
    ('animate = [{friction = "a"}]', "friction = 'a'; give a number")])
def test_a_bad_animate_is_one_line(animate, message):
    with pytest.raises(ColonsimError, match=message):
        spec(animate)


def test_a_sweep_writes_the_movie_of_its_chosen_runs(tmp_path):
    """Two runs on one worker process (about a minute): the chosen one gets its GIF, both their map."""
    s = parse_sweep(GRID.replace('diameter_mm = [30, 36]', 'diameter_mm = 36').format(
        animate='animate = [{scope = "utc"}]', element=SMOKE_ELEMENT_MM, spacing=SMOKE_SCOPE_SPACING_MM,
        speed=SMOKE_PUSH_SPEED))
    report = run_sweep(s.cases, tmp_path, workers=1, spec=s, progress=False)
    assert report.ok == 2
    for case in s.cases:
        folder = tmp_path / "runs" / case.key()
        assert read_stretch_map(folder)["stretch_max"].max() == pytest.approx(1.0, abs=1e-6)
        assert (folder / "stretch_map.png").is_file()
        assert (folder / "insertion.gif").is_file() == (case.scope == "utc")
        if case.scope == "utc":
            with Image.open(folder / "insertion.gif") as gif:
                assert gif.n_frames > 10
    assert (report.table[STRETCHED_WALL_COLUMN] == 0.0).all()
