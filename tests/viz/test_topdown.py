"""The top-down navigation picture: written atomically, shows the chosen object, JSON matches."""

from __future__ import annotations

import json

import numpy as np
from PIL import Image

from capnav.core.grid import OCCUPIED, GridSpec, OccupancyGrid
from capnav.mapping.objects import MapObject
from capnav.viz.topdown import CHOSEN, draw_navigation, short_label, write_navigation


def obj(i: int, label: str, x0: float, y0: float, x1: float, y1: float) -> MapObject:
    fp = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    centre = np.array([(x0 + x1) / 2, (y0 + y1) / 2, 0.4])
    return MapObject(id=i, label=label, label_votes={label: 1.0}, position=centre,
                     extent_min=np.array([x0, y0, 0.0]), extent_max=np.array([x1, y1, 0.8]), footprint=fp,
                     points=np.zeros((0, 3), np.float32), colors=np.zeros((0, 3), np.uint8),
                     feature=np.zeros(4, np.float32), caption=f"{label.upper()}, a test {label}")


def scene() -> tuple[OccupancyGrid, list[MapObject]]:
    cells = np.zeros((80, 120), np.uint8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = OCCUPIED
    occ = OccupancyGrid(GridSpec(0.0, 0.0, 0.05, 80, 120), cells)
    return occ, [obj(1, "sofa", 4.0, 2.5, 5.5, 3.5), obj(2, "coffee table", 1.0, 2.8, 1.6, 3.4)]


def test_picture_highlights_the_chosen_object(tmp_path) -> None:
    occ, objects = scene()
    path = np.array([[0.5, 0.5], [3.0, 1.5], [4.2, 1.8]])
    traj = np.array([[0.5, 0.5], [3.0, 1.55], [4.15, 1.8]])
    out = draw_navigation(occ, objects, 1, path, traj, (0.5, 0.5, 0.0), (4.15, 1.8, 1.2), "go to the sofa",
                          tmp_path / "nav.png", goal=(4.2, 1.8, 1.1), reach=1.0)
    img = np.asarray(Image.open(out).convert("RGB")).astype(int)
    assert img.shape[0] > 200 and img.shape[1] > 400
    red = np.array([int(CHOSEN[i:i + 2], 16) for i in (1, 3, 5)])
    assert (np.abs(img - red).sum(axis=-1) < 40).sum() > 50  # the chosen outline is drawn
    assert not list(tmp_path.glob(".nav.png*"))  # no temporary left behind


def test_json_has_the_same_content(tmp_path) -> None:
    occ, objects = scene()
    png, js = write_navigation(tmp_path, "q0", occ, objects, 2, np.array([[0.5, 0.5], [1.3, 2.0]]),
                               np.array([[0.5, 0.5], [1.3, 2.0]]), (0.5, 0.5, 0.0), (1.3, 2.0, 1.5), "table",
                               instruction="go to the table")
    rec = json.loads(js.read_text())
    assert png.exists()
    assert rec["chosen_id"] == 2 and rec["instruction"] == "go to the table"
    assert [o["chosen"] for o in rec["objects"]] == [False, True]
    assert rec["objects"][1]["short_label"] == short_label(objects[1]) == "2 coffee table"
    assert rec["path"][-1] == [1.3, 2.0] and rec["grid"]["rows"] == 80
    assert rec["occupancy_counts"]["occupied"] == int((occ.cells == OCCUPIED).sum())


def test_abandoned_plans_are_drawn(tmp_path) -> None:
    occ, objects = scene()
    args = (occ, objects, 1, np.array([[0.5, 0.5], [4.2, 1.8]]), None, (0.5, 0.5), (4.2, 1.8), "t")
    a = draw_navigation(*args, tmp_path / "a.png")
    b = draw_navigation(*args, tmp_path / "b.png", abandoned=[np.array([[0.5, 0.5], [0.5, 3.5], [3.0, 3.5]])])
    ia = np.asarray(Image.open(a).convert("L")).astype(int)
    ib = np.asarray(Image.open(b).convert("L")).astype(int)
    assert ia.shape == ib.shape and (np.abs(ia - ib) > 30).sum() > 100
