"""The shared frontier-exploration core: observe, map, pick a frontier, drive there step by step.

Every motion is one discrete agent action (turn or forward step, as in Habitat's object-goal
task). The agent looks (renders, maps, detects) at keyframes: once its view has changed enough
since the last look (a 60 degree turn or 0.5 m; the camera sees 90 degrees), after a collision,
and before every decision that reads the map. Consecutive 30 degree / 0.25 m views overlap by
two thirds, and looking is most of the cost of an action, so this halves the work while the map
and the sightings still grow as the agent moves, and a ``stop`` predicate ends the search at the
first keyframe that shows the goal. The budget counts actions (and, when ``path_limit`` is set,
metres driven: the action budget ends when the agent has driven that far); running out is a
timeout, running out of reachable frontiers means the whole reachable space was seen.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import CapNavError, InputError
from capnav.core.frame import Frame
from capnav.core.grid import FREE, OCCUPIED, UNKNOWN, GridSpec, OccupancyGrid
from capnav.explore.frontier import Frontier, find_frontiers
from capnav.explore.online_map import OnlineMap, OnlineMapConfig
from capnav.explore.sighting import Sighting, lift
from capnav.planning import Costmap, PlannerConfig, build_costmap, plan_path, select_goal
from capnav.planning.search import cost_field

#: ``score(frontiers, explorer) -> one score per frontier``; the highest reachable one is chosen.
FrontierScorer = Callable[[Sequence[Frontier], "FrontierExplorer"], NDArray[np.float64]]
#: ``stop(explorer) -> True`` ends the current drive / search (e.g. the goal is in view).
StopCheck = Callable[["FrontierExplorer"], bool]


class Status(Enum):
    ARRIVED = "arrived"
    STOPPED = "stopped"  # the stop predicate fired
    BUDGET = "budget"  # no actions left: a timeout
    BLOCKED = "blocked"  # could not plan or kept colliding
    EXHAUSTED = "exhausted"  # no reachable frontier left


@dataclass(frozen=True)
class ExplorerConfig:
    """Exploration behaviour. ``planner`` is the shared A* planner's config (same as CapNav's)."""

    map: OnlineMapConfig = field(default_factory=OnlineMapConfig)
    planner: PlannerConfig = field(default_factory=PlannerConfig)
    max_steps: int | None = None  # actions per subgoal; None = the harness's ctx.max_steps
    look_around: bool = True  # a full turn in place at the start and at each reached frontier
    replan_every: int = 6  # forward steps between replans (the map grows while driving)
    min_frontier_cells: int = 4
    frontier_tile: float = 1.5  # m, longest side of one frontier cluster
    visited_radius: float = 0.75  # m, a frontier whose target is this close to a reached one is spent
    max_collisions: int = 4  # per drive, before the target is given up
    max_slides: int = 3  # per waypoint: a blocked step is slid off (``_slide``) this often before a replan
    min_sighting_points: int = 10  # valid depth pixels a detection needs to be lifted
    goal_snap: float = 0.5  # m, a goal inside the inflated obstacles moves to the nearest free cell
    keyframe_turn_deg: float = 60.0  # look again after turning this much since the last look ...
    keyframe_move: float = 0.5  # ... or moving this far (m); 0 and 0: look after every action
    sighting_colours: bool = False  # name each sighting's dominant colours (a search for "the blue chair")

    def __post_init__(self) -> None:
        if self.max_steps is not None and self.max_steps < 1:
            raise InputError(f"max_steps must be >= 1, got {self.max_steps}")
        if self.replan_every < 1 or self.min_frontier_cells < 1 or self.max_collisions < 1:
            raise InputError("replan_every, min_frontier_cells and max_collisions must be >= 1")
        if self.keyframe_turn_deg < 0 or self.keyframe_move < 0:
            raise InputError("keyframe_turn_deg and keyframe_move must be >= 0")


class FrontierExplorer:
    """One episode's exploration state: online map, sightings, spent frontiers, action budget."""

    def __init__(self, agent: Any, detector: Any, config: ExplorerConfig | None = None,
                 online_map: OnlineMap | None = None) -> None:
        """``detector`` None: map only, no sightings. ``online_map``: continue an existing map
        (e.g. one built from the exploration stream) instead of starting empty."""
        self.agent = agent
        self.detector = detector
        self.config = cfg = config or ExplorerConfig()
        x, y, _ = (float(v) for v in agent.pose)
        self.map = online_map if online_map is not None else OnlineMap((x, y), cfg.map)
        self.sightings: list[Sighting] = []
        self.new_sightings: list[Sighting] = []
        self.spent: list[tuple[float, float]] = []
        self.budget = 0
        self.steps = 0
        self.frame: Frame | None = None
        self.looks = 0  # observations made (the costly part of an action)
        self.path_limit: float | None = None  # metres of agent odometry after which the budget is spent
        #: Called with every frame looked at and its detections (a search maps them as it goes).
        self.on_look: Callable[[Frame, list[Any]], None] | None = None
        self._looked_from: tuple[float, float, float] | None = None  # pose of the last observation
        #: Plan without the contact marks on cells the depth saw free (``OnlineMap.cells``): a last resort.
        self.forgive_contacts = False
        self.last_goal: tuple[float, float] | None = None  # the standing cell ``approach`` last aimed at
        agent_cfg = getattr(agent, "cfg", None) or getattr(agent, "config", None)
        self.turn = math.radians(float(getattr(agent_cfg, "turn_deg", 30.0)))
        self.forward = float(getattr(agent_cfg, "forward_step", 0.25))

    # ------------------------------------------------------------------ budget and senses
    def begin(self, max_steps: int) -> None:
        """Start a subgoal with a fresh action budget (map and sightings are kept)."""
        self.budget = int(self.config.max_steps or max_steps)
        self.steps = 0

    @property
    def xy(self) -> tuple[float, float]:
        p = self.agent.pose
        return float(p[0]), float(p[1])

    def observe(self) -> list[Sighting]:
        """Look: fuse depth into the map, run the detector, remember the lifted sightings."""
        frame = self.agent.observe()
        self.frame = frame
        self.looks += 1
        x, y, yaw = (float(v) for v in self.agent.pose)
        self._looked_from = (x, y, yaw)
        self.map.update(frame)
        self.map.mark_free_disk((x, y))
        dets = self.detector.detect(frame) if self.detector is not None else []
        if self.on_look is not None:
            self.on_look(frame, list(dets))
        self.new_sightings = lift(frame, dets, self.config.min_sighting_points,
                                  colours=self.config.sighting_colours)
        self.sightings.extend(self.new_sightings)
        return self.new_sightings

    def sync(self) -> bool:
        """Look if the agent moved since the last look (before a decision that reads the map);
        True if it looked."""
        if self._looked_from is not None and tuple(float(v) for v in self.agent.pose) == self._looked_from:
            return False
        self.observe()
        return True

    def act(self, action: str) -> bool:
        """One action, then a look if it is a keyframe; False when a forward step hit something."""
        ok = bool(self.agent.step(action))
        self.budget -= 1
        self.steps += 1
        x, y, yaw = (float(v) for v in self.agent.pose)
        self.map.mark_free_disk((x, y))  # driven over, so free, whether or not this is a keyframe
        if self.path_limit is not None and float(getattr(self.agent, "path_length", 0.0)) >= self.path_limit:
            self.budget = 0
        if not ok:
            self._mark_contact(x, y, yaw)
        if not ok or self._is_keyframe(x, y, yaw):
            self.observe()
        else:
            self.new_sightings = []
        return ok

    def _mark_contact(self, x: float, y: float, yaw: float) -> None:
        """Record where a blocked forward step touched something.

        Nothing the map knows within reach ahead: the obstacle is unseen (below the depth band, a
        thin leg), straight ahead, as before. Something the map knows within reach in the half
        plane ahead: the robot touched that, at its side (a step of a 30-degree heading grazing a
        convex corner or a gap's side), and the mark goes on the line to it, just beyond the robot's
        radius; a mark straight ahead would sit in free floor on the way (in the gap the robot was
        passing through) and close it to the next plan, while a mark at the touched side makes the
        next plan keep the robot's true clearance there."""
        r = self.config.planner.robot_radius
        side = self._touched(x, y, yaw, r + 0.1)
        if side is None:
            self.map.mark_obstacle((x + (r + 0.06) * math.cos(yaw), y + (r + 0.06) * math.sin(yaw)))
            return
        self.map.mark_obstacle((x + (r + 0.06) * math.cos(side), y + (r + 0.06) * math.sin(side)), 0.05)

    def _occupied_near(self, x: float, y: float, radius: float) -> NDArray[np.float64]:
        """Centres (N, 2) of the online map's occupied cells within ``radius`` of (x, y)."""
        spec = self.map.spec
        rc = spec.to_cell(np.asarray((x, y), dtype=np.float64))
        k = int(np.ceil(radius / spec.resolution)) + 1
        r0, c0 = max(int(rc[0]) - k, 0), max(int(rc[1]) - k, 0)
        r1, c1 = min(int(rc[0]) + k + 1, spec.rows), min(int(rc[1]) + k + 1, spec.cols)
        if r0 >= r1 or c0 >= c1:
            return np.zeros((0, 2))
        win = self.map.cells(self.forgive_contacts)[r0:r1, c0:c1] == OCCUPIED
        rr, cc = np.nonzero(win)
        if rr.size == 0:
            return np.zeros((0, 2))
        pts = spec.to_world(np.stack([rr + r0, cc + c0], axis=1)).astype(np.float64)
        return pts[np.hypot(pts[:, 0] - x, pts[:, 1] - y) <= radius]

    def _touched(self, x: float, y: float, yaw: float, radius: float) -> float | None:
        """The bearing of the nearest occupied cell within ``radius`` in the half plane ahead, or None."""
        pts = self._occupied_near(x, y, radius)
        if not len(pts):
            return None
        ahead = (pts[:, 0] - x) * math.cos(yaw) + (pts[:, 1] - y) * math.sin(yaw) > 0
        if not ahead.any():
            return None
        pts = pts[ahead]
        i = int(np.argmin(np.hypot(pts[:, 0] - x, pts[:, 1] - y)))
        return math.atan2(pts[i, 1] - y, pts[i, 0] - x)

    def _heading(self, k: int, target: tuple[float, float], d: float) -> int:
        """The turn (in turn steps from the current heading) to take before the next forward step
        towards ``target`` (``d`` metres away), nominally ``k`` (the heading nearest the bearing).

        Why: paths are planned at a relaxed inflation (the bare radius less half a cell, so that a
        door the robot fits through stays open) and simplified to straight lines that pass corners
        at that inflation, and the robot follows them at the nearest 30-degree heading: a step
        can then cut a convex corner closer than the robot's radius, and from there every first
        step of every replan touches it again (s100001/s100002: "could not get to ... giving it
        up", wedged between an ottoman and an armchair). So the step is checked against the
        occupied cells of the robot's own map: when the nominal heading passes closer than the
        radius plus half a cell (a cell's centre may lie half a cell off the surface), the
        neighbouring headings (up to two turns away) that still get closer to the target are
        tried, and the one that keeps the most clearance (up to that radius) is taken; none
        clearer: the nominal heading, as before."""
        r = self.config.planner.robot_radius
        need = r + 0.5 * self.map.spec.resolution
        x, y, yaw = (float(v) for v in self.agent.pose)
        pts = self._occupied_near(x, y, self.forward + need + self.map.spec.resolution)
        if not len(pts):
            return k
        ts = np.linspace(0.2, 1.0, 5)

        def clear(j: int) -> float:
            h = yaw + j * self.turn
            sx, sy = x + ts * self.forward * math.cos(h), y + ts * self.forward * math.sin(h)
            dd = np.hypot(sx[:, None] - pts[None, :, 0], sy[:, None] - pts[None, :, 1])
            return float(dd.min())

        def gain(j: int) -> float:
            h = yaw + j * self.turn
            return d - math.dist((x + self.forward * math.cos(h), y + self.forward * math.sin(h)), target)

        c0 = clear(k)
        if c0 >= need:
            return k
        best, best_key = k, (min(c0, need), 0.0)
        for j in (k - 1, k + 1, k - 2, k + 2):
            if gain(j) < 0.02:  # a step that does not get closer to the target is no way there
                continue
            c = clear(j)
            key = (min(c, need), -abs(j - k))
            if key[0] > best_key[0] + 0.005 or (key[0] >= need and best_key[0] < need):
                best, best_key = j, key
        return best

    def _slide(self, target: tuple[float, float], stop: StopCheck | None) -> bool:
        """After a blocked forward step, slide off what was touched as a bumper robot does: turn to
        the heading that gets closest to ``target`` among those that leave the contact (at least a
        right angle from its bearing, ``_touched``; straight ahead when the map knows nothing
        there) and step. True when that step got closer to ``target``.

        Why: a blocked step stops at the contact, and every replan from there heads into the same
        corner at the nearest 30-degree heading (s100001/s100002: "could not get to ... giving it
        up" 3-5 times without moving); a step that leaves the contact goes past it, and the
        partial steps of the contacts also set the robot off the 0.25 m lattice of its steps, which
        is what gets it through a gap a few centimetres wider than itself."""
        r = self.config.planner.robot_radius
        x, y, yaw = (float(v) for v in self.agent.pose)
        phi = self._touched(x, y, yaw, r + 0.1)
        phi = yaw if phi is None else phi
        d0 = math.dist((x, y), target)
        n = max(1, round(2 * math.pi / self.turn))
        best: tuple[float, int] | None = None
        for j in range(-(n // 2), n // 2 + 1):
            h = yaw + j * self.turn
            if math.cos(h - phi) > -0.05:  # would press into the contact
                continue
            g = d0 - math.dist((x + self.forward * math.cos(h), y + self.forward * math.sin(h)), target)
            if g > 0.02 and (best is None or (g, -abs(j)) > (best[0], -abs(best[1]))):
                best = (g, j)
        if best is None:
            return False
        j = best[1]
        for _ in range(abs(j)):
            if self.budget <= 0:
                return False
            self.act("turn_left" if j > 0 else "turn_right")
        if self.budget <= 0:
            return False
        self.act("move_forward")
        return math.dist(self.xy, target) < d0 - 1e-3

    def _is_keyframe(self, x: float, y: float, yaw: float) -> bool:
        if self._looked_from is None:
            return True
        x0, y0, yaw0 = self._looked_from
        cfg = self.config
        return (math.dist((x, y), (x0, y0)) >= cfg.keyframe_move - 1e-9
                or abs(_wrap(yaw - yaw0)) >= math.radians(cfg.keyframe_turn_deg) - 1e-6)

    def look_around(self, stop: StopCheck | None = None) -> Status:
        """A full turn in place, looking at every keyframe heading (every 60 degrees by default)."""
        for _ in range(max(1, round(2 * math.pi / self.turn)) - 1):
            if self.budget <= 0:
                return Status.BUDGET
            self.act("turn_left")
            if stop is not None and stop(self):
                return Status.STOPPED
        return Status.ARRIVED

    def face(self, xy: tuple[float, float], stop: StopCheck | None = None) -> Status:
        """Turn in place towards ``xy`` (a frontier's unknown side), looking at keyframe headings."""
        x, y, yaw = (float(v) for v in self.agent.pose)
        if math.dist((x, y), xy) < 1e-6:
            return Status.ARRIVED
        err = _wrap(math.atan2(xy[1] - y, xy[0] - x) - yaw)
        for _ in range(int(abs(err) / self.turn + 0.5)):
            if self.budget <= 0:
                return Status.BUDGET
            self.act("turn_left" if err > 0 else "turn_right")
            if stop is not None and stop(self):
                return Status.STOPPED
        return Status.ARRIVED

    # ------------------------------------------------------------------ planning
    def grid(self, margin: float = 1.0) -> OccupancyGrid:
        """The online map cropped to its known part plus ``margin`` metres (and the agent).

        Planning floods unknown space at the planner's unknown cost, so the crop keeps every
        search (inflation, cost field, A*) proportional to the explored area, not to the whole
        fixed-size online grid.
        """
        full = self.map.grid(self.forgive_contacts)
        known = full.cells != UNKNOWN
        spec = full.spec
        rows, cols = np.nonzero(known)
        a = spec.to_cell(np.asarray(self.xy))
        k = int(np.ceil(margin / spec.resolution))
        r0 = max(min(int(rows.min()) if rows.size else int(a[0]), int(a[0])) - k, 0)
        r1 = min(max(int(rows.max()) if rows.size else int(a[0]), int(a[0])) + k + 1, spec.rows)
        c0 = max(min(int(cols.min()) if cols.size else int(a[1]), int(a[1])) - k, 0)
        c1 = min(max(int(cols.max()) if cols.size else int(a[1]), int(a[1])) + k + 1, spec.cols)
        sub = GridSpec(spec.x0 + c0 * spec.resolution, spec.y0 + r0 * spec.resolution, spec.resolution,
                       r1 - r0, c1 - c0)
        return OccupancyGrid(sub, full.cells[r0:r1, c0:c1].copy())

    def costmap(self, grid: OccupancyGrid, planner: PlannerConfig | None = None) -> Costmap:
        return build_costmap(grid, planner or self.config.planner)

    def frontiers(self, grid: OccupancyGrid, cm: Costmap) -> list[Frontier]:
        """Reachable, unspent frontiers, cheapest path first.

        Path costs come from the shared planner's cost field, so a frontier seen through a door
        whose posts the map has not resolved yet stays reachable across unknown cells (at the
        planner's unknown cost) instead of being dropped; targets are always known-free cells.
        """
        passable = np.isfinite(cm.weights)
        start = _start_cell(grid, passable & (grid.cells == FREE), self.xy)
        field, _ = cost_field(cm.weights, start)
        known = passable & (grid.cells == FREE)
        dist = np.where(known, field * grid.spec.resolution, np.inf)
        out = find_frontiers(grid, dist, self.config.min_frontier_cells, self.config.frontier_tile)
        r2 = self.config.visited_radius**2
        return [f for f in out if math.isfinite(f.path_distance)
                and not any((f.target_xy[0] - s[0]) ** 2 + (f.target_xy[1] - s[1]) ** 2 < r2 for s in self.spent)]

    # ------------------------------------------------------------------ motion
    def drive_to(self, goal_xy: tuple[float, float], stop: StopCheck | None = None, tolerance: float | None = None,
                 goal_of: Callable[[], tuple[float, float] | None] | None = None,
                 planner: PlannerConfig | None = None) -> Status:
        """Plan on the online map and drive with discrete actions, replanning every few steps.

        ``goal_of`` (optional) re-reads the goal before each replan (an approach whose target
        estimate improves as the agent gets closer); ``tolerance`` is the arrival radius;
        ``planner`` overrides the configured planner for this drive.
        """
        plan_cfg = planner or self.config.planner
        tol = 0.6 * self.forward if tolerance is None else tolerance
        collisions = idle = 0
        while True:
            if self.sync() and stop is not None and stop(self):
                return Status.STOPPED
            if goal_of is not None:
                g = goal_of()
                goal_xy = g if g is not None else goal_xy
            if math.dist(self.xy, goal_xy) <= tol:
                return Status.ARRIVED
            grid = self.grid()
            cm = self.costmap(grid, plan_cfg)
            aim = _snap_goal(cm, goal_xy, self.config.goal_snap)
            if aim is None:
                return Status.BLOCKED
            try:
                path = plan_path(grid, self.xy, aim, plan_cfg, cm)
            except CapNavError:
                return Status.BLOCKED
            before = self.steps
            status = self._follow(path.waypoints, stop, max(tol, math.dist(aim, goal_xy)), goal_xy)
            if status is None:
                idle = idle + 1 if self.steps == before else 0
                if idle >= 3:  # the plan keeps ending where the agent already is
                    return Status.BLOCKED
                continue
            if status is Status.BLOCKED:
                collisions += 1
                if collisions >= self.config.max_collisions:
                    return Status.BLOCKED
                continue
            return status

    def _follow(self, waypoints: NDArray[np.float64], stop: StopCheck | None, tol: float,
                goal_xy: tuple[float, float]) -> Status | None:
        """Walk the waypoints for up to ``replan_every`` forward steps; None means 'replan'.

        A waypoint counts as reached within 0.6 forward steps, or when a forward step towards it
        no longer gets closer (a fixed step cannot land exactly on a point: without this rule
        the agent would step back and forth across it).
        """
        forward = 0
        reach = 0.6 * self.forward
        for wp in waypoints[1:]:
            target = (float(wp[0]), float(wp[1]))
            turns: int | None = None  # turns left before the next forward step (``_heading``)
            slides = 0
            while (d := math.dist(self.xy, target)) > reach:
                if math.dist(self.xy, goal_xy) <= tol:
                    return Status.ARRIVED
                if forward >= self.config.replan_every:
                    return None
                if self.budget <= 0:
                    return Status.BUDGET
                x, y, yaw = (float(v) for v in self.agent.pose)
                if turns is None:
                    err = _wrap(math.atan2(target[1] - y, target[0] - x) - yaw)
                    turns = self._heading(round(err / self.turn), target, d)
                progressed = True
                if turns != 0:
                    ok = self.act("turn_left" if turns > 0 else "turn_right")
                    turns -= 1 if turns > 0 else -1
                else:
                    ok = self.act("move_forward")
                    forward += 1
                    turns = None
                    progressed = math.dist(self.xy, target) < d - 1e-3
                if stop is not None and stop(self):
                    return Status.STOPPED
                if not ok:
                    if slides < self.config.max_slides and self._slide(target, stop):
                        slides += 1
                        continue
                    return Status.BLOCKED
                if not progressed:
                    break
        return Status.ARRIVED if math.dist(self.xy, goal_xy) <= max(tol, self.forward) else None

    def explore(self, score: FrontierScorer, stop: StopCheck) -> Status:
        """Frontier exploration until ``stop`` fires, the budget ends or no frontier is left."""
        if self.frame is None:
            self.observe()
        if stop(self):
            return Status.STOPPED
        if self.config.look_around and not self.spent and self.steps == 0:
            st = self.look_around(stop)
            if st is not Status.ARRIVED:
                return st
        while self.budget > 0:
            if self.sync() and stop(self):
                return Status.STOPPED
            grid = self.grid()
            fronts = self.frontiers(grid, self.costmap(grid))
            if not fronts:
                return Status.EXHAUSTED
            scores = np.asarray(score(fronts, self), dtype=np.float64)
            f = fronts[int(np.argmax(scores))]
            st = self.drive_to(f.target_xy, stop)
            self.spent.append(f.target_xy)
            if st is Status.ARRIVED:
                st = self.look_around(stop) if self.config.look_around else self.face(f.centroid_xy, stop)
            if st in (Status.STOPPED, Status.BUDGET):
                return st
        return Status.BUDGET

    def approach(self, target: Callable[[], tuple[float, float] | None], stop_distance: float,
                 stop: StopCheck | None = None, planner: PlannerConfig | None = None,
                 avoid: Sequence[tuple[float, float]] = (), avoid_radius: float = 0.4) -> Status:
        """Drive until within ``stop_distance`` of the (re-estimated) target, via a reachable
        standing cell chosen by the shared planner's goal selection (``planner``: another
        inflation than the configured one, e.g. a relaxed level of ``levels.inflation_levels``).
        ``avoid``: standing cells an earlier approach aimed at and could not get to; no cell within
        ``avoid_radius`` of them is chosen. The last cell aimed at is kept in ``last_goal``."""
        plan_cfg = planner or self.config.planner

        def standing_cell() -> tuple[float, float] | None:
            t = target()
            if t is None:
                return None
            if math.dist(self.xy, t) <= stop_distance:
                return self.xy
            grid = self.grid()
            cm = self.costmap(grid, plan_cfg)
            allowed = None
            if avoid:
                rr, cc = np.mgrid[0:grid.spec.rows, 0:grid.spec.cols]
                centres = grid.spec.to_world(np.stack([rr.ravel(), cc.ravel()], axis=1))
                far = np.ones(len(centres), bool)
                for a in avoid:
                    far &= np.hypot(centres[:, 0] - a[0], centres[:, 1] - a[1]) > avoid_radius
                allowed = far.reshape(grid.spec.rows, grid.spec.cols)
            try:
                g = select_goal(grid, np.array([t]), self.xy, plan_cfg, cm, allowed=allowed)
            except CapNavError:
                return None
            self.last_goal = (float(g.xy[0]), float(g.xy[1]))
            return self.last_goal

        first = standing_cell()
        if first is None:
            return Status.BLOCKED

        def near_target(ex: FrontierExplorer) -> bool:
            t = target()
            return (t is not None and math.dist(ex.xy, t) <= stop_distance) or (stop is not None and stop(ex))

        if near_target(self):
            return Status.ARRIVED
        st = self.drive_to(first, near_target, goal_of=standing_cell, planner=plan_cfg)
        t = target()
        if t is not None and math.dist(self.xy, t) <= stop_distance:
            return Status.ARRIVED
        # At the best standing cell the map knows, yet not near the target: no closer cell is reachable.
        return Status.BLOCKED if st is Status.ARRIVED else st


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _snap_goal(cm: Costmap, xy: tuple[float, float], max_dist: float) -> tuple[float, float] | None:
    """``xy`` if the planner can stand there, else the nearest traversable cell centre within
    ``max_dist`` (a node or frontier hugging a wall), else None."""
    spec = cm.spec
    rc = spec.to_cell(np.asarray(xy, dtype=np.float64))
    if not spec.inside(rc):
        return None
    if np.isfinite(cm.weights[rc[0], rc[1]]):
        return xy
    k = int(np.ceil(max_dist / spec.resolution))
    r0, c0 = max(int(rc[0]) - k, 0), max(int(rc[1]) - k, 0)
    win = np.isfinite(cm.weights[r0:int(rc[0]) + k + 1, c0:int(rc[1]) + k + 1])
    if not win.any():
        return None
    wr, wc = np.nonzero(win)
    cells = np.stack([wr + r0, wc + c0], axis=1)
    centres = spec.to_world(cells)
    d = np.hypot(centres[:, 0] - xy[0], centres[:, 1] - xy[1])
    i = int(np.argmin(d))
    return (float(centres[i, 0]), float(centres[i, 1])) if d[i] <= max_dist else None


def _start_cell(grid: OccupancyGrid, passable: NDArray[np.bool_], xy: tuple[float, float]) -> tuple[int, int]:
    """The agent's cell, or the nearest passable cell when it stands in the inflation band."""
    rc = grid.spec.to_cell(np.asarray(xy, dtype=np.float64))
    r, c = int(rc[0]), int(rc[1])
    if 0 <= r < passable.shape[0] and 0 <= c < passable.shape[1] and passable[r, c]:
        return r, c
    k = 12
    r0, c0 = max(r - k, 0), max(c - k, 0)
    win = passable[r0:r + k + 1, c0:c + k + 1]
    if not win.any():
        return r, c
    wr, wc = np.nonzero(win)
    i = int(np.argmin((wr + r0 - r) ** 2 + (wc + c0 - c) ** 2))
    return int(wr[i] + r0), int(wc[i] + c0)
