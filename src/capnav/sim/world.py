"""The pybullet world of an apartment: one DIRECT client, static bodies, a body -> instance table.

Structure (floors, ceilings, wall faces) is built from small inward-facing quads: the tiny
renderer rasterises each triangle's screen bounding box and culls back faces, so small one-sided
tiles cost far less than big boxes. Each furniture instance is one multibody whose links are its
parts, so the segmentation mask (body id) maps straight to the manifest instance id.
"""

from __future__ import annotations

import math
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.categories import BY_NAME
from capnav.sim.apartment import Apartment, SceneObject
from capnav.sim.palette import CEILING
from capnav.sim.shapes import Part
from capnav.sim.textures import texture

RGB = tuple[int, int, int]
_AXIS_QUAT = {"z": (0.0, 0.0, 0.0, 1.0), "x": (0.0, math.sqrt(0.5), 0.0, math.sqrt(0.5)),
              "y": (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))}
_TEXTURED_ROLES = ("main", "accent")


def _rgba(rgb: RGB) -> list[float]:
    return [rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0, 1.0]


class Mesh:
    """Accumulates one-sided quads (vertices CCW seen from the normal side) for one visual shape."""

    def __init__(self) -> None:
        self.v: list[list[float]] = []
        self.n: list[list[float]] = []
        self.uv: list[list[float]] = []
        self.idx: list[int] = []

    def quad(self, corners: NDArray[np.float64], normal: tuple[float, float, float]) -> None:
        b = len(self.v)
        self.v += [[float(c) for c in p] for p in corners]
        self.n += [list(normal)] * 4
        self.uv += [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
        self.idx += [b, b + 1, b + 2, b, b + 2, b + 3]


def _tiles(a: float, b: float, step: float) -> list[tuple[float, float]]:
    n = max(1, math.ceil((b - a) / step - 1e-9))
    edges = np.linspace(a, b, n + 1)
    return [(float(edges[i]), float(edges[i + 1])) for i in range(n)]


def _connect_quietly() -> tuple[Any, int]:
    """Import pybullet and open a DIRECT client without its build banner on stdout (the banner would
    clutter CLI output): C stdout/stderr point at /dev/null and flushed before it is restored."""
    import ctypes
    import os
    import sys

    sys.stdout.flush()
    sys.stderr.flush()
    saved = (os.dup(1), os.dup(2))
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            os.dup2(null.fileno(), 2)
            import pybullet

            client = int(pybullet.connect(pybullet.DIRECT))
            try:
                ctypes.CDLL(None).fflush(None)
            except (OSError, AttributeError):  # no libc symbol table (non-POSIX): the banner may show
                pass
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        os.close(saved[0])
        os.close(saved[1])
    return pybullet, client


class BulletWorld:
    """Owns a pybullet DIRECT client with the apartment loaded; close() releases it."""

    def __init__(self, apt: Apartment, textures: bool = True, tile: float = 1.0) -> None:
        self.p, self.client = _connect_quietly()
        self._tmp = Path(tempfile.mkdtemp(prefix="capnav-tex-"))
        self._tex: dict[tuple[str, RGB], int] = {}
        self.textures = textures
        self.tile = tile
        uid_to_instance: dict[int, tuple[int, int]] = {}
        # the colour each visual (body, link) was created with, to restore after hiding its room
        self._colors: dict[int, list[tuple[int, list[float]]]] = {}
        self.room_bodies: list[list[int]] = [[] for _ in apt.plan.rooms]
        try:
            # Creation order is drawing order: near occluders first lets the renderer's depth test
            # skip shading some of the floor/wall pixels hidden behind furniture.
            for o in apt.objects:
                uid = self._build_object(o)
                uid_to_instance[uid] = (o.id, BY_NAME[o.category].id)
                self.room_bodies[o.room].append(uid)
            for it in apt.items:  # small things on furniture: instance ids, no CapNav category
                uid = self._build_object(it)
                uid_to_instance[uid] = (it.id, 0)
                self.room_bodies[it.room].append(uid)
            self._build_structure(apt)
        except Exception:
            self.close()
            raise
        self.shown = set(range(len(self.room_bodies)))
        n = max(uid_to_instance, default=0) + 2
        self.instance_lut = np.zeros(n, dtype=np.int32)  # index: body uid + 1 (so -1 -> 0)
        self.category_lut = np.zeros(n, dtype=np.int32)
        for uid, (iid, cid) in uid_to_instance.items():
            self.instance_lut[uid + 1] = iid
            self.category_lut[uid + 1] = cid

    # -- textures --------------------------------------------------------------------------
    def texture_id(self, pattern: str, rgb: RGB) -> int:
        key = (pattern, rgb)
        if key not in self._tex:
            path = self._tmp / f"{len(self._tex)}.png"
            Image.fromarray(texture(pattern, rgb)).save(path)
            self._tex[key] = int(self.p.loadTexture(str(path), physicsClientId=self.client))
        return self._tex[key]

    def _mesh_body(self, mesh: Mesh, rgb: RGB, pattern: str | None) -> int:
        p = self.p
        textured = self.textures and pattern is not None
        vis = p.createVisualShape(p.GEOM_MESH, vertices=mesh.v, indices=mesh.idx, uvs=mesh.uv, normals=mesh.n,
                                  rgbaColor=[1, 1, 1, 1] if textured else _rgba(rgb), physicsClientId=self.client)
        uid = int(p.createMultiBody(0, -1, vis, physicsClientId=self.client))
        self._colors[uid] = [(-1, [1.0, 1.0, 1.0, 1.0] if textured else _rgba(rgb))]
        if textured and pattern is not None:
            p.changeVisualShape(uid, -1, textureUniqueId=self.texture_id(pattern, rgb), physicsClientId=self.client)
        return uid

    # -- structure -------------------------------------------------------------------------
    def _build_structure(self, apt: Apartment) -> None:
        """Walls first, then floors, then ceilings: drawing order is creation order, and walls hide
        most of what lies behind them (the renderer's depth test then skips shading it)."""
        H = apt.config.layout.wall_height
        for k in range(len(apt.plan.rooms)):
            walls = Mesh()
            for f in (f for f in apt.wall_faces if f.room == k):
                p0, p1 = np.array(f.p0), np.array(f.p1)
                e = p1 - p0
                if e[1] * f.normal[0] - e[0] * f.normal[1] < 0:  # want (p1 - p0) x up == normal
                    p0, p1 = p1, p0
                length = float(np.linalg.norm(p1 - p0))
                for a, b in _tiles(0.0, length, self.tile):
                    qa, qb = p0 + (p1 - p0) * a / length, p0 + (p1 - p0) * b / length
                    for z0, z1 in _tiles(0.0, H, H / 2):
                        walls.quad(np.array([[qa[0], qa[1], z0], [qb[0], qb[1], z0], [qb[0], qb[1], z1],
                                             [qa[0], qa[1], z1]]), (f.normal[0], f.normal[1], 0.0))
            if walls.v:
                self.room_bodies[k].append(self._mesh_body(walls, apt.wall_colors[k], None))
        for level in ("floor", "ceiling"):
            for k, r in enumerate(apt.plan.rooms):
                mesh = Mesh()
                for x0, x1 in _tiles(r.x0, r.x1, self.tile):
                    for y0, y1 in _tiles(r.y0, r.y1, self.tile):
                        if level == "floor":
                            mesh.quad(np.array([[x0, y0, 0], [x1, y0, 0], [x1, y1, 0], [x0, y1, 0]]), (0, 0, 1))
                        else:
                            mesh.quad(np.array([[x0, y0, H], [x0, y1, H], [x1, y1, H], [x1, y0, H]]), (0, 0, -1))
                pattern, rgb = apt.floor_styles[k]
                body = self._mesh_body(mesh, rgb, pattern) if level == "floor" else self._mesh_body(mesh, CEILING, None)
                self.room_bodies[k].append(body)

    # -- furniture -------------------------------------------------------------------------
    def _part_shape(self, part: Part, rgb: RGB) -> int:
        p = self.p
        h = [s / 2 for s in part.size]
        rgba = _rgba(rgb)
        q = _AXIS_QUAT[part.axis]
        if part.kind == "box":
            return int(p.createVisualShape(p.GEOM_BOX, halfExtents=h, rgbaColor=rgba, physicsClientId=self.client))
        if part.kind == "sphere":
            return int(p.createVisualShape(p.GEOM_SPHERE, radius=h[0], rgbaColor=rgba, physicsClientId=self.client))
        length = part.size["xyz".index(part.axis)]
        radius = part.size[(("xyz".index(part.axis)) + 1) % 3] / 2
        return int(p.createVisualShape(p.GEOM_CYLINDER, radius=radius, length=length, rgbaColor=rgba,
                                       visualFrameOrientation=q, physicsClientId=self.client))

    def _build_object(self, o: SceneObject) -> int:
        if o.mesh is not None:
            from capnav.sim.sh3d import build_mesh_body

            return build_mesh_body(self, o)
        p = self.p
        parts = o.model.parts
        shapes, patterns, colors = [], [], []
        for part in parts:
            rgb = o.roles.get(part.role, o.roles["main"])
            pattern: tuple[str, RGB] | None = None
            if part.role.startswith("books:"):  # a block of book spines: always textured
                k = int(part.role.split(":")[1])
                pattern = ("books", (k, k, k))
            elif self.textures and part.role in _TEXTURED_ROLES:
                pattern = (o.material, rgb)
            color = (255, 255, 255) if pattern is not None else rgb
            shapes.append(self._part_shape(part, color))
            patterns.append(pattern)
            colors.append(_rgba(color))
        n = len(parts)
        kw: dict[str, Any] = dict(
            linkMasses=[0.0] * n, linkCollisionShapeIndices=[-1] * n, linkVisualShapeIndices=shapes,
            linkPositions=[list(part.center) for part in parts], linkOrientations=[[0, 0, 0, 1]] * n,
            linkInertialFramePositions=[[0, 0, 0]] * n, linkInertialFrameOrientations=[[0, 0, 0, 1]] * n,
            linkParentIndices=[0] * n, linkJointTypes=[p.JOINT_FIXED] * n, linkJointAxis=[[0, 0, 1]] * n)
        quat = p.getQuaternionFromEuler([0.0, 0.0, o.yaw])
        uid = int(p.createMultiBody(0, -1, -1, basePosition=[o.x, o.y, 0.0], baseOrientation=quat,
                                    physicsClientId=self.client, **kw))
        self._colors[uid] = list(enumerate(colors))
        for link, pat in enumerate(patterns):
            if pat is not None:
                p.changeVisualShape(uid, link, textureUniqueId=self.texture_id(*pat), physicsClientId=self.client)
        return uid

    # -- rendering -------------------------------------------------------------------------
    def show_rooms(self, rooms: set[int]) -> None:
        """Show exactly ``rooms`` (structure and furniture); the renderer skips alpha-0 visuals."""
        p = self.p
        for k, bodies in enumerate(self.room_bodies):
            want = k in rooms
            if want == (k in self.shown):
                continue
            for uid in bodies:
                for link, rgba in self._colors[uid]:
                    color = rgba if want else [rgba[0], rgba[1], rgba[2], 0.0]
                    p.changeVisualShape(uid, link, rgbaColor=color, physicsClientId=self.client)
        self.shown = set(rooms)

    def render(self, width: int, height: int, view: list[float], proj: list[float], shadows: bool = False,
               segmentation: bool = True) -> tuple[NDArray[np.uint8], NDArray[np.float32], NDArray[np.int32]]:
        """Raw (rgba uint8, depth buffer float32 in [0, 1], body-uid segmentation int32) images."""
        p = self.p
        flags = 0 if segmentation else p.ER_NO_SEGMENTATION_MASK
        _, _, rgba, depth, seg = p.getCameraImage(
            width, height, view, proj, renderer=p.ER_TINY_RENDERER, flags=flags, shadow=int(shadows),
            lightDirection=[0.4, 0.3, 1.0], lightAmbientCoeff=0.6, lightDiffuseCoeff=0.45,
            lightSpecularCoeff=0.05, physicsClientId=self.client)
        rgba = np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)
        depth = np.asarray(depth, dtype=np.float32).reshape(height, width)
        seg = np.asarray(seg, dtype=np.int32).reshape(height, width)
        return rgba, depth, seg

    def close(self) -> None:
        if getattr(self, "client", -1) >= 0:
            try:
                self.p.disconnect(physicsClientId=self.client)
            except Exception:  # already disconnected (interpreter shutdown)
                pass
            self.client = -1
        if hasattr(self, "_tmp"):
            shutil.rmtree(self._tmp, ignore_errors=True)

    def __del__(self) -> None:
        self.close()
