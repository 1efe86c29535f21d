"""A folder format for posed RGB-D streams, with an atomic writer and a validating streaming reader.

Layout (format version 1, see docs/formats.md)::

    DIR/meta.json          {"format": "capnav-rgbd", "version": 1, "num_frames": N, "complete": true,
                            "depth_scale": 1000.0, "has_gt": true, "meta": {...}}
    DIR/intrinsics.json    {"fx", "fy", "cx", "cy", "width", "height"}
    DIR/poses.txt          one line per frame: index timestamp T_wc (16 numbers, row-major)
    DIR/rgb/000000.png     8-bit RGB
    DIR/depth/000000.png   16-bit depth in millimetres (value / depth_scale = metres), 0 = invalid
    DIR/gt_instance/000000.png, DIR/gt_category/000000.png   optional 16-bit truth images
    DIR/manifest.json      optional scene manifest (simulator truth, for evaluation only)

Every file is written atomically; ``meta.json`` says ``complete: true`` only once the writer closed.
"""

from __future__ import annotations

import io
import json
from collections.abc import Iterator
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.atomic import write_bytes, write_json, write_text
from capnav.core.errors import DatasetError, FrameError, PoseError
from capnav.core.frame import Frame
from capnav.core.geometry import Intrinsics, check_pose
from capnav.core.jsonfile import read_json_object

FORMAT = "capnav-rgbd"
FORMAT_VERSION = 1
DEPTH_SCALE = 1000.0  # depth PNG units per metre (millimetres)
_GT = ("gt_instance", "gt_category")


class DatasetFrameError(FrameError, DatasetError):
    """A frame of a dataset folder is missing or corrupt (catchable as FrameError or DatasetError)."""


def _png(arr: NDArray[Any]) -> bytes:
    buf = io.BytesIO()
    Image.fromarray(arr).save(buf, format="PNG", compress_level=3)
    return buf.getvalue()


def _clear(path: Path) -> None:
    """Remove a previous dataset's own files (and nothing else) before overwriting it."""
    import shutil

    for sub in ("rgb", "depth", *_GT):
        shutil.rmtree(path / sub, ignore_errors=True)
    for name in ("meta.json", "intrinsics.json", "poses.txt", "manifest.json", "topdown.png"):
        (path / name).unlink(missing_ok=True)


def check_dataset_target(out: Path, overwrite: bool) -> None:
    """``out`` may become a dataset folder: absent, empty, or (with ``overwrite``) a dataset already;
    a folder holding anything else is never replaced."""
    if out.exists() and not out.is_dir():
        raise DatasetError(f"{out} exists and is not a folder")
    if out.is_dir() and any(out.iterdir()):
        if not overwrite:
            raise DatasetError(f"{out} is not empty (pass --overwrite to replace it)")
        if not (out / "meta.json").exists() or not (out / "poses.txt").exists():
            raise DatasetError(f"{out} is not a capnav-rgbd dataset folder; refusing to replace it")


class DatasetWriter:
    """Write a posed RGB-D stream frame by frame. Use as a context manager or call ``close()``."""

    def __init__(self, path: str | Path, intrinsics: Intrinsics, meta: dict[str, Any] | None = None,
                 overwrite: bool = False, write_gt: bool = True) -> None:
        self.path = Path(path)
        if self.path.exists() and not self.path.is_dir():
            raise DatasetError(f"{self.path} exists and is not a folder")
        if self.path.is_dir() and any(self.path.iterdir()) and not overwrite:
            raise DatasetError(f"{self.path} is not empty (pass overwrite=True / --overwrite to replace it)")
        try:
            json.dumps(meta or {})
        except TypeError as e:
            raise DatasetError(f"dataset meta must be JSON-serialisable: {e}") from None
        if overwrite and self.path.is_dir():
            _clear(self.path)
        self.K = intrinsics
        self.meta = dict(meta or {})
        self.write_gt = write_gt
        self._lines: list[str] = []
        self._has_gt: bool | None = None
        self.closed = False
        for sub in ("rgb", "depth", *(_GT if write_gt else ())):
            (self.path / sub).mkdir(parents=True, exist_ok=True)
        write_json(self.path / "intrinsics.json", intrinsics.to_dict())
        self._write_meta(complete=False)

    def __len__(self) -> int:
        return len(self._lines)

    def _write_meta(self, complete: bool) -> None:
        write_json(self.path / "meta.json", {
            "format": FORMAT, "version": FORMAT_VERSION, "num_frames": len(self._lines), "complete": complete,
            "depth_scale": DEPTH_SCALE, "has_gt": bool(self._has_gt), "meta": self.meta})

    def write(self, frame: Frame) -> int:
        """Append ``frame``; returns its position in the dataset (the reader's frame index)."""
        if self.closed:
            raise DatasetError(f"dataset writer for {self.path} is closed")
        i = len(self._lines)
        if frame.K.width != self.K.width or frame.K.height != self.K.height:
            raise FrameError(frame.index, f"size {frame.K.width}x{frame.K.height} differs from the dataset's "
                                          f"{self.K.width}x{self.K.height}")
        frame.validate()
        depth = np.where(frame.valid_depth(), frame.depth, 0.0) * DEPTH_SCALE
        depth_mm = np.where(depth < 65535.5, np.round(depth), 0).astype(np.uint16)
        name = f"{i:06d}.png"
        write_bytes(self.path / "rgb" / name, _png(frame.rgb))
        write_bytes(self.path / "depth" / name, _png(depth_mm))
        has_gt = self.write_gt and frame.gt_instance is not None and frame.gt_category is not None
        if self._has_gt is None:
            self._has_gt = has_gt
        elif self._has_gt != has_gt:
            raise FrameError(frame.index, "ground-truth images must be present in every frame or in none")
        if has_gt:
            for sub in _GT:
                img = np.asarray(getattr(frame, sub))
                if img.min() < 0 or img.max() > 65535:
                    raise FrameError(frame.index, f"{sub} ids must fit in 16 bits")
                write_bytes(self.path / sub / name, _png(img.astype(np.uint16)))
        T = np.asarray(frame.T_wc, dtype=np.float64).reshape(-1)
        self._lines.append(f"{i} {frame.timestamp!r} " + " ".join(repr(float(v)) for v in T))
        if len(self._lines) % 25 == 0:
            self._flush()
        return i

    def _flush(self) -> None:
        write_text(self.path / "poses.txt", "\n".join(self._lines) + ("\n" if self._lines else ""))
        self._write_meta(complete=False)

    def close(self) -> None:
        if self.closed:
            return
        write_text(self.path / "poses.txt", "\n".join(self._lines) + ("\n" if self._lines else ""))
        self._write_meta(complete=True)
        self.closed = True

    def __enter__(self) -> DatasetWriter:
        return self

    def __exit__(self, et: type[BaseException] | None, ev: BaseException | None, tb: TracebackType | None) -> None:
        if et is None:
            self.close()
        else:  # keep what was written readable, but leave complete=false
            self._flush()
            self.closed = True


class DatasetReader:
    """Stream frames of a dataset folder; every problem names the folder and the frame."""

    def __init__(self, path: str | Path, allow_incomplete: bool = False) -> None:
        self.path = Path(path)
        if not self.path.is_dir():
            raise DatasetError(f"dataset folder not found: {self.path}")
        self.meta = self._json("meta.json")
        if self.meta.get("format") != FORMAT:
            raise DatasetError(f"{self.path}/meta.json: not a {FORMAT} dataset (format={self.meta.get('format')!r})")
        if self.meta.get("version") != FORMAT_VERSION:
            raise DatasetError(f"{self.path}: dataset format version {self.meta.get('version')} is not supported "
                               f"(expected {FORMAT_VERSION})")
        if not self.meta.get("complete", False) and not allow_incomplete:
            raise DatasetError(f"{self.path}: dataset is incomplete (its writer did not finish or was "
                               "interrupted); write it again (capnav sim / capnav import --overwrite)")
        k = self._json("intrinsics.json")
        try:
            self.intrinsics = Intrinsics(float(k["fx"]), float(k["fy"]), float(k["cx"]), float(k["cy"]),
                                         int(k["width"]), int(k["height"]))
        except (KeyError, TypeError, ValueError) as e:
            raise DatasetError(f"{self.path}/intrinsics.json is malformed: {e}") from None
        self.depth_scale = float(self.meta.get("depth_scale", DEPTH_SCALE))
        self.has_gt = bool(self.meta.get("has_gt", False))
        self.bad_poses: dict[int, str] = {}  # frame -> why its pose is unusable (that frame raises)
        self.timestamps, self.poses = self._poses()
        n = int(self.meta.get("num_frames", len(self.poses)))
        if self.meta.get("complete", False) and n != len(self.poses):
            raise DatasetError(f"{self.path}: meta.json lists {n} frames but poses.txt has {len(self.poses)}")

    def _json(self, name: str) -> dict[str, Any]:
        return read_json_object(self.path / name, f"dataset file {name}")

    def _poses(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        p = self.path / "poses.txt"
        if not p.exists():
            raise DatasetError(f"{self.path}: missing poses.txt")
        ts: list[float] = []
        poses: list[NDArray[np.float64]] = []
        for ln, line in enumerate(p.read_text().splitlines()):
            if not line.strip():
                continue
            parts = line.split()
            try:
                vals = [float(v) for v in parts]
            except ValueError:
                raise DatasetFrameError(ln, f"{p} line {ln + 1} is not numeric") from None
            if len(vals) != 18 or int(vals[0]) != len(poses):
                raise DatasetFrameError(ln, f"{p} line {ln + 1}: expected 'index timestamp' + 16 pose values "
                                            f"for frame {len(poses)}")
            try:
                T = check_pose(np.array(vals[2:]).reshape(4, 4), frame=len(poses))
            except PoseError as e:  # one bad pose costs its frame (skipped by the mapper), not the dataset
                self.bad_poses[len(poses)] = f"{p} line {ln + 1}: {e.reason}"
                T = np.full((4, 4), np.nan)
            ts.append(vals[1])
            poses.append(T)
        return np.asarray(ts, dtype=np.float64), np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)

    def fingerprint(self) -> str:
        """What identifies this recording (camera, trajectory, producer), so a map can name the dataset
        it was made from and a later command can tell another apartment's dataset from it."""
        import hashlib

        h = hashlib.sha256()
        for name in ("intrinsics.json", "poses.txt"):
            try:
                h.update((self.path / name).read_bytes())
            except OSError as e:
                raise DatasetError(f"{self.path}/{name} is unreadable ({e.strerror or e})") from None
        h.update(json.dumps(self.meta.get("meta") or {}, sort_keys=True).encode("utf-8"))
        return h.hexdigest()[:16]

    @property
    def manifest_path(self) -> Path | None:
        p = self.path / "manifest.json"
        return p if p.exists() else None

    def __len__(self) -> int:
        return int(self.poses.shape[0])

    def _image(self, sub: str, i: int, mode: str) -> NDArray[Any]:
        p = self.path / sub / f"{i:06d}.png"
        try:
            with Image.open(p) as im:
                im.load()
                if im.mode != mode and not (mode == "I;16" and im.mode in ("I", "I;16", "I;16B")):
                    raise DatasetFrameError(i, f"{p} has mode {im.mode}, expected {mode}")
                arr = np.asarray(im)
        except FileNotFoundError:
            raise DatasetFrameError(i, f"missing {p}") from None
        except (OSError, SyntaxError, ValueError) as e:
            raise DatasetFrameError(i, f"corrupt {p}: {e}") from None
        K = self.intrinsics
        if arr.shape[:2] != (K.height, K.width):
            raise DatasetFrameError(i, f"{p} is {arr.shape[1]}x{arr.shape[0]}, expected {K.width}x{K.height}")
        return arr

    def frame(self, i: int) -> Frame:
        if not (0 <= i < len(self)):
            raise DatasetError(f"{self.path}: frame {i} out of range (dataset has {len(self)} frames)")
        if i in self.bad_poses:
            raise DatasetFrameError(i, self.bad_poses[i])
        rgb = self._image("rgb", i, "RGB").astype(np.uint8)
        depth = self._image("depth", i, "I;16").astype(np.float32) / np.float32(self.depth_scale)
        gi = gc = None
        if self.has_gt:
            gi = self._image("gt_instance", i, "I;16").astype(np.int32)
            gc = self._image("gt_category", i, "I;16").astype(np.int32)
        return Frame(index=i, rgb=rgb, depth=depth, K=self.intrinsics, T_wc=self.poses[i].copy(),
                     timestamp=float(self.timestamps[i]), gt_instance=gi, gt_category=gc)

    def __iter__(self) -> Iterator[Frame]:
        for i in range(len(self)):
            yield self.frame(i)
