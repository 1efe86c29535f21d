"""The whole benchmark: one task per apartment (local processes or Ray), then results and report.

Run folder layout::

    OUT/config.json                 the run's settings, seed, version, commit, command
    OUT/episodes/<protocol>.json    the episode files (rerun exactly with --episodes OUT/episodes)
    OUT/scenes/<seed>/map.capnav    the apartment's prior map (built once, shared by all methods)
    OUT/scenes/<seed>/result.json   that apartment's records and timings (reused by a rerun with the
                                    same settings, so an interrupted run resumes where it stopped)
    OUT/logs/<method>/<protocol>/<episode>.json   per-episode logs with trajectories
    OUT/pictures/*.png              failure cases
    OUT/records.jsonl               every scored subgoal (no trajectories)
    OUT/results.json                summaries per (method, protocol), timings, config
    OUT/report.md                   Table 1, Table 2 and the description table, paper beside ours
"""

from __future__ import annotations

import json
import time
from collections import defaultdict
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from capnav.core.atomic import write_json, write_text
from capnav.core.errors import InputError
from capnav.eval.episodes import EpisodeSet
from capnav.eval.method import load_methods, method_note
from capnav.eval.metrics import SubgoalRecord, Summary, summarize_all
from capnav.eval.parallel import run_tasks
from capnav.eval.report import render
from capnav.eval.scene_task import EvalConfig, SceneTask, run_scene, version_and_commit


@dataclass
class BenchmarkResult:
    out: Path
    summaries: list[Summary]
    records: list[SubgoalRecord]
    seconds: float

    def summary(self, method: str, protocol: str) -> Summary:
        for s in self.summaries:
            if s.method == method and s.protocol == protocol:
                return s
        raise InputError(f"no results for {method} / {protocol}")


def load_episode_dir(path: Path, protocols: tuple[str, ...]) -> dict[str, EpisodeSet]:
    """Episode files ``<protocol>.json`` of an earlier run, validated (``DatasetError`` if bad)."""
    sets: dict[str, EpisodeSet] = {}
    for p in protocols:
        es = EpisodeSet.load(path / f"{p}.json")
        if es.protocol != p:
            raise InputError(f"{path / f'{p}.json'} holds {es.protocol!r} episodes, not {p!r}")
        sets[p] = es
    return sets


def run_benchmark(config: EvalConfig, out: str | Path, workers: int = 1, ray_address: str | None = None,
                  episodes_dir: str | Path | None = None, progress: bool = True, command: str = "",
                  episode_sets: dict[str, EpisodeSet] | None = None) -> BenchmarkResult:
    """Evaluate ``config.methods`` on ``config.protocols`` over ``config.scenes`` apartments, or on
    the apartments of given episodes (``episodes_dir`` files, or ``episode_sets`` such as a
    ``phrasing`` set read by ``capnav.eval.phrasings.load_phrasings``)."""
    t0 = time.perf_counter()
    out = Path(out)
    known = load_methods()
    unknown = [m for m in config.methods if m not in known]
    if unknown:
        raise InputError(f"unknown method(s) {', '.join(unknown)}; available: {', '.join(known)}")
    given: dict[str, EpisodeSet] = {}
    scene_seeds = config.scene_seeds()
    if episodes_dir is not None:
        given = load_episode_dir(Path(episodes_dir), config.protocols)
    given.update(episode_sets or {})
    missing = [p for p in given if p not in config.protocols]
    if missing:
        raise InputError(f"episodes given for protocol(s) {', '.join(missing)} that the run does not include")
    if given:
        scene_seeds = sorted({s for es in given.values() for s in es.scene_seeds})
    version, commit = version_and_commit()
    meta = {"version": version, "commit": commit, "seed": config.seed, "scenes": len(scene_seeds),
            "scene_seeds": scene_seeds, "episodes_per_scene": config.episodes_per_scene,
            "detector": f"{config.pipeline.detector}:{config.pipeline.detector_noise}",
            "track": config.pipeline.track,
            "embedder": config.pipeline.embedder, "command": command or "capnav eval", "workers": workers,
            "instructions": next((str(es.generator.get("instructions")) for es in given.values()
                                  if "instructions" in es.generator), None),
            "ray": ray_address, "config": asdict(config)}
    write_json(out / "config.json", meta)
    tasks = [SceneTask(config, s, str(out), {p: [e.model_dump() for e in es.for_scene(s)] for p, es in given.items()}
                       or None) for s in scene_seeds]
    results = run_tasks(run_scene, tasks, workers=workers, ray_address=ray_address, progress=progress)

    # Save the episodes as run (generated ones, and given ones with their drawn starts) so that
    # anyone can rerun exactly with --episodes OUT/episodes.
    for p in config.protocols:
        gen = given[p].generator if p in given else {}
        es = EpisodeSet(protocol=p, seed=config.seed, scene_seeds=scene_seeds,  # type: ignore[arg-type]
                        generator={"episodes_per_scene": config.episodes_per_scene, "subgoals": config.subgoals,
                                   "version": version, **gen},
                        episodes=[e for res in results for e in res["episodes"][p]])
        es.save(out / "episodes" / f"{p}.json")

    records = [SubgoalRecord.from_dict(d) for res in results for d in res["records"]]
    write_text(out / "records.jsonl", "".join(json.dumps({k: v for k, v in r.to_dict().items()
                                                          if k != "trajectory"}) + "\n" for r in records))
    summaries = summarize_all(records)
    timings: dict[str, float] = defaultdict(float)
    for res in results:
        for k, v in res["timings"].items():
            timings[k] += float(v)
    seconds = time.perf_counter() - t0
    # A resumed run reuses apartments finished in an earlier sitting (maybe at another commit): say
    # which, and that the wall clock is this sitting's (the stage times above cover every apartment).
    resumed = [res["scene_seed"] for res in results if res.get("resumed")]
    meta["resumed_scenes"] = resumed
    meta["scene_commits"] = sorted({str(res.get("commit", "unknown")) for res in results})
    timings["wall clock (this sitting)" if resumed else "wall clock (whole run)"] = seconds
    failures = [f for res in results for f in res["failures"]]
    write_json(out / "results.json", {**meta, "seconds": seconds, "timings": dict(timings),
                                      "summaries": [s.to_dict() for s in summaries],
                                      "maps": {str(r["scene_seed"]): r["map"] for r in results}})
    notes = {m: method_note(m) for m in config.methods}
    write_text(out / "report.md", render(summaries, meta, _pick_failures(failures), timings, notes, records))
    return BenchmarkResult(out, summaries, records, seconds)


def _pick_failures(failures: list[dict[str, Any]], per_method: int = 3) -> list[dict[str, Any]]:
    """A few failures per (method, protocol) for the report, pictures first."""
    chosen: list[dict[str, Any]] = []
    count: dict[tuple[str, str], int] = defaultdict(int)
    for f in sorted(failures, key=lambda f: (not f["picture"], f["method"], f["protocol"], f["episode_id"])):
        key = (f["method"], f["protocol"])
        if count[key] < per_method:
            count[key] += 1
            chosen.append(f)
    return sorted(chosen, key=lambda f: (f["method"], f["protocol"], f["episode_id"], f["index"]))
