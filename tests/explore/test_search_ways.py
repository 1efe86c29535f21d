"""The search's ways to its answer in the box world of ``test_object_search.py`` (the first map saw
room A only):

- a seen lookalike of the saved answer, nearer than the saved place, is gone to first: the blue
  chair was carried into room B, where the robot stands, and the saved place is behind the wall
  (``ObjectSearch._lookalike``; before: the saved place first, 5.0 m driven for a 2.2 m drive);
- an answer seen and held back at once does not cut the look around short: "the black chair"
  with an armchair in the first views and the black chair behind the robot (before: the look
  stopped at the armchair, and the robot drove off to room B first);
- an approach blocked at the standing cell it aimed at aims again at the cells farther from it
  (``FrontierExplorer.approach(avoid=...)``)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "mapping"))
from _synth_scene import Box, render
from test_object_search import _EMB, BLUE, CHAIR, BoxAgent, K, _captioned, _gap, _room_a, _search

from capnav.core.geometry import look_at_pose
from capnav.explore.explorer import ExplorerConfig, FrontierExplorer, Status
from capnav.explore.search import ObjectSearch, SearchConfig
from capnav.language import create_embedder
from capnav.mapping import CapNavMap, build_map
from capnav.perception import create_detector, create_encoder
from capnav.retrieval.retriever import Retriever

ARMCHAIR = 2


@pytest.fixture(scope="module")
def room_a_map() -> CapNavMap:
    """Room A, its objects' descriptors from the embedder the search's live map uses (so that a
    saved object and its sighting can look alike)."""
    if not _EMB:
        _EMB.append(create_embedder("minilm"))
    boxes = _room_a((-0.3, 2.0))
    frames = [render(boxes, look_at_pose(np.array([*eye, 1.2]), float(yaw), np.radians(25)), K, index=2 * i + j)
              for i, yaw in enumerate(np.radians(np.linspace(55, 305, 24)))
              for j, eye in enumerate(((-1.2, 0.0), (-1.8, 0.4)))]
    return _captioned(build_map(frames, detector=create_detector("sim", noise="oracle", seed=0),
                                encoder=create_encoder("label-embedding", embedder=_EMB[0]),  # type: ignore[arg-type]
                                progress=False))


def test_a_lookalike_nearer_than_the_saved_place_is_gone_to_first(room_a_map: CapNavMap) -> None:
    moved = Box((1.2, -2.5, 0.0), (1.7, -2.0, 0.9), 3, CHAIR, BLUE)
    world = [*(b for b in _room_a((-0.3, 2.0)) if b.instance != 3), moved]
    agent = BoxAgent(world, 2.0, 0.9, 0.0)  # in room B: the saved place (-0.3, 2.0) is behind the wall
    s = ObjectSearch(room_a_map, agent, create_detector("sim", noise="oracle", seed=0),
                     Retriever(room_a_map, _EMB[0]), SearchConfig(budget_m=40.0))  # type: ignore[arg-type]
    res = s.run("the blue chair")
    assert res.found, res.reason
    assert _gap(agent, moved) <= 1.0, (agent.pose, res.reason)
    assert any("looks like the map's object" in st.reason for st in res.steps), [st.reason for st in res.steps]
    assert res.driven_m < 3.5, (res.driven_m, [st.reason for st in res.steps])


def test_a_held_answer_does_not_cut_the_look_around_short(room_a_map: CapNavMap) -> None:
    armchair = Box((-0.6, -0.4, 0.0), (0.0, 0.2, 0.85), 30, ARMCHAIR, (55, 55, 58))
    black = Box((-2.7, -1.45, 0.0), (-2.2, -0.95, 0.9), 31, CHAIR, (15, 15, 15))
    world = [*_room_a((-0.3, 2.0)), armchair, black]
    agent, res = _search(room_a_map, world, "the black chair")
    assert res.found, res.reason
    assert _gap(agent, black) <= 1.0, (agent.pose, res.reason)
    first = next(k for k, st in enumerate(res.steps) if st.action == "found")
    went = [st.reason for st in res.steps[:first] if st.reason.startswith("go to")]
    assert not went, went  # seen in the look around where the request was heard, not from a place


def test_an_approach_aims_away_from_a_standing_cell_it_could_not_get_to(room_a_map: CapNavMap) -> None:
    world = _room_a((-0.3, 2.0))
    table = next(b for b in world if b.instance == 2)
    agent = BoxAgent(world, -1.2, -0.8, 0.0)
    ex = FrontierExplorer(agent, None, ExplorerConfig())
    ex.begin(400)
    ex.observe()
    ex.look_around()
    t = (float(table.center[0]), float(table.center[1]))
    assert ex.approach(lambda: t, 1.3) is Status.ARRIVED
    first = ex.last_goal
    assert first is not None
    agent.x, agent.y = -1.2, -0.8
    ex.observe()
    ex.approach(lambda: t, 1.3, avoid=[first], avoid_radius=0.6)
    assert ex.last_goal is not None and math.dist(ex.last_goal, first) > 0.6, (first, ex.last_goal)
    assert math.dist(ex.xy, first) > 0.3, (first, ex.xy)
