"""The occupancy grid as a ROS ``map_server`` pair (PGM image + YAML), which Nav2, ROS 1's
map_server and most robot stacks load as a static map.

Rules (docs/design.md, "Occupancy export (ROS map_server)"): pixels 254 free, 0 occupied, 205 unknown;
the image's top row is the map's largest y; ``origin`` [x, y, 0] is the pose of the lower-left
pixel's corner (CapNav's grid origin); ``negate: 0``, ``occupied_thresh: 0.65``, ``free_thresh:
0.196``, ``mode: trinary``. map_server reads a pixel ``v`` as occupancy ``p = (255 - v) / 255``:
``p > occupied_thresh`` occupied, ``p < free_thresh`` free, otherwise unknown. 205 reads as
p = 0.19608, so free_thresh must stay under it (the common 0.25 would load unknown as free).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from PIL import Image

from capnav.core.atomic import atomic_path, write_text
from capnav.core.errors import InputError, pip_hint
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid

PIXEL = {FREE: 254, OCCUPIED: 0, UNKNOWN: 205}
OCCUPIED_THRESH = 0.65
FREE_THRESH = 0.196


def write_ros_map(occ: OccupancyGrid, yaml_path: str | Path) -> tuple[Path, Path]:
    """Write ``<stem>.pgm`` and ``<stem>.yaml`` (the YAML names the image relative to itself)."""
    yp = Path(yaml_path)
    if yp.suffix != ".yaml":
        raise InputError(f"the map_server file must end in .yaml, got {yp}")
    pgm = yp.with_suffix(".pgm")
    img = np.full(occ.cells.shape, PIXEL[UNKNOWN], dtype=np.uint8)
    for cell, v in PIXEL.items():
        img[occ.cells == cell] = v
    with atomic_path(pgm, suffix=".pgm") as tmp:
        Image.fromarray(np.flipud(img), mode="L").save(tmp, format="PPM")  # "L" + PPM writer = binary PGM (P5)
    s = occ.spec
    write_text(yp, "\n".join([
        f"image: {pgm.name}",
        "mode: trinary",
        f"resolution: {s.resolution!r}",
        f"origin: [{s.x0!r}, {s.y0!r}, 0.0]",
        "negate: 0",
        f"occupied_thresh: {OCCUPIED_THRESH}",
        f"free_thresh: {FREE_THRESH}",
    ]) + "\n")
    return pgm, yp


def read_ros_map(yaml_path: str | Path) -> OccupancyGrid:
    """Load a map_server pair as map_server does (the trinary rule above; ``negate`` honoured)."""
    try:
        import yaml
    except ImportError:
        raise InputError(f"reading a map_server YAML needs PyYAML: {pip_hint('pyyaml')}") from None
    yp = Path(yaml_path)
    try:
        meta: dict[str, Any] = yaml.safe_load(yp.read_text())
        res = float(meta["resolution"])
        x0, y0 = (float(v) for v in meta["origin"][:2])
        occ_t, free_t = float(meta["occupied_thresh"]), float(meta["free_thresh"])
        negate = int(meta.get("negate", 0))
        with Image.open(yp.parent / str(meta["image"])) as im:
            v: NDArray[np.float64] = np.asarray(im.convert("L"), dtype=np.float64)
    except FileNotFoundError as e:
        raise InputError(f"map_server map {yp}: file not found ({e.filename})") from None
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError, IndexError) as e:
        raise InputError(f"map_server map {yp}: unreadable ({type(e).__name__}: {e})") from None
    p = v / 255.0 if negate else (255.0 - v) / 255.0
    cells = np.full(v.shape, UNKNOWN, dtype=np.uint8)
    cells[p > occ_t] = OCCUPIED
    cells[p < free_t] = FREE
    cells = np.flipud(cells).copy()  # back to rows growing with y
    return OccupancyGrid(GridSpec(x0, y0, res, int(v.shape[0]), int(v.shape[1])), cells)
