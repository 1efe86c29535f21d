"""The product pipeline: a simulated apartment explored, mapped, captioned and embedded, the one
way the demo, the library face and the benchmark all make a map of a generated apartment. It
drives the simulator (the world) but never reads its scene truth; judging against the truth is
``capnav.eval``'s job."""

from capnav.pipeline.simulated import MAP_FILE, FrameList, PipelineConfig, SimScene, build_scene_map, open_sim_scene

__all__ = ["MAP_FILE", "FrameList", "PipelineConfig", "SimScene", "build_scene_map", "open_sim_scene"]
