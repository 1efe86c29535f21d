"""LM-Nav-style (Shah et al. 2023): match the instruction's landmark to graph nodes, route, drive.

LM-Nav parses landmarks out of an instruction with an LLM, scores every node image of its
topological memory against each landmark with CLIP, searches the graph for the best route and
drives it with a learned local policy. Here the landmark is the goal text (one landmark per
subgoal), a node's match is the best similarity between the goal and the labels the shared
detector saw from that node times that detection's confidence, less a cost per metre between node
and landmark (a clear, close view scores higher, as with CLIP); the route is Dijkstra on the graph
of ``topo_graph``, and the local policy is the shared A* planner between consecutive nodes on the
stream's own depth-derived occupancy. The agent stops at the node, not at the object: LM-Nav
never localises the landmark metrically.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from capnav.core.errors import InputError
from capnav.eval.baselines.explore.goal_match import GoalMatcher
from capnav.eval.baselines.explore.topo_graph import GraphConfig, TopoGraph, build_graph, frames_of
from capnav.eval.method import METHODS, Agent, NavMethod, SceneContext, SubgoalOutcome
from capnav.explore.explorer import ExplorerConfig, FrontierExplorer, Status
from capnav.planning import PlannerConfig


@dataclass(frozen=True)
class LMNavConfig:
    graph: GraphConfig = field(default_factory=GraphConfig)
    drive: ExplorerConfig = field(default_factory=lambda: ExplorerConfig(look_around=False))
    match_threshold: float = 0.6  # label-goal cosine for free-form goals without a category word
    min_match: float = 0.55  # a node's best match (similarity x confidence) must reach this
    distance_weight: float = 0.01  # per metre of route: among equal matches, the nearer node wins
    view_weight: float = 0.2  # per metre from node to landmark: a closer view is clearer (as for CLIP)

    def __post_init__(self) -> None:
        if self.min_match < 0 or self.distance_weight < 0:
            raise InputError("min_match and distance_weight must be >= 0")


class LMNavMethod:
    name = "lmnav"
    uses_prior_map = False

    def __init__(self, config: LMNavConfig | None = None) -> None:
        self.config = config or LMNavConfig()
        self.ctx: SceneContext | None = None
        self.graph: TopoGraph | None = None
        self.driver: FrontierExplorer | None = None

    def start_episode(self, ctx: SceneContext, agent: Agent) -> None:
        if ctx.detector is None:
            raise InputError(f"method {self.name!r} needs the shared detector to describe its graph nodes")
        key = f"lmnav/graph/{self.config.graph!r}"
        if key not in ctx.cache:
            ctx.cache[key] = build_graph(frames_of(ctx.frames), ctx.detector, self.config.graph)
        self.ctx, self.graph = ctx, ctx.cache[key]
        # Driving continues the graph's occupancy with the agent's own depth (a fresh copy per episode).
        self.driver = FrontierExplorer(agent, None, self.config.drive, self.graph.occupancy.copy())

    def run_subgoal(self, goal_text: str, agent: Agent) -> SubgoalOutcome:
        if self.ctx is None or self.graph is None or self.driver is None:
            raise InputError(f"{self.name}: run_subgoal called before start_episode")
        cfg, g, drv = self.config, self.graph, self.driver
        drv.begin(self.ctx.max_steps)
        t0 = time.perf_counter()
        matcher = GoalMatcher(goal_text, self.ctx.embedder, cfg.match_threshold)
        what = matcher.category or repr(goal_text)
        start = g.entry_node(drv.xy)
        dist = g.distances(start)
        best_score, best_node, best_sight = -np.inf, -1, None
        for i, sights in enumerate(g.sightings):
            if not sights or not np.isfinite(dist[i]):
                continue
            labels = [s.label for s in sights]
            ok = matcher.accepts(labels)
            if not ok.any():
                continue
            match = matcher.similarity(labels) * np.array([s.score for s in sights])
            match[~ok | (match < cfg.min_match)] = -np.inf
            view = match - cfg.view_weight * np.array([s.distance for s in sights])
            j = int(np.argmax(view))
            if not np.isfinite(view[j]):
                continue
            score = float(view[j]) - cfg.distance_weight * float(dist[i])
            if score > best_score:
                best_score, best_node, best_sight = score, i, sights[j]
        query = time.perf_counter() - t0
        if best_node < 0 or best_sight is None:
            return SubgoalOutcome(False, f"not found: no node of the {len(g)}-node graph shows a {what}",
                                  query_time_s=query, extra={"nodes": len(g), "edges": g.n_edges})
        route = g.route(start, best_node)
        # Edges were checked with the robot radius alone; when the planner's safety margin closes
        # a gap the edge passes through, the hop is retried with the margin off.
        tight = replace(drv.config.planner, safety_margin=0.0, clearance_cost=0.0)
        status = Status.ARRIVED
        for node in route:
            nxy = (float(g.xy[node, 0]), float(g.xy[node, 1]))
            status = drv.drive_to(nxy, tolerance=0.3)
            if status is Status.BLOCKED:
                status = drv.drive_to(nxy, tolerance=0.3, planner=tight)
            if status is Status.BUDGET:
                break
        nxy = (float(g.xy[best_node, 0]), float(g.xy[best_node, 1]))
        expl = (f"node {best_node} (frame {int(g.frame_index[best_node])}) saw a {best_sight.label} "
                f"(confidence {best_sight.score:.2f}, {best_sight.distance:.1f} m away); score {best_score:.2f}")
        extra = {"node": best_node, "route": route, "landmark_xy": best_sight.xy, "nodes": len(g), "edges": g.n_edges}
        # The target is where the landmark was seen (what the harness judges as the retrieval);
        # the agent drives to the node that saw it.
        if status is Status.BUDGET:
            return SubgoalOutcome(True, f"timeout on the {len(route)}-node route to {expl}", best_sight.xy, None,
                                  query, drv.steps, expl, extra)
        here = drv.xy
        off = float(np.hypot(here[0] - nxy[0], here[1] - nxy[1]))
        note = "" if off <= 0.5 else f" (stopped {off:.2f} m short of it: {status.value})"
        return SubgoalOutcome(True, f"drove a {len(route)}-node route to {expl}{note}", best_sight.xy, None, query,
                              drv.steps, expl, extra)


@METHODS.register("lmnav")
def _make(config: LMNavConfig | None = None, planner: PlannerConfig | None = None, **_: object) -> NavMethod:
    cfg = config or LMNavConfig()
    if planner is not None:
        cfg = replace(cfg, drive=replace(cfg.drive, planner=planner))
    return LMNavMethod(cfg)
