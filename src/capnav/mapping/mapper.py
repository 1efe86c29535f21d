"""The mapping pipeline: frame -> detections (overlaps of one thing merged, ``frame_merge``) + dense
features -> voxel fusion (eq. 4-8) and lifted detections -> SG3DTracker (Algorithm 1) -> persistent
objects -> ``CapNavMap``."""

from __future__ import annotations

import logging
import re
import time
from collections.abc import Iterable
from dataclasses import asdict, dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import FrameError, InputError
from capnav.core.frame import Frame
from capnav.core.progress import track
from capnav.mapping.box_carving import CarveConfig, DepthViews
from capnav.mapping.cmap import CameraTrajectory, CapNavMap
from capnav.mapping.frame_merge import FrameMergeConfig, merge_frame_detections
from capnav.mapping.lifting import LiftConfig, LiftedDetection, lift_detection
from capnav.mapping.memory import MemoryConfig, ObjectMemory
from capnav.mapping.motion import PoseJumps, find_pose_jumps
from capnav.mapping.objects import Observation
from capnav.mapping.occupancy import OccupancyConfig, occupancy_from_voxels
from capnav.mapping.tracker import SG3DTracker, TrackerConfig
from capnav.mapping.voxel_map import VoxelConfig, VoxelMap, random_projection
from capnav.perception.base import DenseFeatureEncoder, Detection, Detector, needs_truth_error, validate_detections

log = logging.getLogger(__name__)


@dataclass
class MapperConfig:
    """All mapping parameters, paper values as defaults where the paper gives them.

    ``on_bad_frame``: "skip" records the frame and the reason in ``meta["frames_skipped"]`` and
    goes on (one bad frame in 10,000 should not lose a map); "raise" stops with ``FrameError``.
    A detector that raises on a frame does not lose it: under "skip" the frame's depth is fused
    without detections, the tracker does not see the frame (no detections is not evidence of
    absence), and the failure is counted per kind in ``meta["detector_errors"]``.
    Frames with more than ``max_invalid_depth`` invalid depth pixels count as bad. A camera that
    moves more than ``max_pose_jump`` and more than ``pose_jump_factor`` times the stream's usual
    step between consecutive used frames is listed in ``meta["pose_jumps"]`` and named in one
    warning (a dropped stretch of frames or a wrong pose convention shows up there; a stream kept
    sparse on purpose does not: ``capnav.mapping.motion``).
    """

    voxel: VoxelConfig = field(default_factory=VoxelConfig)
    tracker: TrackerConfig = field(default_factory=TrackerConfig)
    memory: MemoryConfig = field(default_factory=MemoryConfig)
    occupancy: OccupancyConfig = field(default_factory=OccupancyConfig)
    lift: LiftConfig = field(default_factory=LiftConfig)
    frame_merge: FrameMergeConfig = field(default_factory=FrameMergeConfig)
    carve: CarveConfig = field(default_factory=CarveConfig)
    on_bad_frame: Literal["skip", "raise"] = "skip"
    max_invalid_depth: float = 0.98
    max_pose_jump: float = 1.5  # m between consecutive frames; a shorter move is never reported as a jump
    pose_jump_factor: float = 4.0  # x the stream's usual step; longer moves are reported, not skipped

    def __post_init__(self) -> None:
        if self.on_bad_frame not in ("skip", "raise"):
            raise InputError(f"on_bad_frame must be 'skip' or 'raise', got {self.on_bad_frame!r}")

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


class Mapper:
    """Incremental mapper: ``integrate(frame)`` per frame, ``finish()`` once."""

    def __init__(self, config: MapperConfig | None, detector: Detector, encoder: DenseFeatureEncoder) -> None:
        self.config = config or MapperConfig()
        self.detector = detector
        self.encoder = encoder
        vc = self.config.voxel
        d_in = int(encoder.dim)
        if d_in <= 0:
            raise InputError(f"encoder {encoder.id} reports feature dim {d_in}")
        proj = None
        if vc.feature_dim is not None and vc.feature_dim < d_in:
            proj = random_projection(d_in, vc.feature_dim, vc.projection_seed)
        self.voxels = VoxelMap(vc.resolution, vc.grid_origin, proj.shape[1] if proj is not None else d_in, proj,
                               encoder.text_space)
        self.tracker = SG3DTracker(self.config.tracker)
        self.memory = ObjectMemory(self.config.memory)
        self.views = DepthViews(self.config.carve)  # small depth of the observed frames, for box_carving
        self.carved_points = 0
        self._views_cap = 64
        self.frames_used: list[int] = []
        self.skipped: list[dict[str, Any]] = []
        self.detector_errors: dict[str, dict[str, Any]] = {}
        self.lift_skips = 0
        self.frame_merges = 0
        self.camera_path: list[tuple[int, NDArray[np.float64]]] = []  # (frame index, T_wc) of every frame fused
        self.seconds = 0.0

    def _bad(self, err: FrameError) -> bool:
        if self.config.on_bad_frame == "raise":
            raise err
        self.record_skip(err.frame, err.reason)
        return False

    def _detector_failed(self, frame: int, err: Exception) -> None:
        """Count a detector failure by kind (type + reason, numbers blanked); log each kind once."""
        reason = err.reason if isinstance(err, FrameError) else str(err)
        kind = f"{type(err).__name__}: {re.sub(r'[0-9]+', '#', reason)}"
        entry = self.detector_errors.get(kind)
        if entry is None:
            log.warning("frame %s: the detector failed (%s: %s); mapping its depth without detections",
                        frame, type(err).__name__, reason)
            self.detector_errors[kind] = {"kind": kind, "count": 1, "first_frame": frame, "example": reason}
        else:
            entry["count"] += 1

    def record_skip(self, frame: int | str, reason: str) -> None:
        """Note a frame that could not be used (also for frames a reader failed to load)."""
        log.warning("skipping frame %s: %s", frame, reason)
        self.skipped.append({"frame": frame, "reason": reason})

    def integrate(self, frame: Frame) -> bool:
        """Fuse one frame; returns False when it was skipped (see ``MapperConfig.on_bad_frame``)."""
        t0 = time.perf_counter()
        try:
            frame.validate(max_invalid_fraction=self.config.max_invalid_depth)
        except FrameError as e:
            return self._bad(e)
        if self.detector.needs_truth and frame.gt_instance is None and not self.frames_used:
            raise needs_truth_error(self.detector, f"frame {frame.index}")  # a stream of real frames
        try:
            weak_on = self.config.tracker.weak_h_min > 0
            found = self.detector.detect_candidates(frame) if weak_on else self.detector.detect(frame)
            dets = validate_detections(frame, found)
            dets, n_merged = merge_frame_detections(dets, self.config.frame_merge)
            self.frame_merges += n_merged
        except Exception as e:  # any detector failure: the frame's geometry still counts
            if self.config.on_bad_frame == "raise":
                raise
            self._detector_failed(frame.index, e)
            dets = None
        confident = [d for d in dets or [] if not d.weak]
        try:
            # The voxels' features come from the confident detections only; the weak candidates'
            # own descriptors (for association) from a second encoding with them painted in.
            grid, table = self._encode(frame, confident)
        except FrameError as e:
            return self._bad(e)
        self.camera_path.append((int(frame.index), np.asarray(frame.T_wc, dtype=np.float64).copy()))
        vc = self.config.voxel
        proj = self.voxels.project(table) if self.voxels.projection is not None else table
        self.voxels.integrate_frame(frame.depth, frame.rgb, frame.K, frame.T_wc, grid, proj, vc.sigma,
                                    vc.max_depth, vc.pixel_stride)
        if dets is not None:  # a frame the detector failed on is no evidence that objects are gone
            if len(confident) < len(dets):
                try:
                    grid, table = self._encode(frame, dets)
                except FrameError as e:  # the frame is fused already: go on with its confident detections
                    log.warning("frame %s: %s; its low-score candidates are dropped", frame.index, e.reason)
                    dets = confident
            lifted: list[LiftedDetection] = []
            for k, d in enumerate(dets):
                ld = lift_detection(frame, d, k, grid, table, self.config.lift)
                if ld is None:
                    self.lift_skips += 1
                    continue
                lifted.append(ld)
            self._track(frame, lifted)
            if lifted and self.config.carve.enabled:
                self.views.add(frame.index, frame.depth, frame.K, frame.T_wc)
                if len(self.views.views) >= self._views_cap:  # forget the frames no observation keeps
                    self.views.keep_only(self.memory.observed_frames())
                    self._views_cap = max(64, 2 * len(self.views.views))
        self.frames_used.append(frame.index)
        self.seconds += time.perf_counter() - t0
        return True

    def _encode(self, frame: Frame, dets: list[Detection]) -> tuple[NDArray[np.int64], NDArray[np.float32]]:
        grid, table = self.encoder.encode_indexed(frame, dets)
        grid = np.asarray(grid, dtype=np.int64)
        table = np.asarray(table, dtype=np.float32)
        if table.ndim != 2 or table.shape[1] != self.encoder.dim or grid.ndim != 2:
            raise FrameError(frame.index, f"encoder returned grid {grid.shape} / table {table.shape}, "
                                          f"expected (H', W') / (M, {self.encoder.dim})")
        if grid.size == 0 or grid.min() < 0 or grid.max() >= len(table):
            raise FrameError(frame.index, "encoder feature grid indexes outside its table")
        if not np.all(np.isfinite(table)):
            raise FrameError(frame.index, "encoder returned non-finite features")
        return grid, table

    def _track(self, frame: Frame, lifted: list[LiftedDetection]) -> None:
        step = self.tracker.update(lifted)
        h_min = self.config.tracker.h_min
        busy = {t.object_id for t, _ in step.matches if t.object_id is not None}
        for t, i in step.matches + step.births:
            d = lifted[i]
            obs = Observation(frame_index=frame.index, box=tuple(float(x) for x in d.box),  # type: ignore[arg-type]
                              mask_area=d.detection.area, score=float(d.detection.score), label=d.detection.label,
                              distance=d.distance, truncated=d.truncated, visibility=d.visibility)
            own = t.object_id
            oid = self.memory.observe(t, d, obs, frame.index, h_min, busy - {own} if own is not None else busy,
                                      self.config.tracker)
            if oid is not None:
                busy.add(oid)
        for t in step.deaths:
            self.memory.drop(t)

    def pose_jumps(self) -> PoseJumps:
        """The camera moves so far that are much longer than this stream's usual step."""
        idx = [i for i, _ in self.camera_path]
        eyes = [T[:3, 3] for _, T in self.camera_path]
        return find_pose_jumps(idx, eyes, self.config.max_pose_jump, self.config.pose_jump_factor)

    def finish(self, meta: dict[str, Any] | None = None) -> CapNavMap:
        """Merge duplicates, export objects, derive occupancy; ``meta`` adds/overrides metadata."""
        if self.config.carve.enabled:
            self.views.keep_only(self.memory.observed_frames())
            self.carved_points = self.memory.carve(self.views)
        merged = self.memory.merge_duplicates()
        objects = self.memory.export()
        eyes = np.array([T[:2, 3] for _, T in self.camera_path]).reshape(-1, 2)
        occ = occupancy_from_voxels(self.voxels, self.config.occupancy, cover=eyes)
        jumps = self.pose_jumps()
        if jumps.jumps:
            log.warning(jumps.message())
        info: dict[str, Any] = {
            "frames_used": len(self.frames_used),
            "first_frame": self.frames_used[0] if self.frames_used else None,
            "last_frame": self.frames_used[-1] if self.frames_used else None,
            "frames_skipped": list(self.skipped),
            "detector_errors": list(self.detector_errors.values()),
            "pose_jumps": jumps.jumps,
            "detections_without_depth": self.lift_skips,
            "tracks": self.tracker._next_id - 1,
            "merged_duplicates": merged,
            "carved_points": self.carved_points,
            "merged_in_frame": self.frame_merges,
            "relinked_detections": self.memory.relinks,
            "weak_confirmed_tracks": self.memory.weak_confirmed,
            "shape_confirmed_tracks": self.memory.shape_confirmed,
            "relabelled_by_size": list(self.memory.relabelled),
            "detector": self.detector.id,
            "encoder": self.encoder.id,
            "text_space": self.encoder.text_space,
            "config": self.config.to_dict(),
        }  # no wall-clock time here: the same input gives the same map file, byte for byte (self.seconds)
        labels = getattr(self.detector, "labels", None)
        if labels is not None:  # a closed vocabulary: what the map can never contain is known
            info["detector_labels"] = sorted(labels)
        info.update(meta or {})
        path = (CameraTrajectory(np.array([i for i, _ in self.camera_path]), np.stack([T for _, T in self.camera_path]))
                if self.camera_path else None)
        return CapNavMap(objects=objects, voxels=self.voxels, occupancy=occ, meta=info, trajectory=path)


def build_map(frames: Iterable[Frame], config: MapperConfig | None = None, detector: Detector | None = None,
              encoder: DenseFeatureEncoder | None = None, progress: bool = True, total: int | None = None,
              meta: dict[str, Any] | None = None) -> CapNavMap:
    """Map a whole stream. Defaults: the simulator detector (default noise, seed 0) and the
    label-embedding encoder over MiniLM."""
    from capnav.perception import create_detector, create_encoder

    det = detector or create_detector("sim", noise="default", seed=0)
    enc = encoder or create_encoder("label-embedding")
    mapper = Mapper(config, det, enc)
    for f in track(frames, "mapping", total=total, enabled=progress):
        mapper.integrate(f)
    return mapper.finish(meta)
