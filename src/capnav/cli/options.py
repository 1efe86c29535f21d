"""What every command shares: option types with one set of limits, the output checks run before any
work, and the note printed when Ctrl-C interrupts a command.

Commands declare ``seed: Seed = 0`` or ``max_frames: MaxFrames = None`` instead of spelling the
limits out, so ``map``, ``sim``, ``eval``, ``demo`` and ``import`` refuse the same values with the
same message; and they call :func:`check_output_file` / :func:`check_output_dir` first, so an
unwritable output is found in a second, not after minutes of mapping.
"""

from __future__ import annotations

import errno
import math
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Annotated

import typer

from capnav.core.errors import OutputError
from capnav.core.limits import HFOV_MAX, HFOV_MIN, IMAGE_MAX, IMAGE_MIN


def finite_float(lo: float | None = None, hi: float | None = None) -> Callable[[object], float]:
    """A parser for a float option that names what is wrong: "nan" is not a number (a range check
    alone would call NaN "too large", since every comparison with it is false), "inf" is not finite."""

    def parse(value: object) -> float:
        try:
            x = float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            raise typer.BadParameter(f"{value!r} is not a number") from None
        if math.isnan(x):
            raise typer.BadParameter(f"{value!r} is not a number")
        if math.isinf(x):
            raise typer.BadParameter(f"{value!r} is not a finite number")
        if (lo is not None and x < lo) or (hi is not None and x > hi):
            span = f"between {lo:g} and {hi:g}" if lo is not None and hi is not None else (
                f">= {lo:g}" if lo is not None else f"<= {hi:g}")
            raise typer.BadParameter(f"{x:g} is out of range; give a number {span}")
        return x

    parse.__name__ = "float"  # what --help shows as the option's type
    return parse


# --- option types (the limits live here and in capnav.core.limits, nowhere else) -------------------
Seed = Annotated[int, typer.Option(min=0, help="seed (a whole number >= 0; same seed = same result)")]
Width = Annotated[int, typer.Option(min=IMAGE_MIN, max=IMAGE_MAX, help="camera width (pixels)")]
Height = Annotated[int, typer.Option(min=IMAGE_MIN, max=IMAGE_MAX, help="camera height (pixels)")]
MaxFrames = Annotated[int | None, typer.Option(min=1, help="use at most this many frames (>= 1; default: all)")]
Stride = Annotated[int, typer.Option(min=1, help="keep every k-th frame (>= 1)")]
Hfov = Annotated[float, typer.Option("--hfov", parser=finite_float(HFOV_MIN, HFOV_MAX),
                                     help=f"horizontal field of view (degrees, {HFOV_MIN:g}..{HFOV_MAX:g})")]

# --- the note Ctrl-C prints ----------------------------------------------------------------------------
_DEFAULT_KEPT = "nothing half-written was left behind (CapNav writes every file atomically)"
_kept: list[str] = [_DEFAULT_KEPT]


def on_interrupt(kept: str) -> None:
    """Say what an interrupt at this point keeps (printed after "interrupted: COMMAND;")."""
    _kept[0] = kept


def interrupt_note() -> str:
    return _kept[0]


def reset_interrupt_note() -> None:
    _kept[0] = _DEFAULT_KEPT


# --- output checks ----------------------------------------------------------------------------------
def _nearest_existing(path: Path) -> Path:
    p = path
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def _probe_writable(folder: Path, flag: str, path: Path) -> None:
    """Create and remove a temporary file in ``folder``: the only test that also holds for root,
    read-only mounts and ACLs."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".capnav-probe-", dir=folder)
    except OSError as e:
        raise OutputError(f"{flag} {path}: cannot write in {folder} ({e.strerror or e})") from None
    os.close(fd)
    os.unlink(tmp)


def _check_parent(path: Path, flag: str) -> None:
    base = _nearest_existing(path.parent)
    if not base.is_dir():
        raise OutputError(f"{flag} {path}: {base} is a file, not a folder")
    _probe_writable(base, flag, path)


def check_output_file(path: Path, flag: str = "-o") -> Path:
    """A file output: not a folder, in a folder that exists (or can be made) and is writable."""
    if path.is_dir():
        raise OutputError(f"{flag} {path} is a folder; give a file name inside it (e.g. {path / 'out'})")
    _check_parent(path, flag)
    return path


def check_output_dir(path: Path, flag: str = "--out", must_be_empty: bool = False,
                     overwrite: bool = False) -> Path:
    """A folder output: not a file; writable where it will be made; when ``must_be_empty``, empty
    unless ``overwrite`` (then the folder is replaced only once the new one is complete)."""
    if path.exists() and not path.is_dir():
        raise OutputError(f"{flag} {path} is a file; give a folder")
    if path.is_dir():
        if must_be_empty and not overwrite and any(path.iterdir()):
            raise OutputError(f"{flag} {path} is not empty (pass --overwrite to replace it)")
        _probe_writable(path, flag, path)
    if must_be_empty or not path.is_dir():  # the folder itself is made (or swapped in) beside it
        _check_parent(path, flag)
    return path


def check_input_path(path: Path, what: str, kind: str = "file") -> Path:
    """An input that must exist as a ``file`` or a ``folder``: say so before any work."""
    from capnav.core.errors import InputError

    if not path.exists():
        raise InputError(f"{what} not found: {path}")
    if kind == "file" and path.is_dir():
        raise InputError(f"{what} {path} is a folder, expected a file")
    if kind == "folder" and not path.is_dir():
        raise InputError(f"{what} {path} is a file, expected a folder")
    return path


def describe_os_error(e: OSError) -> str:
    """One line for an OS error: the path(s), what failed, and a hint for the common cases."""
    where = " -> ".join(str(p) for p in (e.filename, e.filename2) if p is not None)
    what = e.strerror or type(e).__name__
    hint = {errno.ENOSPC: "free some disk space and run again", errno.EACCES: "choose a writable path",
            errno.EROFS: "choose a path on a writable disk", errno.EISDIR: "give a file name, not a folder",
            errno.ENOTDIR: "a part of the path is a file, not a folder"}.get(e.errno or 0)
    return f"{where + ': ' if where else ''}{what}{'; ' + hint if hint else ''}"


def check_model_folder(flag: str, name: str, path: Path | None, path_flag: str, required: list[str]) -> None:
    """A back-end that loads a local model folder is told so before anything loads."""
    from capnav.core.errors import InputError

    if "path" in required and path is None:
        raise InputError(f"{flag} {name} needs a local model folder: pass {path_flag} DIR")
    if path is not None and not path.is_dir():
        raise InputError(f"{path_flag} {path} is not an existing folder")


def check_map_matches_dataset(map_meta: dict[str, object], map_path: Path, dataset: Path, reader: object) -> None:
    """A map and a dataset belong together when the dataset is the one the map was made from
    (same fingerprint; older maps: same simulator seed and frame count)."""
    from capnav.core.errors import InputError
    from capnav.io.dataset import DatasetReader

    assert isinstance(reader, DatasetReader)
    made_from = map_meta.get("dataset_id")
    if made_from is not None:
        this = reader.fingerprint()
        if this != made_from:
            raise InputError(f"{dataset} is not the dataset {map_path} was made from (dataset id {this}, the map "
                             f"records {made_from}, made from {map_meta.get('dataset', '?')})")
        return
    seed = (reader.meta.get("meta") or {}).get("seed")
    if map_meta.get("scene_seed") is not None and seed is not None and seed != map_meta["scene_seed"]:
        raise InputError(f"{dataset} records apartment seed {seed} but {map_path} was made in apartment "
                         f"{map_meta['scene_seed']}")
    n = map_meta.get("dataset_frames")
    if isinstance(n, int) and n != len(reader):
        raise InputError(f"{dataset} has {len(reader)} frames but {map_path} was made from a dataset of {n}")


def check_map_scene(map_meta: dict[str, object], map_path: Path, scene: int | None, what: str) -> None:
    """``scene`` (an apartment seed from an option, an episode or a manifest) must be the map's."""
    from capnav.core.errors import InputError

    mine = map_meta.get("scene_seed")
    if scene is not None and mine is not None and int(scene) != mine:  # type: ignore[call-overload]
        raise InputError(f"{what} is apartment {scene} but {map_path} was made in apartment {mine}")


def check_verifier(name: str, flag: str = "--verifier") -> None:
    """An unknown verifier, or one that needs a model folder no command takes, is refused up front."""
    from capnav.core.errors import InputError
    from capnav.language.vlm.base import VLMS
    from capnav.retrieval.verifier import VERIFIERS

    VERIFIERS.required(name)  # unknown name: InputError listing the known ones
    if name in VLMS:
        if "path" in VLMS.required(name):
            raise InputError(f"{flag} {name} needs a local model folder, which the command line does not take; "
                             "use it from Python (capnav.retrieval.create_verifier) or choose another verifier")
