"""Object search by exploration (the CoW / ZSON family): explore until the goal is seen, then go.

No prior map: each episode starts with an empty online map. The agent explores by frontiers
(the subclass says which frontier is best), and every observation runs the shared detector; as
soon as a detection answers the goal (see ``goal_match``) with enough confidence, the agent
lifts it to 3D and approaches it, re-estimating its position from every new sighting. Sightings
are kept for the rest of the episode, so a goal already seen on the way to an earlier subgoal is
reached directly (``remember``). Failures are reported as they are: a timeout when the action
budget ends, "not found" when every reachable frontier was visited.
"""

from __future__ import annotations

import math
import time
from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.eval.baselines.explore.goal_match import GoalMatcher
from capnav.eval.method import Agent, SceneContext, SubgoalOutcome
from capnav.explore.explorer import ExplorerConfig, FrontierExplorer, Status
from capnav.explore.frontier import Frontier
from capnav.explore.sighting import Sighting
from capnav.explore.votes import outvoted
from capnav.planning import PlannerConfig


@dataclass(frozen=True)
class ObjectSearchConfig:
    explorer: ExplorerConfig = field(default_factory=ExplorerConfig)
    goal_score: float = 0.55  # detector confidence a goal sighting needs (above the false-positive band)
    match_threshold: float = 0.6  # label-goal cosine for free-form goals without a category word
    stop_distance: float = 0.8  # m from the sighted goal's centre (success is 1 m from its footprint)
    cluster_radius: float = 1.0  # m, sightings this close to the chosen one refine its position
    remember: bool = True  # goal sightings from earlier subgoals of the episode count
    vote_radius: float = 0.5  # m; a goal sighting outvoted by other labels this close is a confusion (0: off)

    def __post_init__(self) -> None:
        if not (0.0 <= self.goal_score <= 1.0) or self.stop_distance <= 0 or self.cluster_radius <= 0:
            raise InputError("goal_score must be in [0, 1]; stop_distance and cluster_radius > 0")


def with_planner(config: ObjectSearchConfig, planner: PlannerConfig) -> ObjectSearchConfig:
    """The same search driven by another planner config (the harness passes CapNav's)."""
    return replace(config, explorer=replace(config.explorer, planner=planner))


class ObjectSearch(ABC):
    """A NavMethod that searches for the goal by frontier exploration; subclasses rank frontiers."""

    name: str = "object-search"
    uses_prior_map: bool = False

    def __init__(self, config: ObjectSearchConfig | None = None) -> None:
        self.config = config or ObjectSearchConfig()
        self.ctx: SceneContext | None = None
        self.explorer: FrontierExplorer | None = None
        self._decision_time = 0.0

    @abstractmethod
    def score_frontiers(self, frontiers: Sequence[Frontier], explorer: FrontierExplorer,
                        matcher: GoalMatcher) -> NDArray[np.float64]:
        """One score per frontier; the highest is explored next."""

    def describe_choice(self) -> str:
        return ""

    # ------------------------------------------------------------------ NavMethod
    def start_episode(self, ctx: SceneContext, agent: Agent) -> None:
        if ctx.detector is None:
            raise InputError(f"method {self.name!r} needs the shared detector, but the scene context has none")
        self.ctx = ctx
        self.explorer = FrontierExplorer(agent, ctx.detector, self.config.explorer)

    def run_subgoal(self, goal_text: str, agent: Agent) -> SubgoalOutcome:
        if self.ctx is None or self.explorer is None:
            raise InputError(f"{self.name}: run_subgoal called before start_episode")
        ex = self.explorer
        if ex.agent is not agent:
            raise InputError(f"{self.name}: run_subgoal got a different agent than start_episode")
        cfg = self.config
        self._decision_time = 0.0
        ex.begin(self.ctx.max_steps)
        matcher = self._timed(GoalMatcher, goal_text, self.ctx.embedder, cfg.match_threshold)
        what = matcher.category or repr(goal_text)

        def goal_in(pool: Sequence[Sighting], voters: Sequence[Sighting] | None = None) -> list[Sighting]:
            t0 = time.perf_counter()
            good = [s for s in pool if s.score >= cfg.goal_score]
            ok = matcher.accepts([s.label for s in good]) if good else np.zeros(0, bool)
            hits = [s for s, a in zip(good, ok, strict=True) if a]
            if hits and cfg.vote_radius > 0:
                out = outvoted(hits, ex.sightings if voters is None else voters, matcher.accepts, cfg.vote_radius)
                hits = [s for s, o in zip(hits, out, strict=True) if not o]
            self._decision_time += time.perf_counter() - t0
            return hits

        seen = goal_in(ex.sightings) if cfg.remember else []
        status = Status.STOPPED
        if not seen:
            status = ex.explore(lambda fs, e: self._timed(self.score_frontiers, fs, e, matcher),
                                lambda e: bool(goal_in(e.new_sightings)))
            seen = goal_in(ex.new_sightings)
        if not seen:
            if status is Status.BUDGET:
                reason = f"timeout: {ex.steps} actions without seeing a {what}"
            else:
                reason = f"not found: no reachable frontier left and no {what} seen ({status.value})"
            return self._outcome(False, reason, None)

        # Approach the nearest sighting; its estimate is the mean of all goal sightings near it.
        here = np.asarray(ex.xy)
        anchor = min(seen, key=lambda s: float(np.hypot(*(np.asarray(s.xy) - here))))
        state = {"xy": anchor.xy}

        def target() -> tuple[float, float]:
            near = [s for s in ex.sightings if math.dist(s.xy, state["xy"]) <= cfg.cluster_radius + cfg.vote_radius]
            pts = [s for s in goal_in(near, near) if math.dist(s.xy, state["xy"]) <= cfg.cluster_radius]
            if pts:
                w = np.array([s.score for s in pts])
                xy = (np.array([s.xy for s in pts]) * w[:, None]).sum(0) / w.sum()
                state["xy"] = (float(xy[0]), float(xy[1]))
            return state["xy"]

        status = ex.approach(target, cfg.stop_distance)
        goal_xy = target()
        d = math.dist(ex.xy, goal_xy)
        at = f"({goal_xy[0]:.2f}, {goal_xy[1]:.2f})"
        if status is Status.ARRIVED:
            reason = f"{what} seen at {at}; stopped {d:.2f} m from it"
        elif status is Status.BUDGET:
            reason = f"timeout while approaching the {what} seen at {at}, {d:.2f} m away"
        else:
            reason = f"{what} seen at {at} but could not get closer than {d:.2f} m"
        return self._outcome(True, reason, goal_xy, {"goal_label": anchor.label, "goal_score": anchor.score})

    # ------------------------------------------------------------------ helpers
    def _timed(self, fn: Any, *args: Any) -> Any:
        t0 = time.perf_counter()
        try:
            return fn(*args)
        finally:
            self._decision_time += time.perf_counter() - t0

    def _outcome(self, found: bool, reason: str, target_xy: tuple[float, float] | None,
                 extra: dict[str, Any] | None = None) -> SubgoalOutcome:
        ex = self.explorer
        assert ex is not None
        info = {"frontiers_visited": len(ex.spent), "known_area_m2": round(
            ex.map.known_fraction() * ex.map.spec.rows * ex.map.spec.cols * ex.map.spec.resolution**2, 2),
            **(extra or {})}
        return SubgoalOutcome(found=found, reason=reason, target_xy=target_xy, query_time_s=self._decision_time,
                              steps=ex.steps, explanation=self.describe_choice(), extra=info)
