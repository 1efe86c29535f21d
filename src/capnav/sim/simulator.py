"""The simulator facade: an apartment, its pybullet world, the camera, navigability and agents."""

from __future__ import annotations

from types import TracebackType
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, check_pose
from capnav.core.grid import OccupancyGrid
from capnav.sim.agent import Agent
from capnav.sim.apartment import Apartment, _manifest, generate_apartment
from capnav.sim.camera import linear_depth, projection_matrix, view_matrix
from capnav.sim.config import SimConfig
from capnav.sim.culling import RoomCuller
from capnav.sim.manifest import SceneManifest
from capnav.sim.navgrid import NavGrid
from capnav.sim.noise import apply_depth_noise
from capnav.sim.shapes import RectSet
from capnav.sim.world import BulletWorld

if TYPE_CHECKING:
    from capnav.sim.changes import ChangeSpec


class Simulator:
    """A procedural apartment rendered with pybullet's CPU renderer (DIRECT mode).

    ``manifest`` is the scene truth: only the simulator, the simulator detector and evaluation may
    read it. ``render`` gives posed RGB-D frames with ground-truth instance/category images.
    """

    def __init__(self, apartment: Apartment) -> None:
        self.apartment = apartment
        self.config: SimConfig = apartment.config
        self._obstacles: RectSet = apartment.obstacles()
        self._grids: dict[float, NavGrid] = {}
        self.world = BulletWorld(apartment, textures=self.config.textures)
        cam = self.config.camera
        self._culler = RoomCuller(apartment.plan, self.config.layout.wall_height, cam.near) if cam.room_culling \
            else None

    @classmethod
    def from_seed(cls, seed: int, config: SimConfig | None = None, visit: int = 1,
                  changes: ChangeSpec | None = None, change_seed: int = 0) -> Simulator:
        """Apartment ``seed``; ``visit`` > 1 with ``changes`` is the same apartment after seeded
        changes (``capnav.sim.changes``), listed in ``manifest.changes``."""
        from capnav.sim.furniture import FURNITURE, furnish

        config = config if config is not None else SimConfig()
        if config.furniture not in FURNITURE:  # fail before the (slower) scene generation
            FURNITURE.create(config.furniture)
        apt = furnish(generate_apartment(seed, config), config)
        if visit < 1:
            raise InputError(f"visit must be >= 1, got {visit}")
        if visit > 1 and apt.items:
            raise InputError("a later visit of an apartment with surface items is not supported yet (their "
                             "support may move); record the visit without --surface-items")
        if visit > 1:
            from capnav.sim.changes import ChangeSpec, apply_changes

            apt, listed = apply_changes(apt, changes or ChangeSpec(), change_seed, visit)
            new = [o for o in apt.objects if o.id in {c.id for c in listed if c.kind == "added"}]
            if new and config.furniture != "primitives":  # draw the new pieces from the same source
                furnish(Apartment(seed + 7919 * visit, config, apt.plan, new, apt.wall_rects, apt.wall_faces,
                                  apt.floor_styles, apt.wall_colors), config)
                apt.manifest = _manifest(apt)
            apt.manifest.visit = visit
            apt.manifest.changes = listed
        return cls(apt)

    # -- truth -----------------------------------------------------------------------------
    @property
    def manifest(self) -> SceneManifest:
        return self.apartment.manifest

    @property
    def seed(self) -> int:
        return self.apartment.seed

    @property
    def intrinsics(self) -> Intrinsics:
        return self.config.camera.intrinsics()

    # -- rendering -------------------------------------------------------------------------
    def render(self, T_wc: NDArray[np.floating], K: Intrinsics | None = None, index: int = 0) -> Frame:
        """Render the view of an OpenCV camera at ``T_wc`` (camera-to-world) with intrinsics ``K``."""
        T = check_pose(T_wc, frame=index)
        K = K if K is not None else self.intrinsics
        cam = self.config.camera
        if self._culler is not None:
            self.world.show_rooms(self._culler.visible(T, K))
        rgba, buf, seg = self.world.render(K.width, K.height, view_matrix(T), projection_matrix(K, cam.near, cam.far),
                                           shadows=cam.shadows)
        uid = np.where(seg >= 0, seg & 0xFFFFFF, -1)
        uid = np.where(uid + 1 < self.world.instance_lut.size, uid, -1)
        depth = linear_depth(buf, cam.near, cam.far)
        depth[(seg < 0) | (buf >= 1.0)] = 0.0
        if self.config.depth_noise.enabled:
            depth = apply_depth_noise(depth, self.config.depth_noise, index)
        return Frame(index=index, rgb=np.ascontiguousarray(rgba[..., :3]), depth=depth, K=K, T_wc=T,
                     timestamp=index / cam.frame_rate, gt_instance=self.world.instance_lut[uid + 1],
                     gt_category=self.world.category_lut[uid + 1])

    # -- navigation truth ------------------------------------------------------------------
    def nav_grid(self, resolution: float | None = None) -> NavGrid:
        res = float(resolution if resolution is not None else self.config.nav_resolution)
        if not (0.005 <= res <= 1.0):
            raise InputError(f"grid resolution must be within [0.005, 1] m, got {res}")
        if res not in self._grids:
            self._grids[res] = NavGrid(self._obstacles, self.apartment.bounds, self.config.agent.radius, res)
        return self._grids[res]

    def navigable(self, resolution: float | None = None) -> OccupancyGrid:
        """FREE where the agent centre may stand and is connected to the rest of the apartment."""
        return self.nav_grid(resolution).navigable()

    def obstacles(self, resolution: float | None = None) -> OccupancyGrid:
        """Obstacle footprints (walls, furniture), not inflated; UNKNOWN outside the apartment."""
        return self.nav_grid(resolution).obstacles()

    def geodesic_distance(self, start_xy: tuple[float, float], goal_xy: tuple[float, float],
                          snap: float = 0.3) -> float:
        """Shortest navigable path length (m); points off the navigable grid snap to the nearest
        navigable cell within ``snap`` m (the snap distance is added); inf if unreachable."""
        return self.nav_grid().geodesic(_xy(start_xy), _xy(goal_xy), snap)

    def shortest_path(self, start_xy: tuple[float, float], goal_xy: tuple[float, float],
                      snap: float = 0.3) -> NDArray[np.float64]:
        return self.nav_grid().path(_xy(start_xy), _xy(goal_xy), snap)

    def random_navigable_point(self, rng: np.random.Generator) -> tuple[float, float]:
        pts = self.nav_grid().free_points()
        k = int(rng.integers(len(pts)))
        return float(pts[k, 0]), float(pts[k, 1])

    def collides_many(self, xy: NDArray[np.floating]) -> NDArray[np.bool_]:
        """True where an agent disk centred at each (x, y) would overlap an obstacle or leave the flat."""
        pts = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        x0, y0, x1, y1 = self.apartment.bounds
        r = self.config.agent.radius
        outside = (pts[:, 0] < x0 + r) | (pts[:, 0] > x1 - r) | (pts[:, 1] < y0 + r) | (pts[:, 1] > y1 - r)
        return np.asarray(outside | (self._obstacles.min_distance(pts) < r))

    def collides(self, x: float, y: float) -> bool:
        return bool(self.collides_many(np.array([[x, y]]))[0])

    def spawn_agent(self, x: float, y: float, yaw: float = 0.0) -> Agent:
        return Agent(self, x, y, yaw)

    # -- lifetime --------------------------------------------------------------------------
    def close(self) -> None:
        self.world.close()

    def __enter__(self) -> Simulator:
        return self

    def __exit__(self, et: type[BaseException] | None, ev: BaseException | None, tb: TracebackType | None) -> None:
        self.close()


def _xy(p: tuple[float, float] | NDArray[np.floating]) -> tuple[float, float]:
    a = np.asarray(p, dtype=np.float64).reshape(-1)
    if a.size < 2 or not np.all(np.isfinite(a[:2])):
        raise InputError(f"expected a finite (x, y) point, got {p!r}")
    return float(a[0]), float(a[1])
