"""The occupancy grid as a ROS map_server pair: pixel values, orientation, origin, and a round trip
through map_server's load rule (PyYAML and Pillow read what was written)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from PIL import Image

from capnav.core.errors import InputError
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.io.rosmap import read_ros_map, write_ros_map


@pytest.fixture()
def grid() -> OccupancyGrid:
    rng = np.random.default_rng(0)
    spec = GridSpec(x0=-1.35, y0=2.2, resolution=0.05, rows=7, cols=11)  # not square: rows and columns can't swap
    cells = rng.choice(np.array([FREE, OCCUPIED, UNKNOWN], dtype=np.uint8), size=(7, 11))
    cells[:, :] = np.where(cells == OCCUPIED, FREE, cells)
    cells[5, 2] = OCCUPIED  # the one occupied cell: (x, y) = (-1.35 + 2.5 * 0.05, 2.2 + 5.5 * 0.05)
    return OccupancyGrid(spec, cells)


def test_round_trip_through_the_load_rule(grid: OccupancyGrid, tmp_path: Path) -> None:
    pgm, yml = write_ros_map(grid, tmp_path / "out" / "apt.yaml")
    assert pgm == tmp_path / "out" / "apt.pgm" and pgm.read_bytes()[:2] == b"P5"  # binary PGM
    meta = yaml.safe_load(yml.read_text())
    assert meta == {"image": "apt.pgm", "mode": "trinary", "resolution": 0.05, "origin": [-1.35, 2.2, 0.0],
                    "negate": 0, "occupied_thresh": 0.65, "free_thresh": 0.196}
    img = np.asarray(Image.open(pgm))
    assert img.shape == (7, 11) and img.dtype == np.uint8 and set(np.unique(img)) <= {0, 205, 254}
    # map_server's rule by hand: p = (255 - v) / 255; > occupied_thresh occupied, < free_thresh free
    p = (255.0 - img) / 255.0
    loaded = np.where(p > meta["occupied_thresh"], OCCUPIED, np.where(p < meta["free_thresh"], FREE, UNKNOWN))
    np.testing.assert_array_equal(np.flipud(loaded), grid.cells)  # top image row = largest y
    assert (loaded == UNKNOWN).sum() == (grid.cells == UNKNOWN).sum() > 0  # 205 stays unknown, not free
    back = read_ros_map(yml)
    assert back.spec == grid.spec
    np.testing.assert_array_equal(back.cells, grid.cells)


def test_known_cell_world_position(grid: OccupancyGrid, tmp_path: Path) -> None:
    """The occupied pixel, placed the way map_server places pixels, lands on the cell's world centre."""
    pgm, yml = write_ros_map(grid, tmp_path / "apt.yaml")
    img = np.asarray(Image.open(pgm))
    meta = yaml.safe_load(yml.read_text())
    (py, px), = np.argwhere(img == 0)
    h, res = img.shape[0], meta["resolution"]
    x = meta["origin"][0] + (px + 0.5) * res  # origin = the lower-left pixel's corner
    y = meta["origin"][1] + (h - 1 - py + 0.5) * res
    assert (x, y) == pytest.approx((-1.35 + 2.5 * 0.05, 2.2 + 5.5 * 0.05))
    assert (x, y) == pytest.approx(tuple(grid.spec.to_world(np.array([5, 2]))))


def test_bad_paths(grid: OccupancyGrid, tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"must end in \.yaml"):
        write_ros_map(grid, tmp_path / "apt.pgm")
    pgm, yml = write_ros_map(grid, tmp_path / "apt.yaml")
    pgm.unlink()
    with pytest.raises(InputError, match="file not found"):
        read_ros_map(yml)
    yml.write_text("image: apt.pgm\nresolution: [\n")
    with pytest.raises(InputError, match="unreadable"):
        read_ros_map(yml)
