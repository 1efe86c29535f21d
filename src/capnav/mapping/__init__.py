"""Mapping stage: semantic voxel map (eq. 4-8), SG3DTracker (eq. 9-12, Algorithm 1), persistent
objects, occupancy and the ``CapNavMap`` they form."""

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
