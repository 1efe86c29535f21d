"""Search for an object the map is silent or stale about: go where it would be, look, map, ask again.

``capnav navigate MAP "..." --search`` in the simulator. The request is answered as ``capnav
query`` answers it, by the same retriever, but on a map that grows as the robot looks: the saved
map's objects less those the robot's own depth saw gone, plus every object the robot saw that the
saved map does not explain (``live_map``). After each batch of views the retriever is asked again
with the instruction, so "the smallest cabinet" is compared with every cabinet seen so far and "the
plant next to the washing machine" waits for a washing machine to be seen. The robot first looks
around where it stands; then it goes where the answer is: a saved object's place (to see it there,
else it is not there and the question is asked again without it), or, with no answer, the map's
room regions ranked by where such an object would be (``places``) and frontiers of space neither
the map nor the robot has seen, each weighed by its prior over the path to it. The search ends when
the answer is an object the robot has seen (where the map did not explain it, or at its saved place)
and the robot stands by it, or when the budget (metres driven, seconds) is spent. Every step's
reason is kept, in order.

Nothing here reads the simulator's truth: the agent is only driven and asked for frames.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import ndimage

from capnav.core.errors import CapNavError, InputError
from capnav.core.grid import FREE, OCCUPIED, OccupancyGrid
from capnav.explore.explorer import ExplorerConfig, FrontierExplorer, Status
from capnav.explore.levels import Level, search_levels
from capnav.explore.live_map import LiveMap, LiveMapConfig, Snapshot
from capnav.explore.online_map import OnlineMap, OnlineMapConfig
from capnav.explore.places import Place, PlaceConfig, room_places
from capnav.language.context import canonical_label
from capnav.language.embedder import TextEmbedder
from capnav.mapping.cmap import CapNavMap, MapObject
from capnav.mapping.update import likeness
from capnav.planning import Costmap, PlannerConfig
from capnav.planning.costmap import locate_start
from capnav.planning.search import cost_field
from capnav.retrieval.query import ParsedQuery, parse_goals
from capnav.retrieval.query.tokens import nearly_named
from capnav.retrieval.result import QueryResult
from capnav.retrieval.verifier import a as a_


@dataclass(frozen=True)
class SearchConfig:
    """Budget and judgement of a search. ``budget_m``: metres driven (from the request on);
    ``budget_s``: seconds of wall time (None: no time limit)."""

    budget_m: float = 60.0
    budget_s: float | None = None
    at_place: float = 1.0  # m: the robot looks for a saved object from this close to its place
    stop_distance: float = 0.8  # m from the answer's footprint
    cluster_radius: float = 1.0  # m: a seen object this close to the answer (of its label) refines where it is
    batch_views: int = 4  # views between two questions to the retriever
    second_look_prior: float = 0.9  # of a seen object of the requested kind the request did not fit
    second_look_m: float = 1.5  # m from it to look again from
    place_reach: float = 1.0  # m: a place to look from that cannot be stood on is looked from this close
    old_place_prior: float = 0.6  # of the place of a saved answer seen gone from afar (never looked around at)
    distance_scale: float = 4.0  # m: a place's prior is divided by 1 + path / this
    frontier_prior: float = 0.25  # prior of unseen space beyond a frontier of ``frontier_cells`` or more
    frontier_cells: int = 20  # a smaller frontier (a pocket behind furniture) has a prior in proportion
    seen_fraction: float = 0.6  # a region looked around in and this much seen by the robot's own depth is spent
    seen_anyway: float = 0.9  # a region this much seen is spent even if the robot never stood in it
    other_sides: int = 2  # approaches blocked outside reach: aim again this often, away from the cells tried
    avoid_radius: float = 0.4  # m around a standing cell that could not be got to
    places: PlaceConfig = field(default_factory=PlaceConfig)
    live: LiveMapConfig = field(default_factory=LiveMapConfig)
    planner: PlannerConfig = field(default_factory=PlannerConfig)

    def __post_init__(self) -> None:
        if not (self.budget_m > 0 and math.isfinite(self.budget_m)):
            raise InputError(f"search budget must be a positive number of metres, got {self.budget_m}")
        if self.budget_s is not None and not self.budget_s > 0:
            raise InputError(f"search time budget must be positive seconds, got {self.budget_s}")
        if self.batch_views < 1:
            raise InputError(f"batch_views must be >= 1, got {self.batch_views}")


@dataclass
class SearchStep:
    """One decision of the search: what it did, where, and why."""

    action: str  # "map", "ask", "drive", "look", "search", "found", "not found"
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
    asks: int = 0  # questions to the retriever on the growing map

    def to_dict(self) -> dict[str, Any]:
        return {"found": self.found, "reason": self.reason, "from_map": self.from_map, "looks": self.looks,
                "asks": self.asks,
                "driven_m": round(self.driven_m, 3), "chosen_object": self.chosen_object,
                "target_xy": None if self.target_xy is None else [round(v, 3) for v in self.target_xy],
                "steps": [s.to_dict() for s in self.steps]}


#: The region of a place that is a second look at an object seen (not a room region, not a frontier).
SECOND_LOOK = -2


@dataclass
class Answer:
    """The retriever's answer on the map plus what the robot has seen, and what it is to the search:
    ``new`` (an object the robot saw that the saved map does not explain), ``confirmed`` (a saved
    object seen again at its place), ``saved`` (a saved object not yet looked for), ``open`` (an
    object seen, but the request's landmark has not been: not yet an answer) or ``none``."""

    kind: str
    obj: MapObject | None
    reason: str
    seen: int = 0  # objects seen that the saved map does not explain, when asked
    unmet: str | None = None  # why the answer does not stand where the request's landmark relation says

    def same(self, other: Answer | None) -> bool:
        if other is None or other.kind != self.kind:
            return False
        if self.obj is None or other.obj is None:
            return self.obj is other.obj
        if self.kind == "new":  # a seen object's id is renumbered as the map grows: its place names it
            return self.obj.label == other.obj.label and \
                float(np.hypot(*(self.obj.position[:2] - other.obj.position[:2]))) < 1.0
        return self.obj.id == other.obj.id


class ObjectSearch:
    """One request's search with a live agent (anything with ``pose``, ``step``, ``observe`` and
    ``path_length``), the shared detector and the retriever of the saved map (``capnav query``'s)."""

    def __init__(self, cmap: CapNavMap, agent: Any, detector: Any, retriever: Any,
                 config: SearchConfig | None = None) -> None:
        if detector is None:
            raise InputError("a search needs a detector to see the goal with the robot's own camera")
        self.cmap, self.agent, self.detector, self.retriever = cmap, agent, detector, retriever
        self.embedder: TextEmbedder = retriever.embedder
        self.config = cfg = config or SearchConfig()
        spec = cmap.occupancy.spec
        centre = (spec.x0 + 0.5 * spec.cols * spec.resolution, spec.y0 + 0.5 * spec.rows * spec.resolution)
        half = 0.5 * max(spec.cols, spec.rows) * spec.resolution + 3.0
        online = OnlineMap(centre, OnlineMapConfig(resolution=spec.resolution, half_extent=half), cmap.occupancy)
        # A look every 30 degrees: a search must not miss the goal between two views.
        self.explorer = FrontierExplorer(agent, detector, ExplorerConfig(planner=cfg.planner, keyframe_turn_deg=30.0),
                                         online)
        self.live = LiveMap(cmap, detector, self.embedder, cfg.live)
        self.explorer.on_look = self.live.add
        self._levels: list[Level] = search_levels(cfg.planner, spec.resolution)
        self.steps: list[SearchStep] = []
        self._odo0 = float(getattr(agent, "path_length", 0.0))
        self._t0 = time.monotonic()
        self._timed_out = False
        self._answer: Answer | None = None
        self._asked_at = -1  # views when last asked
        self._signature: tuple[Any, ...] | None = None
        self.asks = 0
        self._snap: Snapshot | None = None
        self._found_id: int | None = None
        self._answered: dict[int, MapObject] = {}  # saved objects that were the answer at some time
        self._spots: list[tuple[float, float]] = []  # where the robot looked around
        self._cells_at: tuple[int, np.ndarray] | None = None  # the online map's cells, at a number of views
        self._held: Answer | None = None  # an answer held back while the search looks for a better one (``_hold``)
        self._released: list[Answer] = []  # answers held back once and then taken: never held again
        self._stand_in_for: Answer | None = None  # the saved answer a seen lookalike is approached for
        self._alike_tried: list[Answer] = []  # lookalikes approached once (``_lookalike``)

    # ------------------------------------------------------------------ the request
    def run(self, instruction: str | ParsedQuery, first: QueryResult | None = None) -> SearchResult:
        """Answer ``instruction`` with the robot's own eyes: ask the saved map (``first``, when the
        caller has asked it already), look around, and go where the answer is, asking again after
        every batch of views, until the answer is an object the robot has seen, or the budget is
        spent."""
        cfg, ex = self.config, self.explorer
        ex.begin(10**9)
        ex.path_limit = self._odo0 + cfg.budget_m
        self._instruction = instruction
        self._parsed = instruction if isinstance(instruction, ParsedQuery) else \
            parse_goals(instruction, self.embedder)[0]
        self._start = ex.xy
        self.live.kinds = _kinds(self._parsed)
        q = first if first is not None else self.retriever.query(instruction, robot_xy=self._start)
        # A refusal for a relation of nearness no saved candidate meets keeps the best of them: it is
        # driven to and looked at like any saved answer (it may have been seen badly, or moved).
        self._first = q.chosen if q.found else q.unmet_candidate
        if self._first is not None:
            has = "has it" if q.found else "has it only beyond the relation"
            self._log("map", f"the map {has}: object {self._first.id} ({self._first.caption or self._first.label}) "
                             f"at ({self._first.position[0]:.2f}, {self._first.position[1]:.2f}); {q.reason}",
                      _xy(self._first))
        else:
            self._log("map", f"not in the map: {q.reason}")
        self._answer = Answer("saved" if self._first is not None else "none", self._first, q.reason)
        if self._first is not None:
            self._answered[self._first.id] = self._first
        # Look before leaving: turning in place costs no distance, and the goal may stand right here.
        self._log("look", "looking around where the request was heard", ex.xy)
        ex.observe()
        if not self._stop(ex):
            ex.look_around(self._stop)
        return self._loop()

    def _loop(self) -> SearchResult:
        cfg, ex = self.config, self.explorer
        places, regions = room_places(self.cmap, self._parsed.category, self.embedder, cfg.places)
        visited: list[tuple[float, float]] = []
        self._looked_in: set[int] = {self._region_at(regions, ex.xy)}
        self._spots.append(ex.xy)  # looked around where the request was heard
        while not self._over(None):
            ans = self._ask(force=True)
            if self._hold(ans):
                ans = Answer("none", None, f"{ans.reason} (held back: {self._held_why})", ans.seen)
            elif ans.kind in ("new", "confirmed") and ans.obj is not None:
                res = self._approach(ans)
                if res is not None:
                    return res
                continue
            if ans.kind == "saved" and ans.obj is not None:
                alike = self._lookalike(ans)
                if alike is not None:
                    self._stand_in_for = ans
                    res = self._approach(alike)
                    self._stand_in_for = None
                    if res is not None:
                        return res
                    continue
                self._check_place(ans.obj)
                continue
            cands, dist, levels = self._choices(places, visited, regions)
            utility = np.array([p.prior for p in cands]) / (1.0 + dist / cfg.distance_scale)
            utility[~np.isfinite(dist)] = -1.0
            if self._held is not None and (not cands or utility.max() < 0):
                held, self._held = self._held, None
                self._released.append(held)
                self._log("search", f"no place left to look for what outranks it; taking {held.reason}", ex.xy)
                res = self._approach(held)
                if res is not None:
                    return res
                continue
            if not cands:
                return self._end(f"not found: every place worth looking was looked at ({len(visited)} places, "
                                 f"{ex.looks} views) and {self._none_text(ans)}")
            k = int(np.argmax(utility))
            if utility[k] < 0:
                return self._end(f"not found: no place left to look from can be reached ({len(visited)} places "
                                 f"looked from, {ex.looks} views, also with {self._levels[-1].describe()})")
            level = int(levels[k])
            lvl = self._levels[level]
            if level > 0:
                self._log("search", f"({cands[k].xy[0]:.2f}, {cands[k].xy[1]:.2f}) is not reachable with "
                                    f"{self._levels[0].describe()} (a gap "
                                    f"narrower than the robot and its margin, or closed by a contact mark); "
                                    f"planning with {lvl.describe()}", ex.xy)
            p = cands[k]
            self._log("search", f"go to ({p.xy[0]:.2f}, {p.xy[1]:.2f}), {dist[k]:.1f} m away: {p.why}, prior "
                                f"{p.prior:.2f}, best of {len(cands)} places", p.xy)
            ex.forgive_contacts = lvl.forgive_contacts
            for attempt in range(2):
                before = self.driven()
                st = self._go(p, lvl)
                if st is not Status.BLOCKED or attempt or self.driven() - before > 0.05 or not self._unstick():
                    break
                ex.forgive_contacts = False  # the marks of the steps that touched say where not to go again
            ex.forgive_contacts = False
            visited.append(p.xy)
            self._looked_in.add(self._region_at(regions, ex.xy))
            if st is Status.BLOCKED:
                self._log("search", f"could not get to ({p.xy[0]:.2f}, {p.xy[1]:.2f}); giving it up", ex.xy)
            elif not self._over(st) and st is not Status.STOPPED:
                self._log("look", "looking around", ex.xy)
                self._spots.append(ex.xy)
                ex.look_around(self._stop)
        return self._out_of_budget()

    def _hold(self, ans: Answer) -> bool:
        """Hold back an answer the robot has seen (``new`` or ``confirmed``) while something better
        may still stand in the part of the home not looked at, and search on for it, until no place
        is left to look or half the budget is driven; then the held answer is taken:

        - a superlative ("the biggest plant") whose confirmed answer a saved object of its kind,
          seen gone from its place, outranks: that one was carried somewhere, and is the answer
          wherever it stands now (seed 100: "the biggest houseplant" and "the largest plant"
          answered by a saved plant at its place, while the biggest stood unseen in another room);
        - a superlative with only its answer known of its kind (what was seen, and the saved
          map's own, even those seen gone): "the smallest cabinet" says there are two or more, and
          the first one seen is only the smallest of one (seed 0: the black cabinet by the toilet
          taken for the smallest, the small one stood in the next room); two saved ones, both seen
          gone, are what the request knew of (seed 0: "the biggest nightstand" held with both saved
          nightstands seen gone, the whole home searched, the one seen taken at 36.4 m);
        - a stand-in: an object of another kind that can serve as the one asked for (an armchair
          for "the black chair"), while no object of the kind itself was found: the request named
          that kind, and one may stand out of sight (seed 0: "the black chair" answered twice by a
          dark grey armchair in the room where the request was heard, the black chair had been
          set down two rooms away; seed 100: "the chair next to the armoire" by an armchair after
          the saved chairs were seen gone from their places), unless the request's words nearly
          name the stand-in (``tokens.nearly_named``: "the brown lunge chair" is read as a chair,
          'lunge' being a word, and nearly says "lounge chair", an armchair: seed 7's walnut
          armchair was held until half the budget);
        - a relation of nearness the answer does not meet (``QueryResult.unmet``, the retriever's
          relation constraint): "the plant beside the
          washer" answered by the only plant left, 1.6 m from any washer (seed 0, twice: the plant
          by the washer had been carried to the bedroom)."""
        if self._held is not None and ans.same(self._held):
            if self.driven() < 0.5 * self.config.budget_m:
                return True
            self._log("search", f"half the budget driven; taking {ans.reason}", self.explorer.xy)
            self._held = None
            self._released.append(ans)
            return False
        why = self._why_hold(ans)
        if why is None:
            return False
        self._held, (self._held_why, xy) = ans, why
        self._log("search", f"{ans.reason}; held back: {self._held_why}", xy)
        return True

    def _why_hold(self, ans: Answer) -> tuple[str, tuple[float, float] | None] | None:
        q, o = self._parsed, ans.obj
        if ans.kind not in ("new", "confirmed") or o is None or self._snap is None:
            return None
        if (self._held is not None and ans.same(self._held)) or any(ans.same(r) for r in self._released):
            return None
        rival = self._outranks(ans)
        if rival is not None:
            what = rival.caption or rival.label
            return (f"object {rival.id} ({what}) would be {q.superlative}, and it was seen gone from its place at "
                    f"({rival.position[0]:.2f}, {rival.position[1]:.2f}): looking for it", _xy(rival))
        if ans.unmet is not None:
            return f"{ans.unmet}: looking for one that is", None
        kind = canonical_label(o.label)
        if q.superlative in ("largest", "smallest"):
            # The saved map's own ones count even when seen gone: they are what the request's
            # "two or more" knew of, and one carried off may be the one seen.
            known = {("map", m.id) for m in self.cmap.objects if canonical_label(m.label) == kind} | \
                {("seen", m.id) for m in self._snap.cmap.objects
                 if canonical_label(m.label) == kind and m.id in self._snap.seen_new}
            if len(known) < 2:
                return (f"'{q.superlative}' says there are two or more of them, and this is the only {kind} known "
                        f"yet: looking for the others", None)
        if q.category is not None and kind != q.category and kind in q.category_alternatives \
                and nearly_named(q.text, kind) is None:
            return (f"{a_(kind)} only stands in for {a_(q.category)}, and no {q.category} that fits was found yet: "
                    f"looking for one", None)
        return None

    def _outranks(self, ans: Answer) -> MapObject | None:
        """The saved object of the answer's kind, seen gone or not at its place, that a superlative
        request would rank above a confirmed answer (by more than a tenth), if any."""
        q, snap, o = self._parsed, self._snap, ans.obj
        if q.superlative not in ("largest", "smallest") or ans.kind != "confirmed" or o is None or snap is None:
            return None

        def measure(m: MapObject) -> float:
            ext = np.asarray(m.extent_max, np.float64) - np.asarray(m.extent_min, np.float64)
            return float(ext[2]) if q.size_axis == "height" else float(np.prod(np.maximum(ext, 1e-3)))

        mine = measure(o)
        gone = snap.gone | self.live.absent
        rivals = [m for m in self.cmap.objects if m.id in gone and m.id != o.id and m.label == o.label
                  and (measure(m) > 1.1 * mine if q.superlative == "largest" else measure(m) < mine / 1.1)]
        if not rivals:
            return None
        return max(rivals, key=measure) if q.superlative == "largest" else min(rivals, key=measure)

    def _go(self, p: Place, lvl: Level) -> Status:
        """Drive to a place to look from (an object seen: to a step back from it)."""
        cfg, ex = self.config, self.explorer
        if p.region == SECOND_LOOK:  # the object itself stands there: look at it from a step back
            st = ex.approach(_fixed(p.xy), cfg.second_look_m, self._stop, planner=lvl.planner)
            return Status.ARRIVED if st is Status.BLOCKED and math.dist(ex.xy, p.xy) < 2 * cfg.second_look_m else st
        st = ex.drive_to(p.xy, self._stop, planner=lvl.planner)
        if st is Status.BLOCKED and math.dist(ex.xy, p.xy) > cfg.place_reach:
            # The standing point is taken now (a chair set down on it): look from a free cell near it.
            self._log("search", f"({p.xy[0]:.2f}, {p.xy[1]:.2f}) cannot be stood on; going to a free cell "
                                f"within {cfg.place_reach:.1f} m of it", ex.xy)
            st = ex.approach(_fixed(p.xy), cfg.place_reach, self._stop, planner=lvl.planner)
        return st

    def _unstick(self, tries: int = 4) -> bool:
        """A drive that could not leave the spot: the robot touches furniture (a relaxed inflation
        lets its 0.2 m body plan 0.175 m from things) and every first step of the plan, turned to
        the nearest 30 degrees, runs into it. Turn to the heading whose next step lands farthest from
        anything occupied on the robot's own map, and take that step; True when a step was taken."""
        ex = self.explorer
        grid = ex.grid()
        spec = grid.spec
        clear = ndimage.distance_transform_edt(grid.cells != OCCUPIED) * spec.resolution
        x, y, yaw = (float(v) for v in self.agent.pose)
        n = max(1, round(2 * math.pi / ex.turn))

        def clearance(k: int) -> float:
            h = yaw + k * ex.turn
            rc = spec.to_cell(np.array([x + ex.forward * math.cos(h), y + ex.forward * math.sin(h)]))
            return float(clear[rc[0], rc[1]]) if spec.inside(rc) else 0.0

        order = sorted(range(n), key=lambda k: -clearance(k))
        at = 0
        for k in order[:tries]:
            turns = (k - at) % n
            action = "turn_left" if turns <= n // 2 else "turn_right"
            for _ in range(turns if turns <= n // 2 else n - turns):
                if ex.budget <= 0:
                    return False
                ex.act(action)
            at = k
            if ex.budget <= 0:
                return False
            if ex.act("move_forward"):
                self._log("search", f"could not leave ({x:.2f}, {y:.2f}): every first step touched something; "
                                    f"stepped away from it, {clearance(k):.2f} m clear ahead", ex.xy)
                return True
        return False

    def _choices(self, places: Sequence[Place], visited: Sequence[tuple[float, float]],
                 regions: np.ndarray) -> tuple[list[Place], np.ndarray, np.ndarray]:
        """Places worth looking from, their path lengths, and for each the level to plan with: the
        strictest of ``levels.search_levels`` at which it can be reached (a relaxed level may also
        open frontiers beyond a narrow gap: those a stricter level does not have).

        Why per place: with one level for all (the strictest that reached any place), the kitchen
        whose door only the bare radius fits through was never weighed while any place in the
        first rooms was reachable with the margin, and the search looked in every other room first
        (s100002-added-0, -2: "the chair that is oak" reached at 24-28 m against a 17-20 m limit)."""
        cfg, ex = self.config, self.explorer
        out: list[Place] = []
        dist: list[float] = []
        lv: list[int] = []
        fixed = [p for p in places if not self._spent(p, visited, regions)] + self._second_looks(visited)
        todo = list(range(len(fixed)))
        for level, lvl in enumerate(self._levels):
            ex.forgive_contacts = lvl.forgive_contacts
            grid = ex.grid()
            ex.forgive_contacts = False
            cm = ex.costmap(grid, lvl.planner)
            fronts = [Place(f.target_xy, -1, cfg.frontier_prior * min(1.0, f.size / cfg.frontier_cells),
                            f"a frontier of unseen space ({f.size} cells)")
                      for f in ex.frontiers(grid, cm)
                      if all(math.dist(f.target_xy, v) > ex.config.visited_radius for v in visited)
                      and all(math.dist(f.target_xy, q.xy) > ex.config.visited_radius
                              for q, lq in zip(out, lv, strict=True) if q.region == -1 and lq < level)]
            cands = [fixed[i] for i in todo] + fronts
            reach = [cfg.second_look_m if p.region == SECOND_LOOK else cfg.place_reach for p in cands]
            d = path_lengths(grid, cm, ex.xy, [p.xy for p in cands], lvl.planner, reach) if cands else np.zeros(0)
            last = level == len(self._levels) - 1
            left = []
            for j, p in enumerate(cands):
                if np.isfinite(d[j]) or (last and j < len(todo)):
                    out.append(p)
                    dist.append(float(d[j]))
                    lv.append(level)
                elif j < len(todo):
                    left.append(todo[j])
            todo = left
        return out, np.asarray(dist, np.float64), np.asarray(lv, np.int64)

    def _second_looks(self, visited: Sequence[tuple[float, float]]) -> list[Place]:
        """Objects of the requested kind the robot saw that the retriever did not take: a first
        glimpse (from too close, or of one side) may show a part only, of the wrong size or colour,
        so each is worth one look around from a step back."""
        snap, cfg = self._snap, self.config
        kinds = {self._parsed.category, *self._parsed.category_alternatives} - {None}
        if snap is None:
            return []
        out = [Place(_xy(o), SECOND_LOOK, cfg.old_place_prior,
                     f"where the map had object {o.id} ({o.label}), seen gone from afar: a thing carried off is often "
                     "set down nearby")
               for o in self._answered.values() if o.id in snap.gone and o.id not in self.live.absent
               and not any(math.dist(_xy(o), v) < 1.0 for v in visited)]
        for n in snap.seen_new.values():
            if n.label not in kinds or (self._answer is not None and self._answer.obj is n):
                continue
            xy = _xy(n)
            if any(math.dist(xy, v) < 1.0 for v in visited):
                continue
            out.append(Place(xy, SECOND_LOOK, cfg.second_look_prior,
                             f"a {n.label} seen ({n.hits} views) that the request did not fit: a better look at it"))
        return out

    def _lookalike(self, ans: Answer) -> Answer | None:
        """A seen object that looks like the saved answer (``mapping.update.likeness`` at least the
        update's ``min_likeness``, of its label) and stands nearer the robot than the answer's saved
        place, and that the retriever would answer with were the saved one gone: the saved one
        carried there, as the update would read it. Going to the saved place first was the longer
        way (seed 0: "the largest nightstand" seen 1.2 m off in the bathroom, the saved place looked
        at first through the bedroom door: 3.5 m against a 3.0 m budget)."""
        snap, o, ex = self._snap, ans.obj, self.explorer
        if snap is None or o is None or o.id in self.live.absent:
            return None
        lim = self.config.live.update.min_likeness
        near = [n for n in snap.seen_new.values() if n.label == o.label and likeness(n, o) >= lim
                and not any(Answer("new", n, "").same(t) for t in self._alike_tried)]
        if not near:
            return None
        lvl = self._levels[0]
        grid = ex.grid()
        d = path_lengths(grid, ex.costmap(grid, lvl.planner), ex.xy, [_xy(o), *(_xy(n) for n in near)], lvl.planner,
                         self.config.place_reach)
        near = [n for n, dn in zip(near, d[1:], strict=True) if dn < d[0]]
        if not near:
            return None
        self.live.absent.add(o.id)
        try:
            alt = self._retrieve(self.live.snapshot())
        finally:
            self.live.absent.discard(o.id)
        if alt.kind != "new" or alt.obj is None or not any(Answer("new", n, "").same(alt) for n in near):
            return None
        self._alike_tried.append(alt)
        n = alt.obj
        self._log("search", f"object {n.id} ({n.caption or n.label}) seen at ({n.position[0]:.2f}, "
                            f"{n.position[1]:.2f}) looks like the map's object {o.id} (likeness "
                            f"{likeness(n, o):.2f}), nearer than its place, and is the answer without it: "
                            f"the one carried there; going to it first", _xy(n))
        return alt

    def _check_place(self, o: MapObject) -> None:
        """Go to a saved object's place and look around; not seen there, it is not there."""
        cfg, ex = self.config, self.explorer
        cxy = _xy(o)
        self._log("drive", f"to the map's place of object {o.id} ({o.caption or o.label}) at "
                           f"({cxy[0]:.2f}, {cxy[1]:.2f}) to see it", cxy)
        st = ex.approach(lambda: cxy, cfg.at_place + 0.2, self._stop)
        if st is Status.STOPPED or self._over(st):
            return
        self._log("look", f"at the map's place of object {o.id}: looking around", ex.xy)
        self._spots.append(ex.xy)
        if ex.look_around(self._stop) is Status.STOPPED:
            return
        ans = self._ask(force=True)
        if ans.kind == "confirmed" or (ans.kind == "saved" and ans.obj is not None and ans.obj.id != o.id):
            return
        if self.live.frames and o.id not in self._answer_ids("confirmed"):
            self.live.absent.add(o.id)
            self._asked_at = -1  # ask again now, without it (not after another look around at the same place)
            self._log("search", f"not at its place: object {o.id} not seen within {cfg.at_place + 0.2:.1f} m of "
                                f"where the map has it after {ex.looks} views; asking again without it", ex.xy)

    def _answer_ids(self, kind: str) -> set[int]:
        snap = self._snap
        return snap.confirmed if kind == "confirmed" and snap is not None else set()

    # ------------------------------------------------------------------ asking again
    def _ask(self, force: bool = False) -> Answer:
        """Ask the retriever again on the saved map plus what the robot has seen, when a batch of
        views has come in since the last time (or ``force``) and the map for it changed."""
        ex, cfg = self.explorer, self.config
        if self._answer is not None and not force and ex.looks - self._asked_at < cfg.batch_views:
            return self._answer
        if self._answer is not None and ex.looks == self._asked_at:
            return self._answer
        self._asked_at = ex.looks
        snap = self.live.snapshot()
        self._snap = snap
        if self._answer is not None and snap.signature == self._signature:
            return self._answer
        self._signature = snap.signature
        ans = self._retrieve(snap)
        if not ans.same(self._answer):
            self._log("ask", f"asked again after {ex.looks} views, on the map and {len(snap.seen_new)} objects seen "
                             f"that it does not explain ({len(snap.gone)} of its objects seen gone): "
                             f"{ans.reason}", _xy(ans.obj) if ans.obj is not None else None)
        self._answer = ans
        if ans.kind == "saved" and ans.obj is not None:
            self._answered[ans.obj.id] = ans.obj
        return ans

    def _retrieve(self, snap: Snapshot) -> Answer:
        from capnav.retrieval.retriever import Retriever

        self.asks += 1
        if not snap.cmap.objects:
            return Answer("none", None, "nothing left in the map or seen", len(snap.seen_new))
        # The offline verifier judges these questions: a remote one would cost a call per batch of views.
        r = Retriever(snap.cmap, self.embedder, None, self.retriever.config, time_aware=False)
        q = r.query(self._parsed, robot_xy=self._start)
        n = len(snap.seen_new)
        # Refused for a relation of nearness no candidate meets: the best of them is still the lead
        # (held back as not what was asked when seen, driven to when saved), so the search goes on.
        o = q.chosen if q.found else q.unmet_candidate
        if o is None:
            return Answer("none", None, f"no answer ({q.reason})", n)
        what = f"object {o.id} ({o.caption or o.label}) at ({o.position[0]:.2f}, {o.position[1]:.2f})"
        missing = [c for c in (self._parsed.anchor_category, self._parsed.anchor2_category)
                   if c is not None and not len(r.of_category(c))]
        unmet = q.unmet  # the retriever's relation: "next to" a landmark it stands farther from
        if o.id in snap.seen_new:
            if missing:
                return Answer("open", o, f"{what}, seen, but no {' or '.join(missing)} seen yet to judge it by; "
                                         "looking on", n)
            return Answer("new", o, f"{what}, seen by the robot; {q.reason}", n, unmet)
        if o.id in snap.confirmed:
            return Answer("confirmed", o, f"{what}, seen again at its place; {q.reason}", n, unmet)
        return Answer("saved", o, f"{what}, not seen yet; {q.reason}", n)

    def _none_text(self, ans: Answer) -> str:
        return f"the answer is still: {ans.reason}"
    def _region_at(self, regions: np.ndarray, xy: tuple[float, float]) -> int:
        rc = self.cmap.occupancy.spec.to_cell(np.asarray(xy, dtype=np.float64))
        if not self.cmap.occupancy.spec.inside(rc):
            return -1
        return int(regions[rc[0], rc[1]])

    def _spent(self, p: Place, visited: Sequence[tuple[float, float]], regions: np.ndarray) -> bool:
        """Aimed at already, or looked around at from nearby (where the robot stood, not where it
        aimed: a place that could not be stood on is looked from up to a metre off, maybe in the
        next room), or its region mostly seen by the robot's own depth (from inside it, or nearly
        all of it from outside: a glimpse through a door is not a look)."""
        if any(math.dist(p.xy, v) < 1e-6 for v in visited) or self._looked_from_near(p.xy, self._spots):
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

    def _looked_from_near(self, xy: tuple[float, float], spots: Sequence[tuple[float, float]],
                          radius: float = 1.5) -> bool:
        """Looked at from within ``radius`` with nothing between on the robot's own map: two rooms'
        standing points may lie 1.4 m apart on either side of a wall, and a look around in one does
        not see the other (the room and the object in it were counted as looked at, never seen)."""
        for v in spots:
            d = math.dist(xy, v)
            if d < 1e-6 or (d < radius and self._clear_line(v, xy)):
                return True
        return False

    def _clear_line(self, a: tuple[float, float], b: tuple[float, float], end: float = 0.2) -> bool:
        """No occupied cell of the online map (the saved map where the robot has not looked) on the
        segment from ``a`` to ``b``, ``end`` metres at either end left out (a standing point taken by
        a chair, a place given up on furniture)."""
        own = self.explorer.map
        if self._cells_at is None or self._cells_at[0] != self.explorer.looks:
            self._cells_at = (self.explorer.looks, own.cells())
        cells = self._cells_at[1]
        d = math.dist(a, b)
        if d <= 2 * end:
            return True
        t = np.linspace(end / d, 1.0 - end / d, max(2, int(np.ceil(d / (0.5 * own.spec.resolution)))))
        pts = np.asarray(a, np.float64)[None, :] + t[:, None] * (np.asarray(b, np.float64) - np.asarray(a))[None, :]
        rc = own.spec.to_cell(pts)
        ok = own.spec.inside(rc)
        return not bool((cells[rc[ok, 0], rc[ok, 1]] == OCCUPIED).any())

    # ------------------------------------------------------------------ going to the answer
    def _stop(self, ex: FrontierExplorer) -> bool:
        """Stop a drive or a look-around when a batch of views changed the answer."""
        if self.config.budget_s is not None and time.monotonic() - self._t0 > self.config.budget_s:
            self._timed_out = True
            return True
        prev = self._answer
        ans = self._ask()
        if self._held is not None and ans.same(self._held):
            return False  # still the answer held back (``_hold``): drive on to look for what outranks it
        changed = ans is not prev and (ans.kind in ("new", "confirmed") or not ans.same(prev))
        if changed and ans.kind in ("new", "confirmed") and self._hold(ans):
            # An answer seen that is held back at once: look on. Stopping here cut the look around
            # at a saved answer's place short, and the chair by the fridge 1.3 m off was never in
            # view there (seed 0: the robot drove on to look from another place).
            return False
        return changed

    def _approach(self, ans: Answer) -> SearchResult | None:
        """Go to the answer's footprint; None when a batch of views on the way changed the answer."""
        cfg, ex = self.config, self.explorer
        assert ans.obj is not None
        label = ans.obj.label
        box = [np.asarray(ans.obj.extent_min[:2], np.float64), np.asarray(ans.obj.extent_max[:2], np.float64)]
        from_map = ans.kind == "confirmed"

        seen_at = [-1]

        def refresh() -> None:
            if from_map or seen_at[0] == ex.looks:  # nothing new seen since the last refresh
                return
            seen_at[0] = ex.looks
            c = 0.5 * (box[0] + box[1])
            near = [o for o in self.live.seen_objects()
                    if o.label == label and float(np.hypot(*(o.position[:2] - c))) <= cfg.cluster_radius]
            if near:
                o = min(near, key=lambda o: float(np.hypot(*(o.position[:2] - c))))
                box[0], box[1] = np.asarray(o.extent_min[:2], np.float64), np.asarray(o.extent_max[:2], np.float64)

        def target() -> tuple[float, float]:
            # The point of the object's footprint nearest the robot (a long bookcase is reached at its side).
            lo, hi = box
            inner = np.minimum(0.1, 0.5 * (hi - lo))
            p = np.clip(np.asarray(ex.xy), lo + inner, hi - inner)
            return float(p[0]), float(p[1])

        def refreshed_target() -> tuple[float, float]:
            refresh()
            return target()

        where = "seen again at the map's place" if from_map else "away from where the map has anything like it"
        self._log("found", f"{ans.reason}; {where}; approaching", target())
        self._timed_out = False

        def stop(e: FrontierExplorer) -> bool:  # what the robot sees on the way may change the answer
            now = self._ask()
            return self._budget_only(e) or not (now.same(ans) or now.same(self._stand_in_for))

        avoid: list[tuple[float, float]] = []

        def drive(lvl: Level, stop_at: float) -> Status:
            ex.forgive_contacts = lvl.forgive_contacts
            try:
                return ex.approach(refreshed_target, stop_at, stop, planner=lvl.planner, avoid=avoid,
                                   avoid_radius=cfg.avoid_radius)
            finally:
                ex.forgive_contacts = False

        ex.last_goal = None
        st = climb_levels(self._levels, drive, lambda: math.dist(ex.xy, target()), cfg.stop_distance,
                          cfg.planner.reach, lambda text: self._log("search", text, ex.xy))
        # Blocked outside reach at every level: the standing cell aimed at may be one the map has
        # free and the robot does not fit to (a slot between an armchair and a table, the far side
        # of the object not tried). Aim once more, at the other cells by the object.
        while st is Status.BLOCKED and len(avoid) < cfg.other_sides and ex.last_goal is not None \
                and math.dist(ex.xy, target()) > cfg.planner.reach and not self._over(st):
            g = ex.last_goal
            avoid.append(g)
            self._log("search", f"could not get nearer than {math.dist(ex.xy, target()):.2f} m by way of "
                                f"({g[0]:.2f}, {g[1]:.2f}); aiming at the standing cells by it farther than "
                                f"{cfg.avoid_radius:.1f} m from there", ex.xy)
            ex.last_goal = None
            st = climb_levels(self._levels, drive, lambda: math.dist(ex.xy, target()), cfg.stop_distance,
                              cfg.planner.reach, lambda text: self._log("search", text, ex.xy))
        if st is Status.STOPPED and not self._timed_out:
            return None
        goal_xy = target()
        d = math.dist(ex.xy, goal_xy)
        centre = (float(0.5 * (box[0][0] + box[1][0])), float(0.5 * (box[0][1] + box[1][1])))
        self._found_id = ans.obj.id if from_map else None
        what = ans.obj.caption or ans.obj.label
        if st is Status.ARRIVED or d <= cfg.planner.reach:
            return self._end(f"found: {what} at ({centre[0]:.2f}, {centre[1]:.2f}); stopped {d:.2f} m from it",
                             True, centre, from_map)
        if self._over(st):
            return self._end(f"not found within budget: {what} seen at ({centre[0]:.2f}, {centre[1]:.2f}) but the "
                             f"budget ran out {d:.2f} m from it ({self._spent_text()})", False, centre, from_map)
        return self._end(f"seen but not reached: {what} at ({centre[0]:.2f}, {centre[1]:.2f}); could not get closer "
                         f"than {d:.2f} m", False, centre, from_map)

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
                         f"{self._none_text(self._answer or Answer('none', None, 'no answer'))}")

    def _log(self, action: str, reason: str, xy: tuple[float, float] | None = None) -> None:
        self.steps.append(SearchStep(action, reason, xy, self.driven()))

    def _end(self, reason: str, found: bool = False, target: tuple[float, float] | None = None,
             from_map: bool = False) -> SearchResult:
        self._log("found" if found else "not found", reason, self.explorer.xy)
        return SearchResult(found, reason, target, self.driven(), self.steps, self.explorer.looks, from_map,
                            self._found_id if found and from_map else None, self.asks)



def climb_levels(levels: Sequence[Level], drive: Callable[[Level, float], Status], gap: Callable[[], float],
                 stop_distance: float, reach: float, log: Callable[[str], None]) -> Status:
    """Approach an object one inflation level at a time (``levels.search_levels``, strictest first):
    ``drive(level, stop_at)`` drives until within ``stop_at`` of it, ``gap()`` is the distance left.

    The strictest level aims at ``stop_distance``, inside the ``reach`` that counts as arrived. A
    looser level is tried only when the stricter one was blocked outside ``reach``, and it drives
    only until within ``reach``: its paths graze the furniture around the object, and a robot that
    already stood within reach and drove on for the nearer stop ended farther off than it started
    (a plant boxed in by two armchairs: blocked at 0.88 m, then 1.30 m after the looser levels).
    """
    st = drive(levels[0], stop_distance)
    tried = levels[0]
    for lvl in levels[1:]:
        if st is not Status.BLOCKED:
            break
        d = gap()
        if d <= reach:
            log(f"no standing cell nearer than {d:.2f} m with {tried.describe()}, within the {reach:.1f} m "
                f"reach: stopping here, no looser inflation tried")
            break
        log(f"no standing cell nearer than {d:.2f} m with {tried.describe()}; approaching with {lvl.describe()} "
            f"until within {reach:.1f} m")
        tried = lvl
        st = drive(lvl, reach)
    return st


def path_lengths(grid: OccupancyGrid, cm: Costmap, start_xy: tuple[float, float],
                 targets: Sequence[tuple[float, float]], planner: PlannerConfig,
                 reach: Sequence[float] | float = 0.0) -> NDArray[np.float64]:
    """Metres of the drive from ``start_xy`` to each target, as the drive would plan it: the start
    snapped to a passable cell as ``planning.locate_start`` snaps it (within the planner's escape
    radius, else nothing is reachable: the drive would refuse to plan), a target on a passable cell
    reached there, a blocked one (an object, a room's point on furniture) at the cheapest passable
    cell within ``reach`` of it (the approach that stops that close), else never (inf).

    Why: a start in the inflation band snapped to the nearest passable cell anywhere may land
    behind a wall, and then places look reachable at a strict inflation that the drive refuses
    (every drive "could not get to"), and the relaxed levels that would get the robot out are
    never tried."""
    n = len(targets)
    out = np.full(n, np.inf)
    if n == 0:
        return out
    try:
        s_cell, _ = locate_start(cm, start_xy, planner)
    except CapNavError:
        return out
    fld, _ = cost_field(cm.weights, s_cell)
    spec = grid.spec
    res = spec.resolution
    radii = np.broadcast_to(np.asarray(reach, dtype=np.float64), (n,))
    rc = spec.to_cell(np.asarray(targets, dtype=np.float64).reshape(-1, 2))
    ok = spec.inside(rc)
    out[ok] = fld[rc[ok, 0], rc[ok, 1]] * res
    for i in np.flatnonzero(~np.isfinite(out) & (radii > 0)):
        k = int(np.ceil(radii[i] / res))
        r, c = int(rc[i, 0]), int(rc[i, 1])
        r0, c0 = max(r - k, 0), max(c - k, 0)
        r1, c1 = min(r + k + 1, spec.rows), min(c + k + 1, spec.cols)
        if r0 >= r1 or c0 >= c1:
            continue
        win = fld[r0:r1, c0:c1]
        rr, cc = np.mgrid[r0:r1, c0:c1]
        centres = spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1)).reshape(r1 - r0, c1 - c0, 2)
        tx, ty = targets[int(i)]
        near = np.hypot(centres[..., 0] - tx, centres[..., 1] - ty) <= radii[i]
        vals = win[near & np.isfinite(win)]
        if vals.size:
            out[i] = float(vals.min()) * res
    return out

def search_goal(cmap: CapNavMap, retriever: Any, instruction: Any, agent: Any, detector: Any,
                config: SearchConfig | None = None) -> tuple[Any, SearchResult]:
    """Ask the map (``retriever.query``), then go and confirm it or search, asking again as the
    robot sees. Returns the map's first answer (a ``QueryResult``) and the search's outcome."""
    x, y, _ = (float(v) for v in agent.pose)
    q = retriever.query(instruction, robot_xy=(x, y))
    search = ObjectSearch(cmap, agent, detector, retriever, config)
    return q, search.run(instruction, q)


def _kinds(q: ParsedQuery) -> set[str] | None:
    """The categories a request's answer depends on: its target's (and their alternatives) and its
    landmarks'; None when any category may answer (a purpose, a word for any object)."""
    if q.category is None or q.generic or q.purpose is not None:
        return None
    return {c for c in (q.category, q.anchor_category, q.anchor2_category, *q.category_alternatives) if c}


def _fixed(xy: tuple[float, float]) -> Callable[[], tuple[float, float]]:
    """A target that stays where it is."""
    return lambda: xy


def _xy(o: MapObject) -> tuple[float, float]:
    return float(o.position[0]), float(o.position[1])
