"""Generated apartments: rooms, plausible non-intersecting placement, reachability, lookalikes."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from capnav.core.categories import NAMES
from capnav.core.errors import InputError
from capnav.sim import LayoutConfig, SimConfig
from capnav.sim.apartment import REACH_RADIUS, generate_apartment
from capnav.sim.navgrid import NavGrid
from capnav.sim.primitives import SPECS, build_model
from capnav.sim.shapes import RectSet, rects_overlap

SEEDS = [0, 1, 2, 3, 11]


@pytest.fixture(scope="module", params=SEEDS)
def apt(request: pytest.FixtureRequest):  # type: ignore[no-untyped-def]
    return generate_apartment(request.param, SimConfig())


def test_room_count_and_types(apt) -> None:  # type: ignore[no-untyped-def]
    m = apt.manifest
    assert 3 <= len(m.rooms) <= 7
    assert {r.name for r in m.rooms} <= {"living room", "kitchen", "bedroom", "bathroom", "office", "hallway"}
    assert "living room" in {r.name for r in m.rooms}
    assert len(m.doors) >= len(m.rooms) - 1  # a spanning tree of doors at least


def test_objects_do_not_intersect_and_stay_in_their_room(apt) -> None:  # type: ignore[no-untyped-def]
    objs = apt.objects
    for i, a in enumerate(objs):
        r = apt.plan.rooms[a.room]
        fp = a.footprint()
        assert fp[:, 0].min() >= r.x0 - 1e-6 and fp[:, 0].max() <= r.x1 + 1e-6
        assert fp[:, 1].min() >= r.y0 - 1e-6 and fp[:, 1].max() <= r.y1 + 1e-6
        for b in objs[i + 1:]:
            assert not rects_overlap(fp, b.footprint()), (a.category, b.category)
    # and not into the walls: every footprint keeps out of the wall slabs
    fps = np.concatenate([o.footprint() for o in objs])
    assert apt.wall_rects.min_distance(fps).min() >= -1e-6


def test_every_instance_reachable(apt) -> None:  # type: ignore[no-untyped-def]
    cfg = apt.config
    grid = NavGrid(apt.obstacles(), apt.bounds, cfg.agent.radius, 0.05)
    free = grid.free_points()
    for o in apt.objects:
        rs = RectSet.from_lists([(o.x, o.y)], [o.model.size[:2]], [o.yaw])
        assert rs.min_distance(free).min() <= REACH_RADIUS, f"{o.category} {o.id} unreachable"


def test_some_category_has_three_instances_with_distinct_looks(apt) -> None:  # type: ignore[no-untyped-def]
    counts = Counter(o.category for o in apt.manifest.objects)
    assert max(counts.values()) >= 3
    # lookalikes differ: some multi-instance category has two colours, shapes or sizes
    differ = False
    for cat, n in counts.items():
        if n >= 2:
            inst = apt.manifest.by_category(cat)
            looks = {(o.color_name, o.shape, tuple(round(s, 2) for s in o.size)) for o in inst}
            differ |= len(looks) >= 2
    assert differ


def test_manifest_fields_consistent(apt) -> None:  # type: ignore[no-untyped-def]
    m = apt.manifest
    ids = [o.id for o in m.objects]
    assert ids == list(range(1, len(ids) + 1))
    room_ids = {r.id for r in m.rooms}
    for o in m.objects:
        assert o.category in NAMES and o.room in room_ids
        fp = np.asarray(o.footprint)
        area = 0.5 * abs(np.dot(fp[:, 0], np.roll(fp[:, 1], 1)) - np.dot(fp[:, 1], np.roll(fp[:, 0], 1)))
        assert area == pytest.approx(o.size[0] * o.size[1], rel=1e-6)
        assert o.center[2] == pytest.approx(o.size[2] / 2)


def test_categories_across_seeds_cover_most_of_the_vocabulary() -> None:
    seen = set()
    for s in range(8):
        seen |= {o.category for o in generate_apartment(s, SimConfig()).objects}
    assert len(seen) >= 20, sorted(set(NAMES) - seen)


def test_every_category_and_variant_builds() -> None:
    rng = np.random.default_rng(0)
    assert set(SPECS) == set(NAMES)
    for cat, spec in SPECS.items():
        for v in spec.variants:
            m = build_model(cat, rng, variant=v)
            assert m.parts and all(s > 0 for s in m.size)
            lo = np.min([np.subtract(p.center, np.divide(p.size, 2)) for p in m.parts], axis=0)
            hi = np.max([np.add(p.center, np.divide(p.size, 2)) for p in m.parts], axis=0)
            assert lo[2] >= -1e-9  # nothing below the floor
            np.testing.assert_allclose((lo[:2] + hi[:2]) / 2, 0.0, atol=1e-9)  # footprint centred


def test_bigger_scale_gives_bigger_model() -> None:
    rng = np.random.default_rng(0)
    small = build_model("sofa", rng, variant="straight", scale=0.8)
    big = build_model("sofa", rng, variant="straight", scale=1.25)
    assert big.size[0] > small.size[0] + 0.5


def test_bad_seeds_and_room_counts_rejected() -> None:
    for bad in (-1, 2**32, 1.5, "3", True):
        with pytest.raises(InputError):
            generate_apartment(bad, SimConfig())  # type: ignore[arg-type]
    with pytest.raises(InputError):
        LayoutConfig(rooms=17)
    with pytest.raises(InputError):
        LayoutConfig(rooms=2)


@pytest.mark.parametrize("rooms", [3, 7])
def test_room_count_is_honoured(rooms: int) -> None:
    apt = generate_apartment(5, SimConfig(layout=LayoutConfig(rooms=rooms)))
    assert len(apt.manifest.rooms) == rooms


def test_many_seeds_generate() -> None:
    # seed 45 once hit a floating-point edge case in door placement
    for s in range(40, 52):
        apt = generate_apartment(s, SimConfig())
        assert apt.objects and len(apt.plan.doors) >= len(apt.plan.rooms) - 1


def test_placement_is_plausible(apt) -> None:  # type: ignore[no-untyped-def]
    walls = apt.wall_rects
    rooms = {r.id: r.name for r in apt.manifest.rooms}
    for o in apt.objects:
        if o.category in ("bed", "wardrobe", "bookshelf", "refrigerator", "toilet", "tv", "counter"):
            # the back edge (local -y) touches a wall slab
            c, s = np.cos(o.yaw), np.sin(o.yaw)
            back = np.array([o.x, o.y]) - (o.model.size[1] / 2) * np.array([-s, c])
            assert walls.min_distance(back[None])[0] < 0.03, (o.category, o.id)
        room = rooms[f"room{o.room}"]
        if o.category in ("toilet", "bathtub"):
            assert room == "bathroom"
        if o.category == "bed":
            assert room == "bedroom"
        if o.category == "nightstand":  # beside a bed
            beds = [b for b in apt.objects if b.category == "bed"]
            fp = RectSet.from_lists([(b.x, b.y) for b in beds], [b.model.size[:2] for b in beds], [b.yaw for b in beds])
            assert fp.min_distance(o.footprint()).min() < 0.1


@pytest.mark.parametrize("seed", [0, 3])
def test_the_large_house_preset(seed: int) -> None:
    """Near Matterport scale: 8-14 rooms with hallways, 120-250 m2, 60-150 objects, at most 6 of a
    kind, every object reachable (within 1 m of a navigable cell); the default preset is unchanged."""
    from collections import Counter

    from capnav.sim.config import house_config

    cfg = house_config("large")
    apt = generate_apartment(seed, cfg)
    b = apt.plan.bounds
    counts = Counter(o.category for o in apt.objects)
    assert 8 <= len(apt.plan.rooms) <= 14 and "hallway" in apt.plan.types
    assert 120 <= b.w * b.h <= 250
    assert 60 <= len(apt.objects) <= 150
    assert max(counts.values()) <= 6 and sum(v >= 4 for v in counts.values()) >= 3
    grid = NavGrid(apt.obstacles(), apt.bounds, cfg.agent.radius, cfg.nav_resolution)
    pts = grid.free_points()
    for o in apt.objects:  # the agent's centre can get within REACH_RADIUS of the object's footprint
        rs = RectSet.from_lists([(o.x, o.y)], [o.model.size[:2]], [o.yaw])
        assert rs.min_distance(pts).min() <= REACH_RADIUS, (o.id, o.category)
    assert house_config("default") == SimConfig()
    with pytest.raises(InputError):
        house_config("huge")
