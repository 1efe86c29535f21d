"""Task dispatch: inline, local worker processes and a local Ray instance give the same results."""

from __future__ import annotations

import math

import pytest

from capnav.core.errors import InputError
from capnav.eval.parallel import run_tasks

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
