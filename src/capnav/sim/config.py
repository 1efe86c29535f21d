"""Simulator configuration: one frozen dataclass per part, Habitat-like defaults."""

from __future__ import annotations

from dataclasses import dataclass, field

from capnav.core.errors import InputError
from capnav.core.geometry import Intrinsics
from capnav.core.limits import HFOV_MAX, HFOV_MIN, check_image_size


@dataclass(frozen=True)
class AgentConfig:
    """A cylinder agent (Habitat's defaults: radius 0.1-0.2 m, height 1.5 m, camera at 1.25 m)."""

    radius: float = 0.2
    height: float = 1.5
    camera_height: float = 1.25
    forward_step: float = 0.25
    turn_deg: float = 30.0

    def __post_init__(self) -> None:
        if not (0.05 <= self.radius <= 0.6):
            raise InputError(f"agent radius must be in [0.05, 0.6] m, got {self.radius}")
        if not (0.0 < self.camera_height <= self.height):
            raise InputError(f"camera height must be in (0, height={self.height}], got {self.camera_height}")
        if self.forward_step <= 0 or not (0 < self.turn_deg < 180):
            raise InputError(f"forward_step must be > 0 and turn_deg in (0, 180), got "
                             f"{self.forward_step}, {self.turn_deg}")


@dataclass(frozen=True)
class CameraConfig:
    """Pinhole camera: 320x240 with a 90 degree horizontal field of view (Habitat's default hfov)."""

    width: int = 320
    height: int = 240
    hfov_deg: float = 90.0
    near: float = 0.05
    far: float = 20.0
    shadows: bool = False  # the tiny renderer's shadow pass halves the frame rate
    frame_rate: float = 10.0  # timestamps of rendered frames are index / frame_rate
    room_culling: bool = True  # hide rooms no chain of doors makes visible (same pixels, ~2x faster)

    def __post_init__(self) -> None:
        check_image_size(self.width, self.height)
        if not (HFOV_MIN <= self.hfov_deg <= HFOV_MAX):
            raise InputError(f"hfov must be within {HFOV_MIN:g}..{HFOV_MAX:g} degrees, got {self.hfov_deg}")
        if not (0 < self.near < self.far):
            raise InputError(f"need 0 < near < far, got near={self.near}, far={self.far}")

    def intrinsics(self) -> Intrinsics:
        import math

        f = 0.5 * self.width / math.tan(math.radians(self.hfov_deg) / 2.0)
        return Intrinsics(fx=f, fy=f, cx=self.width / 2.0, cy=self.height / 2.0, width=self.width,
                          height=self.height)


@dataclass(frozen=True)
class DepthNoiseConfig:
    """Consumer RGB-D depth noise (Kinect-v1-like), seeded per frame. Off by default.

    Axial noise sigma(z) = ``sigma0 + sigma2 * (z - 0.4)^2`` (Nguyen et al., 2012), depth quantised
    to ``quantum`` metres, pixels beyond ``[min_range, max_range]`` dropped, pixels on depth
    discontinuities dropped with ``edge_dropout`` probability and any pixel with ``dropout``.
    """

    enabled: bool = False
    sigma0: float = 0.0012
    sigma2: float = 0.0019
    quantum: float = 0.001
    min_range: float = 0.3
    max_range: float = 8.0
    edge_threshold: float = 0.1
    edge_dropout: float = 0.5
    dropout: float = 0.002
    seed: int = 0


#: The largest floor plan the generator makes (the large preset uses 8-14 rooms).
MAX_ROOMS = 16


@dataclass(frozen=True)
class LayoutConfig:
    """Procedural floor plan: ``rooms`` None draws 3..7 from the seed."""

    rooms: int | None = None
    min_rooms: int = 3
    max_rooms: int = 7
    room_area: tuple[float, float] = (11.0, 18.0)
    min_room_side: float = 2.4
    wall_height: float = 2.6
    wall_thickness: float = 0.1
    door_width: float = 0.9
    extra_door_prob: float = 0.35

    def __post_init__(self) -> None:
        if self.rooms is not None and not (3 <= self.rooms <= MAX_ROOMS):
            raise InputError(f"rooms must be between 3 and {MAX_ROOMS}, got {self.rooms}")
        if not (3 <= self.min_rooms <= self.max_rooms <= MAX_ROOMS):
            raise InputError(f"need 3 <= min_rooms <= max_rooms <= {MAX_ROOMS}, got {self.min_rooms}, "
                             f"{self.max_rooms}")


@dataclass(frozen=True)
class FurnishConfig:
    """How densely rooms are furnished. The defaults give the benchmark's apartments; the large
    preset adds instances of a kind (in near colours: lookalikes told apart only by shade, place or
    size) and clutter (small pieces in front of furniture)."""

    count_scale: float = 1.0  # multiplies each room plan's maximum count of a category
    near_color_prob: float = 0.0  # chance that another instance of a category takes a shade of an earlier colour
    clutter_per_room: tuple[int, int] = (0, 0)  # small pieces (plants, stools, ottomans) in front of furniture
    # Small things (cups, bottles, books, vases, bowls, laptops) on each table, counter and shelf
    # piece: (min, max) per piece; (0, 0) places none (``capnav.sim.surface_items``).
    surface_items: tuple[int, int] = (0, 0)
    # Generation speed in big houses: a furnishing that loses at most ``accept_lost`` objects to the
    # reachability check is kept at once, and that check drops ``prune_batch`` objects per pass.
    max_per_category: int | None = None  # at most this many instances of one category in the house
    accept_lost: int = 1
    prune_batch: int = 1

    def __post_init__(self) -> None:
        if not (1.0 <= self.count_scale <= 3.0):
            raise InputError(f"count_scale must be in [1, 3], got {self.count_scale}")
        if not (0.0 <= self.near_color_prob <= 1.0):
            raise InputError(f"near_color_prob must be in [0, 1], got {self.near_color_prob}")
        lo, hi = self.clutter_per_room
        if not (0 <= lo <= hi <= 6):
            raise InputError(f"clutter_per_room must satisfy 0 <= lo <= hi <= 6, got {self.clutter_per_room}")
        lo, hi = self.surface_items
        if not (0 <= lo <= hi <= 8):
            raise InputError(f"surface_items must satisfy 0 <= lo <= hi <= 8, got {self.surface_items}")


@dataclass(frozen=True)
class SimConfig:
    """Everything that defines a simulated apartment and its sensor. Same seed + config = same scene."""

    layout: LayoutConfig = field(default_factory=LayoutConfig)
    agent: AgentConfig = field(default_factory=AgentConfig)
    camera: CameraConfig = field(default_factory=CameraConfig)
    depth_noise: DepthNoiseConfig = field(default_factory=DepthNoiseConfig)
    furniture: str = "primitives"  # or "sh3d" (meshes from Debian's sweethome3d-furniture)
    assets_dir: str | None = None  # where `capnav assets` extracted the meshes (default cache)
    textures: bool = True  # procedural material / floor textures
    nav_resolution: float = 0.05
    furnish: FurnishConfig = field(default_factory=FurnishConfig)


#: House sizes. ``default``: the benchmark's apartments (3-7 rooms, 40-110 m², 15-47 objects).
#: ``large``: near Matterport3D houses' scale (8-14 rooms with hallways, 120-250 m², 60-150
#: objects, up to 6 instances of a category in near colours, clutter in front of furniture).
HOUSE_SIZES: tuple[str, ...] = ("default", "large")


def house_config(size: str, base: SimConfig | None = None) -> SimConfig:
    """``base`` (default: ``SimConfig()``) with the layout and furnishing of a house-size preset."""
    from dataclasses import replace

    base = base or SimConfig()
    if size == "default":
        return base
    if size == "large":
        return replace(base, layout=replace(base.layout, min_rooms=8, max_rooms=14, room_area=(15.0, 18.0)),
                       furnish=FurnishConfig(count_scale=2.0, near_color_prob=0.6, clutter_per_room=(1, 3),
                                             max_per_category=6, accept_lost=8, prune_batch=4))
    raise InputError(f"unknown house size {size!r}; choose from {', '.join(HOUSE_SIZES)}")
