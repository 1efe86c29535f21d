"""Rendered apartments for the benchmarks, cached: one dataset folder per (furniture, seed, size).

``dataset(seed, ...)`` returns ``CACHE/<furniture>-s<seed>-<W>x<H>`` and renders it first
(``capnav.sim.record.record_dataset``, the same as ``capnav sim``) when it is missing or was
left incomplete. Sweet Home 3D furniture needs the meshes of ``capnav assets`` (``--assets-dir``).
Rendering 640x480 costs about a second of CPU per frame, so share the cache between runs.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

from capnav.core.errors import InputError


def dataset(seed: int, cache: Path, width: int = 320, height: int = 240, furniture: str = "sh3d",
            assets_dir: Path | None = None, depth_noise: bool = False, surface_items: bool = False) -> Path:
    """The cached dataset folder of apartment ``seed`` (rendered on first use); ``depth_noise`` and
    ``surface_items`` (``capnav sim --depth-noise --surface-items``) add ``-noise`` / ``-items``
    to its name."""
    from capnav.sim.record import record_dataset

    suffix = ("-noise" if depth_noise else "") + ("-items" if surface_items else "")
    out = Path(cache) / f"{furniture}-s{seed}-{width}x{height}{suffix}"
    meta = out / "meta.json"
    if meta.is_file():
        try:
            if json.loads(meta.read_text()).get("complete"):
                return out
        except (OSError, json.JSONDecodeError):
            pass
    if out.exists():
        shutil.rmtree(out)
    if furniture not in ("sh3d", "primitives"):
        raise InputError(f"furniture must be sh3d or primitives, got {furniture!r}")
    print(record_dataset(seed=seed, out=out, width=width, height=height, furniture=furniture,
                         assets_dir=assets_dir, progress=False, depth_noise=depth_noise,
                         surface_items=surface_items))
    return out
