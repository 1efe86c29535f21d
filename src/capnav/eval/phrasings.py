"""The free-phrasing protocol: episodes from a file of instructions written by people.

One JSON object per line (the format of the shared development set ``phrasings/dev.jsonl``):
``seed`` (the apartment, as ``capnav sim --seed``), ``instruction``, ``robot`` (``[x, y]`` or
null), ``kind`` (free text, reported per kind), ``accept_ids`` (manifest instance ids that count
as the goal; empty when the right answer is "not found"), ``note`` (ignored) and, for a request of
two goals, ``then`` (the ids that count as its second goal). Each line becomes an episode judged
like the description protocol: the agent must stop within 1 m of an accepted instance; for an
absent target, success is a refusal. A ``then`` line is an episode of two subgoals that both
carry the whole instruction (``step`` 0 and 1): the method hears the request as said and is
scored at each goal, the second from where the first stopped. A line without ``robot`` starts
from a seeded navigable pose at least ``min_start_distance`` from its goal.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from pydantic import BaseModel, Field, ValidationError

from capnav.core.errors import DatasetError
from capnav.eval.episodes import Episode, EpisodeSet, StartPose, Subgoal
from capnav.eval.generate import EpisodeConfig, SceneTruth


class PhrasingLine(BaseModel):
    seed: int = Field(ge=0)
    instruction: str = Field(min_length=1)
    robot: tuple[float, float] | None = None
    kind: str = "phrasing"
    accept_ids: list[int] = Field(default_factory=list)
    note: str = ""
    then: list[int] | None = None  # the ids of a second goal ("..., then the sofa")


def load_phrasings(path: str | Path, run_seed: int = 0) -> EpisodeSet:
    """Read an instruction file into a ``phrasing`` episode set; a bad line is a ``DatasetError``
    naming the file, the line and the field."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as e:
        raise DatasetError(f"cannot read instruction file {p}: {e}") from None
    episodes: list[Episode] = []
    for n, raw in enumerate(text.splitlines(), start=1):
        if not raw.strip() or raw.lstrip().startswith("#"):
            continue
        try:
            line = PhrasingLine.model_validate(json.loads(raw))
        except json.JSONDecodeError as e:
            raise DatasetError(f"{p}:{n}: not JSON ({e.msg} at column {e.colno})") from None
        except ValidationError as e:
            first = e.errors()[0]
            where = ".".join(str(x) for x in first["loc"])
            raise DatasetError(f"{p}:{n}: {where or 'line'}: {first['msg']}") from None
        start = None if line.robot is None else StartPose(x=line.robot[0], y=line.robot[1])
        goals = [Subgoal(text=line.instruction, category="", target_ids=sorted(set(line.accept_ids)), kind=line.kind)]
        if line.then is not None:
            goals.append(Subgoal(text=line.instruction, category="", target_ids=sorted(set(line.then)), kind=line.kind,
                                 step=1))
        episodes.append(Episode(id=f"phrasing-{n:04d}", scene_seed=line.seed, start=start, subgoals=goals))
    if not episodes:
        raise DatasetError(f"instruction file {p} has no instructions")
    seeds = sorted({e.scene_seed for e in episodes})
    return EpisodeSet(protocol="phrasing", seed=run_seed, scene_seeds=seeds, episodes=episodes,
                      generator={"instructions": str(p)})


def fill_start(episode: Episode, truth: SceneTruth, rng: np.random.Generator,
               cfg: EpisodeConfig | None = None) -> Episode:
    """The episode with a start: its own, or a seeded navigable pose from which the goal is
    reachable and not already reached (any navigable pose for an absent target)."""
    if episode.start is not None:
        return episode
    cfg = cfg or EpisodeConfig()
    targets = episode.subgoals[0].target_ids
    for _ in range(cfg.max_tries):
        start = truth.sample_start(rng)
        if not targets:
            break
        d = truth.field(targets).at((start.x, start.y))
        if np.isfinite(d) and d >= cfg.min_start_distance:
            break
    else:
        raise DatasetError(f"episode {episode.id}: no navigable start reaches instances {targets} "
                           f"of scene {episode.scene_seed}")
    return episode.model_copy(update={"start": start})
