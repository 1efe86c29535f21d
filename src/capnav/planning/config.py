"""Planner settings in one place, with the values used by the paper's evaluation as defaults."""

from __future__ import annotations

from dataclasses import dataclass

from capnav.core.errors import InputError


@dataclass(frozen=True)
class PlannerConfig:
    """How goals are chosen, how A* weighs the map and how the agent executes a path.

    ``reach`` is the paper's 1 m success radius around the goal instance. Goal selection aims a
    little inside it (``goal_margin``) so a slightly wrong mapped footprint still counts as reached,
    and (``prefer_line_of_sight``, the goal rule of planning/goal.py) at a cell of seen free floor in
    the object's room that sees it from ``eye_height`` when one within reach does.
    """

    robot_radius: float = 0.2  # m, the agent's base radius (the simulator agent's default)
    safety_margin: float = 0.05  # m, added to the radius when obstacles are inflated
    reach: float = 1.0  # m, success radius around the object's footprint
    goal_margin: float = 0.3  # m, aim at cells within reach - goal_margin when possible
    # Among cells within reach, prefer those that see the object on the map (planning/sight.py);
    # False keeps the paper's rule: the nearest cell within reach, wall or no wall.
    prefer_line_of_sight: bool = True
    # The robot's eye (camera) above the floor, for 3D lines of sight (the simulator agent's camera).
    eye_height: float = 1.25
    # Weight of an unknown cell (None = blocked). 5 from a sweep with benchmarks/eval_reach.py on sparse
    # (20-frame, noisy-depth) maps: blocked 82.8%, 1.5 98.1%, 3 98.9%, 5 100%, 10 100% reached.
    unknown_cost: float | None = 5.0
    clearance_band: float = 0.25  # m beyond the inflation where cells cost extra (keeps off walls)
    clearance_cost: float = 1.0  # extra weight at the inflation edge, fading to 0 across the band
    backend: str = "numba"  # grid search backend (see capnav.planning.backends.BACKENDS)
    simplify: bool = True  # line-of-sight simplification of the cell path into waypoints
    escape_radius: float = 0.5  # m, a start inside the inflation band snaps to a free cell this close
    relax: bool = True  # out of reach? retry with the bare radius, then the radius less half a cell
    max_replans: int = 20  # collisions tolerated during execution before giving up
    probe_step: float = 0.03  # m, bumper probe after a contact (0 = assume the obstacle is ahead)
    blocked_mark_radius: float = 0.08  # m, obstacle disk stamped ahead of the agent on a collision
    # A graze is slid off like a bumper robot does: step this far away from the contact, sideways to
    # the way it drives, and drive on; at most ``max_slides`` times per waypoint while each gets closer
    # (0 = mark every contact). A waypoint the world keeps the agent ``slide_tolerance`` from is passed.
    slide_step: float = 0.03  # m
    max_slides: int = 8
    slide_tolerance: float = 0.05  # m
    max_steps: int = 2000  # discrete-action budget when the agent has no move_to

    def __post_init__(self) -> None:
        for name in ("robot_radius", "safety_margin", "goal_margin", "escape_radius", "blocked_mark_radius",
                     "clearance_band", "clearance_cost", "probe_step", "eye_height", "slide_step",
                     "slide_tolerance"):
            v = getattr(self, name)
            if not v >= 0.0:
                raise InputError(f"PlannerConfig.{name} must be >= 0, got {v}")
        if not self.reach > 0.0:
            raise InputError(f"PlannerConfig.reach must be > 0, got {self.reach}")
        if self.unknown_cost is not None and not self.unknown_cost >= 1.0:
            raise InputError(f"PlannerConfig.unknown_cost must be >= 1 or None (blocked), got {self.unknown_cost}")
        if self.max_replans < 0 or self.max_steps < 1 or self.max_slides < 0:
            raise InputError("PlannerConfig.max_replans and max_slides must be >= 0 and max_steps >= 1")

    @property
    def inflation(self) -> float:
        """Distance (m) by which obstacles are grown before planning."""
        return self.robot_radius + self.safety_margin
