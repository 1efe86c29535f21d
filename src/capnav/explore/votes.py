"""Is a goal sighting outvoted by the sightings around it? One confused view must not send the robot.

A detector that confuses a desk with a table, or an armchair with a chair, does so in a minority
of the views of that thing: the sightings near a candidate, weighted by confidence, vote for the
goal's labels or for others, and a candidate whose neighbourhood votes mostly for other labels
is a confusion.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from capnav.explore.sighting import Sighting


def outvoted(cands: Sequence[Sighting], pool: Sequence[Sighting], is_goal: Callable[[list[str]], NDArray[np.bool_]],
             radius: float) -> NDArray[np.bool_]:
    """For each candidate: do the sightings of ``pool`` within ``radius`` of it vote more (summed
    score) for labels ``is_goal`` rejects than for the goal's?"""
    pxy = np.array([s.xy for s in pool], dtype=np.float64).reshape(-1, 2)
    w = np.array([s.score for s in pool], dtype=np.float64)
    goal = np.asarray(is_goal([s.label for s in pool]), dtype=bool).reshape(-1)
    cxy = np.array([s.xy for s in cands], dtype=np.float64).reshape(-1, 2)
    near = ((cxy[:, None, :] - pxy[None, :, :]) ** 2).sum(-1) <= radius**2  # (C, P)
    for_goal = (near * (w * goal)[None, :]).sum(axis=1)
    against = (near * (w * ~goal)[None, :]).sum(axis=1)
    return np.asarray(against > for_goal)
