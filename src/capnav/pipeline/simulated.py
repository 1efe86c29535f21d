"""One simulated apartment, ready to map: simulator, exploration stream, the map and the models.

The exploration stream is regenerated deterministically from (scene seed, settings) when needed;
the map (tracked objects, captions, embeddings, voxels, occupancy) is built ONCE per apartment
and cached in the run folder, keyed by the settings that made it and by the apartment's manifest
(only hashed, to notice a changed simulator), so every map-based method of a run, and every
rerun, uses the identical map. (A change to the mapping code itself is not detected: delete
``scenes/*/map.capnav`` after one.)
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from capnav.core.errors import CapNavError
from capnav.core.frame import Frame
from capnav.language.embedder import TextEmbedder
from capnav.mapping.cmap import CapNavMap
from capnav.perception.base import Detector
from capnav.sim import CameraConfig, ExploreConfig, SimConfig, Simulator, explore
from capnav.sim.config import house_config

MAP_FILE = "map.capnav"


@dataclass(frozen=True)
class PipelineConfig:
    """How each apartment is observed and mapped (the offline defaults of the benchmark)."""

    width: int = 320  # camera image size (pixels)
    height: int = 240
    max_frames: int | None = None  # subsample the exploration stream (None: all, ~200-400 frames)
    detector: str = "sim"
    detector_noise: str = "default"  # the sim detector's noise preset (other detectors ignore it)
    detector_options: tuple[tuple[str, Any], ...] = ()  # backend settings of a real detector (model_dir, ...)
    furniture: str = "primitives"  # or "sh3d": Sweet Home 3D meshes (``capnav assets``)
    size: str = "default"  # house size preset (capnav.sim.config.HOUSE_SIZES): default or large
    encoder: str = "label-embedding"
    embedder: str = "minilm"
    captioner: str = "offline"
    verifier: str = "offline"

    def sim_config(self) -> SimConfig:
        return house_config(self.size, SimConfig(camera=CameraConfig(width=self.width, height=self.height),
                                                 furniture=self.furniture))

    @property
    def track(self) -> str:
        """The perception track a result belongs to: house size, furniture and detector (with its noise)."""
        det = f"{self.detector}:{self.detector_noise}" if self.detector == "sim" else self.detector
        return f"{self.size} houses, {self.furniture} furniture, {det} detector"

    def explore_config(self, seed: int) -> ExploreConfig:
        return ExploreConfig(seed=seed, max_frames=self.max_frames)

    def map_key(self, scene_seed: int, seed: int) -> str:
        """What the cached map depends on; a cached map with another key is rebuilt."""
        blob = json.dumps({"scene": scene_seed, "seed": seed, **asdict(self)}, sort_keys=True)
        return hashlib.sha256(blob.encode()).hexdigest()[:16]


class FrameList:
    """An in-memory exploration stream with the reader interface (``len``, ``frame(i)``, iteration)."""

    def __init__(self, frames: list[Frame]) -> None:
        self.frames = frames

    def __len__(self) -> int:
        return len(self.frames)

    def frame(self, index: int) -> Frame:
        return self.frames[index]

    def __iter__(self) -> Iterator[Frame]:
        return iter(self.frames)


@dataclass
class SimScene:
    """One apartment and the shared models. ``frames`` and ``cmap`` are filled lazily
    (``stream()``, ``prior_map()``)."""

    scene_seed: int
    seed: int
    config: PipelineConfig
    sim: Simulator
    embedder: TextEmbedder
    detector: Detector
    folder: Path
    cmap: CapNavMap | None = None
    frames: FrameList | None = None
    timings: dict[str, float] = field(default_factory=dict)

    def stream(self) -> FrameList:
        """The shared exploration stream (regenerated deterministically on first use)."""
        if self.frames is None:
            t0 = time.perf_counter()
            self.frames = FrameList(list(explore(self.sim, self.config.explore_config(self.seed))))
            self.timings["explore"] = self.timings.get("explore", 0.0) + time.perf_counter() - t0
        return self.frames

    def prior_map(self) -> CapNavMap:
        """The apartment's map, loaded from the run folder or built (then saved) from the stream."""
        if self.cmap is None:
            self.cmap = _cached_map(self)
        return self.cmap


def open_sim_scene(scene_seed: int, seed: int, config: PipelineConfig, folder: Path,
                   embedder: TextEmbedder | None = None) -> SimScene:
    """Simulator and shared models of one apartment (no map yet: see ``prior_map``)."""
    from capnav.language import create_embedder
    from capnav.perception import create_detector

    t0 = time.perf_counter()
    sim = Simulator.from_seed(scene_seed, config.sim_config())
    emb = embedder or create_embedder(config.embedder)
    det = create_detector(config.detector, noise=config.detector_noise, seed=seed) if config.detector == "sim" \
        else create_detector(config.detector, **dict(config.detector_options))
    folder.mkdir(parents=True, exist_ok=True)
    return SimScene(scene_seed, seed, config, sim, emb, det, folder, timings={"simulator": time.perf_counter() - t0})


def _cached_map(scene: SimScene) -> CapNavMap:
    from capnav.io.mapfile import load_map, save_map

    path = scene.folder / MAP_FILE
    # the apartment itself is part of the key: a changed simulator makes a different apartment
    # from the same seed, and a map of the old one must not be scored against the new truth
    apartment = hashlib.sha256(scene.sim.manifest.model_dump_json().encode()).hexdigest()[:16]
    key = f"{scene.config.map_key(scene.scene_seed, scene.seed)}-{apartment}"
    if path.is_file():
        try:
            cmap = load_map(path)
            if cmap.meta.get("eval_key") == key:
                return cmap
        except CapNavError:
            pass  # a stale or damaged cache is rebuilt below
    cmap = build_scene_map(scene)
    cmap.meta["eval_key"] = key
    # float32 features: a rerun from the cache scores exactly what the first run scored
    save_map(cmap, path, feature_dtype="float32")
    return cmap


def build_scene_map(scene: SimScene) -> CapNavMap:
    """Map the exploration stream with the shared detector, then caption and embed every object."""
    from capnav.language.captioner import create_captioner
    from capnav.language.describe import describe_map
    from capnav.mapping.mapper import build_map
    from capnav.perception import create_encoder

    frames = scene.stream()
    t0 = time.perf_counter()
    enc = create_encoder(scene.config.encoder, embedder=scene.embedder)
    cmap = build_map(iter(frames), detector=scene.detector, encoder=enc, progress=False, total=len(frames),
                     meta={"scene_seed": scene.scene_seed, "source": "capnav eval exploration stream"})
    t1 = time.perf_counter()
    describe_map(cmap, frames, create_captioner(scene.config.captioner), scene.embedder, progress=False)
    t2 = time.perf_counter()
    scene.timings["map"] = t1 - t0
    scene.timings["caption"] = t2 - t1
    return cmap
