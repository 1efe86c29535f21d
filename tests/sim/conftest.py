"""Shared small simulators: 3-room apartments rendered at 160x120 keep the suite fast."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from capnav.sim import CameraConfig, LayoutConfig, SimConfig, Simulator

SMALL = SimConfig(layout=LayoutConfig(rooms=3), camera=CameraConfig(width=160, height=120))


@pytest.fixture(scope="session")
def small_config() -> SimConfig:
    return SMALL


@pytest.fixture(scope="session")
def small_sim() -> Iterator[Simulator]:
    sim = Simulator.from_seed(7, SMALL)
    yield sim
    sim.close()
