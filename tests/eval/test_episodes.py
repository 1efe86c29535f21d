"""Episode files: round trip, and clear errors for malformed files and unknown categories."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from capnav.core.errors import DatasetError, InputError
from capnav.eval.episodes import Episode, EpisodeSet, StartPose, Subgoal, check_against_manifest, parse_protocols


def make_set(protocol: str = "label") -> EpisodeSet:
    goals = [Subgoal(text="sofa", category="sofa", target_ids=[3]),
             Subgoal(text="the red chair by the window", category="chair", target_ids=[5], kind="attribute")]
    return EpisodeSet(protocol=protocol, seed=7, scene_seeds=[1],  # type: ignore[arg-type]
                      episodes=[Episode(id="s1-e0", scene_seed=1, start=StartPose(x=1.0, y=2.0, yaw=0.5),
                                        subgoals=goals)])


def test_roundtrip(tmp_path: Path) -> None:
    es = make_set("description")
    es.save(tmp_path / "e.json")
    back = EpisodeSet.load(tmp_path / "e.json")
    assert back == es and back.n_subgoals == 2 and back.for_scene(1)[0].start.yaw == 0.5


@pytest.mark.parametrize("mutate, match", [
    (lambda d: d["episodes"][0]["subgoals"][0].update(category="spaceship"), "unknown category 'spaceship'"),
    (lambda d: d.update(version=99), "version 99"),
    (lambda d: d.update(format="something"), "not a CapNav episode file"),
    (lambda d: d["episodes"][0]["subgoals"][0].update(target_ids=[]), "target_ids"),
    (lambda d: d["episodes"][0].pop("start"), "needs a start pose"),
    (lambda d: d["episodes"][0].update(scene_seed=5), "scene 5 not listed"),
    (lambda d: d["episodes"].append(dict(d["episodes"][0])), "not unique"),
    (lambda d: d["episodes"][0]["subgoals"][0].update(target_ids=[3, 4]), "exactly one target"),
])
def test_malformed_files(tmp_path: Path, mutate, match: str) -> None:  # type: ignore[no-untyped-def]
    data = json.loads(make_set("description").model_dump_json())
    mutate(data)
    p = tmp_path / "bad.json"
    p.write_text(json.dumps(data))
    with pytest.raises(DatasetError, match=match):
        EpisodeSet.load(p)


def test_not_json_and_missing(tmp_path: Path) -> None:
    p = tmp_path / "x.json"
    p.write_text("{not json")
    with pytest.raises(DatasetError, match="not valid JSON"):
        EpisodeSet.load(p)
    p.write_text("[1, 2]")
    with pytest.raises(DatasetError, match="JSON object"):
        EpisodeSet.load(p)
    with pytest.raises(DatasetError, match="not found"):
        EpisodeSet.load(tmp_path / "nope.json")


class _Obj:
    def __init__(self, id: int, category: str) -> None:
        self.id, self.category = id, category


class _Manifest:
    def __init__(self) -> None:
        self.objects = [_Obj(3, "sofa"), _Obj(5, "chair")]


def test_check_against_manifest() -> None:
    es = make_set()
    check_against_manifest(es.episodes, _Manifest())
    es.episodes[0].subgoals[1].target_ids = [3]
    with pytest.raises(DatasetError, match="instance 3 is a sofa, not a chair"):
        check_against_manifest(es.episodes, _Manifest())
    es.episodes[0].subgoals[1].target_ids = [42]
    with pytest.raises(DatasetError, match="instance 42 is not in scene 1"):
        check_against_manifest(es.episodes, _Manifest())


def test_parse_protocols() -> None:
    assert parse_protocols("label, description") == ["label", "description"]
    with pytest.raises(InputError, match="unknown protocol"):
        parse_protocols("label,vibes")
