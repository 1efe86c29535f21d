"""Episode files: versioned JSON so that anyone reruns exactly the same goals from the same poses.

One file per protocol holds the episodes of every apartment. A subgoal carries the text a method
is told and the ground truth the harness scores against (``target_ids``: every instance of the
category under the label-only protocol, the one described instance under the description
protocol). Loading validates everything and fails with one clear message.
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Literal

from pydantic import BaseModel, Field, ValidationError, field_validator, model_validator

from capnav.core.atomic import write_text
from capnav.core.categories import BY_NAME, NAMES
from capnav.core.errors import DatasetError, InputError
from capnav.core.jsonfile import read_json_object

EPISODES_FORMAT: Literal["capnav-episodes"] = "capnav-episodes"
EPISODES_VERSION = 1
PROTOCOLS: tuple[str, ...] = ("label", "description", "phrasing")
Protocol = Literal["label", "description", "phrasing"]
#: Protocols generated from the apartments (``phrasing`` episodes come from a file of instructions).
GENERATED_PROTOCOLS: tuple[str, ...] = ("label", "description")


class StartPose(BaseModel):
    x: float
    y: float
    yaw: float = 0.0


class Subgoal(BaseModel):
    """One goal of an episode: what the method hears and what counts as reaching it."""

    text: str = Field(min_length=1)
    category: str = Field(description="the goal's category; '' for a free phrasing (targets of any category)")
    target_ids: list[int] = Field(description="ground-truth instance ids that count as success; empty when "
                                              "the right answer is 'not found' (phrasing protocol only)")
    kind: str = "category"  # instruction kind: category, attribute, superlative, relation, room, closest, ...
    #: Which goal of its text this subgoal is: 0 the first; 1 the goal after "then" of a request of
    #: two, whose subgoals carry the same text (the phrasing protocol's ``then`` lines).
    step: int = Field(default=0, ge=0)

    @field_validator("category")
    @classmethod
    def _known_category(cls, v: str) -> str:
        if v and v not in BY_NAME:
            raise ValueError(f"unknown category {v!r}; known: {', '.join(NAMES)}")
        return v

    @property
    def absent(self) -> bool:
        """The right answer is 'not found': success is a refusal."""
        return not self.target_ids


class Episode(BaseModel):
    id: str
    scene_seed: int
    #: None: the harness draws a seeded navigable start (free phrasings that give no robot position).
    start: StartPose | None = None
    subgoals: list[Subgoal] = Field(min_length=1)


class EpisodeSet(BaseModel):
    """All episodes of one protocol over a list of apartments."""

    format: Literal["capnav-episodes"] = EPISODES_FORMAT
    version: int = EPISODES_VERSION
    protocol: Protocol
    seed: int
    scene_seeds: list[int]
    generator: dict[str, object] = Field(default_factory=dict, description="generation settings, for the record")
    episodes: list[Episode]

    @model_validator(mode="after")
    def _consistent(self) -> EpisodeSet:
        ids = [e.id for e in self.episodes]
        if len(set(ids)) != len(ids):
            raise ValueError("episode ids are not unique")
        known = set(self.scene_seeds)
        for e in self.episodes:
            if e.scene_seed not in known:
                raise ValueError(f"episode {e.id} uses scene {e.scene_seed} not listed in scene_seeds")
            if self.protocol != "phrasing" and e.start is None:
                raise ValueError(f"episode {e.id}: a {self.protocol} episode needs a start pose")
            for i, g in enumerate(e.subgoals):
                if self.protocol != "phrasing" and (not g.target_ids or not g.category):
                    raise ValueError(f"episode {e.id} subgoal {i}: a {self.protocol} goal needs a category and "
                                     "at least one of target_ids")
                if self.protocol == "description" and len(g.target_ids) != 1:
                    raise ValueError(f"episode {e.id} subgoal {i}: a description goal has exactly one target")
        return self

    def for_scene(self, scene_seed: int) -> list[Episode]:
        return [e for e in self.episodes if e.scene_seed == scene_seed]

    @property
    def n_subgoals(self) -> int:
        return sum(len(e.subgoals) for e in self.episodes)

    def save(self, path: str | Path) -> None:
        write_text(path, self.model_dump_json(indent=1) + "\n")

    @classmethod
    def load(cls, path: str | Path) -> EpisodeSet:
        """Load and validate; any problem is a ``DatasetError`` naming the file and the field."""
        p = Path(path)
        data = read_json_object(p, "episode file")
        if data.get("format") != EPISODES_FORMAT:
            raise DatasetError(f"{p} is not a CapNav episode file (format {data.get('format')!r})")
        if data.get("version") != EPISODES_VERSION:
            raise DatasetError(f"episode file {p} has version {data.get('version')}, expected {EPISODES_VERSION}")
        try:
            return cls.model_validate(data)
        except ValidationError as e:
            first = e.errors()[0]
            where = ".".join(str(x) for x in first["loc"])
            raise DatasetError(f"episode file {p} is malformed at {where or '<root>'}: {first['msg']}"
                               + (f" (and {len(e.errors()) - 1} more problems)" if len(e.errors()) > 1 else "")
                               ) from None


def check_against_manifest(episodes: Iterable[Episode], manifest: object) -> None:
    """Every target id must exist in the apartment and have the subgoal's category.

    ``manifest`` is a ``capnav.sim.manifest.SceneManifest``; an episode file written for another
    generator version or another apartment fails here instead of scoring nonsense.
    """
    objects = {o.id: o for o in manifest.objects}  # type: ignore[attr-defined]
    for e in episodes:
        for i, g in enumerate(e.subgoals):
            for t in g.target_ids:
                if t not in objects:
                    raise DatasetError(f"episode {e.id} subgoal {i}: instance {t} is not in scene {e.scene_seed}")
                if g.category and objects[t].category != g.category:
                    raise DatasetError(f"episode {e.id} subgoal {i}: instance {t} is a {objects[t].category}, "
                                       f"not a {g.category}")


def parse_protocols(text: str | Iterable[str]) -> list[str]:
    """``"label,description"`` -> ["label", "description"]; unknown names are an ``InputError``."""
    items = [t.strip() for t in (text.split(",") if isinstance(text, str) else text) if t.strip()]
    for t in items:
        if t == "phrasing":
            raise InputError("the phrasing protocol runs from a file of instructions: use --instructions FILE")
        if t not in GENERATED_PROTOCOLS:
            raise InputError(f"unknown protocol {t!r}; choose from {', '.join(GENERATED_PROTOCOLS)}")
    if not items:
        raise InputError("no protocol given")
    return items
