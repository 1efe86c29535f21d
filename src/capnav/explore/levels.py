"""The planner's inflation and its relaxations, for a search on its own online map.

Why: a search plans with the robot's radius plus a safety margin. A gap narrower than that (a door
with a chair set down beside it, a passage between a bed and a wall) closes on its costmap although
the robot fits through, so every place beyond it looks unreachable and the search ends in the
first room ("no place left to look from can be reached"), or an approach stops metres short. CapNav's
own execution (``planning.execute``) then relaxes the inflation: the bare radius, then the radius
less half a cell (a cell whose centre is clear may still fit the robot: the grid is coarser than
the geometry). The search does the same, one level at a time and only when the stricter level
leaves nothing within reach; contacts on the way are marked and tell when a level was too bold.
The last level also forgives contact marks on floor the depth has seen free
(``OnlineMap.cells``): a graze of a door post stamps its mark in the doorway, ahead of the robot,
and would close the door for the rest of the search.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from capnav.planning import PlannerConfig


def inflation_levels(cfg: PlannerConfig, resolution: float) -> list[PlannerConfig]:
    """``cfg`` first, then (``cfg.relax``) without the safety margin, then the radius less half a
    cell: the ladder of ``planning.execute``'s levels, strictest first."""
    out = [cfg]
    if not cfg.relax:
        return out
    half = 0.5 * resolution
    if cfg.safety_margin > 0:
        out.append(replace(cfg, safety_margin=0.0))
    if cfg.robot_radius > half:
        out.append(replace(cfg, safety_margin=0.0, robot_radius=cfg.robot_radius - half))
    return out


@dataclass(frozen=True)
class Level:
    """One way to plan: a planner (its inflation) and whether contact marks on seen-free floor count."""

    planner: PlannerConfig
    forgive_contacts: bool = False

    def describe(self) -> str:
        forgiven = ", contact marks on floor seen free forgiven" if self.forgive_contacts else ""
        return f"inflation {self.planner.inflation:.3f} m{forgiven}"


def search_levels(cfg: PlannerConfig, resolution: float) -> list[Level]:
    """``inflation_levels`` strictest first, then the loosest of them with contacts forgiven."""
    levels = [Level(p) for p in inflation_levels(cfg, resolution)]
    if cfg.relax:
        levels.append(Level(levels[-1].planner, True))
    return levels
