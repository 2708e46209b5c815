"""The movie of a run (colonsim.insertion.case.animation) and ``colonsim insert --animate``."""

import json
import os
import stat
import warnings
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from colonsim.catalog import SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM, STRETCHED_WALL_COLUMN
from colonsim.cli import main
from colonsim.errors import ColonsimError, ColonsimWarning
from colonsim.insertion.anatomy.colon_segments import straight_colon
from colonsim.insertion.case.animation import DPI, FRAME_SECONDS, GIF, MAX_FRAMES, MP4, SIZE_IN, write_animation
from colonsim.insertion.case.stretch_map import read_stretch_map

WIDTH, HEIGHT = round(SIZE_IN[0] * DPI), round(SIZE_IN[1] * DPI)
SCOPE_CORE = np.array([26, 26, 26])  # the scope's dark core (grey 0.1)


def scope_pixels(frame) -> int:
    """Pixels of the scope's core in the colon panel (the left 60 % of a frame)."""
    panel = np.asarray(frame.convert("RGB"))[:, : int(0.6 * frame.size[0])].astype(int)
    return int((np.abs(panel - SCOPE_CORE).max(axis=2) <= 6).sum())


def frames_of(path):
    with Image.open(path) as gif:
        frames = []
        for k in range(gif.n_frames):
            gif.seek(k)
            frames.append(gif.convert("RGB"))
        return frames, gif.info.get("duration")


def fake_ffmpeg(folder, exit_code=0):
    """An ``ffmpeg`` that copies its input into its last argument (or fails): the pipe checked
    without a video encoder."""
    script = folder / "ffmpeg"
    script.write_text(f'#!/bin/sh\nfor last; do :; done\ncat > "$last"\nexit {exit_code}\n')
    script.chmod(script.stat().st_mode | stat.S_IEXEC)
    return folder


@pytest.fixture(scope="module")
def animated(tmp_path_factory):
    """``colonsim insert --animate --vtu`` on the tests' smallest case (a straight tube at the smoke
    push), with a stand-in ffmpeg on the path; about 15 s on one core."""
    out = tmp_path_factory.mktemp("animated")
    path = os.environ["PATH"]
    os.environ["PATH"] = f"{fake_ffmpeg(tmp_path_factory.mktemp('bin'))}{os.pathsep}{path}"
    try:
        code = main(["insert", "--segment", "straight", "--scope", "utc", "--element-size", "5", "--no-progress",
                     "--push-speed", str(SMOKE_PUSH_SPEED), "--scope-spacing", str(SMOKE_SCOPE_SPACING_MM),
                     "--animate", "--vtu", "--snapshot-every", "0.01", "--stretch-threshold", "1.05", "--out", str(out)])
    finally:
        os.environ["PATH"] = path
    assert code == 0
    return out / "straight_UTC"


def test_insert_animate_writes_a_gif_of_the_run(animated):
    """The GIF has the thinned frame count, its size and timing, and the scope advances into the
    colon between the first frame and the last."""
    frames, duration = frames_of(animated / GIF)
    summary = json.loads((animated / "summary.json").read_text())
    assert summary["simulated_time_s"] / 0.01 > MAX_FRAMES  # more snapshots than frames: thinned
    assert len(frames) == MAX_FRAMES and frames[0].size == (WIDTH, HEIGHT)
    assert duration == round(FRAME_SECONDS * 1e3)
    first, last = scope_pixels(frames[0]), scope_pixels(frames[-1])
    assert last > first + 200, (first, last)
    # the same frames went to ffmpeg as raw RGB
    assert (animated / MP4).stat().st_size == MAX_FRAMES * WIDTH * HEIGHT * 3


def test_insert_writes_the_stretch_map_at_the_threshold_asked(animated):
    """A centred scope never touches the straight tube: nothing is stretched, nothing touched; the
    summary counts the area at the threshold given on the command line."""
    arrays = read_stretch_map(animated)
    assert arrays["stretch_max"] == pytest.approx(1.0, abs=1e-6) and not arrays["touched"].any()
    assert len(arrays["stretch_max"]) == len(arrays["triangles"]) == len(arrays["area_m2"])
    summary = json.loads((animated / "summary.json").read_text())
    assert summary[STRETCHED_WALL_COLUMN] == 0.0 and summary["wall_stretch"]["threshold"] == 1.05
    assert summary["wall_stretch"]["largest"]["A"] is None  # a flat deformation has no point A
    assert (animated / "stretch_map.png").stat().st_size > 10_000
    meshio = pytest.importorskip("meshio")
    cells = meshio.read(animated / "vtu" / "colon_stretch.vtu").cell_data
    assert cells["stretch_max"][0] == pytest.approx(arrays["stretch_max"], abs=1e-6)
    table = pd.read_csv(animated.parent / "comparison.csv")
    assert table[STRETCHED_WALL_COLUMN].iloc[0] == 0.0


@pytest.mark.parametrize("args, message", [(["--stretch-threshold", "3"], "stretch threshold 3 is outside"),
                                           (["--animate", "--snapshot-every", "0"], "--snapshot-every: 0 is outside 0.001-10")])
def test_bad_visualisation_options_are_one_line(args, message, tmp_path, capsys):
    assert main(["insert", "--segment", "straight", *args, "--no-progress", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "x" / "straight_SDC").exists()


def sliding_scope(frames=12):
    """A run's stand-in (no simulation): a scope sliding 15 cm into a straight tube that inflates
    by 10 %, its snapshots and time series."""
    g = straight_colon(0.20, 0.036, 6e-3, 0.0)
    x0 = g.nodes
    times = np.linspace(0.0, 1.0, frames)
    depth = 0.15 * times
    scope = lambda d: np.column_stack([np.linspace(-0.4, 0.0, 41) + d, np.zeros(41), np.zeros(41)])
    wall = lambda t: x0 * [1.0, 1.0 + 0.1 * t, 1.0 + 0.1 * t]
    snapshots = [(t, wall(t), scope(d)) for t, d in zip(times[:-1], depth[:-1])]
    ts = pd.DataFrame({"time_s": times, "depth_m": depth, "push_force_N": 2.0 * times, "phase": "push",
                       "deformation_m": 0.0018 * times})
    model = SimpleNamespace(shell=SimpleNamespace(x0=x0, triangles=g.triangles), geometry=g)
    return SimpleNamespace(snapshots=snapshots, timeseries=ts, model=model,
                           final_shape={"colon_m": wall(1.0), "scope_m": scope(depth[-1])})


def test_the_frames_follow_the_snapshots_and_a_failing_ffmpeg_only_warns(tmp_path, monkeypatch):
    """Every snapshot and the final shape make a frame (fewer than the cap); the scope grows across
    the tube; an ffmpeg that fails leaves the GIF and no MP4, with a warning."""
    monkeypatch.setenv("PATH", f"{fake_ffmpeg(tmp_path, exit_code=1)}{os.pathsep}{os.environ['PATH']}")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        paths = write_animation(sliding_scope(), tmp_path)
    assert set(paths) == {"animation"} and not (tmp_path / MP4).exists()
    assert any(issubclass(w.category, ColonsimWarning) and "ffmpeg could not write" in str(w.message) for w in caught)
    frames, _ = frames_of(tmp_path / GIF)
    assert len(frames) == 12
    counts = [scope_pixels(f) for f in frames]
    assert counts[-1] > counts[0] + 200 and (np.diff(counts) >= -5).all(), counts


def test_a_run_without_snapshots_has_no_movie(tmp_path):
    run = sliding_scope()
    run.snapshots, run.final_shape = [], None
    with pytest.raises(ColonsimError, match="needs snapshots"):
        write_animation(run, tmp_path)
    assert not (tmp_path / GIF).exists()
