"""Success regions: distance from the agent's stop point to an instance's 2D footprint.

VLMaps and the paper count a subgoal as reached when the agent stops within 1 m of the 2D
footprint of a goal instance; a point inside the footprint has distance 0.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from capnav.core.footprint import footprint_distance

SUCCESS_RADIUS_M = 1.0


def distance_to_instances(xy: Sequence[float] | NDArray[np.floating],
                          footprints: Sequence[NDArray[np.floating]]) -> float:
    """Distance (m) from one point to the nearest of several footprints (inf if there are none)."""
    p = np.asarray(xy, dtype=np.float64).reshape(1, 2)
    if not footprints:
        return float("inf")
    return float(min(footprint_distance(p, np.asarray(f))[0] for f in footprints))


def is_success(xy: Sequence[float] | NDArray[np.floating], footprints: Sequence[NDArray[np.floating]],
               radius: float = SUCCESS_RADIUS_M) -> bool:
    return distance_to_instances(xy, footprints) <= radius


def room_index(xy: Sequence[float] | NDArray[np.floating], rooms: Sequence[NDArray[np.floating]]) -> int:
    """Index of the room polygon holding ``xy`` (-1 in none, e.g. a doorway, or without rooms): the
    "in the object's room" rule of the benchmark and the demo."""
    p = np.asarray(xy, dtype=np.float64).reshape(1, 2)
    return next((k for k, poly in enumerate(rooms) if footprint_distance(p, np.asarray(poly))[0] == 0.0), -1)
