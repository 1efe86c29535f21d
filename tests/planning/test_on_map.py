"""Navigation on a map alone (no simulator): start from the camera path, plan to the described
object, write the goal pose, the path and the map for a robot stack; clear reasons when it can't."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "mapping"))
from _synth_scene import HashEmbedder, orbit

from capnav.cli import app
from capnav.core.errors import InputError
from capnav.core.footprint import footprint_distance
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.io.mapfile import load_map, save_map
from capnav.io.rosmap import read_ros_map
from capnav.language import create_captioner, create_embedder, describe_map
from capnav.mapping import CapNavMap, build_map
from capnav.perception import create_detector, create_encoder
from capnav.planning.costmap import build_costmap
from capnav.planning.goal import polygon_centroid
from capnav.planning.on_map import camera_yaw, free_along_path, navigate_on_map
from capnav.retrieval import Retriever, create_verifier


@pytest.fixture(scope="module")
def described(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, CapNavMap]:
    """A captioned map of the synthetic room (sofa, table, chair, bookshelf, lamp) seen from a camera
    walking a 1.2 m circle: a map with a camera path and no simulator seed."""
    frames = orbit(30)
    cmap = build_map(frames, detector=create_detector("sim", noise="oracle", seed=0),
                     encoder=create_encoder("label-embedding", embedder=HashEmbedder()), progress=False)
    describe_map(cmap, None, create_captioner("offline"), create_embedder("minilm"), progress=False)
    assert "scene_seed" not in cmap.meta and cmap.trajectory is not None
    path = tmp_path_factory.mktemp("onmap") / "room.capnav"
    save_map(cmap, path)
    return path, cmap


def _retriever(cmap: CapNavMap) -> Retriever:
    emb = create_embedder("minilm")
    return Retriever(cmap, emb, create_verifier("offline", embedder=emb))


def test_plan_from_the_last_camera_pose(described: tuple[Path, CapNavMap]) -> None:
    _, cmap = described
    # The camera walked a circle looking out: the floor between it and the bookshelf was never seen.
    refused = navigate_on_map(cmap, _retriever(cmap), "the bookshelf")
    assert not refused.ok and refused.unknown_m > 0 and "m of unknown space" in refused.reason
    assert "--through-unknown" in refused.reason and refused.goal is not None
    rec = refused.to_dict()
    assert rec["ok"] is False and rec["goal"]["ok"] is True and 0 < rec["path"]["seen_free_fraction"] < 1
    nav = navigate_on_map(cmap, _retriever(cmap), "the bookshelf", through_unknown=True)
    assert nav.ok, nav.reason
    assert "accepted (--through-unknown)" in nav.reason
    last = cmap.trajectory.poses[-1]  # type: ignore[union-attr]
    assert nav.start == pytest.approx((last[0, 3], last[1, 3], camera_yaw(last)))
    assert nav.start_source == "the last camera pose (frame 29)"
    assert nav.query.chosen is not None and nav.query.chosen.label == "bookshelf"
    g, p = nav.goal, nav.path
    assert g is not None and p is not None
    assert footprint_distance(g.xy[None], nav.query.chosen.footprint)[0] <= 1.0  # within reach
    c = polygon_centroid(nav.query.chosen.footprint)
    assert g.yaw == pytest.approx(np.arctan2(c[1] - g.xy[1], c[0] - g.xy[0]))  # facing the object
    assert p.waypoints[0] == pytest.approx(nav.start[:2]) and p.waypoints[-1] == pytest.approx(g.xy)
    cm = build_costmap(nav.occupancy)
    assert np.isfinite(cm.weights[p.cells[:, 0], p.cells[:, 1]]).all()  # every path cell is traversable
    # the camera path counts as free; the mapped obstacles stay as they were
    under = nav.occupancy.spec.to_cell(cmap.trajectory.poses[:, :2, 3])  # type: ignore[union-attr]
    assert (nav.occupancy.cells[under[:, 0], under[:, 1]] != UNKNOWN).all()
    np.testing.assert_array_equal(nav.occupancy.cells == OCCUPIED, cmap.occupancy.cells == OCCUPIED)


def test_free_along_path() -> None:
    cells = np.full((20, 30), UNKNOWN, dtype=np.uint8)
    cells[10, 15] = OCCUPIED
    occ = OccupancyGrid(GridSpec(0.0, 0.0, 0.1, 20, 30), cells)
    out, n = free_along_path(occ, np.array([[0.55, 1.05], [2.55, 1.05]]), radius=0.2)
    assert out.cells[10, 15] == OCCUPIED and cells[10, 5] == UNKNOWN  # input untouched
    assert (np.delete(out.cells[10, 5:26], 10) == FREE).all() and (out.cells[8:13, 10] == FREE).all()
    assert out.cells[7, 10] == UNKNOWN and out.cells[10, 28] == UNKNOWN  # 0.3 m off the path
    assert n == int((out.cells == FREE).sum())


def test_cli_plan_only_writes_goal_path_and_ros_map(described: tuple[Path, CapNavMap], tmp_path: Path) -> None:
    path, cmap = described
    res = CliRunner().invoke(app, ["navigate", str(path), "go to the sofa", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    assert "from the last camera pose (frame 29)" in res.output and "goal pose: x" in res.output
    rec = json.loads((tmp_path / "navigate.json").read_text())
    assert rec["frame"] == "map" and rec["ok"] and rec["retrieval"]["chosen"]["label"] == "sofa"
    g = rec["goal"]
    assert set(g) >= {"x", "y", "yaw", "reached_within_reach"} and g["reached_within_reach"]
    wps = np.array(rec["path"]["waypoints"])
    assert wps[0] == pytest.approx([rec["start"]["x"], rec["start"]["y"]], abs=1e-3)
    assert wps[-1] == pytest.approx([g["x"], g["y"]], abs=1e-3)
    assert (tmp_path / "navigate.png").stat().st_size > 10_000
    grid = read_ros_map(tmp_path / rec["map_server"]["yaml"])
    nav = navigate_on_map(cmap, _retriever(cmap), "go to the sofa")
    assert grid.spec == nav.occupancy.spec
    np.testing.assert_array_equal(grid.cells, nav.occupancy.cells)
    # a start given by hand; one off the map is refused with the map's extent
    # a start given by hand in the middle of the orbit, where the floor was never seen: refused, or
    # planned when crossing unknown space is accepted
    res = CliRunner().invoke(app, ["navigate", str(path), "the sofa", "--out", str(tmp_path), "--start", "0,0,1.57"])
    assert res.exit_code == 1 and "of unknown space" in res.output
    res = CliRunner().invoke(app, ["navigate", str(path), "the sofa", "--out", str(tmp_path), "--start", "0,0,1.57",
                                   "--through-unknown"])
    assert res.exit_code == 0, res.output
    assert json.loads((tmp_path / "navigate.json").read_text())["start"]["source"] == "--start"
    res = CliRunner().invoke(app, ["navigate", str(path), "the sofa", "--out", str(tmp_path), "--start", "40,0"])
    assert isinstance(res.exception, InputError) and "start (40.00, 0.00) is off the map, which covers" in str(
        res.exception)
    res = CliRunner().invoke(app, ["navigate", str(path), "the sofa", "--out", str(tmp_path), "--drive"])
    assert isinstance(res.exception, InputError) and "records no scene seed to drive in" in str(res.exception)


def test_unreachable_and_missing_start(described: tuple[Path, CapNavMap], tmp_path: Path) -> None:
    path, cmap = described
    # a wall ring around the room's centre: the start inside it, every object outside
    walled = load_map(path)
    spec = walled.occupancy.spec
    rr, cc = np.mgrid[0:spec.rows, 0:spec.cols]
    d = np.linalg.norm(spec.to_world(np.stack([rr, cc], axis=-1)), axis=-1)
    walled.occupancy.cells[(d > 0.45) & (d < 0.6)] = OCCUPIED
    nav = navigate_on_map(walled, _retriever(walled), "the bookshelf", start=(0.0, 0.0, 0.0))
    assert not nav.ok and nav.goal is not None and not nav.goal.reached_within_reach
    assert nav.reason.startswith("the object is out of reach from the start: no ")
    ring = tmp_path / "walled.capnav"
    save_map(walled, ring)
    res = CliRunner().invoke(app, ["navigate", str(ring), "the bookshelf", "--out", str(tmp_path), "--start", "0,0"])
    assert res.exit_code == 1 and "no plan" in res.output and "out of reach" in res.output
    assert json.loads((tmp_path / "navigate.json").read_text())["ok"] is False
    with pytest.raises(InputError, match="inside an obstacle"):
        navigate_on_map(walled, _retriever(walled), "the bookshelf", start=(0.5, 0.0, 0.0))
    old = CapNavMap(cmap.objects, cmap.voxels, cmap.occupancy, cmap.meta, cmap.caches, trajectory=None)
    with pytest.raises(InputError, match=r"records no camera path .* pass --start"):
        navigate_on_map(old, _retriever(old), "the sofa")


def test_a_sequence_through_a_closed_door_stops_at_that_leg_with_the_reason(
        described: tuple[Path, CapNavMap], tmp_path: Path) -> None:
    path, _ = described
    # A wall closes off the room's south-east quarter, where the lamp stands (more than the reach
    # from the wall); its doorway (y -2.1 to -1.3 m) is open in one map and shut in the other (a
    # closed door reads as wall).
    maps = {}
    for state in ("open", "shut"):
        cmap = load_map(path)
        spec = cmap.occupancy.spec
        rr, cc = np.mgrid[0:spec.rows, 0:spec.cols]
        xy = spec.to_world(np.stack([rr, cc], axis=-1))
        x, y = xy[..., 0], xy[..., 1]
        wall = ((np.abs(x - 1.0) < 0.05) & (y < -0.9)) | ((np.abs(y + 0.9) < 0.05) & (x > 1.0))
        if state == "open":
            wall &= ~((np.abs(x - 1.0) < 0.05) & (y > -2.1) & (y < -1.3))
        cmap.occupancy.cells[wall] = OCCUPIED
        maps[state] = tmp_path / f"{state}.capnav"
        save_map(cmap, maps[state])
    text = "go to the sofa, then the lamp"
    args = ["--start", "-1.5,0.5", "--through-unknown"]
    res = CliRunner().invoke(app, ["navigate", str(maps["open"]), text, "--out", str(tmp_path / "o"), *args])
    assert res.exit_code == 0, res.output
    res = CliRunner().invoke(app, ["navigate", str(maps["shut"]), text, "--out", str(tmp_path / "s"), *args])
    assert res.exit_code == 1 and "goal 2 of 2" in res.output and "no plan" in res.output
    rec = json.loads((tmp_path / "s" / "navigate.json").read_text())
    assert rec["ok"] is False and [leg["ok"] for leg in rec["legs"]] == [True, False]
    lamp = rec["legs"][1]
    assert lamp["retrieval"]["chosen"]["label"] == "lamp"  # the right object, walled off
    assert "out of reach" in lamp["reason"] and "not connected to where the robot stands" in lamp["reason"]
