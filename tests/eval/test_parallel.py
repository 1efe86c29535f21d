"""Task dispatch: inline, local worker processes and a local Ray instance give the same results."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from capnav.core.errors import InputError
from capnav.eval.benchmark import run_benchmark
from capnav.eval.parallel import run_tasks
from capnav.eval.pipeline import PipelineConfig
from capnav.eval.scene_task import EvalConfig

TASKS = [1.0, 4.0, 9.0, 16.0, 25.0]


def test_inline_and_processes_agree() -> None:
    inline = run_tasks(math.sqrt, TASKS, workers=1, progress=False)
    procs = run_tasks(math.sqrt, TASKS, workers=2, progress=False)
    assert inline == procs == [1.0, 2.0, 3.0, 4.0, 5.0]


def test_worker_errors_propagate() -> None:
    with pytest.raises(ValueError):
        run_tasks(math.sqrt, [4.0, -1.0], workers=2, progress=False)
    with pytest.raises(InputError, match="workers"):
        run_tasks(math.sqrt, TASKS, workers=0)


def test_local_ray_instance() -> None:
    ray = pytest.importorskip("ray", reason="ray is an optional extra (pip install 'capnav[ray]')")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        out = run_tasks(math.sqrt, TASKS, ray_address="local", progress=False)
    finally:
        ray.shutdown()
    assert out == [1.0, 2.0, 3.0, 4.0, 5.0]


def test_benchmark_on_local_ray(tmp_path: Path) -> None:
    """The same apartment task runs on a Ray worker and gives the same records as a local run."""
    ray = pytest.importorskip("ray", reason="ray is an optional extra (pip install 'capnav[ray]')")
    cfg = EvalConfig(scenes=1, episodes_per_scene=1, seed=9, methods=("category-only",), protocols=("label",),
                     pipeline=PipelineConfig(width=128, height=96, max_frames=60))
    local = run_benchmark(cfg, tmp_path / "local", progress=False)
    ray.init(num_cpus=1, include_dashboard=False, log_to_driver=False)
    try:
        remote = run_benchmark(cfg, tmp_path / "ray", ray_address="local", progress=False)
    finally:
        ray.shutdown()
    assert len(remote.records) == 4 and (tmp_path / "ray" / "report.md").is_file()
    strip = ("query_time_s",)
    assert [{k: v for k, v in r.to_dict().items() if k not in strip} for r in remote.records] == \
        [{k: v for k, v in r.to_dict().items() if k not in strip} for r in local.records]
