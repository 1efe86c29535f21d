"""``CapNavMap``: everything a map file holds and every later stage reads."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import NotFoundError
from capnav.core.grid import OccupancyGrid
from capnav.mapping.objects import MapObject
from capnav.mapping.voxel_map import VoxelMap


@dataclass
class CameraTrajectory:
    """Where the camera was: ``frames`` (N,) indices of the frames fused, ``poses`` (N, 4, 4) their
    camera-to-world poses, in order. Planning on a map of a recording starts from it and treats the
    floor under it as free (the camera went there)."""

    frames: NDArray[np.int64]
    poses: NDArray[np.float64]

    def __post_init__(self) -> None:
        self.frames = np.asarray(self.frames, dtype=np.int64).reshape(-1)
        self.poses = np.asarray(self.poses, dtype=np.float64).reshape(-1, 4, 4)
        if len(self.frames) != len(self.poses):
            raise ValueError(f"trajectory has {len(self.frames)} frame indices for {len(self.poses)} poses")

    def __len__(self) -> int:
        return len(self.frames)


@dataclass
class CapNavMap:
    """Persistent objects, the semantic voxel map, the top-down occupancy, metadata (JSON-able:
    frames used and skipped, configuration, dataset path, detector / encoder ids) and ``caches``
    (JSON-able dicts owned by later stages, e.g. caption and verification caches)."""

    objects: list[MapObject]
    voxels: VoxelMap
    occupancy: OccupancyGrid
    meta: dict[str, Any] = field(default_factory=dict)
    caches: dict[str, dict[str, Any]] = field(default_factory=dict)
    trajectory: CameraTrajectory | None = None  # None in maps written before it was recorded
    # Objects whose place a later recording observed empty (``capnav map --update``): kept with when
    # they were last seen, never returned as present; ``objects`` holds only present ones.
    retired: list[MapObject] = field(default_factory=list)

    def object(self, object_id: int) -> MapObject:
        for o in self.objects:
            if o.id == object_id:
                return o
        raise NotFoundError(f"no object with id {object_id} in the map (ids: {[o.id for o in self.objects]})")

    def by_label(self, label: str) -> list[MapObject]:
        return [o for o in self.objects if o.label == label]

    def __repr__(self) -> str:
        return (f"CapNavMap({len(self.objects)} objects, {len(self.voxels)} voxels, "
                f"occupancy {self.occupancy.spec.rows}x{self.occupancy.spec.cols})")
