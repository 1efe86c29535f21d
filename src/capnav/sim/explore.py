"""A virtual exploration pass (the paper's posed RGB-D collection): visit every room, look around at
a few spots, look at every object from several distances (from points that see it past walls and
tall furniture), walk between stops on shortest paths.

The policy reads the scene truth to choose viewpoints (it is part of the simulator, like a scripted
data-collection run); the frames it yields are plain observations.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import look_at_pose
from capnav.sim.apartment import SceneObject
from capnav.sim.sightline import SightGrid, sight_grid
from capnav.sim.simulator import Simulator


@dataclass(frozen=True)
class ExploreConfig:
    """Exploration policy knobs; the defaults give about 200-400 frames per apartment."""

    seed: int = 0
    turn_deg: float = 30.0  # rotation step when looking around at a spot
    look_pitches_deg: tuple[float, float] = (8.0, 30.0)  # alternated while looking around
    spot_area: float = 12.0  # one look-around spot per this many m² of room (1..4 per room)
    view_distances: tuple[float, ...] = (1.3, 2.3)  # one view of every object per distance
    travel_step: float = 0.5  # a frame every this many metres while walking
    travel_pitch_deg: float = 12.0
    stride: int = 1  # keep every stride-th frame
    max_frames: int | None = None  # subsample uniformly to at most this many frames
    min_frames: int = 200  # small flats get more viewpoints (extra distances and spots) up to this
    skip_rooms: tuple[int, ...] = ()  # rooms this pass leaves out (a later visit that never enters them)

    def __post_init__(self) -> None:
        if self.stride < 1:
            raise InputError(f"stride must be >= 1, got {self.stride}")
        if self.max_frames is not None and self.max_frames < 1:
            raise InputError(f"max_frames must be >= 1, got {self.max_frames}")
        if not (5.0 <= self.turn_deg <= 180.0) or self.travel_step <= 0:
            raise InputError("turn_deg must be in [5, 180] and travel_step > 0")


def plan_exploration(sim: Simulator, cfg: ExploreConfig) -> list[NDArray[np.float64]]:
    """Camera poses (T_wc) of the whole pass, in order; deterministic given the scene and ``cfg.seed``."""
    poses = _plan(sim, cfg)
    extra = (1.8, 3.0, 0.9)
    for k in range(len(extra)):  # small flats: look from more distances and spots
        if len(poses) >= cfg.min_frames:
            break
        dense = replace(cfg, view_distances=cfg.view_distances + extra[:k + 1], spot_area=cfg.spot_area / (k + 2))
        poses = _plan(sim, dense)
    poses = poses[::cfg.stride]
    if cfg.max_frames is not None and len(poses) > cfg.max_frames:
        keep = np.round(np.linspace(0, len(poses) - 1, cfg.max_frames)).astype(int)
        poses = [poses[i] for i in keep]
    return poses


def _plan(sim: Simulator, cfg: ExploreConfig) -> list[NDArray[np.float64]]:
    rng = np.random.default_rng([cfg.seed, sim.seed, 7])
    extra = np.random.default_rng([cfg.seed, sim.seed, 8])  # the extra views' own draws: the others stay
    grid = sim.nav_grid()
    pts = grid.free_points()
    apt = sim.apartment
    cam_h = sim.config.agent.camera_height
    order = [k for k in _room_order(sim) if k not in cfg.skip_rooms]
    sight = sight_grid(apt, grid.spec)  # walls and tall furniture: a view of an object must see it
    poses: list[NDArray[np.float64]] = []
    pos: NDArray[np.float64] | None = None
    for k in order:
        r = apt.plan.rooms[k]
        inroom = pts[(pts[:, 0] > r.x0) & (pts[:, 0] < r.x1) & (pts[:, 1] > r.y0) & (pts[:, 1] < r.y1)]
        if len(inroom) == 0:
            continue
        # stops: (x, y, look) where look is None for a look-around, or the (x, y, z) to look at
        stops: list[tuple[float, float, tuple[float, float, float] | None]] = []
        spots = _spread_points(inroom, grid, max(1, min(4, round(r.area / cfg.spot_area))), rng)
        for s in spots:
            stops.append((float(s[0]), float(s[1]), None))
        for o in (o for o in apt.objects if o.room == k):
            target = (o.x, o.y, min(o.model.size[2] * 0.6, cam_h))
            d = np.hypot(inroom[:, 0] - o.x, inroom[:, 1] - o.y)
            dists = cfg.view_distances
            if not any(sight.sees(s, o.footprint(), own_ids=(o.id,)) for s in spots):
                # Hidden from every look-around spot (tucked behind a wardrobe), its own views are all
                # it gets: one more, so that a track can be born (the tracker wants three hits).
                dists = (*dists, float(np.mean(dists)))
            for n, dist in enumerate(dists):
                near = np.flatnonzero(np.abs(d - dist) < 0.35)
                if len(near) == 0:
                    near = np.array([int(np.argmin(np.abs(d - dist)))])
                draw = rng if n < len(cfg.view_distances) else extra
                j = int(near[int(draw.integers(len(near)))])
                p = inroom[_in_sight(sight, inroom, d, dist, j, o)]
                stops.append((float(p[0]), float(p[1]), target))
        # visit stops nearest-first from where we are
        remaining = list(range(len(stops)))
        while remaining:
            j = 0
            if pos is not None:
                here = pos
                j = min(range(len(remaining)), key=lambda i: math.hypot(stops[remaining[i]][0] - here[0],
                                                                       stops[remaining[i]][1] - here[1]))
            x, y, look = stops[remaining.pop(j)]
            if pos is not None:
                poses += _walk(sim, pos, np.array([x, y]), cfg)
            pos = np.array([x, y])
            eye = np.array([x, y, cam_h])
            if look is None:
                n = round(360.0 / cfg.turn_deg)
                yaw0 = float(rng.uniform(-math.pi, math.pi))
                for i in range(n):
                    pitch = math.radians(cfg.look_pitches_deg[i % len(cfg.look_pitches_deg)])
                    poses.append(look_at_pose(eye, yaw0 + i * math.radians(cfg.turn_deg), pitch))
            else:
                dx, dy, dz = look[0] - x, look[1] - y, look[2] - cam_h
                yaw = math.atan2(dy, dx)
                pitch = -math.atan2(dz, math.hypot(dx, dy))
                poses.append(look_at_pose(eye, yaw, pitch))
    return poses


#: How many view points, nearest the wanted distance first, are tried for one in sight of the object.
SIGHT_TRIES = 64


def _in_sight(sight: SightGrid, pts: NDArray[np.float64], d: NDArray[np.float64], dist: float, drawn: int,
              obj: SceneObject) -> int:
    """The view point of ``obj`` from ``pts`` (distances ``d`` to it): the ``drawn`` one when it sees
    the object, else the one nearest the wanted ``dist`` that does (a view from behind the wardrobe
    shows the wardrobe), else the drawn one."""
    fp = obj.footprint()
    if sight.sees(pts[drawn], fp, own_ids=(obj.id,)):
        return drawn
    order = np.argsort(np.abs(d - dist), kind="stable")
    # the points nearest the wanted distance, then a spread over the whole room (nearer or farther)
    for i in np.concatenate([order[:SIGHT_TRIES], order[SIGHT_TRIES::max(1, len(order) // SIGHT_TRIES)]]):
        if sight.sees(pts[int(i)], fp, own_ids=(obj.id,)):
            return int(i)
    return drawn


def explore(sim: Simulator, cfg: ExploreConfig | None = None) -> Iterator[Frame]:
    """Render the exploration pass lazily; frame indices count from 0."""
    for i, T in enumerate(plan_exploration(sim, cfg if cfg is not None else ExploreConfig())):
        yield sim.render(T, index=i)


def _room_order(sim: Simulator) -> list[int]:
    """Rooms in breadth-first order over the doors, starting from the living room."""
    plan = sim.apartment.plan
    start = plan.types.index("living room") if "living room" in plan.types else 0
    seen, queue = [start], [start]
    while queue:
        k = queue.pop(0)
        for d in plan.doors:
            if k in d.rooms:
                other = d.rooms[1] if d.rooms[0] == k else d.rooms[0]
                if other not in seen:
                    seen.append(other)
                    queue.append(other)
    return seen + [k for k in range(len(plan.rooms)) if k not in seen]


def _spread_points(pts: NDArray[np.float64], grid: object, n: int,
                   rng: np.random.Generator) -> list[NDArray[np.float64]]:
    """The most open point of the room, then farthest-point samples."""
    from capnav.sim.navgrid import NavGrid

    assert isinstance(grid, NavGrid)
    rc = grid.spec.to_cell(pts)
    clear = grid.clearance[rc[:, 0], rc[:, 1]]
    chosen = [pts[int(np.argmax(clear))]]
    while len(chosen) < n:
        d = np.min([np.hypot(pts[:, 0] - c[0], pts[:, 1] - c[1]) for c in chosen], axis=0)
        chosen.append(pts[int(np.argmax(d + 0.01 * rng.random(len(d))))])
    return chosen


def _walk(sim: Simulator, a: NDArray[np.float64], b: NDArray[np.float64],
          cfg: ExploreConfig) -> list[NDArray[np.float64]]:
    path = sim.shortest_path((float(a[0]), float(a[1])), (float(b[0]), float(b[1])))
    if len(path) < 2:
        return []
    seg = np.hypot(*np.diff(path, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    out = []
    cam_h = sim.config.agent.camera_height
    for t in np.arange(cfg.travel_step, s[-1] - 1e-6, cfg.travel_step):
        i = int(np.searchsorted(s, t) - 1)
        i = min(max(i, 0), len(seg) - 1)
        f = (t - s[i]) / max(seg[i], 1e-9)
        p = path[i] + f * (path[i + 1] - path[i])
        ahead = path[min(len(path) - 1, i + 6)] - p  # look a little ahead, not at the next cell
        yaw = math.atan2(ahead[1], ahead[0]) if np.hypot(*ahead) > 1e-6 else 0.0
        out.append(look_at_pose(np.array([p[0], p[1], cam_h]), yaw, math.radians(cfg.travel_pitch_deg)))
    return out
