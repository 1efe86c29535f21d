"""Per-apartment artefacts shared by every method: the product pipeline's simulated apartment
(``capnav.pipeline``: simulator, exploration stream, prior map) plus the simulator's truth that
the harness scores against. Only this side reads the truth."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from capnav.core.grid import FREE
from capnav.eval.generate import SceneTruth
from capnav.language.embedder import TextEmbedder
from capnav.pipeline.simulated import MAP_FILE, FrameList, PipelineConfig, SimScene, build_scene_map, open_sim_scene
from capnav.planning.config import PlannerConfig
from capnav.sim.navgrid import start_cells
from capnav.sim.sightline import sight_grid

__all__ = ["MAP_FILE", "FrameList", "PipelineConfig", "SceneAssets", "build_scene_map", "open_scene"]


@dataclass
class SceneAssets(SimScene):
    """One apartment, ready to evaluate in: the product's ``SimScene`` and its ``truth``."""

    truth: SceneTruth = field(kw_only=True)


def open_scene(scene_seed: int, seed: int, config: PipelineConfig, folder: Path,
               embedder: TextEmbedder | None = None) -> SceneAssets:
    """Simulator, ground truth and shared models of one apartment (no map yet: see ``prior_map``)."""
    scene = open_sim_scene(scene_seed, seed, config, folder, embedder)
    t0 = time.perf_counter()
    grid = scene.sim.nav_grid()
    nav = grid.navigable()
    margin = PlannerConfig().inflation + nav.spec.resolution
    truth = SceneTruth.from_manifest(scene.sim.manifest, nav.spec, nav.cells == FREE,
                                     sight=sight_grid(scene.sim.apartment, nav.spec),
                                     starts=start_cells(grid.clearance, (nav.cells == FREE), margin))
    timings = dict(scene.timings)
    timings["simulator"] = timings.get("simulator", 0.0) + time.perf_counter() - t0
    return SceneAssets(scene.scene_seed, scene.seed, scene.config, scene.sim, scene.embedder, scene.detector,
                       scene.folder, timings=timings, truth=truth)
