"""Record an apartment's exploration pass to a dataset folder (what ``capnav sim`` runs)."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from capnav.core.atomic import atomic_dir
from capnav.core.progress import track
from capnav.io.dataset import DatasetWriter, check_dataset_target
from capnav.sim.config import CameraConfig, DepthNoiseConfig, LayoutConfig, SimConfig
from capnav.sim.explore import ExploreConfig, plan_exploration
from capnav.sim.simulator import Simulator


def record_dataset(seed: int, out: str | Path, frames: int | None = None, stride: int = 1, width: int = 320,
                   height: int = 240, hfov: float = 90.0, rooms: int | None = None, furniture: str = "primitives",
                   depth_noise: bool = False, overwrite: bool = False, progress: bool = True,
                   config: SimConfig | None = None, assets_dir: str | Path | None = None,
                   surface_items: bool = False) -> str:
    """Build apartment ``seed``, render its exploration pass into ``out``; returns a one-line summary.

    Writes ``out/manifest.json`` (scene truth, for evaluation) and ``out/topdown.png`` beside the frames.
    ``surface_items`` puts 1-3 small things (cups, books, a laptop...) on each table, counter and
    shelf piece (``capnav.sim.surface_items``); the apartment's furniture stays the same.
    """
    from capnav.viz.scene import draw_scene

    out = Path(out)
    check_dataset_target(out, overwrite)
    base = config if config is not None else SimConfig()
    cfg = replace(base, camera=replace(base.camera, width=width, height=height, hfov_deg=hfov)
                  if config is not None else CameraConfig(width=width, height=height, hfov_deg=hfov),
                  layout=LayoutConfig(rooms=rooms) if rooms is not None else base.layout,
                  depth_noise=DepthNoiseConfig(enabled=True, seed=seed) if depth_noise else base.depth_noise,
                  furniture=furniture, assets_dir=str(assets_dir) if assets_dir is not None else base.assets_dir)
    if surface_items:
        cfg = replace(cfg, furnish=replace(cfg.furnish, surface_items=(1, 3)))
    t0 = time.perf_counter()
    with Simulator.from_seed(seed, cfg) as sim:
        t_build = time.perf_counter() - t0
        poses = plan_exploration(sim, ExploreConfig(seed=seed, stride=stride, max_frames=frames))
        meta = {"source": "capnav.sim", "seed": seed, "furniture": furniture, "rooms": len(sim.manifest.rooms),
                "objects": len(sim.manifest.objects), "depth_noise": depth_noise, "exploration": "capnav.sim.explore"}
        if sim.manifest.items:  # only then: default datasets keep their meta.json bytes
            meta["surface_items"] = len(sim.manifest.items)
        t1 = time.perf_counter()
        # Built in a temporary sibling and swapped in whole: an interrupted --overwrite keeps the old one.
        with atomic_dir(out, overwrite=overwrite) as tmp:
            with DatasetWriter(tmp, sim.intrinsics, meta) as writer:
                for i, T in enumerate(track(poses, f"rendering seed {seed}", enabled=progress)):
                    writer.write(sim.render(T, index=i))
            t_render = time.perf_counter() - t1
            sim.manifest.save(tmp / "manifest.json")
            traj = np.array([T[:2, 3] for T in poses]) if poses else None
            draw_scene(sim.manifest, tmp / "topdown.png", navigable=sim.navigable(), trajectory=traj)
        return (f"wrote {len(poses)} frames ({width}x{height}) of apartment seed {seed} "
                f"({len(sim.manifest.rooms)} rooms, {len(sim.manifest.objects)} objects) to {out} "
                f"[build {t_build:.2f} s, render+write {t_render:.1f} s]")
