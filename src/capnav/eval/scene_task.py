"""Evaluate every method on every episode of ONE apartment (the unit of parallel work).

A task opens the apartment, builds or loads its prior map (once, shared by all map-based methods),
generates or takes its episodes, runs each method through each episode with the same start poses,
writes the per-episode logs and a few failure pictures, and returns JSON-able results. Tasks are
independent and deterministic, so a run's numbers do not depend on how tasks were scheduled.
"""

from __future__ import annotations

import hashlib
import json
import subprocess
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from capnav.core.atomic import write_json
from capnav.core.errors import InputError
from capnav.core.limits import check_count, check_seed
from capnav.eval.episode_runner import run_episode
from capnav.eval.episodes import GENERATED_PROTOCOLS, PROTOCOLS, Episode, check_against_manifest
from capnav.eval.generate import EpisodeConfig, description_episodes, label_episodes
from capnav.eval.method import SceneContext, create_method
from capnav.eval.metrics import SubgoalRecord
from capnav.eval.pipeline import SceneAssets, open_scene
from capnav.pipeline import PipelineConfig

RESULT_FILE = "result.json"

#: Every method of the benchmark, in report order (exploration baselines join when registered).
DEFAULT_METHODS: tuple[str, ...] = ("random-object", "category-only", "vlmaps", "capnav-no-verify",
                                    "capnav-no-heuristic", "capnav")


@dataclass(frozen=True)
class EvalConfig:
    """Everything that defines a benchmark run (the paper's setup as defaults)."""

    scenes: int = 10
    episodes_per_scene: int = 9
    seed: int = 0
    methods: tuple[str, ...] = DEFAULT_METHODS
    protocols: tuple[str, ...] = GENERATED_PROTOCOLS
    subgoals: int = 4
    pipeline: PipelineConfig = field(default_factory=PipelineConfig)
    # Motion budget per subgoal for step-driven (exploring) methods: Habitat's ObjectNav allows 500
    # actions in Matterport houses of a few hundred m²; these apartments are 40-110 m², and 200
    # actions (50 m of forward motion at 0.25 m a step) cross one several times.
    max_steps: int = 200
    pictures_per_scene: int = 1  # failure pictures per (method, protocol) and apartment
    method_options: dict[str, dict[str, Any]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("scenes", "episodes_per_scene", "subgoals", "max_steps"):
            check_count(name, getattr(self, name))
        check_count("max_frames", self.pipeline.max_frames, optional=True)
        check_seed("seed", self.seed)
        if self.pictures_per_scene < 0:
            raise InputError(f"pictures_per_scene must be >= 0, got {self.pictures_per_scene}")

    def scene_seeds(self) -> list[int]:
        """Apartment seeds of this run: ``1000 * seed + i`` (seed 0: apartments 0..9)."""
        return [1000 * self.seed + i for i in range(self.scenes)]

    def episode_config(self) -> EpisodeConfig:
        return EpisodeConfig(episodes_per_scene=self.episodes_per_scene, subgoals=self.subgoals)


@dataclass(frozen=True)
class SceneTask:
    config: EvalConfig
    scene_seed: int
    out: str  # run folder
    episodes: dict[str, list[dict[str, Any]]] | None = None  # protocol -> episodes given by the user
    progress: bool = False


def generate_scene_episodes(assets: SceneAssets, config: EvalConfig, protocol: str) -> list[Episode]:
    """The seeded episodes of one apartment and protocol."""
    rng = np.random.default_rng([config.seed, assets.scene_seed, PROTOCOLS.index(protocol)])
    if protocol == "label":
        return label_episodes(assets.truth, rng, config.episode_config())
    from capnav.sim.instructions import InstructionGenerator

    truth = assets.truth
    describe = InstructionGenerator(assets.sim.manifest, walk=lambda xy, o: truth.field([o.id]).at(xy)).describe
    return description_episodes(assets.truth, describe, rng, config.episode_config())


def task_key(task: SceneTask, manifest_json: str = "") -> str:
    """Identity of a task's results: settings, apartment (its manifest) and given episodes."""
    blob = json.dumps({"config": asdict(task.config), "scene": task.scene_seed, "episodes": task.episodes,
                       "manifest": hashlib.sha256(manifest_json.encode()).hexdigest()}, sort_keys=True, default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def run_scene(task: SceneTask) -> dict[str, Any]:
    """Run one apartment; returns {"scene_seed", "episodes", "records", "timings", "failures", "map",
    "commit"} (and "resumed": True when an earlier sitting's result was reused).

    The result is saved in the run folder as soon as the apartment is done; a rerun of the same
    task (same settings, same apartment) returns it instead of recomputing, so an interrupted run
    resumes."""
    cfg = task.config
    out = Path(task.out)
    folder = out / "scenes" / str(task.scene_seed)
    assets = open_scene(task.scene_seed, cfg.seed, cfg.pipeline, folder)
    try:
        key = task_key(task, assets.sim.manifest.model_dump_json())
        saved = folder / RESULT_FILE
        if saved.is_file():
            try:
                old = json.loads(saved.read_text())
                if old.get("task_key") == key:
                    return {**old, "resumed": True}
            except (OSError, json.JSONDecodeError):
                pass  # unreadable: recompute
        res = _run(task, cfg, out, assets)
    finally:
        assets.sim.close()
    res["task_key"] = key
    res["commit"] = version_and_commit()[1]  # the code that computed this apartment
    write_json(saved, res)
    return res


def version_and_commit() -> tuple[str, str]:
    """(installed capnav version, short git commit of the source tree or "unknown")."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        v = version("capnav")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        v = "unknown"
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                                cwd=Path(__file__).parent, timeout=5).stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        commit = "unknown"
    return v, commit


def _run(task: SceneTask, cfg: EvalConfig, out: Path, assets: SceneAssets) -> dict[str, Any]:
    timings = assets.timings
    t0 = time.perf_counter()
    episodes: dict[str, list[Episode]] = {}
    for protocol in cfg.protocols:
        given = (task.episodes or {}).get(protocol)
        if given is not None:
            from capnav.eval.phrasings import fill_start

            rng = np.random.default_rng([cfg.seed, assets.scene_seed, PROTOCOLS.index(protocol)])
            episodes[protocol] = [fill_start(Episode.model_validate(e), assets.truth, rng, cfg.episode_config())
                                  for e in given]
            check_against_manifest(episodes[protocol], assets.sim.manifest)
        else:
            episodes[protocol] = generate_scene_episodes(assets, cfg, protocol)
    timings["episodes"] = time.perf_counter() - t0

    methods = [create_method(m, **cfg.method_options.get(m, {})) for m in cfg.methods]
    cmap = assets.prior_map() if any(m.uses_prior_map for m in methods) else None
    ctx = SceneContext(scene_seed=assets.scene_seed, seed=cfg.seed, sim=assets.sim, embedder=assets.embedder,
                       detector=assets.detector, prior_map=cmap, occupancy=cmap.occupancy if cmap else None,
                       frames=LazyStream(assets), workdir=assets.folder, max_steps=cfg.max_steps)
    records: list[SubgoalRecord] = []
    failures: list[dict[str, Any]] = []
    for method in methods:
        t_m = time.perf_counter()
        for protocol in cfg.protocols:
            pictures = 0
            for ep in episodes[protocol]:
                recs = run_episode(method, ctx, ep, assets.truth, protocol)
                records.extend(recs)
                write_json(out / "logs" / method.name / protocol / f"{ep.id}.json",
                           {"episode": ep.model_dump(), "subgoals": [r.to_dict() for r in recs]})
                for r in recs:
                    if not r.success and pictures < cfg.pictures_per_scene:
                        pictures += 1
                        failures.append(_failure(r, assets, cmap, out))
        timings[f"method:{method.name}"] = time.perf_counter() - t_m
    return {
        "scene_seed": assets.scene_seed,
        "episodes": {p: [e.model_dump() for e in eps] for p, eps in episodes.items()},
        "records": [r.to_dict() for r in records],
        "timings": timings,
        "failures": failures,
        "map": None if cmap is None else {"objects": len(cmap.objects), "instances": len(assets.truth.categories),
                                          "frames": cmap.meta.get("frames_used")},
    }


class LazyStream:
    """The exploration stream for methods that read frames, regenerated only if one asks."""

    def __init__(self, assets: SceneAssets) -> None:
        self._assets = assets

    def __len__(self) -> int:
        return len(self._assets.stream())

    def frame(self, index: int) -> Any:
        return self._assets.stream().frame(index)

    def __iter__(self) -> Any:
        return iter(self._assets.stream())


def _failure(r: SubgoalRecord, assets: SceneAssets, cmap: Any, out: Path) -> dict[str, Any]:
    """A failure case for the report, with a top-down picture when the map exists."""
    item: dict[str, Any] = {"method": r.method, "protocol": r.protocol, "episode_id": r.episode_id, "index": r.index,
                            "text": r.text, "reason": r.reason, "distance_to_goal": r.distance_to_goal,
                            "picture": ""}
    if cmap is None:
        return item
    from capnav.eval.pictures import draw_failure

    rel = Path("pictures") / f"{r.method}-{r.protocol}-{r.episode_id}-{r.index}.png"
    draw_failure(r, assets, cmap, out / rel)
    item["picture"] = str(rel)
    return item
