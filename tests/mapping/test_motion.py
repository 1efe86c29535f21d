"""Pose jumps: a dropped stretch of frames is reported once, with what to do; the simulator's own
exploration, whole or thinned the way the commands thin it, is not."""

from __future__ import annotations

import dataclasses
import logging

import numpy as np
import pytest
from _synth_scene import orbit

from capnav.mapping import Mapper, MapperConfig
from capnav.mapping.motion import find_pose_jumps
from capnav.perception import create_detector, create_encoder
from capnav.sim import CameraConfig, ExploreConfig, SimConfig, Simulator
from capnav.sim.explore import plan_exploration


def _eyes(poses: list[np.ndarray]) -> np.ndarray:
    return np.array([T[:3, 3] for T in poses])


@pytest.mark.parametrize("seed", [0, 4, 8])
def test_the_simulators_exploration_has_no_jumps_whole_or_thinned(seed: int) -> None:
    with Simulator.from_seed(seed, SimConfig(camera=CameraConfig(width=32, height=24))) as sim:
        for kw in ({}, {"stride": 3}, {"stride": 4}, {"stride": 8}, {"max_frames": 6}, {"max_frames": 30},
                   {"max_frames": 120}, {"max_frames": 200}):
            eyes = _eyes(plan_exploration(sim, ExploreConfig(seed=0, **kw)))  # type: ignore[arg-type]
            found = find_pose_jumps(np.arange(len(eyes)), eyes)
            assert found.jumps == [], (seed, kw, found.message())


def test_a_dropped_stretch_is_a_jump_in_a_whole_and_in_a_thinned_stream() -> None:
    with Simulator.from_seed(2, SimConfig(camera=CameraConfig(width=32, height=24))) as sim:
        for stride in (1, 3):
            eyes = _eyes(plan_exploration(sim, ExploreConfig(seed=0, stride=stride)))
            moves = np.linalg.norm(np.diff(eyes, axis=0), axis=1)
            # cut out the frames between two points 4x the stream's longest step apart (a recorder that
            # stopped while the camera walked on)
            a = len(eyes) // 3
            b = next(j for j in range(a + 1, len(eyes)) if np.linalg.norm(eyes[j] - eyes[a]) > 4.5 * moves.max())
            kept = np.r_[0:a + 1, b:len(eyes)]
            found = find_pose_jumps(kept, eyes[kept])
            assert [j["frame"] for j in found.jumps] == [b], stride
            assert found.usual_step is not None and found.limit < np.linalg.norm(eyes[b] - eyes[a])


def test_few_frames_judge_each_move_against_the_others() -> None:
    line = np.array([[0.1 * i, 0.0, 1.2] for i in range(7)])
    line[4:] += [3.0, 0.0, 0.0]  # 6 steps of 0.1 m, one of 3.1 m
    assert [j["frame"] for j in find_pose_jumps(range(7), line).jumps] == [4]
    # too few steps for a usual step: only the floor counts
    assert find_pose_jumps(range(3), line[2:5]).jumps == [{"frame": 2, "metres": pytest.approx(3.1)}]
    assert find_pose_jumps(range(3), line[:3]).jumps == []
    # turning in place is no step: a stream that only turns has no jumps and no usual step
    still = find_pose_jumps(range(5), np.zeros((5, 3)))
    assert still.jumps == [] and still.usual_step is None


def test_the_mapper_warns_once_saying_what_to_check(embedder, caplog: pytest.LogCaptureFixture) -> None:  # type: ignore[no-untyped-def]
    frames = orbit(12)
    m = Mapper(MapperConfig(), create_detector("sim", noise="oracle"), create_encoder("label-embedding",
                                                                                       embedder=embedder))
    with caplog.at_level(logging.WARNING, logger="capnav.mapping"):
        for k, f in enumerate(frames):
            T = f.T_wc.copy()
            if k >= 8:
                T[:3, 3] += [5.0, 0.0, 0.0]  # frames 8.. arrive 5 m away: a stretch was dropped
            m.integrate(dataclasses.replace(f, T_wc=T))
        meta = m.finish().meta
    assert [j["frame"] for j in meta["pose_jumps"]] == [frames[8].index]
    warned = [r.getMessage() for r in caplog.records if "jumped" in r.getMessage()]
    assert len(warned) == 1 and "dropped" in warned[0] and "camera-to-world in metres" in warned[0]
