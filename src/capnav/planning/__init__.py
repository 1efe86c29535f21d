"""Planning: goal selection near the chosen object, A* on the occupancy map, execution.

``select_goal`` turns an object footprint into a reachable pose within the 1 m reach radius,
``plan_path`` runs A* (8-connected, octile, inflated obstacles) and simplifies the path, and
``navigate_to`` drives a simulator agent along it, replanning around obstacles it bumps into.
"""

from capnav.planning.backends import BACKENDS, path_cost
from capnav.planning.config import PlannerConfig
from capnav.planning.costmap import Costmap, build_costmap
from capnav.planning.execute import NavResult, navigate_to
from capnav.planning.goal import GoalPose, select_goal
from capnav.planning.path import PlannedPath, plan_path

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
