"""ZSON-style (zero-shot object navigation with language reasoning): frontiers ranked by what is near them.

The original reasons about where a goal is likely to be from what the agent has seen. Here the
reasoning is the offline text embedder: a frontier scores the highest similarity between the goal
and the labels sighted within ``radius`` of it (a toilet is sought near a sink, a stove near a
fridge), minus a cost per metre of path. Frontiers with nothing seen near them get ``prior``,
the similarity of unrelated labels, so that empty space is neither preferred nor shunned.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.eval.baselines.explore.goal_match import GoalMatcher
from capnav.eval.baselines.explore.object_search import ObjectSearch, ObjectSearchConfig, with_planner
from capnav.eval.method import METHODS, NavMethod
from capnav.explore.explorer import FrontierExplorer
from capnav.explore.frontier import Frontier
from capnav.planning import PlannerConfig


@dataclass(frozen=True)
class ZSONConfig:
    search: ObjectSearchConfig = field(default_factory=ObjectSearchConfig)
    radius: float = 2.5  # m, sightings this close to a frontier describe it
    semantic_weight: float = 1.0
    distance_weight: float = 0.1  # per metre of path
    prior: float = 0.35  # semantic score of a frontier with no sighting near it

    def __post_init__(self) -> None:
        if self.radius <= 0 or self.semantic_weight < 0 or self.distance_weight < 0:
            raise InputError("ZSON radius must be > 0 and weights >= 0")


class ZSONMethod(ObjectSearch):
    name = "zson"

    def __init__(self, config: ZSONConfig | None = None) -> None:
        self.zson = config or ZSONConfig()
        super().__init__(self.zson.search)
        self._last = ""

    def score_frontiers(self, frontiers: Sequence[Frontier], explorer: FrontierExplorer,
                        matcher: GoalMatcher) -> NDArray[np.float64]:
        cfg = self.zson
        dist = np.array([f.path_distance for f in frontiers], dtype=np.float64)
        sem = np.full(len(frontiers), cfg.prior)
        sights = explorer.sightings
        if sights:
            labels = sorted({s.label for s in sights})
            sim_of = dict(zip(labels, matcher.similarity(labels), strict=True))
            xy = np.array([s.xy for s in sights])
            sims = np.array([sim_of[s.label] for s in sights])
            cxy = np.array([f.centroid_xy for f in frontiers])
            near = ((cxy[:, None, :] - xy[None, :, :]) ** 2).sum(-1) <= cfg.radius**2  # (F, S)
            best = np.where(near, sims[None, :], -np.inf).max(axis=1)
            sem = np.where(np.isfinite(best), best, cfg.prior)
            k = int(np.argmax(cfg.semantic_weight * sem - cfg.distance_weight * dist))
            if np.isfinite(best[k]):
                j = int(np.argmax(np.where(near[k], sims, -np.inf)))
                self._last = f"frontier chosen for the nearby {sights[j].label} (similarity {sims[j]:.2f})"
        return cfg.semantic_weight * sem - cfg.distance_weight * dist

    def describe_choice(self) -> str:
        return "language-scored frontier exploration" + (f"; last {self._last}" if self._last else "")


@METHODS.register("zson")
def _make(config: ZSONConfig | None = None, planner: PlannerConfig | None = None, **_: object) -> NavMethod:
    cfg = config or ZSONConfig()
    if planner is not None:
        cfg = replace(cfg, search=with_planner(cfg.search, planner))
    return ZSONMethod(cfg)
