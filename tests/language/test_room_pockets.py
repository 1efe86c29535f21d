"""A small pocket of free space must take the room it opens into, never the room across a wall.

Failure class (the demo apartment with pooled sightings): a plant stands in a pocket between a
wall, the end of a bookshelf and a sofa's back. The only way out of the pocket is a strip behind
the sofa that no frame saw (UNKNOWN cells), so the pocket is a component of the walkable domain
of its own, reached from no room core; its cells got no room, and the only labelled cells in the
plant's ring were the next room's, across the wall."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.language.rooms import object_region, room_regions, segment_rooms, walkable_domain

RES = 0.05


def _two_rooms(neck: bool) -> tuple[OccupancyGrid, NDArray[np.float64], NDArray[np.float64]]:
    """Room A (rows 1-57) and room B (rows 60-98) of a 6 x 5 m flat, a wall (rows 58-59) with a
    doorway at its east end. In A's north-west corner a pocket (rows 43-57, cols 1-14) is closed
    by a bookshelf's end (row 42, occupied outside every box) and a sofa's back (col 17); between
    the pocket and the sofa a strip nobody saw (cols 15-16, UNKNOWN) leads out into A.
    ``neck``: that strip is seen (the sofa's back) and the pocket opens into A through one cell of
    the bookshelf's end row instead (a neck narrower than any robot)."""
    rows, cols = 100, 120
    c = np.full((rows, cols), FREE, dtype=np.uint8)
    c[0, :] = c[-1, :] = OCCUPIED
    c[:, 0] = c[:, -1] = OCCUPIED
    c[58:60, :100] = OCCUPIED                # the wall, a doorway at cols 100-118
    c[42, 1:15] = OCCUPIED                    # the bookshelf's end
    c[41:58, 17] = OCCUPIED                   # the sofa's back
    c[41:58, 15:17] = UNKNOWN                 # the strip behind the sofa nobody saw
    c[52:58, 2:9] = OCCUPIED                  # the plant
    if neck:
        c[41:58, 15:17] = OCCUPIED            # the strip seen: the sofa's back
        c[42, 11] = FREE                      # a one-cell gap in it
    spec = GridSpec(0.0, 0.0, RES, rows, cols)
    # Boxes (x, y): the plant, and the sofa (cols 18-40, its back at col 17 lies outside its box).
    lo = np.array([[0.10, 2.60], [0.90, 2.05]])
    hi = np.array([[0.44, 2.89], [2.00, 2.85]])
    return OccupancyGrid(spec, c), lo, hi


def _room_of(labels: NDArray[np.int32], r: int, c: int) -> int:
    return int(labels[r, c])


def test_a_pocket_reached_only_through_unseen_cells_takes_the_room_it_opens_into() -> None:
    occ, lo, hi = _two_rooms(neck=False)
    labels = room_regions(occ, lo, hi)
    a, b = _room_of(labels, 20, 60), _room_of(labels, 80, 60)
    assert a >= 0 and b >= 0 and a != b
    assert labels[50, 10] == a                       # a pocket cell
    assert object_region(labels, occ.spec, lo[0], hi[0]) == a  # the plant: not room B across the wall


def test_without_the_unseen_cells_the_pocket_is_no_room() -> None:
    """The walkable domain alone leaves the pocket unreached (what the fix is for)."""
    occ, lo, hi = _two_rooms(neck=False)
    labels = segment_rooms(walkable_domain(occ, lo, hi), occ.spec)
    assert labels[50, 10] == -1


def test_a_pocket_joined_by_a_one_cell_neck_is_part_of_its_room_not_a_room() -> None:
    occ, lo, hi = _two_rooms(neck=True)
    labels = room_regions(occ, lo, hi)
    a = _room_of(labels, 20, 60)
    assert labels[50, 10] == a
    assert object_region(labels, occ.spec, lo[0], hi[0]) == a
    assert len(set(np.unique(labels)) - {-1}) == 2   # the pocket forms no room of its own


def test_object_region_does_not_count_a_room_across_a_wall() -> None:
    """An object in a shallow alcove: few of its own room's cells in its ring, many of the next
    room's beyond a wall (cells -1). Only cells joined to the object's own cells vote."""
    spec = GridSpec(0.0, 0.0, RES, 40, 40)
    labels = np.full((40, 40), -1, dtype=np.int32)
    labels[22:40, :] = 1                          # room 1, beyond the wall (rows 20-21)
    labels[14:20, 12:20] = 0                      # the alcove of room 0 the object stands in
    labels[:10, :] = 0                            # room 0 itself, joined to the alcove below
    labels[10:14, 14:18] = 0
    lo, hi = np.array([0.62, 0.72]), np.array([0.98, 0.99])  # cols 12-19, rows 14-19
    assert object_region(labels, spec, lo, hi) == 0
