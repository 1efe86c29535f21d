"""Mapping stage: semantic voxel map (eq. 4-8), SG3DTracker (eq. 9-12, Algorithm 1), persistent
objects, occupancy and the ``CapNavMap`` they form.

Names are imported on first use (PEP 562): reading a map file needs ``CapNavMap`` and the object
types, not the mapper, tracker and detectors (numba, scipy, the perception stage: about 1 s of a
one-shot ``capnav query``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.core.lazy import lazy_exports

if TYPE_CHECKING:
    from capnav.mapping.cmap import CapNavMap
    from capnav.mapping.lifting import (
        LiftConfig,
        LiftedDetection,
        depth_consistent,
        indexed_descriptor,
        lift_detection,
        mask_descriptor,
        outline_visibility,
    )
    from capnav.mapping.mapper import Mapper, MapperConfig, build_map
    from capnav.mapping.memory import MemoryConfig, ObjectMemory
    from capnav.mapping.objects import MapObject, ObjectView, Observation
    from capnav.mapping.occupancy import OccupancyConfig, occupancy_from_voxels
    from capnav.mapping.stream import map_dataset
    from capnav.mapping.tracker import SG3DTracker, Track, TrackerConfig, TrackerStep
    from capnav.mapping.voxel_map import VoxelConfig, VoxelMap, radial_weight, random_projection

#: Public name -> the submodule that defines it.
_SOURCES = {
    "CapNavMap": "cmap",
    **dict.fromkeys(["LiftConfig", "LiftedDetection", "depth_consistent", "indexed_descriptor", "lift_detection",
                     "mask_descriptor", "outline_visibility"], "lifting"),
    **dict.fromkeys(["Mapper", "MapperConfig", "build_map"], "mapper"),
    **dict.fromkeys(["MemoryConfig", "ObjectMemory"], "memory"),
    **dict.fromkeys(["MapObject", "ObjectView", "Observation"], "objects"),
    **dict.fromkeys(["OccupancyConfig", "occupancy_from_voxels"], "occupancy"),
    "map_dataset": "stream",
    **dict.fromkeys(["SG3DTracker", "Track", "TrackerConfig", "TrackerStep"], "tracker"),
    **dict.fromkeys(["VoxelConfig", "VoxelMap", "radial_weight", "random_projection"], "voxel_map"),
}

__getattr__, __dir__ = lazy_exports(__name__, _SOURCES)


__all__ = [
    "CapNavMap",
    "LiftConfig",
    "LiftedDetection",
    "MapObject",
    "Mapper",
    "MapperConfig",
    "MemoryConfig",
    "ObjectMemory",
    "ObjectView",
    "Observation",
    "OccupancyConfig",
    "SG3DTracker",
    "Track",
    "TrackerConfig",
    "TrackerStep",
    "VoxelConfig",
    "VoxelMap",
    "build_map",
    "depth_consistent",
    "indexed_descriptor",
    "lift_detection",
    "map_dataset",
    "mask_descriptor",
    "occupancy_from_voxels",
    "outline_visibility",
    "radial_weight",
    "random_projection",
]
