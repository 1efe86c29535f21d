"""A recording shorter than the confirmation count (``h_min`` frames) still gives a map: a
one-frame recording (a single real RGB-D frame with the identity pose, as a user makes one) can
show each object at most once, so confirmation asks for at most as many sightings as there are
frames, and the map says it did (meta ``h_min_used``). Before, every object of such a map was
dropped and the CLI only warned "none of N tracks was seen in 3 frames"."""

from __future__ import annotations

from pathlib import Path

from _synth_scene import orbit
from typer.testing import CliRunner

from capnav.cli import app
from capnav.io.dataset import DatasetWriter
from capnav.io.mapfile import load_map


def _write(root: Path, n: int) -> Path:
    frames = orbit(24)[:n]
    with DatasetWriter(root, frames[0].K) as w:
        for f in frames:
            w.write(f)
    return root


def test_one_frame_recording_keeps_its_objects(tmp_path: Path) -> None:
    ds = _write(tmp_path / "one", 1)
    out = tmp_path / "m.capnav"
    r = CliRunner().invoke(app, ["map", str(ds), "-o", str(out), "--noise", "oracle", "--no-progress"])
    assert r.exit_code == 0, r.output
    cmap = load_map(out)
    assert len(cmap.objects) >= 1, r.output
    assert cmap.meta["h_min_used"] == 1
    assert "1 frame" in r.output and "h_min" in r.output  # the lowered confirmation is said


def test_long_recording_keeps_h_min(tmp_path: Path) -> None:
    ds = _write(tmp_path / "six", 6)
    out = tmp_path / "m.capnav"
    r = CliRunner().invoke(app, ["map", str(ds), "-o", str(out), "--noise", "oracle", "--no-progress"])
    assert r.exit_code == 0, r.output
    assert load_map(out).meta["h_min_used"] == 3


def test_the_grid_covers_the_cameras_that_saw_it() -> None:
    """A camera looking ahead never sees the floor under it (the real NYU frame's floor starts
    0.85 m ahead): the grid still covers it, so the camera's pose can be a start (on unknown
    floor, said as such by the planner) instead of "start (0.00, 0.00) is off the map"."""
    import numpy as np

    from capnav.core.grid import UNKNOWN
    from capnav.mapping.occupancy import occupancy_from_voxels
    from capnav.mapping.voxel_map import VoxelMap

    vm = VoxelMap(0.05, feature_dim=1)
    xs, ys = np.meshgrid(np.arange(-1.0, 1.0, 0.05), np.arange(0.85, 3.0, 0.05))
    pts = np.stack([xs.ravel(), ys.ravel(), np.full(xs.size, 0.01)], axis=1)
    vm.integrate(pts, np.ones(len(pts)), np.zeros((len(pts), 3), np.uint8), np.zeros(len(pts), int),
                 np.zeros((1, 1), np.float32))
    eye = np.array([[0.0, 0.0]])
    occ = occupancy_from_voxels(vm, cover=eye)
    rc = occ.spec.to_cell(eye)
    assert occ.spec.inside(rc).all()
    assert occ.cells[rc[0, 0], rc[0, 1]] == UNKNOWN  # covered, not claimed free
    plain = occupancy_from_voxels(vm)
    assert abs((occ.spec.x0 - plain.spec.x0) / 0.05 - round((occ.spec.x0 - plain.spec.x0) / 0.05)) < 1e-6


def test_an_empty_map_is_refused_as_empty_not_as_uncaptioned(tmp_path: Path) -> None:
    """A one-frame map whose detector kept nothing: `capnav query` said "has no captions/embeddings:
    run `capnav caption` first" although caption had run; the reason is that the map is empty."""
    from capnav.core.errors import InputError
    from capnav.io.mapfile import save_map
    from capnav.mapping.cmap import CapNavMap
    from capnav.mapping.occupancy import occupancy_from_voxels
    from capnav.mapping.voxel_map import VoxelMap

    vm = VoxelMap(0.05, feature_dim=1)
    out = tmp_path / "empty.capnav"
    save_map(CapNavMap(objects=[], voxels=vm, occupancy=occupancy_from_voxels(vm), meta={}), out)
    r = CliRunner().invoke(app, ["query", str(out), "the chair", "--json"])
    assert isinstance(r.exception, InputError), r.output
    assert "has no objects" in str(r.exception) and "caption" not in str(r.exception)
