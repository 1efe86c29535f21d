"""A detection lifted to the floor plane: what an exploring robot remembers of a sighting.

No object map is built: a sighting is one detection's label, score and robust 3D centre (the
median of its mask's back-projected depth, eq. 2-3) together with where it was seen from.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from capnav.core.frame import Frame
from capnav.core.geometry import backproject
from capnav.perception.base import Detection


@dataclass(frozen=True)
class Sighting:
    label: str
    score: float
    xy: tuple[float, float]  # median of the mask's points on the floor plane (m)
    z: float  # median height (m)
    distance: float  # camera centre to that point (m)
    frame_index: int
    camera_xy: tuple[float, float]
    #: CIELAB of the mask's colours with a fifth of its pixels or more, largest share first (only
    #: when lifted with ``colours``).
    colours: tuple[tuple[float, float, float], ...] = ()


def lift(frame: Frame, detections: Sequence[Detection], min_points: int = 10,
         max_distance: float = 6.0, colours: bool = False) -> list[Sighting]:
    """Sightings of ``detections`` with enough valid depth in their masks; others are dropped
    (a mask over invalid depth gives no place to go). ``colours``: also the mask pixels' dominant
    colours (clusters of at least a fifth of the pixels, the largest first: "the plant in the
    blue pot" names a part), for a goal that names a colour."""
    out: list[Sighting] = []
    cam = np.asarray(frame.T_wc, dtype=np.float64)[:3, 3]
    for d in detections:
        pts, _ = backproject(frame.depth, frame.K, frame.T_wc, mask=d.mask)
        if len(pts) < min_points:
            continue
        c = np.median(pts.astype(np.float64), axis=0)
        dist = float(np.linalg.norm(c - cam))
        if dist > max_distance:
            continue
        labs: tuple[tuple[float, float, float], ...] = ()
        if colours:
            from capnav.language.colors import object_colors

            cols = object_colors(frame.rgb[d.mask].reshape(-1, 3))
            labs = tuple(k.lab for i, k in enumerate(cols) if i == 0 or k.fraction >= 0.2)
        out.append(Sighting(d.label, float(d.score), (float(c[0]), float(c[1])), float(c[2]), dist,
                            int(frame.index), (float(cam[0]), float(cam[1])), labs))
    return out
