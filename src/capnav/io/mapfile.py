"""The CapNav map file: one zip archive, no pickle, validated on load.

Layout (format ``capnav-map``, version 4; versions 1 to 3 still load)::

    header.json            format, version, and for every other entry: sha256, size, and for
                           arrays their dtype and shape
    meta.json caches.json  the map's JSON-able metadata and the later stages' caches
    objects.json           per object: scalar / JSON fields, observations, views (without bytes),
                           and the shape of each of its arrays
    objects/<field>.npy    that array field of every object, flattened and concatenated
    views/<o>_<k>_<kind>.png  view PNG bytes (frame / crop)
    voxels/*.npy, occupancy/cells.npy, grids in objects.json / header.json
    trajectory/frames.npy trajectory/poses.npy   (version 2, when the map recorded one) the
                           fused frames' indices and camera-to-world poses (N, 4, 4)
    retired/objects.json retired/objects/<field>.npy retired/views/...   (version 4, when a later
                           recording retired objects) the retired objects, laid out like the present

Arrays are ``.npy`` written and read with ``allow_pickle=False``. Loading checks the format name,
the version, every entry's presence, checksum, dtype and shape, and the cross-array consistency;
any failure is a ``MapFileError`` that names the file and what is wrong. Writes are atomic.
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import io
import json
import warnings
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.atomic import write_with
from capnav.core.errors import CapNavError, InputError, MapFileError
from capnav.core.grid import GridSpec, OccupancyGrid
from capnav.mapping.cmap import CameraTrajectory, CapNavMap
from capnav.mapping.objects import MapObject, ObjectView, Observation
from capnav.mapping.voxel_map import VoxelMap

FORMAT = "capnav-map"
VERSION = 4
# version 1: no trajectory/; version 2: voxel features always float32 and arrays stored
# uncompressed; version 3: voxel features float16 by default (``save_map(feature_dtype=...)``) and
# arrays DEFLATE-compressed (level 1: 4x on an apartment's features, ~0.1 s to inflate).
# version 4: objects carry ``last_seen`` and ``history`` and the map its ``retired`` objects (map updates).
READS = (1, 2, 3, 4)
FEATURE_DTYPES = ("float16", "float32")
_F16_MAX = float(np.finfo(np.float16).max)
_OBJ_FIELDS = [f.name for f in dataclasses.fields(MapObject)]
_ARRAY_DTYPES = {"position": np.float64, "extent_min": np.float64, "extent_max": np.float64,
                 "footprint": np.float64, "points": np.float32, "colors": np.uint8, "feature": np.float32,
                 "embedding": np.float32}


def _npy(arr: NDArray[Any]) -> bytes:
    buf = io.BytesIO()
    np.save(buf, np.ascontiguousarray(arr), allow_pickle=False)
    return buf.getvalue()


def _json(obj: Any, what: str) -> bytes:
    try:
        return json.dumps(obj, indent=1, allow_nan=True).encode("utf-8")
    except (TypeError, ValueError) as e:
        raise MapFileError(f"cannot save the map: {what} is not JSON-serialisable ({e})") from None


def _encode_objects(objects: list[MapObject], prefix: str = "") -> tuple[list[dict[str, Any]], dict[str, bytes]]:
    records: list[dict[str, Any]] = []
    blobs: dict[str, bytes] = {}
    arrays: dict[str, list[NDArray[Any]]] = {}
    for n, o in enumerate(objects):
        rec: dict[str, Any] = {"arrays": {}}
        for name in _OBJ_FIELDS:
            val = getattr(o, name)
            if name in _ARRAY_DTYPES:
                if val is None:
                    rec["arrays"][name] = None
                    continue
                a = np.asarray(val, dtype=_ARRAY_DTYPES[name])
                rec["arrays"][name] = list(a.shape)
                arrays.setdefault(name, []).append(a.reshape(-1))
            elif name == "observations":
                rec[name] = [dataclasses.asdict(ob) for ob in val]
            elif name == "views":
                views = []
                for k, v in enumerate(val):
                    d = dataclasses.asdict(v)
                    for kind in ("frame_png", "crop_png"):
                        data = d.pop(kind)
                        key = f"{prefix}views/{n}_{k}_{kind[:-4]}.png"
                        d[kind] = key if data else None
                        if data:
                            blobs[key] = bytes(data)
                    views.append(d)
                rec[name] = views
            else:
                rec[name] = val
        records.append(rec)
    for name, dtype in _ARRAY_DTYPES.items():
        parts = arrays.get(name, [])
        blobs[f"{prefix}objects/{name}.npy"] = _npy(np.concatenate(parts) if parts else np.zeros(0, dtype=dtype))
    return records, blobs


def save_map(cmap: CapNavMap, path: str | Path, feature_dtype: str = "float16") -> Path:
    """Write ``cmap`` to ``path`` atomically (a crash never leaves a half-written map).

    Voxel features (eq. 6) are stored as ``feature_dtype``: float16 by default, half the bytes of
    the dominant entry at a relative error <= 2^-11 per value. Only dense voxel queries read them
    (the VLMaps-style baseline); CapNav's object retrieval does not (benchmarks/bench_mapfile.py
    measures both). ``"float32"`` keeps them bit for bit. Features beyond float16's range are kept
    in float32 with a warning that says so."""
    if feature_dtype not in FEATURE_DTYPES:
        raise InputError(f"feature_dtype must be one of {', '.join(FEATURE_DTYPES)}, got {feature_dtype!r}")
    vox = cmap.voxels
    feats = vox.features
    if feature_dtype == "float16":
        if feats.size and not float(np.max(np.abs(feats))) <= _F16_MAX:
            warnings.warn(f"voxel features exceed float16's range (|f| > {_F16_MAX:g}) or are not finite; "
                          "storing them as float32", stacklevel=2)
        else:
            feats = feats.astype(np.float16)
    records, blobs = _encode_objects(cmap.objects)
    blobs["voxels/coords.npy"] = _npy(vox.coords)
    blobs["voxels/colors.npy"] = _npy(vox.colors)
    blobs["voxels/weights.npy"] = _npy(vox.weights)
    blobs["voxels/features.npy"] = _npy(feats)
    if vox.projection is not None:
        blobs["voxels/projection.npy"] = _npy(vox.projection)
    blobs["occupancy/cells.npy"] = _npy(cmap.occupancy.cells)
    if cmap.trajectory is not None:
        blobs["trajectory/frames.npy"] = _npy(cmap.trajectory.frames)
        blobs["trajectory/poses.npy"] = _npy(cmap.trajectory.poses)
    blobs["objects.json"] = _json(records, "an object field")
    if cmap.retired:
        old, old_blobs = _encode_objects(cmap.retired, "retired/")
        blobs.update(old_blobs)
        blobs["retired/objects.json"] = _json(old, "a retired object's field")
    blobs["meta.json"] = _json(cmap.meta, "meta")
    blobs["caches.json"] = _json(cmap.caches, "caches")
    entries: dict[str, dict[str, Any]] = {}
    for name, data in blobs.items():
        e: dict[str, Any] = {"sha256": hashlib.sha256(data).hexdigest(), "bytes": len(data)}
        if name.endswith(".npy"):
            arr = np.load(io.BytesIO(data), allow_pickle=False)
            e["dtype"], e["shape"] = arr.dtype.str, list(arr.shape)
        entries[name] = e
    header = {
        "format": FORMAT, "version": VERSION, "n_objects": len(cmap.objects), "n_voxels": len(vox),
        "voxels": {"resolution": vox.resolution, "origin": vox.origin.tolist(), "dim": vox.dim,
                   "text_space": vox.text_space},
        "occupancy": cmap.occupancy.spec.to_dict(), "entries": entries,
    }

    def writer(fh: IO[bytes]) -> None:
        with zipfile.ZipFile(fh, "w") as zf:
            for name, data in [*blobs.items(), ("header.json", _json(header, "header"))]:
                # A fixed timestamp keeps the file bit-identical for identical maps.
                info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
                # PNGs are compressed already; JSON and arrays deflate (arrays at level 1: most of
                # the gain at a fifth of level 6's time).
                png = name.endswith(".png")
                info.compress_type = zipfile.ZIP_STORED if png else zipfile.ZIP_DEFLATED
                info.external_attr = 0o644 << 16
                zf.writestr(info, data, compresslevel=None if png or name.endswith(".json") else 1)

    out = Path(path)
    write_with(out, writer)
    return out


class _Reader:
    def __init__(self, path: Path, zf: zipfile.ZipFile, header: dict[str, Any]) -> None:
        self.path, self.zf, self.entries = path, zf, header["entries"]

    def fail(self, msg: str) -> MapFileError:
        return MapFileError(f"{self.path}: {msg}")

    def raw(self, name: str) -> bytes:
        if name not in self.entries:
            raise self.fail(f"entry {name!r} is missing from the header")
        try:
            data = self.zf.read(name)
        except KeyError:
            raise self.fail(f"entry {name!r} is missing (truncated file?)") from None
        except (zipfile.BadZipFile, zlib.error, EOFError, OSError) as e:
            raise self.fail(f"entry {name!r} is unreadable ({e}); the file is corrupt or truncated") from None
        ent = self.entries[name]
        if len(data) != ent.get("bytes") or hashlib.sha256(data).hexdigest() != ent.get("sha256"):
            raise self.fail(f"entry {name!r} fails its sha256 checksum (corrupted)")
        return data

    def json(self, name: str) -> Any:
        try:
            return json.loads(self.raw(name).decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as e:
            raise self.fail(f"entry {name!r} is not valid JSON ({e})") from None

    def array(self, name: str) -> NDArray[Any]:
        data = self.raw(name)
        try:
            arr = np.load(io.BytesIO(data), allow_pickle=False)
        except (ValueError, OSError) as e:
            raise self.fail(f"array {name!r} is not a valid .npy without pickles ({e})") from None
        ent = self.entries[name]
        if arr.dtype.str != ent.get("dtype") or list(arr.shape) != ent.get("shape"):
            raise self.fail(f"array {name!r} is {arr.dtype.str} {list(arr.shape)}, header says "
                            f"{ent.get('dtype')} {ent.get('shape')}")
        return arr


def load_map(path: str | Path, voxels: bool = True) -> CapNavMap:
    """Read and validate a map file; any problem raises ``MapFileError`` saying what is wrong.

    ``voxels=False`` skips the voxel arrays (most of the file): the map gets an empty voxel map
    with the stored resolution, origin, feature dim and projection. For readers that use only
    objects and occupancy (``capnav query``); entries not read are not checksummed."""
    p = Path(path)
    if p.is_dir():
        hint = ", ".join(sorted(q.name for q in p.glob("*.capnav"))[:3])
        raise MapFileError(f"{p} is a folder, not a map file; give the .capnav file `capnav map -o` wrote"
                           + (f" (this folder has {hint})" if hint else ""))
    if not p.is_file():
        raise MapFileError(f"map file not found: {p}")
    try:
        zf = zipfile.ZipFile(p, "r")
    except (zipfile.BadZipFile, OSError) as e:
        raise MapFileError(f"{p}: not a CapNav map file or truncated ({e})") from None
    with zf:
        try:
            header = json.loads(zf.read("header.json").decode("utf-8"))
        except KeyError:
            raise MapFileError(f"{p}: no header.json; not a CapNav map file or truncated") from None
        except (zipfile.BadZipFile, zlib.error, EOFError, OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
            raise MapFileError(f"{p}: header.json is unreadable ({e})") from None
        if not isinstance(header, dict) or header.get("format") != FORMAT:
            fmt = header.get("format") if isinstance(header, dict) else None
            raise MapFileError(f"{p}: not a CapNav map (format {fmt!r}, expected {FORMAT!r})")
        if header.get("version") not in READS:
            raise MapFileError(f"{p}: map format version {header.get('version')} is not supported (this CapNav "
                               f"reads versions {', '.join(map(str, READS))}); rebuild the map with `capnav map`")
        if not isinstance(header.get("entries"), dict):
            raise MapFileError(f"{p}: header has no entry table")
        r = _Reader(p, zf, header)
        try:
            return _decode(r, header, voxels)
        except MapFileError:
            raise
        except (CapNavError, KeyError, TypeError, ValueError, IndexError) as e:
            raise r.fail(f"inconsistent content ({type(e).__name__}: {e})") from None


def _features(r: _Reader) -> NDArray[np.float32]:
    """Voxel features as float32 (stored float16 since version 3, float32 before)."""
    f = r.array("voxels/features.npy")
    if f.dtype not in (np.float16, np.float32):
        raise r.fail(f"voxels/features.npy is {f.dtype}, expected float16 or float32")
    return f.astype(np.float32, copy=False)


def _decode(r: _Reader, header: dict[str, Any], with_voxels: bool = True) -> CapNavMap:
    vh = header["voxels"]
    proj = r.array("voxels/projection.npy") if "voxels/projection.npy" in r.entries else None
    if with_voxels:
        coords = r.array("voxels/coords.npy")
        n = int(header["n_voxels"])
        if coords.shape != (n, 3):
            raise r.fail(f"voxels/coords has shape {coords.shape}, header says {n} voxels")
        colors, weights, feats = r.array("voxels/colors.npy"), r.array("voxels/weights.npy"), _features(r)
    else:
        dim = int(vh.get("dim", 0))
        coords, colors, weights = np.zeros((0, 3), np.int32), np.zeros((0, 3), np.float32), np.zeros(0)
        feats = np.zeros((0, dim), np.float32)
    voxels = VoxelMap.from_arrays(float(vh["resolution"]), np.asarray(vh["origin"]), coords, colors, weights,
                                  feats, proj, str(vh.get("text_space", "")))
    spec = GridSpec(**header["occupancy"])
    occ = OccupancyGrid(spec, r.array("occupancy/cells.npy"))
    objects = _decode_objects(r, "", int(header["n_objects"]))
    retired = _decode_objects(r, "retired/", None) if "retired/objects.json" in r.entries else []
    meta = r.json("meta.json")
    caches = r.json("caches.json")
    if not isinstance(meta, dict) or not isinstance(caches, dict):
        raise r.fail("meta.json and caches.json must hold JSON objects")
    traj = None
    if "trajectory/poses.npy" in r.entries:
        traj = CameraTrajectory(r.array("trajectory/frames.npy"), r.array("trajectory/poses.npy"))
    cmap = CapNavMap(objects=objects, voxels=voxels, occupancy=occ, meta=meta, caches=caches, trajectory=traj,
                     retired=retired)
    _check_finite(r, cmap)
    return cmap


def _decode_objects(r: _Reader, prefix: str, n: int | None) -> list[MapObject]:
    records = r.json(f"{prefix}objects.json")
    if not isinstance(records, list) or (n is not None and len(records) != n):
        raise r.fail(f"{prefix}objects.json holds {len(records) if isinstance(records, list) else '?'} objects, "
                     f"header says {n}")
    flat = {name: r.array(f"{prefix}objects/{name}.npy") for name in _ARRAY_DTYPES}
    offs = dict.fromkeys(_ARRAY_DTYPES, 0)
    objects: list[MapObject] = []
    for rec in records:
        kw: dict[str, Any] = {}
        for name, shape in rec["arrays"].items():
            if name not in _ARRAY_DTYPES:
                raise r.fail(f"unknown object array {name!r}")
            if shape is None:
                kw[name] = None
                continue
            size = int(np.prod(shape)) if shape else 1
            chunk = flat[name][offs[name]: offs[name] + size]
            if chunk.size != size:
                raise r.fail(f"{prefix}objects/{name}.npy is too short for object {rec.get('id')}")
            kw[name] = chunk.reshape(shape).copy()
            offs[name] += size
        for name in _OBJ_FIELDS:
            if name in _ARRAY_DTYPES or name not in rec:
                continue
            if name == "observations":
                kw[name] = [Observation(**{**d, "box": tuple(d["box"])}) for d in rec[name]]
            elif name == "views":
                views = []
                for d in rec[name]:
                    d = dict(d)
                    for kind in ("frame_png", "crop_png"):
                        d[kind] = r.raw(d[kind]) if d.get(kind) else b""
                    views.append(ObjectView(**{**d, "box": tuple(d["box"])}))
                kw[name] = views
            else:
                kw[name] = rec[name]
        objects.append(MapObject(**kw))
    for name, arr in flat.items():
        if offs[name] != arr.size:
            raise r.fail(f"{prefix}objects/{name}.npy has {arr.size - offs[name]} values no object claims")
    return objects


def _check_finite(r: _Reader, cmap: CapNavMap) -> None:
    """Checksums prove the bytes are the ones written, not that they make sense: a NaN position or
    voxel would reach the planner's integer grid maths. Every float array must be finite."""
    for o in [*cmap.objects, *cmap.retired]:
        for name in _ARRAY_DTYPES:
            a = getattr(o, name)
            if a is not None and np.asarray(a).dtype.kind == "f" and not np.isfinite(a).all():
                raise r.fail(f"object {o.id}: {name} holds NaN or infinite values")
    vox = cmap.voxels
    for name in ("coords", "colors", "weights", "features", "projection", "origin"):
        a = getattr(vox, name, None)
        if a is not None and np.asarray(a).dtype.kind == "f" and not np.isfinite(a).all():
            raise r.fail(f"voxels/{name} holds NaN or infinite values")
    spec = cmap.occupancy.spec
    if not np.isfinite([spec.x0, spec.y0, spec.resolution]).all():
        raise r.fail("the occupancy grid's origin or resolution is not finite")
    if not np.isfinite(float(vox.resolution)) or vox.resolution <= 0:
        raise r.fail(f"voxel resolution {vox.resolution} is not a positive number")
    if cmap.trajectory is not None and not np.isfinite(cmap.trajectory.poses).all():
        raise r.fail("trajectory/poses holds NaN or infinite values")


@contextlib.contextmanager
def lock_map(path: str | Path) -> Iterator[None]:
    """Hold ``<path>.lock`` (an exclusive, non-blocking ``flock``) while a command rewrites a map:
    a second update of the same map at once is refused instead of racing the first one's write.
    The lock dies with its process, so a killed update never leaves the map locked."""
    import fcntl
    import os

    p = Path(str(path) + ".lock")
    try:
        fd = os.open(p, os.O_RDWR | os.O_CREAT, 0o644)
    except OSError as e:
        raise MapFileError(f"cannot create the lock file {p} ({e.strerror or e})") from None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "?"
            raise MapFileError(f"{path} is being updated by another process (pid {holder}, lock {p}); wait for it "
                               "to finish") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, str(os.getpid()).encode(), 0)
        yield
    finally:
        os.close(fd)  # releases the flock
