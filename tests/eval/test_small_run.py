"""A whole (small) benchmark on a real simulated apartment: 1 scene, 2 episodes, low resolution.

Checks what a user relies on: every file of the run folder, harness-side scoring that agrees with
the ground truth, an exact rerun from the saved episode files, and clear errors for bad input.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from capnav.eval.benchmark import run_benchmark
from capnav.eval.pipeline import PipelineConfig
from capnav.eval.scene_task import DEFAULT_METHODS, EvalConfig

pytestmark = pytest.mark.slow

CFG = EvalConfig(scenes=1, episodes_per_scene=2, seed=4, methods=DEFAULT_METHODS,
                 pipeline=PipelineConfig(width=160, height=120, max_frames=80))


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, object]:
    out = tmp_path_factory.mktemp("run")
    return out, run_benchmark(CFG, out, workers=1, progress=False)


def test_run_folder_and_scoring(run: tuple[Path, object]) -> None:
    out, res = run
    for name in ("config.json", "results.json", "report.md", "records.jsonl", "episodes/label.json",
                 "episodes/description.json", "scenes/4000/map.capnav", "scenes/4000/result.json"):
        assert (out / name).is_file(), name
    records = res.records  # type: ignore[attr-defined]
    assert len(records) == len(DEFAULT_METHODS) * 2 * 2 * 4
    for r in records:
        assert r.success == (r.distance_to_goal <= 1.0)
        assert r.success_strict is not None and (not r.success_strict or r.success)  # strict implies success
        assert math.isfinite(r.shortest_path)
        if r.index == 0:  # the first goal is never reached at the start
            assert r.shortest_path >= 1.0 - 1e-9
        assert 0.0 <= r.spl <= 1.0 and r.path_length >= 0.0
        if r.protocol == "description":
            assert len(r.target_ids) == 1
    logs = list((out / "logs" / "capnav" / "description").glob("*.json"))
    assert len(logs) == 2 and len(json.loads(logs[0].read_text())["subgoals"]) == 4
    results = json.loads((out / "results.json").read_text())
    assert {(s["method"], s["protocol"]) for s in results["summaries"]} == {
        (m, p) for m in DEFAULT_METHODS for p in ("label", "description")}
    report = (out / "report.md").read_text()
    assert "Table 1" in report and "62 / 40 / 22 / 14" in report and "Description protocol" in report
    assert "Strict indep." in report and results["summaries"][0]["independent_strict"] is not None


def test_rerun_from_episode_files_is_identical(run: tuple[Path, object], tmp_path: Path) -> None:
    out, res = run
    again = run_benchmark(CFG, tmp_path / "again", workers=1, progress=False, episodes_dir=out / "episodes")
    strip = ("query_time_s",)
    a = [{k: v for k, v in r.to_dict().items() if k not in strip} for r in res.records]  # type: ignore[attr-defined]
    b = [{k: v for k, v in r.to_dict().items() if k not in strip} for r in again.records]
    assert a == b


def test_phrasing_protocol_from_a_file(run: tuple[Path, object], tmp_path: Path) -> None:
    """Instructions of the shared file format: a present target, one with a robot position, an
    absent one (success = refusal), a request of two goals (``then``: scored at each goal), and a
    malformed line that names its line number."""
    from capnav.eval.phrasings import load_phrasings
    from capnav.sim import Simulator

    with Simulator.from_seed(4000, CFG.pipeline.sim_config()) as sim:
        objs = sim.manifest.objects
    counts: dict[str, int] = {}
    for o in objs:
        counts[o.category] = counts.get(o.category, 0) + 1
    single = next(o for o in objs if counts[o.category] == 1)
    second = next(o for o in objs if counts[o.category] == 1 and o.category != single.category)
    x, y = float(single.center[0]) + 2.0, float(single.center[1])
    lines = [{"seed": 4000, "instruction": f"go to the {single.category}", "robot": None, "kind": "category",
              "accept_ids": [single.id]},
             {"seed": 4000, "instruction": f"the {single.category} please", "robot": [x, y], "kind": "category",
              "accept_ids": [single.id]},
             {"seed": 4000, "instruction": "take me to the grand piano", "robot": None, "kind": "absent",
              "accept_ids": []},
             {"seed": 4000, "instruction": f"go to the {single.category} and then to the {second.category}",
              "robot": None, "kind": "two_step", "accept_ids": [single.id], "then": [second.id]}]
    f = tmp_path / "mine.jsonl"
    f.write_text("".join(json.dumps(d) + "\n" for d in lines))
    es = load_phrasings(f)
    assert [e.start is None for e in es.episodes] == [True, False, True, True]
    assert [g.step for g in es.episodes[3].subgoals] == [0, 1] and es.episodes[3].subgoals[1].target_ids == [second.id]
    cfg = EvalConfig(scenes=1, seed=4, methods=("capnav", "random-object"), protocols=("phrasing",),
                     pipeline=CFG.pipeline)
    res = run_benchmark(cfg, tmp_path / "p", workers=1, progress=False, episode_sets={"phrasing": es})
    recs = {(r.method, r.episode_id): r for r in res.records if r.index == 0}
    assert len(res.records) == 10 and len(recs) == 8
    chain = [r for r in res.records if r.method == "capnav" and r.episode_id == "phrasing-0004"]
    assert [r.index for r in chain] == [0, 1] and chain[1].target_ids == [second.id]
    assert chain[1].retrieval_correct, chain[1].reason  # the second goal, heard in the same words
    absent = recs[("capnav", "phrasing-0003")]
    assert absent.success == (not absent.found) and absent.target_ids == []
    assert recs[("capnav", "phrasing-0002")].start_xy == pytest.approx((x, y), abs=1e-6)
    saved = json.loads((tmp_path / "p" / "episodes" / "phrasing.json").read_text())
    assert all(e["start"] is not None for e in saved["episodes"])  # drawn starts are kept for reruns
    report = (tmp_path / "p" / "report.md").read_text()
    assert "Free phrasings" in report and "| absent | 1 |" in report
    assert "Requests of several goals" in report
    bad = tmp_path / "bad.jsonl"
    bad.write_text(json.dumps(lines[0]) + "\n" + '{"seed": 4000, "robot": null}\n')
    p = _cli("--instructions", str(bad), "--out", str(tmp_path / "o"), "--no-progress")
    assert p.returncode == 2 and "bad.jsonl:2: instruction: Field required" in " ".join(p.stderr.split())
    assert "Traceback" not in p.stderr


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "capnav.cli", "eval", *args], capture_output=True, text=True,
                          timeout=120)


def test_cli_bad_input(tmp_path: Path) -> None:
    ep = tmp_path / "episodes"
    ep.mkdir()
    (ep / "label.json").write_text('{"format": "capnav-episodes", "version": 1, "protocol": "label"}')
    p = _cli("--episodes", str(ep), "--protocols", "label", "--out", str(tmp_path / "o"), "--no-progress")
    assert p.returncode == 2 and "malformed" in p.stderr and "Traceback" not in p.stderr
    p = _cli("--methods", "capnav,teleport", "--out", str(tmp_path / "o"), "--no-progress")
    assert p.returncode == 2 and "unknown method(s) teleport" in p.stderr
    p = _cli("--protocols", "label,vibes", "--out", str(tmp_path / "o"), "--no-progress")
    assert p.returncode == 2 and "unknown protocol 'vibes'" in p.stderr
    p = _cli("--protocols", "phrasing", "--out", str(tmp_path / "o"), "--no-progress")
    assert p.returncode == 2 and "--instructions" in p.stderr
    p = _cli("--detector", "x-ray", "--out", str(tmp_path / "o"), "--no-progress")
    assert p.returncode == 2 and "unknown detector 'x-ray'" in " ".join(p.stderr.split())
    p = _cli("--furniture", "ikea", "--out", str(tmp_path / "o"), "--no-progress")
    assert p.returncode == 2 and "unknown furniture 'ikea'" in " ".join(p.stderr.split())


def test_the_perception_track_is_named_and_part_of_the_map_key() -> None:
    sim = PipelineConfig()
    real = PipelineConfig(detector="yolo-fastest", furniture="sh3d", detector_options=(("score", 0.3),))
    assert sim.track == "default houses, primitives furniture, sim:default detector"
    assert real.track == "default houses, sh3d furniture, yolo-fastest detector"
    assert PipelineConfig(size="large").sim_config().layout.min_rooms == 8
    assert real.sim_config().furniture == "sh3d"
    assert sim.map_key(0, 0) != real.map_key(0, 0)


def test_a_resumed_run_says_which_apartments_it_reused(run: tuple[Path, object], tmp_path: Path) -> None:
    """Rerunning into a finished run's folder reuses its apartments; the results and the report say
    so, with the commit that computed them, rather than passing this sitting's wall clock and commit
    off as the whole run's."""
    import shutil

    out, res = run
    again = tmp_path / "again"
    shutil.copytree(out, again)
    second = run_benchmark(CFG, again, workers=1, progress=False)
    assert [r.to_dict() for r in second.records] == [r.to_dict() for r in res.records]  # type: ignore[attr-defined]
    results = json.loads((again / "results.json").read_text())
    first = json.loads((out / "results.json").read_text())
    assert first["resumed_scenes"] == [] and "wall clock (whole run)" in first["timings"]
    assert results["resumed_scenes"] == [4000] and "wall clock (this sitting)" in results["timings"]
    assert results["scene_commits"] == first["scene_commits"] and results["scene_commits"] != []
    assert "Resumed run: apartments [4000]" in (again / "report.md").read_text()
    assert "Resumed run" not in (out / "report.md").read_text()
