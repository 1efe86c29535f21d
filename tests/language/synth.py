"""Synthetic map objects and frames for language/retrieval tests (no simulator, no manifest)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, look_at_pose
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.language.embedder import TextEmbedder
from capnav.mapping.cmap import CameraTrajectory, CapNavMap
from capnav.mapping.objects import MapObject, Observation
from capnav.mapping.voxel_map import VoxelMap
from capnav.retrieval import Retriever


def make_obj(oid: int, label: str, center: tuple[float, float], size: tuple[float, float, float],
             rgb: tuple[int, int, int], seed: int = 0, n: int = 600, second: tuple[int, int, int] | None = None,
             shading: tuple[float, float] = (0.6, 1.0)) -> MapObject:
    """A box-shaped object with shaded surface points of colour ``rgb`` (20% ``second`` if given)."""
    rng = np.random.default_rng(seed + oid)
    c = np.array([center[0], center[1], size[2] / 2])
    half = np.array(size) / 2
    pts = c + rng.uniform(-1, 1, (n, 3)) * half
    base = np.tile(np.array(rgb, dtype=np.float64), (n, 1))
    if second is not None:
        base[: n // 5] = second
    lin = (base / 255.0) ** 2.2 * rng.uniform(*shading, (n, 1))
    cols = np.clip(255 * lin ** (1 / 2.2), 0, 255).astype(np.uint8)
    lo, hi = c - half, c + half
    fp = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
    return MapObject(id=oid, label=label, label_votes={label: 5.0}, position=c, extent_min=lo, extent_max=hi,
                     footprint=fp, points=pts.astype(np.float32), colors=cols, feature=np.zeros(4, np.float32),
                     hits=5)


def grid_with_wall(xmin: float, ymin: float, xmax: float, ymax: float, wall_x: float | None = None,
                   door: tuple[float, float] | None = None) -> OccupancyGrid:
    """A FREE rectangle with outer walls and optionally a wall at x = ``wall_x`` with a door (y range)."""
    spec = GridSpec.covering(xmin, ymin, xmax, ymax, 0.05, margin=0.2)
    cells = np.full((spec.rows, spec.cols), FREE, dtype=np.uint8)
    cells[:3, :], cells[-3:, :], cells[:, :3], cells[:, -3:] = OCCUPIED, OCCUPIED, OCCUPIED, OCCUPIED
    if wall_x is not None:
        col = int(spec.to_cell(np.array([wall_x, 0.0]))[1])
        cells[:, col - 1:col + 2] = OCCUPIED
        if door is not None:
            r0 = int(spec.to_cell(np.array([0.0, door[0]]))[0])
            r1 = int(spec.to_cell(np.array([0.0, door[1]]))[0])
            cells[r0:r1, col - 1:col + 2] = FREE
    return OccupancyGrid(spec, cells)


def make_map(objects: list[MapObject], occupancy: OccupancyGrid | None = None) -> CapNavMap:
    if occupancy is None:
        occupancy = grid_with_wall(-1, -1, 9, 7)
    return CapNavMap(objects=objects, voxels=VoxelMap(), occupancy=occupancy)


def living_scene() -> list[MapObject]:
    """Two sofas (red large, grey small), a bed, two chairs, a stove, a lamp."""
    return [
        make_obj(1, "sofa", (1.0, 1.0), (2.2, 0.9, 0.8), (178, 34, 34)),
        make_obj(2, "sofa", (5.0, 1.0), (1.6, 0.8, 0.8), (128, 128, 128)),
        make_obj(3, "bed", (7.0, 5.0), (1.6, 2.0, 0.5), (40, 70, 170)),
        make_obj(4, "chair", (7.0, 3.6), (0.5, 0.5, 0.9), (180, 140, 90)),
        make_obj(5, "chair", (1.0, 5.0), (0.5, 0.5, 0.9), (180, 140, 90)),
        make_obj(6, "stove", (1.0, 6.2), (0.6, 0.6, 0.9), (190, 192, 196)),
        make_obj(7, "lamp", (3.0, 3.0), (0.4, 0.4, 1.6), (225, 190, 40)),
    ]


class SquareReader:
    """Frames of a coloured square on grey, viewed from several places (a FrameReader)."""

    def __init__(self, n: int = 8, width: int = 160, height: int = 120) -> None:
        self.K = Intrinsics.from_fov(width, height, 60.0)
        self.n = n

    def __len__(self) -> int:
        return self.n

    def frame(self, index: int) -> Frame:
        h, w = self.K.height, self.K.width
        rgb = np.full((h, w, 3), 120, dtype=np.uint8)
        x0, y0, x1, y1 = self.box(index)
        yy, xx = np.mgrid[0:h, 0:w]
        checker = ((xx // 4 + yy // 4) % 2).astype(np.uint8) * 60
        sl = (slice(int(y0), int(y1)), slice(int(x0), int(x1)))
        rgb[sl] = np.stack([200 + checker[sl] // 2, 30 + checker[sl] // 3, 30 + 0 * checker[sl]], axis=-1)
        yaw = 2 * np.pi * index / self.n
        eye = np.array([3 * np.cos(yaw), 3 * np.sin(yaw), 1.0])
        return Frame(index, rgb, np.full((h, w), 2.0, np.float32), self.K, look_at_pose(eye, yaw + np.pi, 0.2))

    def box(self, index: int) -> tuple[float, float, float, float]:
        s = 10 + 6 * index  # grows with the index
        cx = 20 + 15 * index
        return (float(max(cx - s, 0)), float(60 - s // 2), float(min(cx + s, 159)), float(60 + s // 2))

    def observations(self) -> list[Observation]:
        out = []
        for i in range(self.n):
            b = self.box(i)
            out.append(Observation(i, b, int((b[2] - b[0]) * (b[3] - b[1])), 0.9, "sofa", 2.0,
                                   truncated=b[0] <= 0 or b[2] >= 159, visibility=1.0))
        return out


def captioned_map(objects: list[MapObject], emb: TextEmbedder, occupancy: OccupancyGrid | None = None) -> CapNavMap:
    """``objects`` captioned by the offline captioner (rooms and walls from ``occupancy``) and
    embedded with ``emb``, as a map: what retrieval tests ask."""
    from capnav.language import create_captioner
    from capnav.language.context import SceneContext

    scene = SceneContext(objects, occupancy) if occupancy is not None else SceneContext(objects)
    cap = create_captioner("offline")
    texts = [cap.caption(o, scene).text for o in objects]
    for o, text, v in zip(objects, texts, emb.embed(texts), strict=True):
        o.caption = text
        o.embedding, o.embedding_model = v, emb.model_id
    return make_map(objects, occupancy)


def offline_retriever(objects: list[MapObject], occupancy: OccupancyGrid | None = None) -> Retriever:
    """A retriever over ``objects`` described as ``capnav caption`` does offline (rooms, captions,
    MiniLM embeddings) and judged by the offline verifier: the scene a retrieval test asks."""
    from capnav.language import create_captioner, create_embedder
    from capnav.language.describe import describe_map
    from capnav.retrieval import Retriever, create_verifier

    cmap = make_map(objects, occupancy)
    emb = create_embedder("minilm")
    describe_map(cmap, None, create_captioner("offline"), emb, progress=False)
    return Retriever(cmap, emb, create_verifier("offline", embedder=emb))



def bedroom_and_lounge() -> Retriever:
    """A bedroom (bed, lamp 2) and a lounge (sofa, tv, lamp 5) either side of a wall with a door:
    the smallest scene in which a room word chooses between two lamps."""
    objs = [
        make_obj(1, "bed", (1.0, 1.5), (1.6, 2.0, 0.5), (200, 200, 210)),
        make_obj(2, "lamp", (2.5, 4.5), (0.3, 0.3, 1.5), (230, 230, 220)),
        make_obj(3, "sofa", (6.5, 1.0), (2.0, 0.9, 0.8), (90, 90, 100)),
        make_obj(4, "tv", (6.5, 5.5), (1.0, 0.2, 0.6), (20, 20, 20)),
        make_obj(5, "lamp", (5.0, 4.5), (0.3, 0.3, 1.5), (230, 230, 220)),
    ]
    return offline_retriever(objs, grid_with_wall(-1, -1, 9, 7, wall_x=4.0, door=(2.5, 3.5)))

def described_living_map(folder: Path) -> Path:
    """The living scene (a wall with a door at x = 3.8) captioned offline, embedded with MiniLM
    and saved as ``folder/living.capnav``: the map the API and server tests read."""
    from capnav.api import CapNav
    from capnav.language import create_captioner, create_embedder
    from capnav.language.describe import describe_map

    cmap = make_map(living_scene(), two_rooms())
    describe_map(cmap, None, create_captioner("offline"), create_embedder("minilm"), progress=False)
    path = folder / "living.capnav"
    CapNav(cmap).save(path)
    return path


def walked_through_the_door(map_file: Path) -> CapNavMap:
    """The living map with its door's floor unknown (depth never saw it) and a camera path from the
    left room through the door to (6, 3) on the right: the floor the camera crossed is free."""
    from capnav.io.mapfile import load_map

    cmap = load_map(map_file)
    spec = cmap.occupancy.spec
    rr, cc = np.mgrid[0:spec.rows, 0:spec.cols]
    xy = spec.to_world(np.stack([rr, cc], axis=-1))
    door = (np.abs(xy[..., 0] - 3.8) < 0.15) & (xy[..., 1] > 2.4) & (xy[..., 1] < 3.6)
    cmap.occupancy.cells[door & (cmap.occupancy.cells == FREE)] = UNKNOWN
    xs = np.linspace(1.0, 6.0, 11)
    cmap.trajectory = CameraTrajectory(np.arange(11) * 3, np.stack([look_at_pose(np.array([x, 3.0, 1.2]), 0.0, 0.3)
                                                                   for x in xs]))
    return cmap


def textured_view(obj: MapObject, pattern: str, scale: float = 1.0, texel: int | None = None) -> MapObject:
    """Give ``obj`` one view: a crop of the simulator's ``pattern`` texture in the object's median
    point colour, resampled by ``scale`` (as a renderer samples it), on a wall-coloured margin.
    With ``texel``, each texel is drawn as a block of that many pixels instead (nearest sampling:
    how the simulator's renderer draws a near face)."""
    import io

    from PIL import Image

    from capnav.mapping.objects import ObjectView
    from capnav.sim.textures import texture

    rgb = tuple(int(v) for v in np.median(np.asarray(obj.colors), axis=0))
    tile = np.tile(texture(pattern, rgb), (2, 2, 1))  # type: ignore[arg-type]
    n = int(128 * scale) if texel is None else 128 * texel
    surf = np.asarray(Image.fromarray(tile).resize((n, n), Image.BILINEAR if texel is None else Image.NEAREST))
    img = np.full((n + 40, n + 40, 3), (205, 200, 190), np.uint8)
    img[20:20 + n, 20:20 + n] = surf
    buf = io.BytesIO()
    Image.fromarray(img).save(buf, format="PNG")
    obj.views = [ObjectView(0, (0.0, 0.0, float(n + 40), float(n + 40)), 1.0, b"", buf.getvalue())]
    return obj


def disc_points(center: tuple[float, float], radius: float, height: float, n: int = 2000,
                seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t, r = rng.uniform(0, 2 * np.pi, n), radius * np.sqrt(rng.uniform(0, 1, n))
    return np.stack([center[0] + r * np.cos(t), center[1] + r * np.sin(t), rng.uniform(0, height, n)],
                    1).astype(np.float32)


def plant_points(center: tuple[float, float], foliage_radius: float, seed: int = 0) -> np.ndarray:
    """A pot (radius 0.15 m, 0.3 m high) with a foliage column of ``foliage_radius`` up to 1.1 m."""
    rng = np.random.default_rng(seed)
    pot = disc_points(center, 0.15, 0.3, 600, seed)
    leaves = disc_points(center, foliage_radius, 0.8, 1500, seed + 1)
    leaves[:, 2] += 0.3
    return np.concatenate([pot, leaves])[rng.permutation(2100)].astype(np.float32)


def two_rooms() -> OccupancyGrid:
    """The living scene's floor: 10 x 8 m, a wall at x = 3.8 with a door at y 2.5-3.5."""
    return grid_with_wall(-1, -1, 9, 7, wall_x=3.8, door=(2.5, 3.5))


def room_of(r: Retriever) -> dict[int, str]:
    """Map object id -> the room type the retriever's scene gave it."""
    return {o.id: r.scene.rooms[k] for k, o in enumerate(r.objects)}


def grid_with_walls(xmin: float, ymin: float, xmax: float, ymax: float,
                    walls: list[tuple[float, tuple[float, float]]]) -> OccupancyGrid:
    """A FREE rectangle with outer walls and a wall at each x of ``walls``, each with a door (y range)."""
    spec = GridSpec.covering(xmin, ymin, xmax, ymax, 0.05, margin=0.2)
    cells = np.full((spec.rows, spec.cols), FREE, dtype=np.uint8)
    cells[:3, :], cells[-3:, :], cells[:, :3], cells[:, -3:] = OCCUPIED, OCCUPIED, OCCUPIED, OCCUPIED
    for wall_x, (d0, d1) in walls:
        col = int(spec.to_cell(np.array([wall_x, 0.0]))[1])
        cells[:, col - 1:col + 2] = OCCUPIED
        r0 = int(spec.to_cell(np.array([0.0, d0]))[0])
        r1 = int(spec.to_cell(np.array([0.0, d1]))[0])
        cells[r0:r1, col - 1:col + 2] = FREE
    return OccupancyGrid(spec, cells)
