"""Execution: drive a simulator (or robot) agent along the planned path to the goal.

The agent follows the waypoints with ``move_to`` (straight segments, stops at contact) or, when it
only has discrete actions, with turn / forward steps. A graze at the agent's side is slid off (a
passage may have just the robot's clearance, a few centimetres less on the map); a contact it cannot
slide off means the map missed an obstacle: the cells ahead of the agent are marked blocked, and goal
and path are chosen again from where the agent stands, up to ``max_replans`` times. A contact the
map already holds teaches nothing, so the same plan would come back: the goal cells under the agent
are refused instead, and a goal that was only the closest the map allows ends the drive there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import CapNavError
from capnav.core.footprint import footprint_distance
from capnav.core.grid import OCCUPIED, OccupancyGrid
from capnav.planning.config import PlannerConfig
from capnav.planning.costmap import Costmap, build_costmap, mark_blocked
from capnav.planning.goal import GoalPose, check_footprint, select_goal
from capnav.planning.path import PlannedPath, plan_path
from capnav.planning.sight import HeightColumns


@runtime_checkable
class StepAgent(Protocol):
    """The least an agent offers: a pose ``(x, y, yaw)`` and discrete actions."""

    @property
    def pose(self) -> tuple[float, float, float]: ...

    def step(self, action: str) -> bool: ...


@dataclass
class NavResult:
    """The outcome of one navigation: whether the agent stopped within reach of the (mapped)
    footprint, where, how far it drove, how often it replanned, and why it stopped."""

    reached: bool
    final_pose: tuple[float, float, float]
    path_length: float
    replans: int
    waypoints: NDArray[np.float64]  # (M, 2) of the last plan
    reason: str
    goal: GoalPose | None = None
    distance_to_object: float = float("inf")
    trajectory: NDArray[np.float64] = field(default_factory=lambda: np.empty((0, 2)))  # (T, 2) executed x, y
    plans: list[PlannedPath] = field(default_factory=list)
    events: list[str] = field(default_factory=list)
    recovery: list[str] = field(default_factory=list)  # escapes used: backing out, relaxed inflation

    def to_dict(self) -> dict[str, Any]:
        return {
            "reached": self.reached,
            "final_pose": [round(float(v), 4) for v in self.final_pose],
            "path_length": round(self.path_length, 4),
            "replans": self.replans,
            "distance_to_object": round(self.distance_to_object, 4),
            "reason": self.reason,
            "goal": self.goal.to_dict() if self.goal else None,
            "waypoints": np.round(self.waypoints, 4).tolist(),
            "trajectory": np.round(self.trajectory, 4).tolist(),
            "plans": [p.to_dict() for p in self.plans],
            "events": list(self.events),
            "recovery": list(self.recovery),
        }


def navigate_to(agent: StepAgent, occ: OccupancyGrid, target_footprint: NDArray[np.floating],
                config: PlannerConfig | None = None, costmap: Costmap | None = None, *,
                z_range: tuple[float, float] | None = None, columns: HeightColumns | None = None) -> NavResult:
    """Select a goal near ``target_footprint`` (heights ``z_range``, seen through ``columns`` or the
    costmap's), plan with A*, and drive ``agent`` there.

    Bad input (map, footprint, a start inside an obstacle) raises; failing to get there (goal
    unreachable, too many collisions) returns ``reached=False`` with the reason.
    """
    cfg = config or PlannerConfig()
    fp = check_footprint(target_footprint)
    events: list[str] = []
    radius = _agent_radius(agent)
    if radius is not None and radius > cfg.robot_radius:
        # Planning for a thinner robot than the one driving would graze every wall.
        cfg = replace(cfg, robot_radius=radius)
        events.append(f"robot_radius raised to the agent's {radius:.2f} m")
        columns = columns if columns is not None else (costmap.columns if costmap is not None else None)
        costmap = None
    levels = _Levels(occ, cfg, costmap, columns, z_range)
    log = _Log(agent, cfg.max_steps)
    recovery: list[str] = []  # which escapes were used, in order
    goal: GoalPose | None = None
    plans: list[PlannedPath] = []
    replans = 0
    reason = ""
    first = True
    backed = False
    held = False  # stopped by a contact the map already held
    held_at: set[tuple[int, ...]] = set()  # cells of such contacts
    while True:
        try:
            goal, plan, note = levels.plan(fp, log.xy())
        except CapNavError as e:
            # Boxed in (a pocket, or marks from contacts): back out the way it came, once, and try again.
            if not backed and (moved := _back_out(agent, cfg, log)) > 0:
                backed = True
                recovery.append(f"backed out {moved:.2f} m along the way it came (no plan from where it stood: {e})")
                events.append(recovery[-1])
                continue
            if first:
                raise
            reason = f"replanning failed after {replans} collision(s): {e}"
            break
        if not goal.reached_within_reach and not backed and (moved := _back_out(agent, cfg, log)) > 0:
            backed = True
            recovery.append(f"backed out {moved:.2f} m along the way it came (nothing within reach from where it "
                            "stood)")
            events.append(recovery[-1])
            continue
        if note:
            recovery.append(note)
        first = False
        plans.append(plan)
        events.extend([*plan.notes, *([note] if note else [])])
        slides: list[float] = []
        contact = _follow(agent, plan.waypoints, cfg, log, slides)
        if slides:
            recovery.append(f"slid {sum(slides):.2f} m off {len(slides)} graze(s) instead of marking them")
            events.append(recovery[-1])
        if contact is None:
            _face(agent, goal.yaw, log)
            reason = goal.reason
            break
        blocked_at = contact[0]
        here = np.asarray(log.xy()).reshape(1, 2)
        if footprint_distance(here, fp)[0] <= cfg.reach - cfg.goal_margin:
            _face(agent, goal.yaw, log)
            reason = "stopped within reach after a contact (the map missed an obstacle near the object)"
            events.append(f"contact near ({blocked_at[0]:.2f}, {blocked_at[1]:.2f}) within reach; stopping")
            break
        n = levels.mark(blocked_at, log.xy())
        if n == 0:  # felt where the map has it already: what stopped the way ahead is not drawn there
            n = levels.mark(blocked_at := contact[1], log.xy())
        at = f"contact near ({blocked_at[0]:.2f}, {blocked_at[1]:.2f})"
        if n == 0:
            # Nothing new to block: the same plan would come back. Near its goal the agent stands as
            # close to it as the world lets it: a goal that was only the closest the map allows ends
            # the drive there, another is refused. Farther off, the way is blocked where the map
            # already has the obstacle (the agent stands in its margin): back out the way it came,
            # and stop when the same contact comes back.
            short = float(np.linalg.norm(goal.xy - here[0]))
            cell = tuple(int(v) for v in occ.spec.to_cell(blocked_at))
            near_goal = short <= cfg.robot_radius + cfg.slide_tolerance
            if near_goal and not goal.reached_within_reach:
                _face(agent, goal.yaw, log)
                held = True
                reason = (f"stopped {short:.2f} m short of the goal against an obstacle the map already holds "
                          f"(a replan would learn nothing): {goal.reason}")
                events.append(f"{at} already on the map; stopping as close as it gets")
                break
            if cell in held_at:
                held = True
                reason = (f"stopped {short:.2f} m short of the goal: the same contact again at ({blocked_at[0]:.2f}, "
                          f"{blocked_at[1]:.2f}), which the map already holds (the way is narrower than the map "
                          f"shows): {goal.reason}")
                events.append(f"{at} already on the map, again; stopping")
                break
            held_at.add(cell)
            replans += 1
            if near_goal:
                levels.refuse(here[0])
                events.append(f"{at} already on the map ({short:.2f} m short of the goal); goals where it stands "
                              "refused; replanning")
            else:
                moved = _back_out(agent, cfg, log)
                recovery.append(f"backed out {moved:.2f} m along the way it came (a contact the map already held)")
                events.append(f"{at} already on the map; {recovery[-1]}; replanning")
        else:
            replans += 1
            events.append(f"{at}; {n} cells blocked; replanning")
        if replans > cfg.max_replans:
            reason = f"gave up after {cfg.max_replans} replans (the map keeps disagreeing with the world)"
            break
    pose = tuple(float(v) for v in agent.pose)
    dist = float(footprint_distance(np.asarray(pose[:2]).reshape(1, 2), fp)[0])
    reached = dist <= cfg.reach
    if not reached and (held or reason == (goal.reason if goal else "")):
        reason = f"stopped {dist:.2f} m from the object (reach {cfg.reach:.2f} m): {reason}"
    return NavResult(reached, (pose[0], pose[1], pose[2]), log.length, replans,
                     plans[-1].waypoints if plans else np.empty((0, 2)), reason, goal, dist, log.array(), plans,
                     events, recovery)


class _Levels:
    """The costmaps of the configured inflation and of its relaxations, sharing contact marks.

    Level 0 is the config. When it leaves the object out of reach (a gap narrower than the robot
    plus margin, or the start boxed in by the inflation), ``config.relax`` allows two more: the
    bare robot radius, then the radius less half a cell (a grid cell whose centre is clear may
    still fit the robot: the grid is coarser than the geometry). Contacts will tell if not. A
    level under the true radius may drive through such cells but stops only where the robot's
    disk fits between the obstacle cells' centres. Goal cells the agent could not get to
    (``refuse``) are no goal on any level.
    """

    def __init__(self, occ: OccupancyGrid, cfg: PlannerConfig, costmap: Costmap | None,
                 columns: HeightColumns | None = None, z_range: tuple[float, float] | None = None) -> None:
        self.z_range = z_range
        self.radius = cfg.robot_radius
        self.cfgs = [cfg]
        if cfg.relax:
            half = 0.5 * occ.spec.resolution
            if cfg.safety_margin > 0:
                self.cfgs.append(replace(cfg, safety_margin=0.0))
            if cfg.robot_radius > half:
                self.cfgs.append(replace(cfg, safety_margin=0.0, robot_radius=cfg.robot_radius - half))
        base = build_costmap(occ, cfg, columns) if costmap is None else costmap
        self.columns = columns if columns is not None else base.columns
        # Private copies: contact marks must not leak into the caller's map (the room regions may
        # be shared: a contact mark does not move a wall).
        self.maps = {0: Costmap(OccupancyGrid(base.spec, base.occ.cells.copy()), base.weights.copy(), self.columns,
                                dict(base.cache))}
        self.refused = np.zeros(base.weights.shape, dtype=bool)

    def refuse(self, xy: NDArray[np.float64]) -> None:
        """No goal within the robot's radius (and half a cell) of ``xy`` from now on."""
        spec = self.maps[0].spec
        rr, cc = np.indices(self.refused.shape)
        rc = spec.to_cell(np.asarray(xy, dtype=np.float64))
        self.refused |= np.hypot(rr - rc[0], cc - rc[1]) * spec.resolution <= self.radius + 0.5 * spec.resolution

    def _allowed(self, i: int) -> NDArray[np.bool_]:
        """Cells that may be goals on level ``i``: not refused, and under the true radius, where the
        robot's disk fits between the obstacle cells' centres."""
        if self.cfgs[i].robot_radius >= self.radius - 1e-9:
            return ~self.refused
        from scipy import ndimage

        cm = self.maps[i]
        clear = ndimage.distance_transform_edt(cm.occ.cells != OCCUPIED) * cm.spec.resolution
        return ~self.refused & (clear >= self.radius - 1e-6)

    def _map(self, i: int) -> Costmap:
        if i not in self.maps:  # built lazily from level 0's grid, so it carries the marks so far
            self.maps[i] = build_costmap(self.maps[0].occ, self.cfgs[i], self.columns)
            self.maps[i].cache.update(self.maps[0].cache)
        return self.maps[i]

    def plan(self, fp: NDArray[np.float64], here: tuple[float, float]) -> tuple[GoalPose, PlannedPath, str]:
        """Goal and path at the strictest level that gets within reach, else the fallback goal
        closest to the object over the levels (the strictest of equals)."""
        fallback: tuple[GoalPose, PlannedPath, str] | None = None
        error: CapNavError | None = None
        for i, cfg in enumerate(self.cfgs):
            cm = self._map(i)
            try:
                goal = select_goal(cm.occ, fp, here, cfg, cm, z_range=self.z_range, allowed=self._allowed(i))
                plan = plan_path(cm.occ, here, goal.xy, cfg, cm)
            except CapNavError as e:
                error = error or e
                continue
            what = ("the robot's true radius" if abs(cfg.inflation - self.radius) < 1e-9 else
                    "half a cell under the true radius: a cell whose centre is clear may fit")
            note = "" if i == 0 else (f"relaxed inflation to {cfg.inflation:.3f} m ({what}): nothing within reach "
                                      f"at {self.cfgs[0].inflation:.3f} m")
            if goal.reached_within_reach:
                return goal, plan, note
            if fallback is None or goal.distance_to_object < fallback[0].distance_to_object - 1e-9:
                fallback = (goal, plan, note)
        if fallback is not None:
            return fallback
        assert error is not None
        raise error

    def mark(self, xy: NDArray[np.float64], robot_xy: tuple[float, float]) -> int:
        """Block a contact on every level, grown by the full robot radius + margin even on relaxed
        levels (a contact is proof the relaxation was too optimistic there); the number of cells
        newly blocked on any level (0: the map held the contact already)."""
        radius = self.cfgs[0].blocked_mark_radius
        return max(mark_blocked(cm, xy, radius, self.cfgs[0], np.asarray(robot_xy)) for cm in self.maps.values())


class _Log:
    """The executed trajectory and its length, recorded from the agent's pose after every motion."""

    def __init__(self, agent: StepAgent, max_steps: int) -> None:
        self.agent = agent
        self.budget = [max_steps]  # discrete actions left (shared by driving and turning)
        self.points: list[tuple[float, float]] = [self.xy()]
        self.length = 0.0

    def xy(self) -> tuple[float, float]:
        p = self.agent.pose
        return float(p[0]), float(p[1])

    def record(self, trace: list[tuple[float, float]] | None = None) -> None:
        for q in [*(trace or []), self.xy()]:
            last = self.points[-1]
            d = math.hypot(q[0] - last[0], q[1] - last[1])
            if d > 1e-9:
                self.points.append(q)
                self.length += d

    def array(self) -> NDArray[np.float64]:
        return np.asarray(self.points, dtype=np.float64)


def _follow(agent: StepAgent, waypoints: NDArray[np.float64], cfg: PlannerConfig, log: _Log,
            slides: list[float] | None = None) -> NDArray[np.float64] | None:
    """Drive through the waypoints; when blocked, return (2, 2): where the contact is (felt around)
    and the point just beyond the agent's rim on the way it was going.

    An agent with ``move_to`` slides off a graze (:func:`_slide`); how far each slide moved it is
    appended to ``slides``."""
    move_to = getattr(agent, "move_to", None)
    for wp in waypoints[1:]:
        if move_to is None:
            if not _drive_discrete(agent, wp, cfg, log):
                return np.stack([_contact_point(agent, wp, cfg, log), _ahead(log, wp, cfg)])
            continue
        shift = np.zeros(2)  # how far slides moved this leg sideways: drive on parallel to it
        for tries in range(cfg.max_slides + 1):
            aim = wp + shift
            before = len(_trajectory(agent))
            ok = bool(move_to(float(aim[0]), float(aim[1])))
            log.record(_trajectory(agent)[before:])
            if ok:
                break
            here = np.asarray(log.xy())
            normal = _probe(agent, aim, cfg, log)
            if float(np.linalg.norm(aim - here)) <= cfg.slide_tolerance:
                break  # as close to this waypoint as the world lets it: on to the next
            step = np.zeros(2) if tries == cfg.max_slides else _slide(agent, aim, normal, cfg, log)
            if float(np.linalg.norm(step)) <= 1e-3 or float(np.linalg.norm(shift + step)) > cfg.robot_radius:
                return np.stack([np.asarray(log.xy()) + normal * (cfg.robot_radius + cfg.blocked_mark_radius),
                                 _ahead(log, aim, cfg)])
            shift += step
            if slides is not None:
                slides.append(float(np.linalg.norm(step)))
    return None


def _slide(agent: StepAgent, target: NDArray[np.float64], normal: NDArray[np.float64], cfg: PlannerConfig,
           log: _Log) -> NDArray[np.float64]:
    """Step up to ``slide_step`` away from a contact, sideways to the way to ``target``, as a bumper
    robot slides off what it grazed; stopped by something on the other side, to the middle of the
    room between the two. Returns the displacement (zero for a contact head-on: nothing to slide
    along)."""
    here = np.asarray(log.xy())
    d = np.asarray(target, dtype=np.float64) - here
    d /= max(float(np.linalg.norm(d)), 1e-9)
    side = -(normal - float(normal @ d) * d)
    if float(np.linalg.norm(side)) < 0.3 or cfg.slide_step <= 0:  # within ~17 degrees of head-on
        return np.zeros(2)
    side /= float(np.linalg.norm(side))
    p = here + side * cfg.slide_step
    before = len(_trajectory(agent))
    move_to = agent.move_to  # type: ignore[attr-defined]
    if not move_to(float(p[0]), float(p[1])):
        mid = (here + np.asarray(agent.pose[:2], dtype=np.float64)) / 2
        move_to(float(mid[0]), float(mid[1]))
    log.record(_trajectory(agent)[before:])
    return np.asarray(log.xy()) - here


#: How far the executor backs out along the way it came when boxed in (m).
BACK_OUT_M = 0.5


def _back_out(agent: StepAgent, cfg: PlannerConfig, log: _Log, distance: float = BACK_OUT_M) -> float:
    """Drive back along the agent's own trajectory (the way it came, known to be passable) for up
    to ``distance`` metres; returns how far it got (0 with no trajectory to retrace)."""
    traj = _trajectory(agent)
    if len(traj) < 2:
        return 0.0
    here = np.asarray(traj[-1], dtype=np.float64)
    # Only the points that take it farther from here: the bumper's probes went out and back.
    back: list[NDArray[np.float64]] = []
    far = 0.0
    for p in reversed(traj[:-1]):
        q = np.asarray(p, dtype=np.float64)
        d = float(np.linalg.norm(q - here))
        if d <= far + 1e-6:
            continue
        if d >= distance:  # stop part-way along this segment
            last = back[-1] if back else here
            back.append(last + (q - last) * ((distance - far) / (d - far)))
            break
        back.append(q)
        far = d
    if not back:
        return 0.0
    start = np.asarray(log.xy(), dtype=np.float64)
    _follow(agent, np.vstack([start, *back]), cfg, log)
    return float(np.linalg.norm(np.asarray(log.xy()) - start))


def _trajectory(agent: object) -> list[tuple[float, float]]:
    traj = getattr(agent, "trajectory", None)
    if traj is None:
        return []
    return [(float(p[0]), float(p[1])) for p in traj]


def _ahead(log: _Log, target: NDArray[np.float64], cfg: PlannerConfig) -> NDArray[np.float64]:
    here = np.asarray(log.xy())
    d = np.asarray(target, dtype=np.float64) - here
    n = float(np.linalg.norm(d))
    if n < 1e-9:
        return here
    return here + d / n * (cfg.robot_radius + cfg.blocked_mark_radius)


def _contact_point(agent: StepAgent, target: NDArray[np.float64], cfg: PlannerConfig, log: _Log
                   ) -> NDArray[np.float64]:
    """Where the unseen obstacle is: just beyond the agent's rim, in the direction of contact."""
    x, y, _ = (float(v) for v in agent.pose)
    return np.array([x, y]) + _probe(agent, target, cfg, log) * (cfg.robot_radius + cfg.blocked_mark_radius)


def _probe(agent: StepAgent, target: NDArray[np.float64], cfg: PlannerConfig, log: _Log) -> NDArray[np.float64]:
    """The unit direction from the agent to what stopped it.

    The direction of travel is a poor guess when the agent grazed something at its side (it would
    seal a corridor the agent can pass), so an agent with ``move_to`` feels around like a bumper:
    tiny moves in 8 directions, each undone. Each blocked one points at an obstacle, weighted by
    how little of the move it got (in a passage with less slack than the probe both walls block,
    the one it touches the most).
    """
    x, y, yaw = (float(v) for v in agent.pose)
    d = np.asarray(target, dtype=np.float64) - (x, y)
    n = float(np.hypot(*d))
    u = d / n if n > 1e-6 else np.array([math.cos(yaw), math.sin(yaw)])
    move_to = getattr(agent, "move_to", None)
    if move_to is not None and cfg.probe_step > 0:
        pushes = []
        for a in np.linspace(0.0, 2 * np.pi, 8, endpoint=False):
            v = np.array([math.cos(a), math.sin(a)])
            if not move_to(x + cfg.probe_step * v[0], y + cfg.probe_step * v[1]):
                got = math.hypot(agent.pose[0] - x, agent.pose[1] - y)
                pushes.append(v * (1.0 - min(got / cfg.probe_step, 1.0)))
            if math.hypot(agent.pose[0] - x, agent.pose[1] - y) > 1e-9:
                move_to(x, y)
        log.record()
        if pushes:
            m = np.sum(pushes, axis=0)
            if float(np.hypot(*m)) > 1e-6:
                u = m / float(np.hypot(*m))
    return np.asarray(u, dtype=np.float64)


def _agent_radius(agent: object) -> float | None:
    ac = getattr(agent, "cfg", None) or getattr(agent, "config", None)
    r = getattr(ac, "radius", None)
    return float(r) if isinstance(r, (int, float)) else None


def _motion(agent: object) -> tuple[float, float]:
    """The agent's forward step (m) and turn angle (rad), from its config when it has one."""
    ac = getattr(agent, "cfg", None) or getattr(agent, "config", None)
    step = float(getattr(ac, "forward_step", 0.25))
    turn = math.radians(float(getattr(ac, "turn_deg", 30.0)))
    return step, turn


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


def _turn_towards(agent: StepAgent, yaw: float, turn: float, log: _Log, budget: list[int]) -> None:
    while budget[0] > 0:
        err = _wrap(yaw - float(agent.pose[2]))
        if abs(err) <= turn / 2:
            return
        agent.step("turn_left" if err > 0 else "turn_right")
        budget[0] -= 1
        log.record()


def _drive_discrete(agent: StepAgent, target: NDArray[np.float64], cfg: PlannerConfig, log: _Log) -> bool:
    step, turn = _motion(agent)
    budget = log.budget
    while budget[0] > 0:
        x, y, _ = agent.pose
        dx, dy = float(target[0]) - x, float(target[1]) - y
        dist = math.hypot(dx, dy)
        if dist <= step / 2:
            return True
        _turn_towards(agent, math.atan2(dy, dx), turn, log, budget)
        ok = agent.step("move_forward")
        budget[0] -= 1
        log.record()
        if not ok:
            return False
    return True


def _face(agent: StepAgent, yaw: float, log: _Log) -> None:
    """Turn in place to face the object when the agent has turn actions."""
    if callable(getattr(agent, "step", None)):
        _, turn = _motion(agent)
        _turn_towards(agent, yaw, turn, log, [math.ceil(math.pi / turn) + 1])
