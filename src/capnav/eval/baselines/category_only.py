"""Category-only instance map: the nearest mapped instance whose label is the goal's category.

The same instance map as CapNav (same tracker, same objects) but no captions and no embeddings:
the goal is reduced to its category word (for a description, the first vocabulary word or synonym
it mentions), and the nearest object with that label in the grid distance of eq. 17 is the target.
This is what an instance map without language can do, and the bar captions have to beat.
"""

from __future__ import annotations

import numpy as np

from capnav.eval.method import METHODS, NavMethod
from capnav.eval.methods.base import Decision, PriorMapMethod, object_decision
from capnav.eval.methods.words import category_in_text
from capnav.planning import PlannerConfig


class CategoryOnly(PriorMapMethod):
    name = "category-only"

    def decide(self, goal_text: str, robot_xy: tuple[float, float]) -> Decision | str:
        cmap = self.cmap
        cat = category_in_text(goal_text)
        if cat is None:
            return f"no category word in {goal_text!r}"
        cands = [o for o in cmap.objects if o.label == cat]
        if not cands:
            return f"no {cat} in the map"
        d = np.array([np.hypot(o.position[0] - robot_xy[0], o.position[1] - robot_xy[1]) for o in cands])
        k = int(np.argmin(d))
        return object_decision(cands[k], f"nearest of {len(cands)} mapped {cat} ({d[k]:.1f} m)", cands[k].label)


@METHODS.register("category-only")
def _make(planner: PlannerConfig | None = None, **_: object) -> NavMethod:
    return CategoryOnly(planner)
