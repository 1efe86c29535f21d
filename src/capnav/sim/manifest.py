"""The scene manifest: the simulator's ground truth, for the simulator detector and evaluation only.

The mapping, captioning and retrieval pipeline never reads it. Versioned; saved as
``manifest.json`` beside a generated scene / dataset. See docs/formats.md.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import BaseModel, Field, SerializerFunctionWrapHandler, ValidationError, model_serializer

from capnav.core.atomic import write_text
from capnav.core.errors import DatasetError
from capnav.core.jsonfile import read_json_object

MANIFEST_VERSION = 1

Vec2 = tuple[float, float]
Vec3 = tuple[float, float, float]


class ObjectInstance(BaseModel):
    """One physical object. ``id`` equals the instance id in the rendered ``gt_instance`` images."""

    id: int = Field(ge=1)
    category: str
    category_id: int = Field(ge=1)
    color_name: str
    color_rgb: tuple[int, int, int]
    material: str
    shape: str = Field(description="shape variant, e.g. 'curved', 'round', 'l-shaped'")
    size: Vec3 = Field(description="extent (m) along the object's local x, y, z axes")
    center: Vec3 = Field(description="centre of the oriented box in the world (m)")
    yaw: float = Field(description="rotation about world z (rad) of the local x axis")
    footprint: list[Vec2] = Field(description="4 world (x, y) corners of the 2D footprint, counter-clockwise")
    room: str = Field(description="id of the room containing the centre")
    model: str = Field(description="'primitive:<name>' or 'sh3d:<catalog id>'")
    license: str = "CC0-1.0"


class ItemInstance(BaseModel):
    """A small thing standing on a piece of furniture (``capnav sim --surface-items``). Its
    ``category`` is a COCO class name (cup, bottle, book, vase, bowl, laptop), not a CapNav
    category; ``support`` is the id of the object it stands on. ``id`` is its instance id in
    ``gt_instance`` (after the objects' ids)."""

    id: int = Field(ge=1)
    category: str
    color_name: str
    size: Vec3 = Field(description="extent (m) along the item's local x, y, z axes")
    center: Vec3
    yaw: float
    footprint: list[Vec2]
    room: str
    support: int = Field(ge=1, description="id of the object it stands on")


class ObjectChange(BaseModel):
    """One change between visit 1 and a later visit; poses are (x, y, yaw) in the apartment frame."""

    kind: str = Field(description="moved | removed | added | hidden (moved into a room the visit's "
                      "recording does not enter)")
    id: int = Field(ge=1, description="manifest id (the same object keeps its id across visits)")
    category: str
    old_pose: Vec3 | None = None
    new_pose: Vec3 | None = None
    old_room: str | None = None
    new_room: str | None = None


class Room(BaseModel):
    id: str
    name: str = Field(description="room type: living room, kitchen, bedroom, bathroom, office, hallway")
    polygon: list[Vec2]


class Door(BaseModel):
    rooms: tuple[str, str]
    center: Vec2
    width: float


class SceneManifest(BaseModel):
    version: int = MANIFEST_VERSION
    seed: int
    generator: str = "capnav.sim.apartment"
    bounds: tuple[float, float, float, float] = Field(description="xmin, ymin, xmax, ymax of the walls (m)")
    wall_height: float
    rooms: list[Room]
    doors: list[Door] = []
    objects: list[ObjectInstance]
    items: list[ItemInstance] | None = None  # absent from the file unless the scene has items
    visit: int = Field(default=1, ge=1, description="1 = the apartment as generated; later visits hold `changes`")
    changes: list[ObjectChange] = []
    frame_offset: tuple[float, float, float] | None = Field(
        default=None, description="(x, y, yaw) of the recording's world frame in the apartment frame, when offset")

    @model_serializer(mode="wrap")
    def _without_empty_items(self, handler: SerializerFunctionWrapHandler) -> dict[str, Any]:
        data: dict[str, Any] = handler(self)
        if data.get("items") is None:
            data.pop("items", None)  # default scenes keep their manifest bytes (and cache keys)
        if data.get("visit") == 1 and data.get("frame_offset") is None:  # and so do first visits
            for k in ("visit", "changes", "frame_offset"):
                data.pop(k, None)
        return data

    def object(self, instance_id: int) -> ObjectInstance:
        for o in self.objects:
            if o.id == instance_id:
                return o
        raise KeyError(f"no instance {instance_id} in scene seed {self.seed}")

    def by_category(self, name: str) -> list[ObjectInstance]:
        return [o for o in self.objects if o.category == name]

    def save(self, path: str | Path) -> None:
        write_text(path, self.model_dump_json(indent=2) + "\n")

    @classmethod
    def load(cls, path: str | Path) -> SceneManifest:
        p = Path(path)
        data = read_json_object(p, "manifest")
        if data.get("version") != MANIFEST_VERSION:
            raise DatasetError(f"manifest {p} has version {data.get('version')}, expected {MANIFEST_VERSION}")
        try:
            return cls.model_validate(data)
        except ValidationError as e:
            raise DatasetError(f"manifest {p} is malformed: {_first_problem(e)}") from None


def _first_problem(e: ValidationError) -> str:
    """The first field pydantic refused, in one line ("objects[3].category is missing"), and how
    many more there are; not pydantic's multi-line dump with its documentation link."""
    errs = e.errors(include_url=False)
    first = errs[0]
    where = "".join(f"[{k}]" if isinstance(k, int) else f".{k}" for k in first["loc"]).lstrip(".") or "the top level"
    what = "is missing" if first["type"] == "missing" else f"is wrong: {first['msg']}"
    more = f" (and {len(errs) - 1} more problem{'s' if len(errs) > 2 else ''})" if len(errs) > 1 else ""
    return f"{where} {what}{more}"
