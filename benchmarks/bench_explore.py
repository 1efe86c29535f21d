"""Exploring baselines: looking at keyframes beside looking after every action, in one run.

The CoW-, ZSON- and LM-Nav-style agents move by discrete actions (0.25 m steps, 30 degree turns);
a look (render, online map update, detection) costs most of an action. By default they look at
keyframes (60 degrees of turn or 0.5 m of travel since the last look, after a collision, before
every decision); the reference is the naive schedule, a look after every action. Both run the
same episodes of the same apartments through the evaluation harness; the table gives CPU seconds
per subgoal, looks and actions per subgoal, and subgoal successes, so a speed-up that costs
successes shows.

    .venv/bin/python benchmarks/bench_explore.py [--scenes 3] [--first-scene 0] [--episodes 2] [--seed 0]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from dataclasses import replace
from typing import Any

from capnav.eval.baselines.explore.lmnav import LMNavConfig
from capnav.eval.baselines.explore.object_search import ObjectSearchConfig
from capnav.eval.baselines.explore.zson import ZSONConfig
from capnav.eval.scene_task import EvalConfig, SceneTask, run_scene
from capnav.explore import explorer as explorer_module
from capnav.explore.explorer import ExplorerConfig

METHODS = ("cow", "zson", "lmnav")


def options(every_action: bool) -> dict[str, dict[str, Any]]:
    """Method configs for the harness: defaults, or the same with a look after every action."""
    if not every_action:
        return {}
    naive = {"keyframe_turn_deg": 0.0, "keyframe_move": 0.0}
    search = ObjectSearchConfig(explorer=ExplorerConfig(**naive))  # type: ignore[arg-type]
    return {"cow": {"config": search}, "zson": {"config": ZSONConfig(search=search)},
            "lmnav": {"config": LMNavConfig(drive=replace(LMNavConfig().drive, **naive))}}  # type: ignore[arg-type]


class LookCounter:
    """Counts the explorer's looks and actions (the harness reports steps, not looks)."""

    def __init__(self) -> None:
        self.looks = self.actions = 0
        cls = explorer_module.FrontierExplorer
        self._observe, self._act = cls.observe, cls.act
        counter = self

        def observe(ex: Any) -> Any:
            counter.looks += 1
            return counter._observe(ex)

        def act(ex: Any, action: str) -> bool:
            counter.actions += 1
            return bool(counter._act(ex, action))

        # wrap the class methods: the harness builds the explorers inside the methods
        setattr(cls, "observe", observe)  # noqa: B010
        setattr(cls, "act", act)  # noqa: B010

    def close(self) -> None:
        cls = explorer_module.FrontierExplorer
        setattr(cls, "observe", self._observe)  # noqa: B010
        setattr(cls, "act", self._act)  # noqa: B010


def run(method: str, every_action: bool, scenes: list[int], episodes: int, seed: int) -> dict[str, float]:
    cfg = EvalConfig(scenes=len(scenes), episodes_per_scene=episodes, seed=seed, methods=(method,),
                     method_options=options(every_action))
    counter = LookCounter()
    subgoals = successes = 0
    cpu = 0.0
    try:
        for s in scenes:
            with tempfile.TemporaryDirectory() as out:
                t0 = time.process_time()
                res = run_scene(SceneTask(cfg, s, out))
                cpu += time.process_time() - t0
            subgoals += len(res["records"])
            successes += sum(bool(r["success"]) for r in res["records"])
    finally:
        counter.close()
    return {"cpu": cpu / subgoals, "looks": counter.looks / subgoals, "actions": counter.actions / subgoals,
            "subgoals": subgoals, "successes": successes}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", type=int, default=3, help="apartments 1000*seed + first .. first+N-1")
    ap.add_argument("--first-scene", type=int, default=0, help="index of the first apartment")
    ap.add_argument("--episodes", type=int, default=2, help="episodes per apartment and protocol")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    scenes = [1000 * args.seed + args.first_scene + i for i in range(args.scenes)]
    print(f"apartments {scenes}, {args.episodes} episodes per apartment and protocol, seed {args.seed}; "
          "CPU time includes opening the apartment (and LM-Nav's graph)")
    print("| method | looks | CPU s / subgoal | looks / subgoal | actions / subgoal | successes |")
    print("|---|---|---:|---:|---:|---:|")
    for method in METHODS:
        for every in (True, False):
            r = run(method, every, scenes, args.episodes, args.seed)
            name = "every action (reference)" if every else "keyframes (default)"
            print(f"| {method} | {name} | {r['cpu']:.2f} | {r['looks']:.1f} | {r['actions']:.1f} "
                  f"| {r['successes']} / {r['subgoals']} |", flush=True)


if __name__ == "__main__":
    main()
