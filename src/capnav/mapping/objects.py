"""Persistent object instances: what the map remembers about each physical object.

This is the contract between mapping (which fills geometry, label votes and observations),
language (which fills views, caption and embedding) and retrieval/planning (which read them).
Add fields freely; do not rename or remove them without updating every stage.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray


@dataclass
class Observation:
    """One sighting of an object in one frame (kept bounded per object by the mapper)."""

    frame_index: int
    box: tuple[float, float, float, float]  # x0, y0, x1, y1 pixels
    mask_area: int  # pixels
    score: float  # detector confidence
    label: str  # detector label in that frame
    distance: float  # camera centre to the object's lifted centroid (m)
    truncated: bool  # the box touches the image border
    visibility: float = 1.0  # estimated unoccluded fraction in [0, 1]


@dataclass
class ObjectView:
    """A view chosen for captioning (language stage)."""

    frame_index: int
    box: tuple[float, float, float, float]
    score: float  # view-selection score (higher is better)
    frame_png: bytes = b""  # full frame with the box drawn, as the paper's prompt expects
    crop_png: bytes = b""  # tight crop with a small margin


@dataclass
class MapObject:
    """A persistent 3D instance with its language entry."""

    id: int
    label: str  # current category estimate (majority of label votes)
    label_votes: dict[str, float]  # label -> accumulated detector confidence x m² of surface seen
    position: NDArray[np.float64]  # (3,) world centroid (m)
    extent_min: NDArray[np.float64]  # (3,) world axis-aligned box
    extent_max: NDArray[np.float64]  # (3,)
    footprint: NDArray[np.float64]  # (K, 2) convex hull of the points in world x, y
    points: NDArray[np.float32]  # (N, 3) bounded sample of fused surface points
    colors: NDArray[np.uint8]  # (N, 3) RGB of those points
    feature: NDArray[np.float32]  # (D,) mean instance descriptor (eq. 10, EMA)
    hits: int = 0
    first_frame: int = 0
    last_frame: int = 0
    observations: list[Observation] = field(default_factory=list)
    views: list[ObjectView] = field(default_factory=list)
    caption: str | None = None
    caption_source: str | None = None  # backend id, or "fallback: <reason>"
    embedding: NDArray[np.float32] | None = None  # (E,) L2-normalised (eq. 14)
    embedding_model: str | None = None
    category_id: int = 0  # vocabulary id of ``label`` (0 = outside the vocabulary)
    track_ids: list[int] = field(default_factory=list)  # SG3DTracker tracks fused into this object
    # Over several recordings (``capnav map --update``): where and when it was last seen
    # ({"recording", "frame", "timestamp"}; None = in the map's only recording, at ``last_frame``)
    # and its changes ({"recording", "event": born | moved | retired, "position", ...}), oldest first.
    last_seen: dict[str, Any] | None = None
    history: list[dict[str, Any]] = field(default_factory=list)

    @property
    def size(self) -> NDArray[np.float64]:
        return np.asarray(self.extent_max - self.extent_min, dtype=np.float64)

    @property
    def xy(self) -> NDArray[np.float64]:
        return np.asarray(self.position[:2], dtype=np.float64)
