"""Shared by the import tests: simulator views to write into recordings and read back."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
import pytest

from capnav.core.frame import Frame
from capnav.core.geometry import look_at_pose
from capnav.sim import CameraConfig, LayoutConfig, SimConfig, Simulator

SIM_CFG = SimConfig(layout=LayoutConfig(rooms=3), camera=CameraConfig(width=160, height=120))


@pytest.fixture(scope="session")
def render_views() -> Callable[[int, Sequence[float]], list[Frame]]:
    """``render(seed, pitches_deg)``: one view per pitch, from a seeded random navigable spot and
    heading of apartment 0 (3 rooms, 160x120), camera 1.25 m up looking down by that pitch."""

    def render(seed: int, pitches_deg: Sequence[float]) -> list[Frame]:
        sim = Simulator.from_seed(0, SIM_CFG)
        try:
            rng = np.random.default_rng(seed)
            out = []
            for i, pitch in enumerate(pitches_deg):
                x, y = sim.random_navigable_point(rng)
                yaw = float(rng.uniform(-math.pi, math.pi))
                out.append(sim.render(look_at_pose(np.array([x, y, 1.25]), yaw, math.radians(pitch)), index=i))
            return out
        finally:
            sim.close()

    return render


@pytest.fixture(scope="session")
def wall_views() -> Callable[[float], list[Frame]]:
    """``walls(dx)``: five views of apartment 0 (160x120) looking level (pitch 0) at the same wall,
    the camera 1.25 m up and sliding sideways 0.8 m along it; ``dx = 0`` stands 2.3 m from the wall
    (the floor is a strip at the bottom, a few percent of the pixels), ``dx = 1.2`` stands 1.1 m
    from it (no floor in view)."""

    def render(dx: float) -> list[Frame]:
        sim = Simulator.from_seed(0, SIM_CFG)
        try:
            return [sim.render(look_at_pose(np.array([2.675 + dx, 5.325 + s, 1.25]), 0.0, 0.0), index=i)
                    for i, s in enumerate(np.linspace(-0.4, 0.4, 5))]
        finally:
            sim.close()

    return render
