"""Shared scaffolding of the prior-map methods: decide on a target, then plan and drive there.

Every map-based method (CapNav, its ablations, VLMaps-style, category-only, random-object) does
the same two things per subgoal: pick a target region from the shared prior map (the part that
differs between methods, timed as the query) and drive to it with the same A* planner on the same
occupancy map (the part that must not differ, so that only the decision is compared).
"""

from __future__ import annotations

import time
from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.grid import OccupancyGrid
from capnav.eval.method import Agent, SceneContext, SubgoalOutcome
from capnav.mapping.cmap import CapNavMap
from capnav.planning import Costmap, PlannerConfig, build_costmap, navigate_to
from capnav.planning.sight import map_columns, object_heights


@dataclass
class Decision:
    """A method's choice for one goal: the region to reach and why."""

    footprint: NDArray[np.float64]  # (K, 2) world x, y of the target region
    target_xy: tuple[float, float]
    chosen_object: int | None = None
    reason: str = ""
    explanation: str = ""
    extra: dict[str, Any] = field(default_factory=dict)
    z_range: tuple[float, float] | None = None  # the object's heights, for 3D lines of sight


class PriorMapMethod(ABC):
    """Base of the methods that query the shared prior map. Subclasses implement ``prepare``
    (once per apartment) and ``decide`` (once per subgoal)."""

    name: str = "prior-map"
    uses_prior_map: bool = True

    def __init__(self, planner: PlannerConfig | None = None) -> None:
        self.planner = planner or PlannerConfig()
        self.ctx: SceneContext | None = None

    # -- per apartment / episode -------------------------------------------------------------
    def start_episode(self, ctx: SceneContext, agent: Agent) -> None:
        if ctx.prior_map is None or ctx.occupancy is None:
            raise InputError(f"method {self.name!r} needs the prior map, but the scene context has none")
        if self.ctx is not ctx:
            self.ctx = ctx
            self.prepare(ctx)

    def prepare(self, ctx: SceneContext) -> None:  # noqa: B027 - optional hook
        """Per-apartment set-up (indexes, retrievers). Default: nothing."""

    @property
    def cmap(self) -> CapNavMap:
        m = self._ctx().prior_map
        if m is None:
            raise InputError(f"method {self.name!r} needs the prior map")
        return m

    @property
    def occ(self) -> OccupancyGrid:
        o = self._ctx().occupancy
        if o is None:
            raise InputError(f"method {self.name!r} needs the prior occupancy map")
        return o

    def costmap(self) -> Costmap:
        """The inflated costmap of the prior occupancy, built once per apartment and planner."""
        ctx = self._ctx()
        key = f"costmap/{self.planner!r}"
        if key not in ctx.cache:
            ctx.cache[key] = build_costmap(self.occ, self.planner, map_columns(self.cmap))
        cm: Costmap = ctx.cache[key]
        return cm

    def _ctx(self) -> SceneContext:
        if self.ctx is None:
            raise InputError(f"{self.name}: run_subgoal called before start_episode")
        return self.ctx

    # -- per subgoal -----------------------------------------------------------------------
    @abstractmethod
    def decide(self, goal_text: str, robot_xy: tuple[float, float]) -> Decision | str:
        """The target region for ``goal_text``, or a string saying why there is none."""

    def run_subgoal(self, goal_text: str, agent: Agent) -> SubgoalOutcome:
        pose = agent.pose
        t0 = time.perf_counter()
        decision = self.decide(goal_text, (float(pose[0]), float(pose[1])))
        query_time = time.perf_counter() - t0
        if isinstance(decision, str):
            return SubgoalOutcome(found=False, reason=decision, query_time_s=query_time)
        nav = navigate_to(agent, self.occ, decision.footprint, self.planner, costmap=self.costmap(),
                          z_range=decision.z_range)
        return SubgoalOutcome(
            found=True, reason=f"{decision.reason}; {nav.reason}" if decision.reason else nav.reason,
            target_xy=decision.target_xy, chosen_object=decision.chosen_object, query_time_s=query_time,
            steps=max(len(nav.trajectory) - 1, 0), explanation=decision.explanation,
            extra={"replans": nav.replans, **decision.extra})


def object_decision(obj: Any, reason: str, explanation: str = "") -> Decision:
    """A decision for a prior-map object: its footprint (or its centroid if it has none)."""
    fp = np.asarray(obj.footprint, dtype=np.float64).reshape(-1, 2)
    if len(fp) == 0:
        fp = np.asarray(obj.position[:2], dtype=np.float64).reshape(1, 2)
    return Decision(fp, (float(obj.position[0]), float(obj.position[1])), int(obj.id), reason,
                    explanation or (obj.caption or obj.label), z_range=object_heights(obj))
