"""The wall-stretch map (colonsim.insertion.case.stretch_map): its values against a closed form,
its choice of the samples A and C, its unrolling, and the stretched area both ways."""

import numpy as np
import pandas as pd
import pytest

from colonsim.catalog import COLUMNS, STRETCHED_WALL_COLUMN, STRETCHED_WALL_THRESHOLD
from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.colon_segments import straight_colon
from colonsim.insertion.case.outcomes import characteristic_points, principal_stretches
from colonsim.insertion.case.stretch_figure import stretch_map_figure, unrolled_polygons
from colonsim.insertion.case.stretch_map import (FIELDS, WallStretch, area_above, check_threshold, read_stretch_map,
                                                 stretched_area_section, unrolled_nodes, write_stretch_map,
                                                 write_stretch_vtu)
from colonsim.insertion.engine.shell_membrane import reference_frames

D, LENGTH, H, FIXED = 0.036, 0.20, 5e-3, 0.03


@pytest.fixture(scope="module")
def tube():
    """A 20 cm straight tube along +x, its first and last 3 cm held."""
    g = straight_colon(LENGTH, D, H, 0.0, fixed_length=FIXED)
    dm_inv, area = reference_frames(g.nodes, g.triangles)
    return g, dm_inv, area


def inflated(nodes, stretch):
    """The tube inflated uniformly: every point moved radially from the axis by ``stretch``. Every
    chord across the axis grows by ``stretch`` and every axial one keeps its length, so each flat
    triangle's largest in-plane stretch is exactly ``stretch`` (a chord between two nodes of one
    ring lies in every triangle)."""
    x = nodes.copy()
    x[:, 1:] *= stretch
    return x


def record(g, dm_inv, stretches, deformation):
    """A WallStretch fed the inflated tube at each of ``stretches`` with these deformations."""
    tracker = WallStretch(g.triangles, dm_inv, g.fixed | g.end_ring)
    for lam, u in zip(stretches, deformation):
        x = np.ascontiguousarray(inflated(g.nodes, lam) if lam != 1.0 else g.nodes)
        tracker.sample(principal_stretches(x, tracker.triangles, tracker.dm_inv), u)
    return tracker


def series(deformation):
    n = len(deformation)
    return pd.DataFrame({"time_s": np.arange(n) * 1e-3, "depth_m": np.arange(n) * 1e-4, "deformation_m": deformation})


def test_a_uniformly_inflated_tube_is_stretched_alike_everywhere(tube):
    """Every free triangle takes the inflation's stretch, the held ones stay at 1; the map keeps
    the largest over the run and the fields of the samples A, C and the end."""
    g, dm_inv, _ = tube
    # deformation rises to A (sample 3), falls to B (5), rises to C (8), and settles lower
    u = np.array([0.0, 1.0, 2.0, 3.0, 2.0, 1.0, 2.0, 2.5, 2.8, 2.6, 2.6])
    lam = 1.0 + 0.05 * u  # the inflation follows the deformation: 1.15 at A, 1.14 at C
    tracker = record(g, dm_inv, lam, u)
    fields = tracker.fields(series(u))
    points = characteristic_points(np.arange(len(u)), np.arange(len(u)), u)
    assert (points["A"]["time_s"], points["C"]["time_s"]) == (3, 8)
    free = ~(g.fixed | g.end_ring)[g.triangles].all(axis=1)
    assert free.sum() > 1000 and (~free).sum() > 100
    for name, value in (("max", lam.max()), ("A", lam[3]), ("C", lam[8]), ("end", lam[-1])):
        assert fields[name][free] == pytest.approx(value, abs=1e-12), name
        assert fields[name][~free] == pytest.approx(1.0)


def test_a_curve_without_point_a_gives_nan_there(tube):
    g, dm_inv, _ = tube
    u = np.array([0.0, 1.0, 2.0, 3.0, 3.5])
    fields = record(g, dm_inv, 1.0 + 0.02 * u, u).fields(series(u))
    assert np.isnan(fields["A"]).all() and not np.isnan(fields["C"]).any()
    assert fields["C"].max() == pytest.approx(1.07, abs=1e-12)


def test_only_samples_that_can_still_be_a_or_c_are_kept():
    """A long noisy rise keeps a handful of fields, not one per wiggle, and still finds A and C."""
    rng = np.random.default_rng(0)
    n = 3000
    trend = np.concatenate([np.linspace(0, 2, 1000), np.linspace(2, 1, 500), np.linspace(1, 3, 1500)])
    u = trend + 0.002 * rng.standard_normal(n)
    tracker = WallStretch(np.array([[0, 1, 2]]), np.zeros((1, 2, 2)), np.zeros(3, dtype=bool))
    for k in range(n):
        tracker.sample(np.array([float(k)]), u[k])
    assert len(tracker._candidates) < 60
    points = characteristic_points(np.arange(n) * 1e-3, np.arange(n), u)
    fields = tracker.fields(series(u))
    for name in ("A", "C"):
        assert fields[name][0] == pytest.approx(round(points[name]["time_s"] * 1e3))


def test_the_kept_samples_are_those_characteristic_points_chooses():
    """On random walks (rounded, so plateaus occur) the fields at A and C are those of the samples
    :func:`characteristic_points` names (on a plateau: its first sample, whose deformation is the same)."""
    rng = np.random.default_rng(1)
    for trial in range(300):
        n = int(rng.integers(3, 120))
        u = np.round(np.abs(np.cumsum(rng.standard_normal(n))), 1 if trial % 2 else 6)
        tracker = WallStretch(np.array([[0, 1, 2]]), np.zeros((1, 2, 2)), np.zeros(3, dtype=bool))
        for k in range(n):
            tracker.sample(np.array([float(k)]), u[k])
        points = characteristic_points(np.arange(n) * 1e-3, np.arange(n), u)
        fields = tracker.fields(series(u))
        for name in ("A", "C"):
            if points[name] is None:
                assert np.isnan(fields[name]).all()
                continue
            chosen = round(points[name]["time_s"] * 1e3)
            kept = int(fields[name][0])
            assert kept <= chosen and u[kept] == u[chosen] and (u[kept:chosen + 1] == u[chosen]).all(), (trial, name)


def test_the_map_unrolls_a_marked_element_where_it_lies(tube):
    """A triangle marked on the wall lands in the map at its position along the tube and its angle
    around it: 10 cm in, and 90 deg from a triangle a quarter turn away, 180 from the opposite one."""
    g, _, area = tube
    axial, angle = unrolled_nodes(g, g.nodes)
    assert axial == pytest.approx(g.nodes[:, 0], abs=3e-4)  # the centerline is the x axis
    centroids = g.nodes[g.triangles].mean(axis=1)

    def at(direction):
        return int(np.argmin(np.linalg.norm(centroids - np.array([0.10, *(0.5 * D * np.array(direction))]), axis=1)))

    marked, quarter, opposite = at((1.0, 0.0)), at((0.0, 1.0)), at((-1.0, 0.0))
    stretch = np.ones(len(g.triangles))
    stretch[marked] = 1.5
    arrays = {"triangles": g.triangles, "axial_m": axial, "angle_deg": angle, "stretch_max": stretch,
              "held": (g.fixed | g.end_ring)[g.triangles].all(axis=1), "touched": np.zeros(len(g.triangles), bool),
              "area_m2": area, "flexure_names": np.array([], dtype=str), "flexure_m": np.zeros((0, 2))}
    polygons, owner = unrolled_polygons(arrays)
    centre = {k: polygons[np.flatnonzero(owner == k)[0]].mean(axis=0) for k in (marked, quarter, opposite)}
    assert centre[marked][0] == pytest.approx(10.0, abs=H * 100)
    turn = (centre[quarter][1] - centre[marked][1]) % 360.0
    assert min(turn, 360.0 - turn) == pytest.approx(90.0, abs=360.0 / (np.pi * D / H))
    assert (centre[opposite][1] - centre[marked][1]) % 360.0 == pytest.approx(180.0, abs=360.0 / (np.pi * D / H))
    # the figure colours the marked triangle with the largest value, at that place
    fig = stretch_map_figure(arrays)
    drawn = fig.axes[0].collections[0]
    hottest = np.argmax(drawn.get_array())
    assert drawn.get_paths()[hottest].vertices[:3].mean(axis=0) == pytest.approx(centre[marked], abs=1e-6)
    # the seam is covered: every angle band of the map has a triangle
    assert polygons[:, :, 1].min() <= -180.0 and polygons[:, :, 1].max() >= 180.0


def test_the_stretched_area_comes_out_both_ways(tube):
    """The area above the threshold is the free wall's area when the whole free wall passes it,
    and nothing when none does; the threshold is checked."""
    g, dm_inv, area = tube
    tracker = record(g, dm_inv, [1.0, 1.15], [0.0, 1.0])
    largest = tracker.full(tracker.largest)
    free_cm2 = area[largest > 1.0].sum() * 1e4
    assert free_cm2 == pytest.approx(np.pi * (D + 0.0) * (LENGTH - 2 * FIXED) * 1e4, rel=0.05)
    below = stretched_area_section(largest, area, STRETCHED_WALL_THRESHOLD)
    assert below[STRETCHED_WALL_COLUMN] == pytest.approx(free_cm2)
    assert below["wall_stretch"]["threshold"] == STRETCHED_WALL_THRESHOLD
    assert stretched_area_section(largest, area, 1.2)[STRETCHED_WALL_COLUMN] == 0.0
    assert area_above(largest, area, 1.149) == pytest.approx(free_cm2)
    for bad in (1.0, 2.5, float("nan")):
        with pytest.raises(ColonsimError, match="stretch threshold"):
            check_threshold(bad)
    assert COLUMNS[STRETCHED_WALL_COLUMN].unit == "cm2" and COLUMNS[STRETCHED_WALL_COLUMN].label


def test_the_map_files_keep_every_field(tube, tmp_path):
    """The NPZ reads back unchanged; the VTU holds each field as cell data of the rest mesh."""
    meshio = pytest.importorskip("meshio")
    g, dm_inv, area = tube
    tracker = record(g, dm_inv, [1.0, 1.2, 1.1], [0.0, 2.0, 1.0])
    fields = tracker.fields(series(np.array([0.0, 2.0, 1.0])))
    arrays = {**{f"stretch_{k}": fields[k].astype(np.float32) for k in FIELDS}, "triangles": g.triangles.astype(np.int32),
              "held": (g.fixed | g.end_ring)[g.triangles].all(axis=1), "touched": np.zeros(len(g.triangles), bool)}
    write_stretch_map(arrays, tmp_path)
    back = read_stretch_map(tmp_path)
    assert set(back) == set(arrays) and all(np.array_equal(back[k], arrays[k], equal_nan=True) for k in arrays)
    write_stretch_vtu(arrays, g.nodes, tmp_path / "colon_stretch.vtu")
    mesh = meshio.read(tmp_path / "colon_stretch.vtu")
    assert mesh.cells_dict["triangle"].shape == g.triangles.shape
    assert mesh.cell_data["stretch_max"][0].max() == pytest.approx(1.2, abs=1e-6)
    assert mesh.cell_data["stretch_A"][0].max() == pytest.approx(1.2, abs=1e-6)
    assert mesh.cell_data["stretch_end"][0].max() == pytest.approx(1.1, abs=1e-6)


def test_the_surrogate_fits_the_stretched_area():
    """The column is a surrogate target (``--targets wall_area_stretched_cm2``): a sweep's table
    carrying it trains a model of it."""
    from colonsim.surrogate.model import SweepSurrogate
    from colonsim.surrogate.synthetic import synthetic_sweep

    table = synthetic_sweep(n_runs=30, segments=("rsj",))
    table[STRETCHED_WALL_COLUMN] = 40.0 * table["final_deformation_cm"]
    model = SweepSurrogate(targets=(STRETCHED_WALL_COLUMN,), random_state=0).fit(table)
    cv = model.cv_["rsj"][STRETCHED_WALL_COLUMN]
    assert cv["n"] == 29 and cv["rmse"] < 0.1 * table[STRETCHED_WALL_COLUMN].std()
