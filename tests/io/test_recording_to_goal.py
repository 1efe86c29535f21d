"""A recording nobody aligned, end to end with no simulator and no hand-written Python: a TUM folder
in a tilted world goes through `capnav import tum` (no --up), `capnav map` with a real COCO detector,
`capnav caption`, `capnav query` and `capnav navigate`, and the goal lands by the chair it saw.

The frames are the simulator's (320x240, a short walk past the kitchen's red stools, which the
Yolo-Fastest model reads as chairs); from the TUM folder on, every step reads only the files.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from test_import_tum import write_tum
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.footprint import footprint_distance
from capnav.core.frame import Frame
from capnav.core.geometry import look_at_pose
from capnav.io.dataset import DatasetReader
from capnav.io.mapfile import load_map
from capnav.io.rosmap import read_ros_map
from capnav.sim import CameraConfig, LayoutConfig, SimConfig, Simulator

pytestmark = pytest.mark.slow  # six frames through every stage (about half a minute)

# The recording's world: CapNav's z up is tilted 100 deg about x, 8 about y, yawed 40, and shifted.
WORLD = np.eye(4)
WORLD[:3, :3] = Rotation.from_euler("xyz", [100.0, 8.0, 40.0], degrees=True).as_matrix()
WORLD[:3, 3] = [0.3, 1.4, -0.5]


@pytest.fixture(scope="module")
def walk() -> tuple[list[Frame], list[np.ndarray]]:
    """Six views of apartment 0 walking from (7.38, 0.73) to (6.83, 0.28), turning from 113 to 61
    degrees, camera 1.25 m up pitched 15 degrees down; with the stools' true centres."""
    sim = Simulator.from_seed(0, SimConfig(layout=LayoutConfig(rooms=3), camera=CameraConfig(width=320, height=240)))
    try:
        frames = []
        for i, t in enumerate(np.linspace(0.0, 1.0, 6)):
            eye = np.array([7.375 - 0.55 * t, 0.725 - 0.45 * t, 1.25])
            frames.append(sim.render(look_at_pose(eye, 1.968 - 0.896 * t, math.radians(15)), index=i))
        stools = [np.asarray(o.center, dtype=np.float64) for o in sim.manifest.objects if o.category == "stool"]
    finally:
        sim.close()
    return frames, stools


def test_recording_to_goal_pose(walk, shared_dir: Path, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    frames, stools = walk
    seq, ds, run = tmp_path / "living_room", tmp_path / "ds", tmp_path / "run"
    write_tum(seq, frames, world=WORLD)
    cli = CliRunner()

    r = cli.invoke(app, ["import", "tum", str(seq), "-o", str(ds), "--intrinsics", str(seq / "cam.json"),
                         "--no-progress"])
    assert r.exit_code == 0, r.output
    assert "6 frames written" in r.output and "up found: the recording's" in r.output
    align = DatasetReader(ds).meta["meta"]["alignment"]
    assert align["method"] == "floor-auto" and align["confidence"] >= 0.9
    M = np.asarray(align["A"]).reshape(4, 4) @ WORLD  # the simulator's world -> the imported one
    assert abs(M[2, 2] - 1.0) < 1e-4 and abs(M[2, 3]) < 0.01  # z up, floor at 0: only yaw and xy are free

    weights = shared_dir / "weights" / "yolo-fastest-1.1-xl"
    r = cli.invoke(app, ["map", str(ds), "-o", str(run / "room.capnav"), "--detector", "yolo-fastest",
                         "--detector-option", f"model_dir={weights}", "--no-progress"])
    assert r.exit_code == 0, r.output
    chairs = load_map(run / "room.capnav").by_label("chair")
    assert chairs, r.output

    r = cli.invoke(app, ["caption", str(run / "room.capnav"), "--dataset", str(ds), "-o", str(run / "described.capnav"),
                         "--no-progress"])
    assert r.exit_code == 0, r.output

    r = cli.invoke(app, ["query", str(run / "described.capnav"), "the chair", "--json"])
    assert r.exit_code == 0, r.output
    chosen = json.loads(r.stdout)["chosen"]
    assert chosen["label"] == "chair"
    cmap = load_map(run / "described.capnav")
    obj = cmap.object(chosen["id"])
    # it is one of the red stools: its centre, taken back to the simulator's world, is near one
    p = np.linalg.solve(M, np.r_[obj.position, 1.0])[:3]
    assert min(float(np.linalg.norm(p[:2] - s[:2])) for s in stools) < 0.5

    # The camera never saw part of the floor on the way: the plan says so (not ok) unless that is accepted.
    r = cli.invoke(app, ["navigate", str(run / "described.capnav"), "go to the chair", "--out", str(run)])
    assert r.exit_code == 1 and "of unknown space" in r.output
    rec = json.loads((run / "navigate.json").read_text())
    assert rec["ok"] is False and rec["goal"]["ok"] and rec["path"]["seen_free_fraction"] < 1
    r = cli.invoke(app, ["navigate", str(run / "described.capnav"), "go to the chair", "--out", str(run),
                         "--through-unknown"])
    assert r.exit_code == 0, r.output
    rec = json.loads((run / "navigate.json").read_text())
    assert rec["frame"] == "map" and rec["ok"] and rec["retrieval"]["chosen"]["label"] == "chair"
    start, goal = rec["start"], rec["goal"]
    last = M @ frames[-1].T_wc  # the start is the last camera pose, on the floor
    assert start["source"].startswith("the last camera pose") and [start["x"], start["y"]] == pytest.approx(
        last[:2, 3], abs=1e-3)
    target = cmap.object(rec["retrieval"]["chosen"]["id"]).footprint
    assert footprint_distance(np.array([[goal["x"], goal["y"]]]), target)[0] <= 1.0
    wps = np.array(rec["path"]["waypoints"])
    assert wps[0] == pytest.approx([start["x"], start["y"]], abs=1e-3) and wps[-1] == pytest.approx(
        [goal["x"], goal["y"]], abs=1e-3)
    grid = read_ros_map(run / rec["map_server"]["yaml"])
    assert grid.spec == cmap.occupancy.spec
    assert (run / "navigate.png").stat().st_size > 10_000
