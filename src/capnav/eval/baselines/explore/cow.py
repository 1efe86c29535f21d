"""CoW-style (CLIP on Wheels, Gadre et al. 2022): nearest-frontier exploration plus object localisation.

CoW explores with a frontier policy that ignores the goal, localises the goal in every view
(CLIP saliency) and drives to it once found. Here the localiser is the shared detector's labels
matched to the goal text (``goal_match``; a sighting needs enough confidence and must not be
outvoted by other labels seen at the same place), lifted to 3D with depth; the frontier chosen is
the nearest by path cost on an occupancy map built online from the agent's own depth.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from capnav.eval.baselines.explore.goal_match import GoalMatcher
from capnav.eval.baselines.explore.object_search import ObjectSearch, ObjectSearchConfig, with_planner
from capnav.eval.method import METHODS, NavMethod
from capnav.explore.explorer import FrontierExplorer
from capnav.explore.frontier import Frontier
from capnav.planning import PlannerConfig


class CoWMethod(ObjectSearch):
    name = "cow"

    def score_frontiers(self, frontiers: Sequence[Frontier], explorer: FrontierExplorer,
                        matcher: GoalMatcher) -> NDArray[np.float64]:
        return -np.array([f.path_distance for f in frontiers], dtype=np.float64)

    def describe_choice(self) -> str:
        return "nearest-frontier exploration; goal localised by detector label"


@METHODS.register("cow")
def _make(config: ObjectSearchConfig | None = None, planner: PlannerConfig | None = None, **_: object) -> NavMethod:
    cfg = config or ObjectSearchConfig()
    return CoWMethod(with_planner(cfg, planner) if planner is not None else cfg)
