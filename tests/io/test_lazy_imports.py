"""Reading a map for a query loads no mapping, perception or numba code (one-shot `capnav query`
pays for every import: issue 16's < 1 s)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

from capnav.io.mapfile import save_map
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.voxel_map import VoxelMap
from language.synth import living_scene, make_map

HEAVY = ("numba", "scipy.ndimage", "capnav.perception", "capnav.mapping.mapper", "capnav.mapping.tracker")


def test_loading_a_map_without_voxels_imports_no_mapping_code(tmp_path: Path) -> None:
    m = make_map(living_scene())
    n = 40
    vox = VoxelMap.from_arrays(0.05, np.zeros(3), np.stack([np.arange(n), np.zeros(n), np.ones(n)], axis=1),
                               np.full((n, 3), 128.0), np.ones(n), np.eye(n, 4, dtype=np.float32))
    path = save_map(CapNavMap(m.objects, vox, m.occupancy), tmp_path / "m.capnav")
    code = ("import sys\nfrom capnav.io.mapfile import load_map\n"
            f"m = load_map({str(path)!r}, voxels=False)\nassert len(m.objects) == 7 and len(m.voxels) == 0\n"
            f"print(sorted(k for k in {HEAVY!r} if k in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]", out.stdout + out.stderr
    # With voxels the numba kernels load when first needed, and the voxels are what was saved.
    code = ("from capnav.io.mapfile import load_map\n"
            f"m = load_map({str(path)!r})\nprint(len(m.voxels), m.voxels.slots(m.voxels.coords[:3]).tolist())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split()[0] == str(len(vox)) and len(vox) > 0
    assert out.stdout.split(maxsplit=1)[1].strip() == "[0, 1, 2]"
