"""Arena: validation, true Betti numbers, geometry helpers, generators, GeoJSON."""

import json
import re

import numpy as np
import pytest
import shapely
from scipy import stats
from shapely.geometry import MultiPolygon, Polygon, box

from swarmtopo.arena import (
    HOLE_SHAPES,
    OUTER_SHAPES,
    Arena,
    annulus_arena,
    default_arena,
    random_arena,
    square_arena,
    two_rooms_arena,
)
from swarmtopo.errors import ArenaError, InputError, SwarmtopoError
from swarmtopo.io import read_arena, write_arena


def ring_hole(x0, y0, x1, y1):
    return box(x0, y0, x1, y1).exterior


def holes_of(arena):
    return arena.obstacles


def min_clearances(arena):
    """(smallest hole-hole distance, smallest hole-outer-wall distance) per region."""
    hole_gap, wall_gap = np.inf, np.inf
    for region in arena.regions:
        holes = [Polygon(r) for r in region.interiors]
        for i, h in enumerate(holes):
            wall_gap = min(wall_gap, region.exterior.distance(h))
            for g in holes[i + 1:]:
                hole_gap = min(hole_gap, h.distance(g))
    return hole_gap, wall_gap


# -- true Betti numbers: hand cases -------------------------------------------------------
def test_betti_of_hand_cases():
    assert square_arena(500).betti == (1, 0)
    assert square_arena(500, [box(50, 50, 150, 150), box(300, 300, 400, 450)]).betti == (1, 2)
    room_with_hole = Polygon(box(0, 0, 100, 100).exterior, [ring_hole(40, 40, 60, 60)])
    assert Arena(MultiPolygon([room_with_hole, box(200, 0, 300, 100)])).betti == (2, 1)
    assert annulus_arena(100, 80).betti == (1, 1)
    assert default_arena().betti == (1, 1)


def test_island_inside_a_hole_is_a_separate_region():
    outer = Polygon(box(0, 0, 100, 100).exterior, [ring_hole(20, 20, 80, 80)])
    island = box(40, 40, 60, 60)
    arena = Arena(MultiPolygon([outer, island]))
    assert arena.betti == (2, 1)
    assert arena.region_of([10, 50, 30], [10, 50, 30]).tolist() == [0, 1, -1]


def test_default_arena_is_the_documented_one():
    arena = default_arena()
    assert arena.bounds == (0.0, 0.0, 500.0, 500.0)
    assert arena.area == pytest.approx(500**2 - 150**2, rel=1e-12)
    (hole,) = arena.obstacles
    assert hole.bounds == (175.0, 175.0, 325.0, 325.0)


def test_annulus_area_is_that_of_the_inscribed_polygons():
    n, r_out, r_in = 128, 100.0, 70.0
    arena = annulus_arena(r_out, r_in, segments=n, center=(5, -3))
    polygon_area = 0.5 * n * np.sin(2 * np.pi / n) * (r_out**2 - r_in**2)
    assert arena.area == pytest.approx(polygon_area, rel=1e-12)
    assert arena.contains([5 + 85], [-3]).tolist() == [True]
    assert arena.contains([5], [-3]).tolist() == [False]
    assert len(arena.boundary_segments) == 2 * n


@pytest.mark.parametrize("args", [(50, 50), (50, 80), (-1, -2), (100, 50, 2)])
def test_annulus_rejects_bad_radii(args):
    r_out, r_in, *seg = args
    with pytest.raises(SwarmtopoError):
        annulus_arena(r_out, r_in, segments=seg[0] if seg else 128)


# -- validation ---------------------------------------------------------------------------
BAD_GEOMETRIES = {
    "self-intersecting ring": (Polygon([(0, 0), (10, 10), (10, 0), (0, 10)]), "crosses itself"),
    "hole outside shell": (Polygon(box(0, 0, 10, 10).exterior, [ring_hole(20, 20, 30, 30)]),
                           "hole 0 is not strictly inside"),
    "hole crossing the shell": (Polygon(box(0, 0, 10, 10).exterior, [ring_hole(5, 5, 15, 15)]),
                                "hole 0 is not strictly inside"),
    "hole touching the shell": (Polygon(box(0, 0, 10, 10).exterior, [ring_hole(0, 2, 3, 3)]),
                                "hole 0 is not strictly inside"),
    "overlapping holes": (Polygon(box(0, 0, 10, 10).exterior, [ring_hole(1, 1, 4, 4), ring_hole(3, 3, 6, 6)]),
                          "holes 0 and 1 overlap or touch"),
    "touching holes": (Polygon(box(0, 0, 10, 10).exterior, [ring_hole(1, 1, 4, 4), ring_hole(4, 4, 6, 6)]),
                       "holes 0 and 1 overlap or touch (near x=4, y=4)"),
    "overlapping regions": (MultiPolygon([box(0, 0, 10, 10), box(5, 5, 15, 15)]), "regions 0 and 1 overlap"),
    "touching regions": (MultiPolygon([box(0, 0, 10, 10), box(10, 0, 20, 10)]), "regions 0 and 1 overlap or touch"),
    "collinear shell": (Polygon([(0, 0), (1, 1), (2, 2), (0, 0)]),
                        "region 0 outer wall has zero area: its corners are collinear"),
    "collinear hole": (Polygon(box(0, 0, 10, 10).exterior, [[(1, 5), (3, 5), (8, 5), (1, 5)]]),
                       "region 0 hole 0 has zero area: its corners are collinear"),
    "two corners": (Polygon([(0, 0), (1, 1), (0, 0), (0, 0)]), "fewer than 3 distinct corners"),
}


@pytest.mark.parametrize("name", list(BAD_GEOMETRIES))
def test_invalid_geometry_raises_arena_error(name):
    geom, expected = BAD_GEOMETRIES[name]
    with pytest.raises(ArenaError) as info:
        Arena(geom, source="walls.geojson")
    message = str(info.value)
    assert expected in message
    assert message.startswith("walls.geojson: ")


def test_non_polygon_geometry_is_refused():
    with pytest.raises(ArenaError, match="expected a Polygon or MultiPolygon, got LineString"):
        Arena(shapely.LineString([(0, 0), (1, 1)]))


BAD_GEOJSON = {
    "point": ({"type": "Point", "coordinates": [0, 0]}, "geometry type 'Point' is not supported"),
    "feature with line": ({"type": "Feature", "geometry": {"type": "LineString", "coordinates": [[0, 0], [1, 1]]}},
                          "geometry type 'LineString' is not supported"),
    "no type": ({"coordinates": []}, "no 'type' member"),
    "not an object": ([1, 2], "no 'type' member"),
    "flat coordinates": ({"type": "Polygon", "coordinates": [[0, 0], [1, 1]]}, "malformed coordinates"),
    "text coordinate": ({"type": "Polygon", "coordinates": [[["a", 0], [1, 0], [1, 1], [0, 0]]]},
                        "coordinate 'a' is not a number"),
    "numeric text": ({"type": "Polygon", "coordinates": [[["0", 0], [9, 0], [9, 9], [0, 0]]]},
                     "coordinate '0' is not a number"),
    "boolean coordinate": ({"type": "Polygon", "coordinates": [[[False, 0], [9, 0], [9, 9], [0, 0]]]},
                           "coordinate False is not a number"),
    "null coordinate": ({"type": "Polygon", "coordinates": [[[None, 0], [9, 0], [9, 9], [0, 0]]]},
                        "coordinate None is not a number"),
    "feet": ({"type": "Feature", "properties": {"units": "ft"},
              "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [9, 0], [9, 9], [0, 0]]]}},
             "properties.units 'ft' is not supported; expected one of mm, cm, m"),
    "units not text": ({"type": "Feature", "properties": {"units": ["m"]},
                        "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [9, 0], [9, 9], [0, 0]]]}},
                       "properties.units ['m'] is not supported"),
    "two points": ({"type": "Polygon", "coordinates": [[[0, 0], [1, 0]]]}, "malformed coordinates"),
    "no coordinates": ({"type": "Polygon"}, "Polygon has no 'coordinates'"),
    "feature without geometry": ({"type": "Feature", "geometry": None}, "Feature has no geometry"),
    "empty collection": ({"type": "FeatureCollection", "features": []}, "holds no features"),
    "collection with a null geometry": ({"type": "FeatureCollection",
                                         "features": [{"type": "Feature", "geometry": None}]},
                                        "feature 0 has no geometry"),
    "collection with a point": ({"type": "FeatureCollection", "features": [
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": [0, 0]}}]},
        "feature 0: geometry type 'Point'"),
    "self-intersecting": ({"type": "Polygon", "coordinates": [[[0, 0], [10, 10], [10, 0], [0, 10], [0, 0]]]},
                          "crosses itself"),
    "three collinear points": ({"type": "Polygon", "coordinates": [[[0, 0], [250, 100], [500, 200], [0, 0]]]},
                               "outer wall has zero area: its corners are collinear, it encloses no area"),
}


@pytest.mark.parametrize("name", list(BAD_GEOJSON))
def test_invalid_geojson_raises_arena_error(name):
    obj, expected = BAD_GEOJSON[name]
    with pytest.raises(ArenaError) as info:
        Arena.from_geojson(obj, source="in.geojson")
    assert expected in str(info.value)
    assert info.value.file == "in.geojson"


def test_z_coordinates_and_repeated_vertices_are_dropped():
    poly = Polygon([(0, 0, 1), (10, 0, 1), (10, 0, 1), (10, 10, 1), (0, 10, 1)])
    arena = Arena(poly)
    assert not arena.geometry.has_z
    assert len(arena.boundary_segments) == 4
    seg = arena.boundary_segments
    assert np.all(np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1]) > 0)


# -- geometry helpers ---------------------------------------------------------------------
def test_boundary_segments_are_the_ring_edges_with_free_space_on_the_left():
    arena = random_arena(3, rng=4, shapes=HOLE_SHAPES)
    rings = [r for region in arena.regions for r in (region.exterior, *region.interiors)]
    assert len(arena.boundary_segments) == sum(len(r.coords) - 1 for r in rings)
    seg = arena.boundary_segments
    assert seg.flags.c_contiguous and not seg.flags.writeable
    # a point just left of each edge's midpoint is free space, just right is not
    mid = (seg[:, :2] + seg[:, 2:]) / 2
    d = seg[:, 2:] - seg[:, :2]
    left = np.column_stack([-d[:, 1], d[:, 0]]) / np.hypot(d[:, 0], d[:, 1])[:, None]
    eps = 1e-3
    assert arena.contains(*(mid + eps * left).T).all()
    assert not arena.contains(*(mid - eps * left).T).any()


def test_hand_counted_segments():
    arena = square_arena(500, [box(50, 50, 150, 150), box(300, 300, 400, 450)])
    assert arena.boundary_segments.shape == (12, 4)


def test_contains_region_of_and_distance_to_boundary():
    arena = default_arena()
    x, y = np.array([10.0, 250.0, 100.0, 600.0]), np.array([10.0, 250.0, 250.0, 250.0])
    assert arena.contains(x, y).tolist() == [True, False, True, False]
    assert arena.region_of(x, y).tolist() == [0, -1, 0, -1]
    assert arena.distance_to_boundary(x, y)[[0, 2]] == pytest.approx([10.0, 75.0])


def test_sample_uniform_is_uniform_over_the_free_space():
    """Chi-square test of counts over a 10 x 10 grid of 50 mm cells.

    Expected count of a cell = n * (free area of the cell) / (free area).  With n =
    20000 every cell that is at least half free expects >= 100 points, so the
    chi-square approximation is accurate; p > 1e-3 fails a correct sampler with
    probability 1e-3 (and the seed is fixed, so the test is deterministic).  Cells
    inside the hole must get no point at all.
    """
    arena = default_arena()
    n = 20_000
    pts = arena.sample_uniform(n, rng=12345)
    assert pts.shape == (n, 2)
    assert arena.contains(pts[:, 0], pts[:, 1]).all()
    edges = np.linspace(0, 500, 11)
    counts, _, _ = np.histogram2d(pts[:, 0], pts[:, 1], bins=[edges, edges])
    cells = shapely.box(edges[:-1, None], edges[None, :-1], edges[1:, None], edges[None, 1:])
    free = shapely.area(shapely.intersection(cells, arena.geometry))
    expected = n * free / arena.area
    has_space = free > 0
    assert counts[~has_space].sum() == 0
    chi2 = ((counts[has_space] - expected[has_space]) ** 2 / expected[has_space]).sum()
    assert stats.chi2.sf(chi2, df=has_space.sum() - 1) > 1e-3


def test_sample_uniform_clearance_is_exact_and_deterministic():
    # 50000 points put a few dozen into the slivers between the rounded corners of the
    # shrunk free space and their chords, where a buffer-only test would come too close
    arena = default_arena()
    pts = arena.sample_uniform(50_000, rng=7, clearance=40.0)
    assert arena.distance_to_boundary(pts[:, 0], pts[:, 1]).min() >= 40.0
    assert np.array_equal(pts, arena.sample_uniform(50_000, rng=7, clearance=40.0))
    with pytest.raises(ArenaError, match="no free space"):
        arena.sample_uniform(10, rng=1, clearance=200.0)
    with pytest.raises(InputError, match="number of points must be a non-negative integer"):
        arena.sample_uniform(-1)


def test_scaled():
    arena = default_arena()
    big = arena.scaled(2.0)
    assert big.betti == arena.betti
    assert big.area == pytest.approx(4 * arena.area)
    assert big.bounds == (0.0, 0.0, 1000.0, 1000.0)
    for bad in (0, -1.0, float("nan")):
        with pytest.raises(InputError, match="scale factor must be a positive finite number"):
            arena.scaled(bad)


# -- generators -----------------------------------------------------------------------------
SEEDS = range(40)


@pytest.mark.parametrize("k", [0, 1, 2, 3])
def test_random_arena_holes_count_clearance_and_containment(k):
    for seed in SEEDS:
        arena = random_arena(k, rng=seed)
        assert arena.betti == (1, k)
        assert arena.bounds == (0.0, 0.0, 500.0, 500.0)
        hole_gap, wall_gap = min_clearances(arena)
        assert hole_gap >= 60.0 - 1e-9 and wall_gap >= 60.0 - 1e-9
        shell = Polygon(arena.regions[0].exterior)
        for hole in arena.obstacles:
            assert shell.contains(hole)
            assert hole.area == pytest.approx(125.0**2)  # default size 0.25 * side, axis-aligned square
            x0, y0, x1, y1 = hole.bounds
            assert x1 - x0 == pytest.approx(125.0) and y1 - y0 == pytest.approx(125.0)


def hole_area(family, s):
    n = 64
    return {"square": s**2, "disc": 0.5 * n * np.sin(2 * np.pi / n) * (s / 2) ** 2, "L": 0.75 * s**2,
            "triangle": np.sqrt(3) / 4 * s**2, "wall": 0.1 * s**2}[family]


@pytest.mark.parametrize("outer", OUTER_SHAPES)
@pytest.mark.parametrize("family", HOLE_SHAPES)
def test_each_shape_family_and_outer_wall_gives_valid_arenas(family, outer):
    for seed in range(8):
        arena = random_arena(2, rng=seed, shapes=(family,), outer=outer)
        assert arena.betti == (1, 2)
        region = arena.regions[0]
        assert Polygon(region.exterior).area == pytest.approx(500.0**2, rel=1e-9)  # same area
        hole_gap, wall_gap = min_clearances(arena)
        assert min(hole_gap, wall_gap) >= 60.0 - 1e-9
        for hole in arena.obstacles:
            assert hole.area == pytest.approx(hole_area(family, 125.0), rel=1e-9)
        x0, y0, x1, y1 = arena.bounds
        assert (x0, y0) == pytest.approx((0.0, 0.0), abs=1e-9)
        if outer == "rectangle":
            assert 1.0 <= (x1 - x0) / (y1 - y0) <= 2.0 + 1e-12


def test_polygon_outer_walls_vary_and_are_mildly_non_convex_at_most():
    shells = [Polygon(random_arena(0, rng=s, outer="polygon").regions[0].exterior) for s in range(20)]
    corners = {len(p.exterior.coords) - 1 for p in shells}
    assert corners <= set(range(5, 10)) and len(corners) > 1
    # corner radii vary by +-20 %, so the shell keeps most of its convex hull
    assert min(p.area / p.convex_hull.area for p in shells) > 0.85


def test_mixed_shapes_draw_every_family():
    signatures = set()
    for seed in range(30):
        for hole in random_arena(3, rng=seed, shapes=HOLE_SHAPES).obstacles:
            signatures.add(round(hole.area / 125.0**2, 3))
    assert len(signatures) == len(HOLE_SHAPES)


def test_scale_multiplies_every_length():
    for seed in range(10):
        base = random_arena(2, rng=seed, shapes=HOLE_SHAPES)
        big = random_arena(2, rng=seed, shapes=HOLE_SHAPES, scale=2.5)
        assert big.area == pytest.approx(2.5**2 * base.area, rel=1e-12)
        assert big.bounds == pytest.approx(tuple(2.5 * v for v in base.bounds))
        hole_gap, wall_gap = min_clearances(big)
        assert min(hole_gap, wall_gap) >= 2.5 * 60.0 - 1e-6


def test_defaults_scale_with_side():
    arena = random_arena(1, rng=0, side=1000.0)
    (hole,) = arena.obstacles
    assert hole.area == pytest.approx(250.0**2)  # 0.25 * side
    assert min_clearances(arena)[1] >= 120.0 - 1e-9  # 0.12 * side


def test_random_arena_is_deterministic():
    a = random_arena(3, rng=99, shapes=HOLE_SHAPES, outer="polygon")
    b = random_arena(3, rng=np.random.default_rng(99), shapes=HOLE_SHAPES, outer="polygon")
    assert shapely.to_wkb(a.geometry) == shapely.to_wkb(b.geometry)
    assert a != random_arena(3, rng=100, shapes=HOLE_SHAPES, outer="polygon")


def test_impossible_request_raises_a_clear_error():
    with pytest.raises(SwarmtopoError) as info:
        random_arena(5, rng=0, max_tries=2000)
    assert str(info.value).startswith(
        "cannot place 5 holes of 125 mm with 60 mm clearance in a 500 mm square after 2000 tries")
    with pytest.raises(SwarmtopoError, match="cannot place 1 hole of 800 mm"):
        random_arena(1, rng=0, scale=2.0, hole_size=400.0, max_tries=50)


@pytest.mark.parametrize("kwargs, message", [
    ({"n_holes": -1}, "n_holes must be a non-negative integer"),
    ({"n_holes": 1.5}, "n_holes must be a non-negative integer"),
    ({"n_holes": 1, "scale": 0}, "scale must be a positive finite number"),
    ({"n_holes": 1, "side": -5}, "side must be a positive finite number"),
    ({"n_holes": 1, "shapes": ("hexagon",)}, "unknown hole shape 'hexagon'"),
    ({"n_holes": 1, "shapes": ()}, "unknown hole shape None"),
    ({"n_holes": 1, "outer": "circle"}, "unknown outer wall 'circle'"),
    ({"n_holes": 1, "clearance": -1.0}, "clearance must be a finite number >= 0"),
    ({"n_holes": 1, "hole_size": float("inf")}, "hole_size must be a positive finite number"),
])
def test_random_arena_rejects_bad_arguments(kwargs, message):
    with pytest.raises(SwarmtopoError, match=re.escape(message)):
        random_arena(**kwargs)


def test_two_rooms():
    arena = two_rooms_arena(rng=1)
    assert arena.betti == (2, 0)
    a, b = arena.regions
    assert a.distance(b) == pytest.approx(100.0)
    for seed in range(10):
        arena = two_rooms_arena(rng=seed, n_holes=3, scale=1.5)
        assert arena.betti == (2, 3)
        assert [len(r.interiors) for r in arena.regions] == [2, 1]
        assert min(min_clearances(arena)) >= 1.5 * 60.0 - 1e-6
        assert arena.area == pytest.approx(1.5**2 * (2 * 500.0**2 - 3 * 125.0**2))
    assert [len(r.interiors) for r in two_rooms_arena(rng=0, n_holes=(0, 2), gap=40).regions] == [0, 2]
    with pytest.raises(SwarmtopoError, match="in a 500 mm square room"):
        two_rooms_arena(n_holes=(5, 0), rng=0, max_tries=200)


def test_square_arena_with_bad_holes():
    with pytest.raises(ArenaError, match="holes 0 and 1 overlap"):
        square_arena(500, [box(10, 10, 100, 100), box(50, 50, 150, 150)])


# -- GeoJSON ------------------------------------------------------------------------------------
def roundtrip(arena):
    return Arena.from_geojson(json.loads(json.dumps(arena.to_geojson())))


def test_geojson_round_trip_of_generated_arenas():
    for arena in (default_arena(), random_arena(3, rng=5, shapes=HOLE_SHAPES, outer="polygon"),
                  two_rooms_arena(rng=2, n_holes=2), annulus_arena(100, 90)):
        back = roundtrip(arena)
        assert back == arena and back.betti == arena.betti
        assert np.array_equal(back.boundary_segments, arena.boundary_segments)


def test_geojson_input_kinds():
    shell = [[0, 0], [100, 0], [100, 100], [0, 100], [0, 0]]
    hole = [[40, 40], [40, 60], [60, 60], [60, 40], [40, 40]]
    room2 = [[200, 0], [300, 0], [300, 100], [200, 100], [200, 0]]
    polygon = {"type": "Polygon", "coordinates": [shell, hole]}
    multi = {"type": "MultiPolygon", "coordinates": [[shell, hole], [room2]]}
    feature = {"type": "Feature", "properties": {}, "geometry": multi}
    collection = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": polygon},
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [room2]}}]}
    assert Arena.from_geojson(polygon).betti == (1, 1)
    two = Arena.from_geojson(multi)
    assert two.betti == (2, 1)
    assert Arena.from_geojson(feature) == two
    assert Arena.from_geojson(collection) == two
    assert roundtrip(two) == two


def test_geojson_file_round_trip(tmp_path):
    for i, arena in enumerate((default_arena(), two_rooms_arena(rng=3, n_holes=1))):
        path = write_arena(arena, tmp_path / f"a{i}.geojson")
        assert read_arena(path) == arena
    collection = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "properties": {}, "geometry": {"type": "Polygon", "coordinates": [
            [[0, 0], [10, 0], [10, 10], [0, 10], [0, 0]]]}}]}
    (tmp_path / "fc.geojson").write_text(json.dumps(collection))
    assert read_arena(tmp_path / "fc.geojson").betti == (1, 0)
    (tmp_path / "bad.geojson").write_text(json.dumps({"type": "Point", "coordinates": [0, 0]}))
    with pytest.raises(ArenaError) as info:
        read_arena(tmp_path / "bad.geojson")
    assert info.value.file == str(tmp_path / "bad.geojson")


@pytest.mark.parametrize("units, mm", [("mm", 1.0), ("cm", 10.0), ("m", 1000.0)])
def test_geojson_units_are_converted_to_mm(units, mm):
    square = [[[0, 0], [0.5, 0], [0.5, 0.5], [0, 0.5], [0, 0]]]
    feature = {"type": "Feature", "properties": {"units": units}, "geometry": {"type": "Polygon", "coordinates": square}}
    arena = Arena.from_geojson(feature)
    assert arena.area == pytest.approx(0.25 * mm ** 2) and arena.bounds == pytest.approx((0, 0, 0.5 * mm, 0.5 * mm))
    collection = {"type": "FeatureCollection", "features": [feature]}
    assert Arena.from_geojson(collection) == arena
    # units set once on the collection hold for its features that set none, not for one that does
    bare = {"type": "Feature", "geometry": {"type": "Polygon", "coordinates": square}}
    assert Arena.from_geojson({**collection, "features": [bare], "properties": {"units": units}}) == arena
    assert Arena.from_geojson({**collection, "properties": {"units": "cm" if units == "m" else "m"}}) == arena


def test_a_nan_coordinate_is_refused_without_a_shapely_warning(recwarn):
    with pytest.raises(ArenaError, match="non-finite coordinate"):
        Arena.from_geojson({"type": "Polygon", "coordinates": [[[0, 0], [9, 0], [9, float("nan")], [0, 9], [0, 0]]]})
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_narrow_passages_are_the_hole_gaps_below_the_width():
    holes = [box(5, 200, 105, 300), box(200, 200, 300, 300), box(315, 200, 415, 300)]
    arena = Arena(Polygon(box(0, 0, 500, 500).exterior, [h.exterior for h in holes]))
    assert arena.narrow_passages(30.0) == ["region 0: hole 0 is 5 mm from the outer wall",
                                           "region 0: hole 2 is 15 mm from hole 1"]
    assert arena.narrow_passages(10.0) == ["region 0: hole 0 is 5 mm from the outer wall"]
    assert arena.narrow_passages(5.0) == [] and square_arena(500.0).narrow_passages(1e6) == []


def test_a_room_inside_a_hole_is_drawn_as_free_space():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from swarmtopo.viz.plots import plot_arena

    arena = Arena(MultiPolygon([Polygon(box(0, 0, 600, 600).exterior, [box(150, 150, 450, 450).exterior]),
                                box(250, 250, 350, 350)]))
    fig, ax = plt.subplots(figsize=(4, 4), dpi=50)
    plot_arena(arena, ax)
    ax.set_axis_off()
    ax.set_position([0, 0, 1, 1])
    ax.set_xlim(0, 600)
    ax.set_ylim(0, 600)
    fig.canvas.draw()
    pixels = np.asarray(fig.canvas.buffer_rgba())[..., :3] / 255.0
    plt.close(fig)

    def grey_at(x, y):  # data (mm) -> pixel; the image's rows run top-down
        h, w = pixels.shape[:2]
        return pixels[int((1 - y / 600) * (h - 1)), int(x / 600 * (w - 1))].mean()

    assert grey_at(300, 300) == pytest.approx(0.93, abs=0.02)  # the island: free space
    assert grey_at(200, 300) == pytest.approx(0.45, abs=0.02)  # the hole round it
    assert grey_at(75, 75) == pytest.approx(0.93, abs=0.02)  # the outer room
