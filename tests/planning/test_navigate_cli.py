"""``capnav navigate`` end to end on a small mapped, captioned apartment."""

from __future__ import annotations

import json

import numpy as np
import pytest
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError
from capnav.core.footprint import footprint_distance

SCENE = 2
pytestmark = pytest.mark.slow  # explores, maps and captions a (small) apartment first


@pytest.fixture(scope="module")
def small_map(tmp_path_factory):
    from capnav.pipeline import PipelineConfig, open_sim_scene

    folder = tmp_path_factory.mktemp("map")
    assets = open_sim_scene(SCENE, SCENE, PipelineConfig(width=160, height=120, max_frames=40), folder)
    cmap = assets.prior_map()
    assets.sim.close()
    return folder / "map.capnav", cmap


def test_navigate_writes_picture_and_json(small_map, tmp_path) -> None:
    path, cmap = small_map
    target = max(cmap.objects, key=lambda o: float(np.prod(o.size[:2])))
    words = (target.caption or target.label).split(",")[1].strip()  # "a large grey sofa, ..." part
    res = CliRunner().invoke(app, ["navigate", str(path), f"go to {words}", "--out", str(tmp_path),
                                   "--occupancy", "truth", "--seed", "3"])
    assert res.exit_code in (0, 1), res.output
    rec = json.loads((tmp_path / "navigate.json").read_text())
    assert (tmp_path / "navigate.png").stat().st_size > 10_000
    assert (tmp_path / "navigate_map.yaml").is_file() and (tmp_path / "navigate_map.pgm").is_file()
    assert rec["instruction"] == f"go to {words}" and rec["occupancy"] == "truth"
    chosen = rec["retrieval"]["chosen"]
    assert chosen is not None and rec["chosen_id"] == chosen["id"]
    nav = rec["navigation"]
    # The JSON tells the truth about where the agent stopped relative to the chosen object.
    fp = cmap.object(chosen["id"]).footprint
    end = np.asarray(nav["final_pose"][:2]).reshape(1, 2)
    assert footprint_distance(end, fp)[0] == pytest.approx(nav["distance_to_object"], abs=1e-3)
    assert nav["reached"] == (nav["distance_to_object"] <= 1.0) == (res.exit_code == 0)
    assert rec["trajectory"][0] == pytest.approx(rec["start"][:2], abs=1e-3)


def test_navigate_bad_start(small_map, tmp_path) -> None:
    path, _ = small_map
    res = CliRunner().invoke(app, ["navigate", str(path), "the sofa", "--out", str(tmp_path), "--start", "1,two"])
    assert isinstance(res.exception, InputError) and "X,Y" in str(res.exception)
    res = CliRunner().invoke(app, ["navigate", str(path), "the sofa", "--out", str(tmp_path), "--start", "-5,-5,0"])
    assert isinstance(res.exception, InputError) and "cannot spawn" in str(res.exception)


def test_navigate_unknown_occupancy(small_map, tmp_path) -> None:
    path, _ = small_map
    res = CliRunner().invoke(app, ["navigate", str(path), "the sofa", "--out", str(tmp_path), "--occupancy", "x"])
    assert isinstance(res.exception, InputError) and "mapped, truth" in str(res.exception)
