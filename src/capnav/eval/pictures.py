"""Top-down pictures of failed subgoals (the planning stage's Figure-5-style drawing)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from capnav.core.footprint import footprint_distance
from capnav.eval.metrics import SubgoalRecord


def draw_failure(r: SubgoalRecord, assets: Any, cmap: Any, out_png: Path) -> Path:
    """The prior map's objects (the chosen one highlighted with its 1 m reach), the executed
    trajectory, and an X on the ground-truth instance the agent should have reached."""
    from capnav.viz.topdown import draw_navigation

    truth = assets.truth
    stop = np.asarray(r.stop_xy, dtype=np.float64).reshape(1, 2)
    nearest = min(r.target_ids, key=lambda t: float(footprint_distance(stop, truth.footprints[t])[0]))
    goal_xy = truth.footprints[nearest].mean(axis=0)
    title = (f"{r.method} / {r.protocol} / {r.episode_id} #{r.index}: \"{r.text}\" - "
             f"chose {'map object ' + str(r.chosen_object) if r.chosen_object is not None else 'no object'}; "
             f"true {r.category} (instance {nearest}, X) is {r.distance_to_goal:.2f} m from the stop. {r.reason[:160]}")
    traj = np.asarray(r.trajectory, dtype=np.float64).reshape(-1, 2)
    return draw_navigation(cmap.occupancy, cmap.objects, r.chosen_object, None, traj, r.start_xy, r.stop_xy,
                           title[:400], out_png, goal=(float(goal_xy[0]), float(goal_xy[1])), reach=1.0, dpi=80)
