"""Map a dataset folder: the reader's per-frame failures become named skips, not a lost map."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from capnav.core.errors import FrameError
from capnav.core.limits import check_count
from capnav.core.progress import track
from capnav.io.dataset import DatasetReader
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.mapper import Mapper, MapperConfig
from capnav.perception.base import DenseFeatureEncoder, Detector, needs_truth_error


def map_dataset(path: str | Path | DatasetReader, detector: Detector, encoder: DenseFeatureEncoder,
                config: MapperConfig | None = None, max_frames: int | None = None, progress: bool = True
                ) -> CapNavMap:
    """Build a map from a ``capnav-rgbd`` dataset folder (``capnav.io.dataset``) or its reader."""
    check_count("max_frames", max_frames, optional=True)
    reader = path if isinstance(path, DatasetReader) else DatasetReader(path)
    path = reader.path
    if detector.needs_truth and not reader.has_gt:
        raise needs_truth_error(detector, str(path))
    n = len(reader) if max_frames is None else min(len(reader), max_frames)
    cfg = config or MapperConfig()
    if 0 < n < cfg.tracker.h_min:
        # A recording of n frames shows an object at most n times: asking for more sightings than
        # there are frames would drop every object of a short (e.g. one-frame) recording.
        cfg = dataclasses.replace(cfg, tracker=dataclasses.replace(cfg.tracker, h_min=n))
    mapper = Mapper(cfg, detector, encoder)
    for i in track(range(n), "mapping", total=n, enabled=progress):
        try:
            frame = reader.frame(i)
        except FrameError as e:
            if mapper.config.on_bad_frame == "raise":
                raise
            mapper.record_skip(i, e.reason)
            continue
        mapper.integrate(frame)
    # What the map was made from, so caption / map-eval / navigate can refuse another apartment's data.
    meta: dict[str, Any] = {"dataset": str(Path(path).resolve()), "dataset_frames": len(reader),
                            "dataset_id": reader.fingerprint(), "h_min_used": cfg.tracker.h_min}
    producer = reader.meta.get("meta") or {}
    if producer.get("source") == "capnav.sim" and isinstance(producer.get("seed"), int):
        meta["scene_seed"] = producer["seed"]  # lets `capnav navigate` drive in the same apartment
    return mapper.finish(meta)
