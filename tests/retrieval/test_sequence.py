"""Requests of several goals through the query CLI, the API and navigate: the first goal keeps
the single-goal shape at the top level, every goal is in ``goals`` / ``legs``, and a goal that is
not found stops the sequence with the reason."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from capnav.api import CapNav
from capnav.cli import app
from language.synth import described_living_map, walked_through_the_door


@pytest.fixture(scope="module")
def map_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return described_living_map(tmp_path_factory.mktemp("seq"))


def test_query_json_keeps_the_first_goal_on_top_and_lists_every_goal(map_file: Path) -> None:
    r = CliRunner().invoke(app, ["query", str(map_file), "the stove and then the grey sofa", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["found"] and d["chosen"]["id"] == 6 and "reason" in d and "runners_up" in d
    assert [g["chosen"]["id"] for g in d["goals"]] == [6, 2] and d["goals_total"] == 2 and d["stopped"] == ""
    one = json.loads(CliRunner().invoke(app, ["query", str(map_file), "the stove", "--json"]).stdout)
    assert "goals" not in one and one["chosen"]["id"] == 6  # one goal: the shape of before


def test_a_goal_not_found_stops_the_sequence(map_file: Path) -> None:
    r = CliRunner().invoke(app, ["query", str(map_file), "the lamp, then the piano, then the bed", "--json"])
    d = json.loads(r.stdout)
    assert d["found"] and len(d["goals"]) == 2 and not d["goals"][1]["found"] and d["goals_total"] == 3
    assert "goal 2 of 3" in d["stopped"] and "not tried" in d["stopped"]
    printed = CliRunner().invoke(app, ["query", str(map_file), "the lamp, then the piano, then the bed"])
    assert printed.exit_code == 1 and "goal 2 of 3" in printed.stdout and "stopped:" in printed.stdout


def test_too_many_goals_is_a_clear_error(map_file: Path) -> None:
    text = ", then ".join(["the lamp", "the bed", "the stove", "the red sofa", "the grey sofa", "the lamp"])
    r = CliRunner().invoke(app, ["query", str(map_file), text])
    assert r.exit_code != 0 and "at most 5" in str(r.exception)


def test_api_ask_returns_the_sequence_and_keeps_the_old_answer(map_file: Path) -> None:
    nav = CapNav.open(map_file)
    ans = nav.ask("go to the red sofa, after that the bed", robot=(2.0, 2.0))
    assert ans.found and ans.object is not None and ans.object.id == 1  # the first goal, as before
    assert [g.object.id for g in ans.goals if g.object] == [1, 3] and ans.stopped == ""
    # the second goal is asked from where the first leaves the robot (its goal pose)
    assert ans.goal is not None and ans.goals[1].robot == pytest.approx(tuple(ans.goal.xy))
    d = ans.to_dict()
    assert d["object"]["id"] == 1 and [g["object"]["id"] for g in d["goals"]] == [1, 3]
    single = nav.ask("the bed")
    assert single.goals == () and "goals" not in single.to_dict()


def test_navigate_plans_each_leg_and_fails_when_one_fails(map_file: Path, tmp_path: Path) -> None:
    from capnav.io.mapfile import save_map

    path = tmp_path / "walked.capnav"
    save_map(walked_through_the_door(map_file), path)
    r = CliRunner().invoke(app, ["navigate", str(path), "the bed, then the red sofa", "--out", str(tmp_path / "a")])
    assert r.exit_code == 0, r.output
    d = json.loads((tmp_path / "a" / "navigate.json").read_text())
    assert d["ok"] and d["goal"] is not None and len(d["legs"]) == 2 and all(leg["ok"] for leg in d["legs"])
    assert d["legs"][0]["retrieval"]["chosen"]["id"] == 3 and d["legs"][1]["retrieval"]["chosen"]["id"] == 1
    # the second leg starts at the first leg's goal pose
    g1 = d["legs"][0]["goal"]
    assert (d["legs"][1]["start"]["x"], d["legs"][1]["start"]["y"]) == pytest.approx((g1["x"], g1["y"]))
    assert (tmp_path / "a" / "navigate_leg2.json").exists()
    r = CliRunner().invoke(app, ["navigate", str(path), "the bed, then the piano", "--out", str(tmp_path / "b")])
    assert r.exit_code == 1
    d = json.loads((tmp_path / "b" / "navigate.json").read_text())
    assert not d["ok"] and d["legs"][0]["ok"] and not d["legs"][1]["ok"]
