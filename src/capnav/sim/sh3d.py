"""Real furniture meshes from Debian's ``sweethome3d-furniture`` package (fetched by ``capnav assets``).

``fetch_assets`` runs ``apt-get download`` + ``dpkg-deb -x``, reads each catalog's
``PluginFurnitureCatalog.properties`` (name, category, size, creator, licence), keeps the models
that map to CapNav's categories, and splits every multi-material OBJ into one OBJ per material
(pybullet keeps a single colour per visual shape, so an unsplit model loses its colours). The split
meshes are normalised to a unit box in CapNav's object frame (x width, y depth with the front at
+y, z up, origin on the floor at the footprint centre), so an instance is drawn with
``meshScale = (w, d, h)``. Meshes are never committed; they live in a cache folder.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

from capnav.core.atomic import write_json, write_text
from capnav.core.errors import CapNavError, DatasetError
from capnav.core.progress import track

if TYPE_CHECKING:
    from capnav.sim.apartment import SceneObject

PACKAGE = "sweethome3d-furniture"
CATALOG_VERSION = 1
DEFAULT_DIR = Path.home() / ".cache" / "capnav" / "assets"
# SPDX ids of the catalogs (debian/copyright of the package).
LICENSES = {"BlendSwap-CC-0": "CC0-1.0", "BlendSwap-CC-BY": "CC-BY-3.0", "KatorLegaz": "CC-BY-3.0-US",
            "Reallusion": "CC-BY-3.0-US", "Scopia": "CC-BY-3.0"}
# First matching pattern (on the lower-case model name) wins; more specific names come first.
NAME_RULES: list[tuple[str, str]] = [
    (r"washing machine|washer", "washing machine"), (r"refrigerator|fridge", "refrigerator"),
    (r"night ?stand|bedside", "nightstand"), (r"coffee table|low table|side table", "coffee table"),
    (r"\bdesk\b", "desk"), (r"armchair|arm chair|relax chair|recliner", "armchair"),
    (r"sofa|couch|settee", "sofa"), (r"\bstool\b", "stool"), (r"ottoman|pouf|footstool", "ottoman"),
    (r"\bchair\b", "chair"), (r"\bbed\b|double bed|single bed", "bed"), (r"wardrobe|closet|armoire", "wardrobe"),
    (r"dresser|chest of drawers|\bchest\b|commode", "dresser"),
    (r"book ?case|book ?shelf|shelves|shelving", "bookshelf"),
    (r"\btv\b|television", "tv"), (r"\blamp\b|floor light", "lamp"), (r"\bplant\b|\bficus\b|\bpalm\b", "plant"),
    (r"toilet|\bwc\b", "toilet"), (r"washbasin|\bsink\b|wash basin", "sink"), (r"bath ?tub|\bbath\b", "bathtub"),
    (r"\bstove\b|cooker|\boven\b|\brange\b", "stove"), (r"counter|worktop", "counter"),
    (r"sideboard|cupboard|\bcabinet\b", "cabinet"), (r"\btable\b", "table"),
]
_EXCLUDE = re.compile(r"upper|wall|corner cabinet|hood|radiator|tablecloth|\bmini\b|toy|doll|outdoor|garden|pool|"
                      r"light bulb|lampshade|pot\b|cup\b|\bbox\b|remote|brush|paper|tennis|football|\bfan\b|"
                      r"ceiling|chandelier|pendant|street|camping|freezer|baby|child|hospital|beach|deck chair|"
                      r"changing|tv stand|television cabinet|desk lamp|bunk|mezzanine|opened|folding")


def map_category(name: str) -> str | None:
    """CapNav category of a Sweet Home 3D model name, or None when it is none of ours."""
    n = name.lower()
    if _EXCLUDE.search(n):
        return None
    for pattern, cat in NAME_RULES:
        if re.search(pattern, n):
            return cat
    return None


def parse_properties(text: str) -> dict[str, str]:
    """Java ``.properties``: ``key=value`` lines, ``#`` comments, ``\\`` continuations, ``\\uXXXX`` escapes."""
    out: dict[str, str] = {}
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i].strip()
        i += 1
        if not line or line[0] in "#!":
            continue
        while line.endswith("\\") and i < len(lines):
            line = line[:-1] + lines[i].strip()
            i += 1
        key, sep, value = line.partition("=")
        if not sep:
            key, sep, value = line.partition(":")
        if sep:
            value = re.sub(r"\\u([0-9a-fA-F]{4})", lambda m: chr(int(m.group(1), 16)), value.strip())
            out[key.strip()] = value.replace("\\:", ":").replace("\\=", "=")
    return out


def catalog_models(props: dict[str, str], catalog: str) -> list[dict[str, Any]]:
    """Entries of one catalog that map to a CapNav category (no doors/windows)."""
    out = []
    for key in props:
        if not key.startswith("id#"):
            continue
        k = key[3:]
        name = props.get(f"name#{k}", "")
        cat = map_category(name)
        if cat is None or props.get(f"doorOrWindow#{k}", "false") == "true" or f"model#{k}" not in props:
            continue
        try:
            size = [float(props[f"{d}#{k}"]) / 100.0 for d in ("width", "depth", "height")]
        except (KeyError, ValueError):
            continue
        rot = props.get(f"modelRotation#{k}")
        out.append({"id": props[key], "name": name, "category": cat, "sh3d_category": props.get(f"category#{k}", ""),
                    "catalog": catalog, "license": LICENSES.get(catalog, "CC-BY-3.0"),
                    "creator": props.get(f"creator#{k}", ""), "size": size, "model": props[f"model#{k}"],
                    "rotation": [float(v) for v in rot.split()] if rot else None})
    return out


@dataclass(frozen=True)
class ObjMesh:
    vertices: NDArray[np.float64]  # (V, 3)
    faces: list[tuple[str, NDArray[np.int64]]]  # (material, (F, 3) triangle vertex indices)
    materials: dict[str, tuple[float, float, float]]  # material -> diffuse RGB in [0, 1]


def read_obj(path: Path) -> ObjMesh:
    """Positions, triangulated faces grouped by material, and MTL diffuse colours (a ``map_Kd``
    texture contributes its mean colour, so textured materials keep their look)."""
    verts: list[list[float]] = []
    groups: dict[str, list[list[int]]] = {}
    mtl = "default"
    libs: list[str] = []
    with open(path, encoding="latin-1") as fh:
        for line in fh:
            if line.startswith("v "):
                verts.append([float(v) for v in line.split()[1:4]])
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) for t in line.split()[1:]]
                idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
                g = groups.setdefault(mtl, [])
                for j in range(1, len(idx) - 1):
                    g.append([idx[0], idx[j], idx[j + 1]])
            elif line.startswith("usemtl"):
                mtl = line.split(maxsplit=1)[1].strip() if len(line.split()) > 1 else "default"
            elif line.startswith("mtllib"):
                libs.append(line.split(maxsplit=1)[1].strip())
    colors: dict[str, tuple[float, float, float]] = {}
    for lib in libs:
        colors.update(_read_mtl(path.parent / lib))
    faces = [(m, np.asarray(f, dtype=np.int64)) for m, f in groups.items() if f]
    return ObjMesh(np.asarray(verts, dtype=np.float64).reshape(-1, 3), faces, colors)


def _read_mtl(path: Path) -> dict[str, tuple[float, float, float]]:
    out: dict[str, tuple[float, float, float]] = {}
    if not path.exists():
        return out
    name = None
    for line in path.read_text(encoding="latin-1").splitlines():
        parts = line.split()
        if not parts:
            continue
        if parts[0] == "newmtl":
            name = " ".join(parts[1:])
            out[name] = (0.8, 0.8, 0.8)
        elif name is not None and parts[0] == "Kd" and len(parts) >= 4:
            out[name] = (float(parts[1]), float(parts[2]), float(parts[3]))
        elif name is not None and parts[0] == "map_Kd":
            tex = path.parent / parts[-1]
            try:
                from PIL import Image

                with Image.open(tex) as im:
                    mean = np.asarray(im.convert("RGB").resize((16, 16))).reshape(-1, 3).mean(axis=0) / 255.0
                kd = out[name]
                out[name] = (float(mean[0] * kd[0]), float(mean[1] * kd[1]), float(mean[2] * kd[2]))
            except (OSError, ValueError):
                pass
    return out


def _to_capnav_frame(v: NDArray[np.float64], rotation: list[float] | None) -> NDArray[np.float64]:
    """Sweet Home 3D model axes (x right, y up, front towards +z) -> CapNav object axes (x, y front, z up),
    normalised to the unit box [-0.5, 0.5]^2 x [0, 1]."""
    if rotation is not None and len(rotation) == 9:
        v = v @ np.asarray(rotation).reshape(3, 3).T
    ours = np.stack([-v[:, 0], v[:, 2], v[:, 1]], axis=1)  # a proper rotation (det +1)
    lo, hi = ours.min(axis=0), ours.max(axis=0)
    ext = np.maximum(hi - lo, 1e-9)
    out = (ours - lo) / ext
    out[:, :2] -= 0.5
    return np.asarray(out)


def split_model(obj: Path, out_dir: Path, rotation: list[float] | None) -> list[dict[str, Any]]:
    """Write one OBJ per material (unit box, CapNav axes, flat normals); returns [{obj, rgba, area}]."""
    mesh = read_obj(obj)
    if len(mesh.vertices) == 0 or not mesh.faces:
        raise DatasetError(f"{obj} has no geometry")
    v = _to_capnav_frame(mesh.vertices, rotation)
    out_dir.mkdir(parents=True, exist_ok=True)
    parts = []
    for k, (mtl, f) in enumerate(mesh.faces):
        used, inv = np.unique(f.reshape(-1), return_inverse=True)
        tri = inv.reshape(-1, 3)
        pv = v[used]
        n = np.cross(pv[tri[:, 1]] - pv[tri[:, 0]], pv[tri[:, 2]] - pv[tri[:, 0]])
        area = np.linalg.norm(n, axis=1)
        n = n / np.maximum(area, 1e-12)[:, None]
        lines = [f"v {a:.6f} {b:.6f} {c:.6f}" for a, b, c in pv]
        lines += [f"vn {a:.5f} {b:.5f} {c:.5f}" for a, b, c in n]
        lines += [f"f {a + 1}//{i + 1} {b + 1}//{i + 1} {c + 1}//{i + 1}" for i, (a, b, c) in enumerate(tri)]
        path = out_dir / f"part{k}.obj"
        write_text(path, "\n".join(lines) + "\n")
        rgb = mesh.materials.get(mtl, (0.8, 0.8, 0.8))
        parts.append({"obj": path.name, "rgba": [*map(float, rgb), 1.0], "area": float(area.sum() / 2)})
    return parts


def _run(cmd: list[str], cwd: Path) -> None:
    try:
        subprocess.run(cmd, cwd=cwd, check=True, capture_output=True, text=True)
    except FileNotFoundError:
        raise CapNavError(f"`{cmd[0]}` not found: `capnav assets` needs a Debian/Ubuntu system "
                          f"(or extract the {PACKAGE} .deb yourself and pass --deb)") from None
    except subprocess.CalledProcessError as e:
        raise CapNavError(f"`{' '.join(cmd)}` failed: {(e.stderr or e.stdout).strip()[-400:]}") from None


def fetch_assets(dest: Path | None = None, deb: Path | None = None, catalogs: list[str] | None = None,
                 progress: bool = True) -> Path:
    """Download (or take ``deb``), extract, select and split the meshes; returns ``dest/catalog.json``."""
    dest = Path(dest) if dest is not None else DEFAULT_DIR
    dest.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="capnav-sh3d-") as tmp_s:
        tmp = Path(tmp_s)
        if deb is None:
            _run(["apt-get", "download", PACKAGE], tmp)
            debs = sorted(tmp.glob(f"{PACKAGE}_*.deb"))
            if not debs:
                raise CapNavError(f"apt-get download {PACKAGE} produced no .deb (is the package in your sources?)")
            deb = debs[0]
        if not Path(deb).exists():
            raise CapNavError(f"no such .deb: {deb}")
        _run(["dpkg-deb", "-x", str(Path(deb).resolve()), str(tmp / "x")], tmp)
        files = sorted((tmp / "x").rglob("*.sh3f"))
        if not files:
            raise CapNavError(f"{deb} holds no .sh3f furniture catalogs")
        entries = []
        for sh3f in files:
            name = sh3f.stem
            if catalogs and name not in catalogs:
                continue
            with zipfile.ZipFile(sh3f) as z:
                props = parse_properties(z.read("PluginFurnitureCatalog.properties").decode("latin-1"))
                models = catalog_models(props, name)
                members = set(z.namelist())
                for m in track(models, f"{name}: {len(models)} models", enabled=progress):
                    model_path = PurePosixPath(m["model"].lstrip("/"))
                    folder = str(model_path.parent)
                    for member in members:
                        if member.startswith(folder + "/") and not member.endswith("/"):
                            z.extract(member, dest / "raw" / name)
                    obj = dest / "raw" / name / model_path
                    if not obj.exists():
                        continue
                    safe = re.sub(r"[^A-Za-z0-9_.-]+", "_", m["id"])
                    try:
                        m["parts"] = split_model(obj, dest / "split" / safe, m["rotation"])
                    except (DatasetError, ValueError, IndexError):
                        continue
                    m["dir"] = f"split/{safe}"
                    entries.append(m)
    shutil.rmtree(dest / "raw", ignore_errors=True)
    out = dest / "catalog.json"
    write_json(out, {"version": CATALOG_VERSION, "package": PACKAGE, "models": entries})
    return out


@dataclass(frozen=True)
class MeshModel:
    """One catalog model ready to draw: per-material unit meshes and their colours."""

    id: str
    name: str
    category: str
    license: str
    creator: str
    size: tuple[float, float, float]
    parts: tuple[tuple[str, tuple[float, float, float, float], float], ...]  # (abs obj path, rgba, area)


def load_catalog(dest: Path | None = None) -> list[MeshModel]:
    dest = Path(dest) if dest is not None else DEFAULT_DIR
    p = dest / "catalog.json"
    if not p.exists():
        raise DatasetError(f"no furniture meshes in {dest}: run `capnav assets --dir {dest}` first "
                           "(or use SimConfig.furniture='primitives')")
    try:
        data = json.loads(p.read_text())
    except json.JSONDecodeError as e:
        raise DatasetError(f"{p} is not valid JSON: {e}") from None
    if data.get("version") != CATALOG_VERSION:
        raise DatasetError(f"{p} has version {data.get('version')}, expected {CATALOG_VERSION}: re-run capnav assets")
    out = []
    for m in data["models"]:
        m["category"] = map_category(m["name"])  # today's rules, so a rule fix needs no re-download
        if m["category"] is None:
            continue
        parts = tuple((str(dest / m["dir"] / q["obj"]), tuple(q["rgba"]), float(q["area"])) for q in m["parts"])
        if all(Path(q[0]).exists() for q in parts):
            out.append(MeshModel(m["id"], m["name"], m["category"], m["license"], m["creator"],
                                 tuple(m["size"]), parts))  # type: ignore[arg-type]
    return out


class MeshWorld(Protocol):
    """What ``build_mesh_body`` needs of a pybullet world (``capnav.sim.world.BulletWorld``, which
    imports this module: typed structurally so the two do not import each other)."""

    p: Any
    client: int
    _colors: dict[int, list[tuple[int, list[float]]]]


def build_mesh_body(world: MeshWorld, o: SceneObject) -> int:
    """A multibody with one link per material mesh, scaled to the instance's (w, d, h)."""
    mesh = o.mesh
    assert isinstance(mesh, MeshModel)
    p = world.p
    w, d, h = o.model.size
    shapes, colors = [], []
    for path, rgba, _ in mesh.parts:
        shapes.append(int(p.createVisualShape(p.GEOM_MESH, fileName=path, meshScale=[w, d, h], rgbaColor=list(rgba),
                                              physicsClientId=world.client)))
        colors.append(list(rgba))
    n = len(shapes)
    uid = int(p.createMultiBody(
        0, -1, -1, basePosition=[o.x, o.y, 0.0], baseOrientation=p.getQuaternionFromEuler([0.0, 0.0, o.yaw]),
        linkMasses=[0.0] * n, linkCollisionShapeIndices=[-1] * n, linkVisualShapeIndices=shapes,
        linkPositions=[[0, 0, 0]] * n, linkOrientations=[[0, 0, 0, 1]] * n,
        linkInertialFramePositions=[[0, 0, 0]] * n, linkInertialFrameOrientations=[[0, 0, 0, 1]] * n,
        linkParentIndices=[0] * n, linkJointTypes=[p.JOINT_FIXED] * n, linkJointAxis=[[0, 0, 1]] * n,
        physicsClientId=world.client))
    world._colors[uid] = list(enumerate(colors))
    return uid
