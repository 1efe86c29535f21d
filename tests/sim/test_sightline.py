"""The strict success rule's line of sight: walls and tall objects block it, doorways and low
furniture do not, and the object's own footprint never does."""

from __future__ import annotations

import numpy as np

from capnav.core.grid import GridSpec
from capnav.sim.shapes import RectSet
from capnav.sim.sightline import SightGrid

SPEC = GridSpec.covering(0.0, 0.0, 6.0, 4.0, 0.05)
LAMP = np.array([[4.0, 1.8], [4.4, 1.8], [4.4, 2.2], [4.0, 2.2]])  # 0.4 m square at x 4.0-4.4


def _wall_x3(door: tuple[float, float] | None) -> RectSet:
    """A 0.1 m thick wall along x = 3 over y 0-4, with an optional opening (y0, y1)."""
    if door is None:
        return RectSet.from_lists([(3.0, 2.0)], [(0.1, 4.0)], [0.0])
    y0, y1 = door
    return RectSet.from_lists([(3.0, y0 / 2), (3.0, (y1 + 4.0) / 2)], [(0.1, y0), (0.1, 4.0 - y1)], [0.0, 0.0])


def test_a_wall_between_agent_and_object_blocks_the_sight() -> None:
    g = SightGrid.from_scene(SPEC, _wall_x3(None), [])
    assert not g.sees((2.6, 2.0), LAMP, own_ids=(7,))  # 0.4 m from the wall, 1.4 m from the lamp: hidden
    assert g.sees((3.6, 2.0), LAMP, own_ids=(7,))  # same side as the lamp


def test_an_open_doorway_does_not_block() -> None:
    g = SightGrid.from_scene(SPEC, _wall_x3((1.5, 2.5)), [])
    assert g.sees((2.6, 2.0), LAMP, own_ids=(7,))  # looking through the 1 m opening
    # Beside the opening, the wall hides a lamp pressed against its far side.
    low = np.array([[3.1, 0.2], [3.5, 0.2], [3.5, 0.6], [3.1, 0.6]])
    assert not g.sees((2.5, 0.4), low, own_ids=(7,))


def test_tall_objects_block_low_ones_do_not_and_the_target_never_blocks_itself() -> None:
    walls = RectSet.from_lists([], [], [])
    wardrobe = (3, RectSet.from_lists([(3.0, 2.0)], [(0.6, 2.0)], [0.0]), 2.0)
    table = (4, RectSet.from_lists([(3.0, 2.0)], [(0.6, 2.0)], [0.0]), 0.75)
    assert not SightGrid.from_scene(SPEC, walls, [wardrobe]).sees((1.5, 2.0), LAMP, own_ids=(7,))
    assert SightGrid.from_scene(SPEC, walls, [table]).sees((1.5, 2.0), LAMP, own_ids=(7,))
    lamp_self = (7, RectSet.from_lists([(4.2, 2.0)], [(0.4, 0.4)], [0.0]), 1.6)
    assert SightGrid.from_scene(SPEC, walls, [lamp_self]).sees((3.5, 2.0), LAMP, own_ids=(7,))
    beside = (5, RectSet.from_lists([(3.0, 3.5)], [(0.6, 0.6)], [0.0]), 2.0)  # tall, but off the line
    assert SightGrid.from_scene(SPEC, walls, [beside]).sees((1.5, 2.0), LAMP, own_ids=(7,))
