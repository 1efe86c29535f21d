"""Search for an object the map is silent or stale about: go where it would be, look, map, re-ask.

``capnav navigate MAP "..." --search`` in the simulator. The map is asked first; when it names an
object, the robot drives there on an online map that starts from the saved map's occupancy and
is corrected by its own depth (``OnlineMap`` with a prior), and looks around. The goal counts as
seen only from the robot's own frames: a detection of the goal's category (in the goal's colour
when the goal names one) that the map does not already explain as another object of that
category. When the map names nothing (the object is new, or retired), or the object is not at
its place, the robot searches: the map's room regions ranked by where such an object would be
(``places``), and frontiers of space neither the map nor the robot has seen, each weighed by its
prior over the path to it. At each place it looks around; every batch of views is asked again
whether it shows the goal. The search ends when the goal is reached, or when the budget (metres
driven, seconds) is spent. Every step's reason is kept, in order.

Nothing here reads the simulator's truth: the agent is only driven and asked for frames.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from capnav.core.errors import InputError
from capnav.core.grid import FREE
from capnav.explore.explorer import ExplorerConfig, FrontierExplorer, Status
from capnav.explore.online_map import OnlineMap, OnlineMapConfig
from capnav.explore.places import Place, PlaceConfig, room_places
from capnav.explore.sighting import Sighting
from capnav.explore.votes import outvoted
from capnav.language.embedder import TextEmbedder
from capnav.mapping.cmap import CapNavMap, MapObject
from capnav.planning import PlannerConfig
from capnav.planning.search import cost_field


@dataclass(frozen=True)
class SearchConfig:
    """Budget and judgement of a search. ``budget_m``: metres driven (from the request on);
    ``budget_s``: seconds of wall time (None: no time limit)."""

    budget_m: float = 60.0
    budget_s: float | None = None
    goal_score: float = 0.55  # detector confidence a goal sighting needs
    label_match: float = 0.6  # label-goal cosine when the goal names no known category
    at_place: float = 1.0  # m: a goal sighting this close to the map object's box confirms it
    known_margin: float = 0.4  # m: a sighting inside another same-label object's box plus this, in its colours, is it
    colour_distance: float = 20.0  # CIEDE2000 (kL 2) within which a seen colour is the goal's colour word
    stop_distance: float = 0.8  # m from the sighted goal's centre
    cluster_radius: float = 1.0  # m: goal sightings this close refine the target
    vote_radius: float = 0.5  # m: a goal sighting outvoted by other labels this close is a confusion
    distance_scale: float = 4.0  # m: a place's prior is divided by 1 + path / this
    frontier_prior: float = 0.25  # prior of unseen space beyond a frontier of ``frontier_cells`` or more
    frontier_cells: int = 20  # a smaller frontier (a pocket behind furniture) has a prior in proportion
    seen_fraction: float = 0.6  # a region looked around in and this much seen by the robot's own depth is spent
    seen_anyway: float = 0.9  # a region this much seen is spent even if the robot never stood in it
    places: PlaceConfig = field(default_factory=PlaceConfig)
    planner: PlannerConfig = field(default_factory=PlannerConfig)

    def __post_init__(self) -> None:
        if not (self.budget_m > 0 and math.isfinite(self.budget_m)):
            raise InputError(f"search budget must be a positive number of metres, got {self.budget_m}")
        if self.budget_s is not None and not self.budget_s > 0:
            raise InputError(f"search time budget must be positive seconds, got {self.budget_s}")


@dataclass
class SearchStep:
    """One decision of the search: what it did, where, and why."""

    action: str  # "map", "drive", "look", "search", "found", "not found"
    reason: str
    xy: tuple[float, float] | None = None
    driven_m: float = 0.0  # metres driven since the request when the step was taken

    def to_dict(self) -> dict[str, Any]:
        return {"action": self.action, "reason": self.reason, "driven_m": round(self.driven_m, 3),
                "xy": None if self.xy is None else [round(self.xy[0], 3), round(self.xy[1], 3)]}


@dataclass
class SearchResult:
    found: bool
    reason: str
    target_xy: tuple[float, float] | None
    driven_m: float
    steps: list[SearchStep]
    looks: int
    from_map: bool  # the goal was where the map said
    chosen_object: int | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"found": self.found, "reason": self.reason, "from_map": self.from_map, "looks": self.looks,
                "driven_m": round(self.driven_m, 3), "chosen_object": self.chosen_object,
                "target_xy": None if self.target_xy is None else [round(v, 3) for v in self.target_xy],
                "steps": [s.to_dict() for s in self.steps]}


@dataclass(frozen=True)
class Goal:
    """What the robot's camera must show: a category (or a phrase for labels) and colour words."""

    category: str | None
    phrase: str
    colours: tuple[str, ...] = ()

    @property
    def what(self) -> str:
        kind = self.category or self.phrase
        return f"{' '.join(self.colours)} {kind}".strip()


class ObjectSearch:
    """One request's search with a live agent (anything with ``pose``, ``step``, ``observe`` and
    ``path_length``) and the shared detector."""

    def __init__(self, cmap: CapNavMap, agent: Any, detector: Any, embedder: TextEmbedder,
                 config: SearchConfig | None = None) -> None:
        if detector is None:
            raise InputError("a search needs a detector to see the goal with the robot's own camera")
        self.cmap, self.agent, self.detector, self.embedder = cmap, agent, detector, embedder
        self.config = cfg = config or SearchConfig()
        spec = cmap.occupancy.spec
        centre = (spec.x0 + 0.5 * spec.cols * spec.resolution, spec.y0 + 0.5 * spec.rows * spec.resolution)
        half = 0.5 * max(spec.cols, spec.rows) * spec.resolution + 3.0
        online = OnlineMap(centre, OnlineMapConfig(resolution=spec.resolution, half_extent=half), cmap.occupancy)
        # A look every 30 degrees: a search must not miss the goal between two views.
        self.explorer = FrontierExplorer(agent, detector, ExplorerConfig(planner=cfg.planner, sighting_colours=True,
                                                                         keyframe_turn_deg=30.0), online)
        self.steps: list[SearchStep] = []
        self._odo0 = float(getattr(agent, "path_length", 0.0))
        self._t0 = time.monotonic()
        self._timed_out = False
        self._object_colours: dict[int, list[tuple[float, float, float]]] = {}

    # ------------------------------------------------------------------ the request
    def run(self, goal: Goal, chosen: MapObject | None, map_reason: str) -> SearchResult:
        """Look around, go to ``chosen`` (the map's answer, None when it has none) and confirm it,
        else search."""
        cfg, ex = self.config, self.explorer
        ex.begin(10**9)
        ex.path_limit = self._odo0 + cfg.budget_m
        self._goal = goal
        self._stale = chosen
        # Look before leaving: turning in place costs no distance, and the goal may stand right here.
        self._log("look", "looking around where the request was heard", ex.xy)
        ex.observe()
        if not self._stop(ex):
            ex.look_around(self._stop)
        hits = self._hits(ex.sightings)
        if hits:
            return self._approach(hits, from_map=chosen is not None and any(self._at(s, chosen) for s in hits))
        if chosen is not None:
            cxy = (float(chosen.position[0]), float(chosen.position[1]))
            self._log("map", f"the map has it: object {chosen.id} ({chosen.caption or chosen.label}) at "
                             f"({cxy[0]:.2f}, {cxy[1]:.2f}); {map_reason}", cxy)
            st = ex.approach(lambda: cxy, cfg.at_place + 0.2, self._stop)
            if not self._over(st):
                self._log("look", f"at the map's place of object {chosen.id}: looking around", ex.xy)
                ex.look_around(self._stop)
            hits = self._hits(ex.sightings)
            if hits:
                return self._approach(hits, from_map=any(self._at(s, chosen) for s in hits))
            if self._over(None):
                return self._out_of_budget()
            self._log("search", f"not at its place: no {goal.what} seen within {cfg.at_place:.1f} m of where the map "
                                f"has object {chosen.id} after {ex.looks} views; searching", ex.xy)
        else:
            self._log("search", f"not in the map ({map_reason}); searching", ex.xy)
        return self._search()

    # ------------------------------------------------------------------ search loop
    def _search(self) -> SearchResult:
        cfg, ex = self.config, self.explorer
        places, regions = room_places(self.cmap, self._goal.category, self.embedder, cfg.places)
        visited: list[tuple[float, float]] = []
        self._looked_in: set[int] = {self._region_at(regions, ex.xy)}
        while not self._over(None):
            grid = ex.grid()
            cm = ex.costmap(grid)
            cands = [p for p in places if not self._spent(p, visited, regions)]
            fronts = ex.frontiers(grid, cm)
            cands += [Place(f.target_xy, -1, cfg.frontier_prior * min(1.0, f.size / cfg.frontier_cells),
                            f"a frontier of unseen space ({f.size} cells)")
                      for f in fronts if all(math.dist(f.target_xy, v) > ex.config.visited_radius for v in visited)]
            if not cands:
                return self._end(f"not found: every place worth looking was looked at ({len(visited)} places, "
                                 f"{ex.looks} views) and no {self._goal.what} was seen")
            dist = self._path_lengths(grid, cm, [p.xy for p in cands])
            utility = np.array([p.prior for p in cands]) / (1.0 + dist / cfg.distance_scale)
            utility[~np.isfinite(dist)] = -1.0
            k = int(np.argmax(utility))
            if utility[k] < 0:
                return self._end(f"not found: no place left to look from can be reached ({len(visited)} places "
                                 f"looked from, {ex.looks} views)")
            p = cands[k]
            self._log("search", f"go to ({p.xy[0]:.2f}, {p.xy[1]:.2f}), {dist[k]:.1f} m away: {p.why}, prior "
                                f"{p.prior:.2f}, best of {len(cands)} places", p.xy)
            st = ex.drive_to(p.xy, self._stop)
            visited.append(p.xy)
            self._looked_in.add(self._region_at(regions, ex.xy))
            if st is Status.BLOCKED:
                self._log("search", f"could not get to ({p.xy[0]:.2f}, {p.xy[1]:.2f}); giving it up", ex.xy)
            elif not self._over(st) and st is not Status.STOPPED:
                self._log("look", "looking around", ex.xy)
                ex.look_around(self._stop)
            hits = self._hits(ex.sightings)
            if hits:
                return self._approach(hits, from_map=False)
        return self._out_of_budget()

    def _region_at(self, regions: np.ndarray, xy: tuple[float, float]) -> int:
        rc = self.cmap.occupancy.spec.to_cell(np.asarray(xy, dtype=np.float64))
        if not self.cmap.occupancy.spec.inside(rc):
            return -1
        return int(regions[rc[0], rc[1]])

    def _spent(self, p: Place, visited: Sequence[tuple[float, float]], regions: np.ndarray) -> bool:
        """Looked from nearby already, or its region mostly seen by the robot's own depth (from
        inside it, or nearly all of it from outside: a glimpse through a door is not a look)."""
        if any(math.dist(p.xy, v) < 1.5 for v in visited):
            return True
        mask = regions == p.region
        if not mask.any():
            return False
        spec = self.cmap.occupancy.spec
        rr, cc = np.nonzero(mask & (self.cmap.occupancy.cells == FREE))
        if rr.size == 0:
            return False
        xy = spec.to_world(np.stack([rr, cc], axis=1))
        own = self.explorer.map
        rc = own.spec.to_cell(xy)
        inside = own.spec.inside(rc)
        seen = np.zeros(len(xy), bool)
        obs = own.observed()
        seen[inside] = obs[rc[inside, 0], rc[inside, 1]]
        frac = float(seen.mean())
        return frac >= self.config.seen_anyway or (p.region in self._looked_in and frac >= self.config.seen_fraction)

    def _path_lengths(self, grid: Any, cm: Any, targets: list[tuple[float, float]]) -> np.ndarray:
        passable = np.isfinite(cm.weights)
        rc0 = grid.spec.to_cell(np.asarray(self.explorer.xy))
        start = (int(np.clip(rc0[0], 0, grid.spec.rows - 1)), int(np.clip(rc0[1], 0, grid.spec.cols - 1)))
        if not passable[start]:
            near = np.argwhere(passable)
            if len(near):
                j = int(np.argmin(((near - np.asarray(start)) ** 2).sum(1)))
                start = (int(near[j, 0]), int(near[j, 1]))
        fld, _ = cost_field(cm.weights, start)
        out = np.full(len(targets), np.inf)
        rc = grid.spec.to_cell(np.asarray(targets, dtype=np.float64).reshape(-1, 2))
        ok = grid.spec.inside(rc)
        out[ok] = fld[rc[ok, 0], rc[ok, 1]] * grid.spec.resolution
        return out

    # ------------------------------------------------------------------ the goal in view
    def _hits(self, pool: Sequence[Sighting]) -> list[Sighting]:
        """Sightings that show the goal: its category (or a label close to its phrase) seen with
        enough confidence, not outvoted by the other labels seen at that spot, in its colour when it
        names one, and not another object the map holds."""
        cfg, g = self.config, self._goal
        good = [s for s in pool if s.score >= cfg.goal_score]
        if not good:
            return []
        good = [s for s, ok in zip(good, self._is_goal([s.label for s in good]), strict=True) if ok]
        if good and cfg.vote_radius > 0:
            out = outvoted(good, self.explorer.sightings, self._is_goal, cfg.vote_radius)
            good = [s for s, o in zip(good, out, strict=True) if not o]
        if g.colours:
            good = [s for s in good if self._colour_ok(s)]
        return [s for s in good if not self._known_other(s)]

    def _is_goal(self, labels: list[str]) -> np.ndarray:
        """Which detector labels are the goal: its category, or labels close to its phrase."""
        g = self._goal
        if g.category is not None:
            return np.array([lab == g.category for lab in labels], bool)
        uniq = sorted(set(labels))
        if not uniq:
            return np.zeros(0, bool)
        vecs = self.embedder.embed([g.phrase, *uniq]).astype(np.float64)
        vecs /= np.maximum(np.linalg.norm(vecs, axis=1, keepdims=True), 1e-9)
        ok = {lab for lab, c in zip(uniq, vecs[1:] @ vecs[0], strict=True) if c >= self.config.label_match}
        return np.array([lab in ok for lab in labels], bool)

    def _colour_ok(self, s: Sighting) -> bool:
        from capnav.language.colors import color_distance, color_lab

        words = [w for w in self._goal.colours if color_lab(w) is not None]
        if not words:
            return True
        return any(color_distance(w, lab) <= self.config.colour_distance for w in words for lab in s.colours)

    def _known_other(self, s: Sighting) -> bool:
        """The sighting lies on a map object of its label, in that object's colours, that is not
        the stale answer: the map already holds that one, and ranked it below the goal (or the goal
        is not in the map). Another main colour there is something new standing where that one
        stood (compared by the largest colour of each: a black chair is not a red one with black legs)."""
        m = self.config.known_margin
        for o in self.cmap.objects:
            if o.label != s.label or (self._stale is not None and o.id == self._stale.id):
                continue
            if (o.extent_min[0] - m <= s.xy[0] <= o.extent_max[0] + m
                    and o.extent_min[1] - m <= s.xy[1] <= o.extent_max[1] + m) and self._looks_like(s, o):
                return True
        return False

    def _looks_like(self, s: Sighting, o: MapObject) -> bool:
        from capnav.core.colour import ciede2000
        from capnav.language.colors import object_colors

        if o.id not in self._object_colours:
            cols = object_colors(np.asarray(o.colors).reshape(-1, 3)) if len(o.colors) else []
            self._object_colours[o.id] = [c.lab for c in cols[:1]]
        mine = self._object_colours[o.id]
        if not mine or not s.colours:
            return True  # nothing to tell them apart by
        d = float(ciede2000(np.asarray(s.colours[0]), np.asarray(mine[0]), kL=2.0))
        return d <= self.config.colour_distance

    def _at(self, s: Sighting, o: MapObject) -> bool:
        m = self.config.at_place
        return (o.extent_min[0] - m <= s.xy[0] <= o.extent_max[0] + m
                and o.extent_min[1] - m <= s.xy[1] <= o.extent_max[1] + m)

    def _stop(self, ex: FrontierExplorer) -> bool:
        if self.config.budget_s is not None and time.monotonic() - self._t0 > self.config.budget_s:
            self._timed_out = True
            return True
        return bool(self._hits(ex.new_sightings))

    def _approach(self, hits: list[Sighting], from_map: bool) -> SearchResult:
        cfg, ex = self.config, self.explorer
        here = np.asarray(ex.xy)
        anchor = min(hits, key=lambda s: float(np.hypot(*(np.asarray(s.xy) - here))))
        state = {"xy": anchor.xy}

        def target() -> tuple[float, float]:
            pts = [s for s in self._hits(ex.sightings) if math.dist(s.xy, state["xy"]) <= cfg.cluster_radius]
            if pts:
                w = np.array([s.score for s in pts])
                xy = (np.array([s.xy for s in pts]) * w[:, None]).sum(0) / w.sum()
                state["xy"] = (float(xy[0]), float(xy[1]))
            return state["xy"]

        where = "at the map's place" if from_map else "away from where the map has it"
        self._log("found", f"a {anchor.label} ({self._goal.what}) seen at ({anchor.xy[0]:.2f}, {anchor.xy[1]:.2f}), "
                           f"score {anchor.score:.2f}, {where}; approaching", anchor.xy)
        self._timed_out = False
        st = ex.approach(target, cfg.stop_distance, self._budget_only)
        goal_xy = target()
        d = math.dist(ex.xy, goal_xy)
        if st is Status.ARRIVED or d <= cfg.planner.reach:
            return self._end(f"found: {self._goal.what} seen at ({goal_xy[0]:.2f}, {goal_xy[1]:.2f}); stopped "
                             f"{d:.2f} m from it", True, goal_xy, from_map)
        if self._over(st):
            return self._end(f"not found within budget: {self._goal.what} seen at ({goal_xy[0]:.2f}, "
                             f"{goal_xy[1]:.2f}) but the budget ran out {d:.2f} m from it ({self._spent_text()})",
                             False, goal_xy, from_map)
        return self._end(f"seen but not reached: {self._goal.what} at ({goal_xy[0]:.2f}, {goal_xy[1]:.2f}); could "
                         f"not get closer than {d:.2f} m", False, goal_xy, from_map)

    def _budget_only(self, ex: FrontierExplorer) -> bool:
        if self.config.budget_s is not None and time.monotonic() - self._t0 > self.config.budget_s:
            self._timed_out = True
            return True
        return False

    # ------------------------------------------------------------------ bookkeeping
    def driven(self) -> float:
        return float(getattr(self.agent, "path_length", 0.0)) - self._odo0

    def _over(self, st: Status | None) -> bool:
        return self._timed_out or st is Status.BUDGET or self.explorer.budget <= 0 or \
            self.driven() >= self.config.budget_m

    def _spent_text(self) -> str:
        t = time.monotonic() - self._t0
        lim = f" of {self.config.budget_s:.0f} s" if self.config.budget_s is not None else ""
        return f"drove {self.driven():.1f} of {self.config.budget_m:.1f} m, {t:.0f}{lim} s, {self.explorer.looks} views"

    def _out_of_budget(self) -> SearchResult:
        looked = sum(1 for s in self.steps if s.action == "look")
        return self._end(f"not found within budget: {self._spent_text()}, looked around from {looked} places, "
                         f"no {self._goal.what} seen that the map does not already hold")

    def _log(self, action: str, reason: str, xy: tuple[float, float] | None = None) -> None:
        self.steps.append(SearchStep(action, reason, xy, self.driven()))

    def _end(self, reason: str, found: bool = False, target: tuple[float, float] | None = None,
             from_map: bool = False) -> SearchResult:
        self._log("found" if found else "not found", reason, self.explorer.xy)
        return SearchResult(found, reason, target, self.driven(), self.steps, self.explorer.looks, from_map,
                            self._stale.id if self._stale is not None and from_map else None)


def search_goal(cmap: CapNavMap, retriever: Any, instruction: Any, agent: Any, detector: Any,
                config: SearchConfig | None = None) -> tuple[Any, SearchResult]:
    """Ask the map (``retriever.query``), then go and confirm it or search. Returns the map's
    answer (a ``QueryResult``) and the search's outcome."""
    from capnav.retrieval.query import ParsedQuery, parse_goals

    x, y, _ = (float(v) for v in agent.pose)
    q = retriever.query(instruction, robot_xy=(x, y))
    parsed = instruction if isinstance(instruction, ParsedQuery) else parse_goals(instruction, retriever.embedder)[0]
    goal = Goal(parsed.category, parsed.target_phrase or parsed.text, tuple(parsed.colors))
    chosen = q.chosen if q.found else None
    search = ObjectSearch(cmap, agent, detector, retriever.embedder, config)
    return q, search.run(goal, chosen, q.reason)
