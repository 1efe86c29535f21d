"""The map file round-trips everything and rejects corrupt, truncated or foreign files clearly."""

from __future__ import annotations

import copy
import hashlib
import sys
import zipfile
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "mapping"))
from _synth_scene import HashEmbedder, orbit

from capnav.core.errors import InputError, MapFileError
from capnav.io.mapfile import load_map, save_map
from capnav.mapping import CapNavMap, ObjectView, build_map
from capnav.perception import create_detector, create_encoder


@pytest.fixture(scope="module")
def cmap() -> CapNavMap:
    m = build_map(orbit(30), detector=create_detector("sim", noise="default", seed=0),
                  encoder=create_encoder("label-embedding", embedder=HashEmbedder()), progress=False,
                  meta={"dataset": "synthetic"})
    assert len(m.objects) >= 3
    o = m.objects[0]
    o.views = [ObjectView(frame_index=3, box=(1.0, 2.0, 30.0, 40.0), score=0.7, frame_png=b"\x89PNG-frame",
                          crop_png=b"\x89PNG-crop"), ObjectView(frame_index=5, box=(0, 0, 1, 1), score=0.1)]
    o.caption, o.caption_source = "SOFA, a grey sofa.", "template"
    o.embedding, o.embedding_model = np.arange(8, dtype=np.float32) / 10, "test-model"
    m.caches = {"captions": {"k": "v"}, "verify": {"q": [1, 2]}}
    return m


def _same_object(a, b) -> None:  # type: ignore[no-untyped-def]
    for name in a.__dataclass_fields__:
        va, vb = getattr(a, name), getattr(b, name)
        if isinstance(va, np.ndarray):
            assert vb.dtype == va.dtype and vb.shape == va.shape
            np.testing.assert_array_equal(va, vb)
        else:
            assert va == vb, name


def test_round_trip_everything(cmap: CapNavMap, tmp_path: Path) -> None:
    p = save_map(cmap, tmp_path / "m.capnav")
    back = load_map(p)
    assert len(back.objects) == len(cmap.objects)
    for a, b in zip(cmap.objects, back.objects, strict=True):
        _same_object(a, b)
    assert back.objects[0].views[0].frame_png == b"\x89PNG-frame"
    assert back.objects[1].embedding is None
    v, w = cmap.voxels, back.voxels
    for name in ("coords", "colors", "weights", "projection", "origin"):
        np.testing.assert_array_equal(getattr(v, name), getattr(w, name))
    # Voxel features are stored in float16 by default: exactly the float16 rounding, nothing else.
    assert w.features.dtype == np.float32
    np.testing.assert_array_equal(w.features, v.features.astype(np.float16).astype(np.float32))
    assert w.resolution == v.resolution and w.text_space == v.text_space
    np.testing.assert_array_equal(back.occupancy.cells, cmap.occupancy.cells)
    assert back.occupancy.spec == cmap.occupancy.spec
    assert back.caches == cmap.caches
    assert back.meta["dataset"] == "synthetic" and back.meta["frames_used"] == 30
    assert cmap.trajectory is not None and back.trajectory is not None and len(back.trajectory) == 30
    np.testing.assert_array_equal(back.trajectory.frames, np.arange(30))
    np.testing.assert_array_equal(back.trajectory.poses, cmap.trajectory.poses)
    np.testing.assert_array_equal(back.trajectory.poses[-1], orbit(30)[-1].T_wc)  # the last camera, as fused
    # a loaded voxel map still answers slot lookups and queries identically
    np.testing.assert_array_equal(w.slots(v.coords[:50]), np.arange(50))
    q = np.random.default_rng(0).standard_normal(32)
    np.testing.assert_allclose(w.query(q), v.query(q), atol=2e-3)  # float16 features


def test_same_inputs_and_seed_give_a_bit_identical_file(tmp_path: Path) -> None:
    def run(name: str) -> bytes:
        m = build_map(orbit(20), detector=create_detector("sim", noise="default", seed=7),
                      encoder=create_encoder("label-embedding", embedder=HashEmbedder()), progress=False)
        assert not any("second" in k for k in m.meta)  # no wall-clock time in the file
        return save_map(m, tmp_path / name).read_bytes()

    a, b = run("a.capnav"), run("b.capnav")
    assert hashlib.sha256(a).hexdigest() == hashlib.sha256(b).hexdigest()


def test_truncated_file(cmap: CapNavMap, tmp_path: Path) -> None:
    p = save_map(cmap, tmp_path / "m.capnav")
    data = p.read_bytes()
    for cut in (10, len(data) // 2, len(data) - 40):
        bad = tmp_path / f"cut{cut}.capnav"
        bad.write_bytes(data[:cut])
        with pytest.raises(MapFileError):
            load_map(bad)


def _edited_copy(src: Path, dst: Path, entry: str, edit: Callable[[bytes], bytes]) -> Path:
    """A copy of the map file ``src`` whose zip entry ``entry`` went through ``edit``."""
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dst, "w") as zout:
        for info in zin.infolist():
            data = zin.read(info.filename)
            zout.writestr(info.filename, edit(data) if info.filename == entry else data)
    return dst


def test_corrupted_entry_is_named(cmap: CapNavMap, tmp_path: Path) -> None:
    p = save_map(cmap, tmp_path / "m.capnav")
    bad = _edited_copy(p, tmp_path / "bad.capnav", "voxels/weights.npy", lambda d: d[:-8] + b"\x00" * 8)
    with pytest.raises(MapFileError, match=r"voxels/weights\.npy.*checksum"):
        load_map(bad)


def test_version_1_without_trajectory_loads(cmap: CapNavMap, tmp_path: Path) -> None:
    """Maps written before the camera trajectory was stored (version 1: no trajectory/ entries)."""
    old = CapNavMap(cmap.objects, cmap.voxels, cmap.occupancy, cmap.meta, cmap.caches, trajectory=None)
    p = save_map(old, tmp_path / "m.capnav")
    with zipfile.ZipFile(p) as zf:
        assert not [n for n in zf.namelist() if n.startswith("trajectory/")]
    v1 = _edited_copy(p, tmp_path / "v1.capnav", "header.json", lambda d: d.replace(b'"version": 4', b'"version": 1'))
    back = load_map(v1)
    assert back.trajectory is None and len(back.objects) == len(cmap.objects)


def test_float32_features_and_version_2_files(cmap: CapNavMap, tmp_path: Path) -> None:
    """``feature_dtype="float32"`` keeps features bit for bit, and so does a version 2 file (float32
    features, arrays stored uncompressed), which still loads."""
    p = save_map(cmap, tmp_path / "m.capnav", feature_dtype="float32")
    assert load_map(p).voxels.features.tobytes() == cmap.voxels.features.tobytes()
    v2 = tmp_path / "v2.capnav"
    with zipfile.ZipFile(p) as zin, zipfile.ZipFile(v2, "w") as zout:
        for info in zin.infolist():
            data = zin.read(info.filename)
            if info.filename == "header.json":
                data = data.replace(b'"version": 4', b'"version": 2')
            zout.writestr(info.filename, data, compress_type=zipfile.ZIP_STORED)
    back = load_map(v2)
    assert back.voxels.features.tobytes() == cmap.voxels.features.tobytes()
    assert len(back.objects) == len(cmap.objects)


def test_float16_is_smaller_and_out_of_range_features_stay_float32(cmap: CapNavMap, tmp_path: Path) -> None:
    small = save_map(cmap, tmp_path / "a.capnav").stat().st_size
    exact = save_map(cmap, tmp_path / "b.capnav", feature_dtype="float32").stat().st_size
    assert small < exact
    with pytest.raises(InputError, match="feature_dtype"):
        save_map(cmap, tmp_path / "c.capnav", feature_dtype="int8")
    big = CapNavMap(cmap.objects, copy.deepcopy(cmap.voxels), cmap.occupancy, cmap.meta, cmap.caches)
    big.voxels.features[0, 0] = 1e6
    with pytest.warns(UserWarning, match="float16's range"):
        p = save_map(big, tmp_path / "d.capnav")
    assert load_map(p).voxels.features[0, 0] == 1e6


def test_wrong_version_and_foreign_files(cmap: CapNavMap, tmp_path: Path) -> None:
    p = save_map(cmap, tmp_path / "m.capnav")
    bad = _edited_copy(p, tmp_path / "v9.capnav", "header.json",
                       lambda d: d.replace(b'"version": 4', b'"version": 9'))
    with pytest.raises(MapFileError, match="version 9"):
        load_map(bad)
    txt = tmp_path / "x.capnav"
    txt.write_text("hello")
    with pytest.raises(MapFileError, match="not a CapNav map"):
        load_map(txt)
    with pytest.raises(MapFileError, match="not found"):
        load_map(tmp_path / "missing.capnav")


def test_load_without_voxels_keeps_everything_else(cmap: CapNavMap, tmp_path: Path) -> None:
    p = save_map(cmap, tmp_path / "m.capnav")
    back = load_map(p, voxels=False)
    assert len(back.voxels) == 0 and back.voxels.dim == cmap.voxels.dim
    np.testing.assert_array_equal(back.voxels.projection, cmap.voxels.projection)
    assert back.voxels.resolution == cmap.voxels.resolution
    for a, b in zip(cmap.objects, back.objects, strict=True):
        _same_object(a, b)
    np.testing.assert_array_equal(back.occupancy.cells, cmap.occupancy.cells)
