"""Run one method through one episode and score every subgoal against the ground truth.

The harness, not the method, measures what counts: where the agent stopped (from its pose), how
far it drove in this subgoal (from its odometry), whether that is within 1 m of a goal footprint,
the geodesic shortest path for SPL, and whether the method's chosen target was the right instance.
Each subgoal starts where the previous one stopped.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from capnav.core.errors import CapNavError
from capnav.eval.episodes import Episode
from capnav.eval.generate import SceneTruth
from capnav.eval.method import NavMethod, SceneContext, SubgoalOutcome
from capnav.eval.metrics import SubgoalRecord
from capnav.sim.success import distance_to_instances

#: A chosen target counts as the right instance when it lies this close to the instance's footprint
#: (map centroids of large objects sit inside their footprint; small ones within a few decimetres).
RETRIEVAL_TOLERANCE_M = 0.5


def _xy(agent: Any) -> tuple[float, float]:
    p = agent.pose
    return float(p[0]), float(p[1])


def _trajectory(agent: Any) -> list[tuple[float, float]]:
    traj = getattr(agent, "trajectory", None)
    return [] if traj is None else [(float(p[0]), float(p[1])) for p in traj]


def _odometry(agent: Any) -> float:
    """Distance the agent has driven since it was spawned (its own counter, else its trajectory)."""
    pl = getattr(agent, "path_length", None)
    if pl is not None:
        return float(pl() if callable(pl) else pl)
    t = np.asarray(_trajectory(agent), dtype=np.float64).reshape(-1, 2)
    return float(np.linalg.norm(np.diff(t, axis=0), axis=1).sum()) if len(t) > 1 else 0.0


def retrieval_correct(truth: SceneTruth, target_xy: tuple[float, float] | None, target_ids: list[int]) -> bool | None:
    """Is the method's chosen target at a goal instance, and nearer to it than to any other instance?

    None when the method chose no target (it then counts as wrong in the top-1 rate)."""
    if target_xy is None:
        return None
    d_goal = distance_to_instances(target_xy, [truth.footprints[i] for i in target_ids])
    others = [f for i, f in truth.footprints.items() if i not in target_ids]
    d_other = distance_to_instances(target_xy, others)
    return bool(d_goal <= RETRIEVAL_TOLERANCE_M and d_goal <= d_other)


def run_episode(method: NavMethod, ctx: SceneContext, episode: Episode, truth: SceneTruth, protocol: str
                ) -> list[SubgoalRecord]:
    """Spawn the agent at the episode's start, run the subgoals in order, score each."""
    s = episode.start
    if s is None:
        raise CapNavError(f"episode {episode.id} has no start pose (fill it with eval.phrasings.fill_start)")
    agent = ctx.sim.spawn_agent(s.x, s.y, s.yaw)
    broken = ""
    try:
        method.start_episode(ctx, agent)
    except CapNavError as e:  # e.g. a map without objects: every subgoal fails, the run goes on
        broken = f"could not start: {type(e).__name__}: {e}"
    except Exception as e:  # a bug in a method must not end an hour-long run; it is counted as a crash
        broken = f"CRASH in start_episode: {type(e).__name__}: {e}"
    records: list[SubgoalRecord] = []
    for i, goal in enumerate(episode.subgoals):
        start_xy = _xy(agent)
        odo0, traj0 = _odometry(agent), len(_trajectory(agent))
        t0 = time.perf_counter()
        error = ""
        if broken:
            out = SubgoalOutcome(found=False, reason=broken)
            error = broken if broken.startswith("CRASH") else ""
        else:
            try:
                out = method.run_subgoal(goal.text, agent)
            except CapNavError as e:  # an expected failure (unreachable goal, bad map): the agent stays put
                out = SubgoalOutcome(found=False, reason=f"{type(e).__name__}: {e}",
                                     query_time_s=time.perf_counter() - t0)
            except Exception as e:  # a bug: scored as a failure, counted and reported as a crash
                error = f"CRASH: {type(e).__name__}: {e}"
                out = SubgoalOutcome(found=False, reason=error, query_time_s=time.perf_counter() - t0)
        stop_xy = _xy(agent)
        footprints = [truth.footprints[t] for t in goal.target_ids]
        dist = distance_to_instances(stop_xy, footprints)
        if goal.absent:  # the right answer is "not found": success is a refusal, wherever the agent is
            success: bool = not out.found
            strict: bool | None = success if truth.sight is not None else None
            room: bool | None = success if truth.sight is not None and truth.rooms else None
            judged: bool | None = not out.found
            shortest = 0.0
        else:
            success = bool(dist <= truth.radius)
            strict = truth.sees_goal(stop_xy, goal.target_ids)
            room = truth.in_goal_room(stop_xy, goal.target_ids)
            judged = retrieval_correct(truth, out.target_xy, goal.target_ids)
            shortest = truth.field(goal.target_ids).at(start_xy)
        traj = _trajectory(agent)[max(traj0 - 1, 0):] or [start_xy, stop_xy]
        records.append(SubgoalRecord(
            method=method.name, protocol=protocol, scene_seed=episode.scene_seed, episode_id=episode.id, index=i,
            text=goal.text, category=goal.category, target_ids=list(goal.target_ids), kind=goal.kind,
            success=success, distance_to_goal=dist, success_strict=strict, success_room=room,
            path_length=max(_odometry(agent) - odo0, 0.0),
            shortest_path=shortest,
            start_xy=start_xy, stop_xy=stop_xy, found=bool(out.found),
            retrieval_correct=judged,
            query_time_s=float(out.query_time_s), steps=int(out.steps), reason=out.reason,
            target_xy=None if out.target_xy is None else (float(out.target_xy[0]), float(out.target_xy[1])),
            chosen_object=out.chosen_object, explanation=out.explanation,
            trajectory=[(round(x, 3), round(y, 3)) for x, y in traj], error=error))
    return records
