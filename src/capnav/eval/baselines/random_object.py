"""Random-object baseline: a uniformly random mapped object, whatever the goal says.

It measures how much of a score is owed to the apartment (few objects, large success radius)
rather than to the method: any method should be well above it.
"""

from __future__ import annotations

import numpy as np

from capnav.eval.method import METHODS, NavMethod, SceneContext
from capnav.eval.methods.base import Decision, PriorMapMethod, object_decision
from capnav.planning import PlannerConfig


class RandomObject(PriorMapMethod):
    name = "random-object"

    def __init__(self, planner: PlannerConfig | None = None) -> None:
        super().__init__(planner)
        self.rng = np.random.default_rng(0)

    def prepare(self, ctx: SceneContext) -> None:
        # seeded per apartment so results do not depend on which worker ran which apartment
        self.rng = np.random.default_rng([ctx.seed, ctx.scene_seed, 7])

    def decide(self, goal_text: str, robot_xy: tuple[float, float]) -> Decision | str:
        objects = self.cmap.objects
        if not objects:
            return "the map has no objects"
        obj = objects[int(self.rng.integers(len(objects)))]
        return object_decision(obj, f"random object {obj.id} of {len(objects)}")


@METHODS.register("random-object")
def _make(planner: PlannerConfig | None = None, **_: object) -> NavMethod:
    return RandomObject(planner)
