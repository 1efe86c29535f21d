"""Planning: goal selection near the chosen object, A* on the occupancy map, execution.

``select_goal`` turns an object footprint into a reachable pose within the 1 m reach radius,
``plan_path`` runs A* (8-connected, octile, inflated obstacles) and simplifies the path, and
``navigate_to`` drives a simulator agent along it, replanning around obstacles it bumps into.

Names are imported on first use (PEP 562): a process that only reads ``PlannerConfig`` (asking a
map without a robot position) does not load numba and scipy for the search and the costmap.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from capnav.core.lazy import lazy_exports

if TYPE_CHECKING:
    from capnav.planning.backends import BACKENDS, path_cost
    from capnav.planning.config import PlannerConfig
    from capnav.planning.costmap import Costmap, build_costmap
    from capnav.planning.execute import NavResult, navigate_to
    from capnav.planning.goal import GoalPose, select_goal
    from capnav.planning.path import PlannedPath, plan_path

#: Public name -> the submodule that defines it.
_SOURCES = {
    **dict.fromkeys(["BACKENDS", "path_cost"], "backends"),
    "PlannerConfig": "config",
    **dict.fromkeys(["Costmap", "build_costmap"], "costmap"),
    **dict.fromkeys(["NavResult", "navigate_to"], "execute"),
    **dict.fromkeys(["GoalPose", "select_goal"], "goal"),
    **dict.fromkeys(["PlannedPath", "plan_path"], "path"),
}

__getattr__, __dir__ = lazy_exports(__name__, _SOURCES)


__all__ = [
    "BACKENDS",
    "Costmap",
    "GoalPose",
    "NavResult",
    "PlannedPath",
    "PlannerConfig",
    "build_costmap",
    "navigate_to",
    "path_cost",
    "plan_path",
    "select_goal",
]
