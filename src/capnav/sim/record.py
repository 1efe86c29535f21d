"""Record an apartment's exploration pass to a dataset folder (what ``capnav sim`` runs)."""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from capnav.core.atomic import atomic_dir
from capnav.core.frame import Frame
from capnav.core.progress import track
from capnav.io.dataset import DatasetWriter, check_dataset_target
from capnav.sim.config import CameraConfig, DepthNoiseConfig, LayoutConfig, SimConfig
from capnav.sim.explore import ExploreConfig, plan_exploration
from capnav.sim.simulator import Simulator

if TYPE_CHECKING:
    from capnav.sim.changes import ChangeSpec


def planar_pose(x: float, y: float, yaw: float) -> NDArray[np.float64]:
    """4x4 rigid transform: a rotation ``yaw`` (rad) about z, then a shift (x, y)."""
    c, s = np.cos(yaw), np.sin(yaw)
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[0, 3], T[1, 3] = x, y
    return T


def _render_kept(sim: Simulator, poses: Iterable[NDArray[np.float64]], hide: NDArray[np.int32],
                 kept: list[NDArray[np.float64]]) -> Iterator[Frame]:
    """Render each pose once, numbered by the frames kept; a view showing any pixel of ``hide`` is dropped.

    A visit that never entered the hidden objects' room must not see them through its door either;
    ``kept`` collects the poses written.
    """
    for T in poses:
        f = sim.render(T, index=len(kept))
        if hide.size and f.gt_instance is not None and np.isin(f.gt_instance, hide).any():
            continue
        kept.append(T)
        yield f


def record_dataset(seed: int, out: str | Path, frames: int | None = None, stride: int = 1, width: int = 320,
                   height: int = 240, hfov: float = 90.0, rooms: int | None = None, furniture: str = "primitives",
                   depth_noise: bool = False, overwrite: bool = False, progress: bool = True,
                   config: SimConfig | None = None, assets_dir: str | Path | None = None, visit: int = 1,
                   changes: ChangeSpec | None = None, change_seed: int = 0,
                   frame_offset: tuple[float, float, float] | None = None,
                   surface_items: bool = False, export: str | None = None, tilt: str | None = None) -> str:
    """Build apartment ``seed``, render its exploration pass into ``out``; returns a one-line summary.

    Writes ``out/manifest.json`` (scene truth, for evaluation) and ``out/topdown.png`` beside the frames.
    ``visit`` > 1 records the apartment after ``changes`` (seeded by ``change_seed``); ``frame_offset``
    (x, y, yaw in degrees: where the recording's world frame lies in the apartment's) writes the poses
    in another world frame, as a robot started elsewhere on another day would.
    ``surface_items`` puts 1-3 small things (cups, books, a laptop...) on each table, counter and
    shelf piece (``capnav.sim.surface_items``); the apartment's furniture stays the same.
    ``export`` writes the frames in another tool's layout instead (``capnav.io.export``: tum, open3d,
    3dmatch, scannet), with the poses in a world turned by ``tilt`` ("ROLL,PITCH,YAW" degrees), so an
    importer has to find up itself; manifest.json beside them stays in the apartment's frame.
    """
    from capnav.io.export import check_export_target, tilt_matrix, writer
    from capnav.viz.scene import draw_scene

    out = Path(out)
    write_layout = writer(export) if export is not None else None
    W = tilt_matrix(tilt)
    if tilt is not None and export is None:
        from capnav.core.errors import InputError

        raise InputError("--tilt turns the world of an --export recording; give --export too")
    if write_layout is None:
        check_dataset_target(out, overwrite)
    else:
        check_export_target(out, overwrite)
    base = config if config is not None else SimConfig()
    cfg = replace(base, camera=replace(base.camera, width=width, height=height, hfov_deg=hfov)
                  if config is not None else CameraConfig(width=width, height=height, hfov_deg=hfov),
                  layout=LayoutConfig(rooms=rooms) if rooms is not None else base.layout,
                  depth_noise=DepthNoiseConfig(enabled=True, seed=seed) if depth_noise else base.depth_noise,
                  furniture=furniture, assets_dir=str(assets_dir) if assets_dir is not None else base.assets_dir)
    if surface_items:
        cfg = replace(cfg, furnish=replace(cfg.furnish, surface_items=(1, 3)))
    t0 = time.perf_counter()
    with Simulator.from_seed(seed, cfg, visit=visit, changes=changes, change_seed=change_seed) as sim:
        t_build = time.perf_counter() - t0
        from capnav.sim.changes import hidden_ids, left_out_rooms

        poses = plan_exploration(sim, ExploreConfig(seed=seed, stride=stride, max_frames=frames,
                                                    skip_rooms=tuple(sorted(left_out_rooms(sim.manifest.changes)))))
        hide = np.asarray(sorted(hidden_ids(sim.manifest.changes)), dtype=np.int32)
        meta = {"source": "capnav.sim", "seed": seed, "furniture": furniture, "rooms": len(sim.manifest.rooms),
                "objects": len(sim.manifest.objects), "depth_noise": depth_noise, "exploration": "capnav.sim.explore"}
        if sim.manifest.items:  # only then: default datasets keep their meta.json bytes
            meta["surface_items"] = len(sim.manifest.items)
        if visit > 1:  # what a robot knows of its own recording: which visit (day) it is
            meta["visit"] = visit
        to_rec: NDArray[np.float64] = np.eye(4)
        if frame_offset is not None:
            ox, oy, oyaw = frame_offset
            sim.manifest.frame_offset = (float(ox), float(oy), float(oyaw))
            to_rec = np.asarray(np.linalg.inv(planar_pose(ox, oy, np.radians(oyaw))), dtype=np.float64)
        t1 = time.perf_counter()
        # Built in a temporary sibling and swapped in whole: an interrupted --overwrite keeps the old one.
        with atomic_dir(out, overwrite=overwrite) as tmp:
            kept: list[NDArray[np.float64]] = []
            rendered = _render_kept(sim, track(poses, f"rendering seed {seed}", enabled=progress), hide, kept)
            if write_layout is None:
                with DatasetWriter(tmp, sim.intrinsics, meta) as dataset:
                    for f in rendered:
                        if frame_offset is not None:
                            f = replace(f, T_wc=to_rec @ f.T_wc)
                        dataset.write(f)
            else:
                write_layout((replace(f, T_wc=W @ to_rec @ f.T_wc, gt_instance=None, gt_category=None)
                              for f in rendered), sim.intrinsics, tmp)
            t_render = time.perf_counter() - t1
            sim.manifest.save(tmp / "manifest.json")
            traj = np.array([T[:2, 3] for T in kept]) if kept else None
            draw_scene(sim.manifest, tmp / "topdown.png", navigable=sim.navigable(), trajectory=traj)
        what = f"visit {visit} ({changes}) of " if visit > 1 else ""
        if export is not None:
            what = f"{export} layout{f', world tilted {tilt}' if tilt else ''}, " + what
        return (f"wrote {len(kept)} frames ({width}x{height}) of {what}apartment seed {seed} "
                f"({len(sim.manifest.rooms)} rooms, {len(sim.manifest.objects)} objects) to {out} "
                f"[build {t_build:.2f} s, render+write {t_render:.1f} s]")
