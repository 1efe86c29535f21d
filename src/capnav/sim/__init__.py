"""Simulator: procedural apartments with lookalike furniture, pybullet rendering, agent motion,
navigability truth and a virtual exploration pass. The only place that knows a scene's truth."""

from capnav.sim.agent import Agent
from capnav.sim.config import AgentConfig, CameraConfig, DepthNoiseConfig, LayoutConfig, SimConfig
from capnav.sim.explore import ExploreConfig, explore
from capnav.sim.manifest import SceneManifest
from capnav.sim.simulator import Simulator

__all__ = ["Agent", "AgentConfig", "CameraConfig", "DepthNoiseConfig", "ExploreConfig", "LayoutConfig",
           "SceneManifest", "SimConfig", "Simulator", "explore"]
