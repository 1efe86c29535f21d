"""An object's label, checked against its size: the detector's leading label unless the object's
footprint rules it out and a runner-up label it also voted for does not.

Issue 21: a real COCO detector scores a dining table low in every frame while the chairs around
it score high, and their boxes hold pieces of the top; the object mapped there then carries
"chair" (CenterNet on a simulated kitchen at 640x480: chair 0.68, table 0.13 over a 1.6 x 1.9 m
top). No chair is 1.4 m long, and the same sightings also said table: that label is the one
the object's size allows. Only labels with a footprint prior (``corroborate.PRIORS``: tables,
coffee tables and chairs, from furniture standards) take part: the leading one is ruled out only
by a clear margin (``slack``), and a runner-up that holds ``min_share`` of the votes takes its
place only when its own prior fits. A runner-up without a prior is no evidence from size: a new
chair fused with a stool beside it (1.7 m) would become a "stool" (change track seed 100, scene
100002), so a sofa seen as a 2 m "chair" stays a chair. Reading the points only, never the
scene's truth."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from capnav.mapping.corroborate import PRIORS, sides


@dataclass(frozen=True)
class LabelFitConfig:
    """``slack``: the footprint's long side must exceed the prior's ``long_hi`` by this factor (or
    its short side fall below ``short_lo`` divided by it) to rule a label out; ``min_share``: the
    runner-up's part of all votes; ``min_points`` below which the size says nothing."""

    enabled: bool = True
    slack: float = 1.5
    min_share: float = 0.1
    min_points: int = 60


def ruled_out(label: str, short: float, long: float, cfg: LabelFitConfig) -> bool:
    """Whether a footprint of ``short`` x ``long`` m is clearly too large or too thin for ``label``."""
    prior = PRIORS.get(label)
    if prior is None:
        return False
    return long > prior.long_hi * cfg.slack or short < prior.short_lo / cfg.slack


def fitting_label(votes: Mapping[str, float], points: NDArray[np.floating],
                  cfg: LabelFitConfig = LabelFitConfig()) -> tuple[str | None, str]:
    """(label, why): the runner-up label the object's size allows when it rules out the leading
    one, else (None, reason kept). ``points``: the object's world points (z up)."""
    if not cfg.enabled or len(votes) < 2 or len(points) < cfg.min_points:
        return None, ""
    ranked = sorted(votes.items(), key=lambda kv: (-kv[1], kv[0]))
    lead = ranked[0][0]
    short, long = sides(np.asarray(points, dtype=np.float64)[:, :2])
    if not ruled_out(lead, short, long, cfg):
        return None, ""
    total = sum(max(v, 0.0) for _, v in ranked)
    for label, v in ranked[1:]:
        if total > 0 and v / total >= cfg.min_share and label in PRIORS and not ruled_out(label, short, long, cfg):
            return label, (f"a {lead} is never {long:.2f} x {short:.2f} m; its sightings also said "
                           f"{label} ({v / total:.0%} of the votes), which that size allows")
    return None, ""
