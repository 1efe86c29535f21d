"""Start poses for one instruction: parsed from --start or taken from an episode file."""

from __future__ import annotations

import pytest

from capnav.core.errors import DatasetError, InputError
from capnav.eval.episodes import Episode, EpisodeSet, StartPose, Subgoal
from capnav.pipeline.drive import episode_start, parse_pose


def test_parse_pose() -> None:
    assert parse_pose("1.5,-2") == (1.5, -2.0, 0.0)
    assert parse_pose(" 1, 2, 0.5 ") == (1.0, 2.0, 0.5)
    for bad in ("1", "1,2,3,4", "a,b", "1,nan", ""):
        with pytest.raises(InputError, match="X,Y"):
            parse_pose(bad)


def test_episode_start(tmp_path) -> None:
    goal = Subgoal(text="go to the sofa", category="sofa", target_ids=[3])
    eps = EpisodeSet(protocol="label", seed=0, scene_seeds=[4, 7], episodes=[
        Episode(id="a", scene_seed=4, start=StartPose(x=1.0, y=2.0, yaw=0.3), subgoals=[goal]),
        Episode(id="b", scene_seed=7, start=StartPose(x=3.0, y=1.0), subgoals=[goal])])
    path = tmp_path / "episodes.json"
    eps.save(path)
    assert episode_start(path) == (4, (1.0, 2.0, 0.3))
    assert episode_start(path, "b") == (7, (3.0, 1.0, 0.0))
    with pytest.raises(InputError, match="no episode 'c'"):
        episode_start(path, "c")
    with pytest.raises(DatasetError):
        episode_start(tmp_path / "missing.json")
