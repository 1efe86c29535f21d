"""Run one task per apartment: inline, on local worker processes, or on a Ray cluster.

The task function and its argument must be picklable (a module-level function and a dataclass).
Results are returned in task order whatever the completion order, so a run's output does not
depend on scheduling.
"""

from __future__ import annotations

import multiprocessing
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from typing import Any, TypeVar

from capnav.core.errors import InputError, pip_hint
from capnav.core.progress import track

T = TypeVar("T")
R = TypeVar("R")


def run_tasks(fn: Callable[[T], R], tasks: Sequence[T], workers: int = 1, ray_address: str | None = None,
              progress: bool = True, description: str = "apartments") -> list[R]:
    """``[fn(t) for t in tasks]`` spread over ``workers`` processes, or over Ray if ``ray_address``.

    ``ray_address`` is a cluster address (``ray://host:10001``, ``host:6379``, ``auto``) or
    ``local`` to start a private local instance; if Ray is already initialised in this process
    (e.g. by a test), that instance is used as it is.
    """
    if workers < 1:
        raise InputError(f"workers must be >= 1, got {workers}")
    if ray_address is not None:
        return _run_ray(fn, tasks, ray_address, progress, description)
    if workers == 1 or len(tasks) <= 1:
        return [fn(t) for t in track(tasks, description, enabled=progress)]
    # spawn, not fork: pybullet, onnxruntime and numba threads do not survive a fork cleanly.
    ctx = multiprocessing.get_context("spawn")
    results: dict[int, R] = {}
    # Workers ignore Ctrl-C: the parent alone decides, and stops them at once (_stop) instead of
    # waiting for every running apartment to finish; finished ones have written their results.
    pool = ProcessPoolExecutor(max_workers=min(workers, len(tasks)), mp_context=ctx, initializer=_ignore_sigint)
    try:
        futures: dict[Future[R], int] = {pool.submit(fn, t): i for i, t in enumerate(tasks)}
        pending = set(futures)
        for _ in track(range(len(tasks)), description, enabled=progress):
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for f in done:
                results[futures[f]] = f.result()
            if not pending:
                break
    except BaseException:
        _stop(pool)
        raise
    pool.shutdown()
    return [results[i] for i in range(len(tasks))]


def _ignore_sigint() -> None:
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _stop(pool: ProcessPoolExecutor, grace: float = 2.0) -> None:
    """Terminate the workers now (an error or Ctrl-C must not wait for running tasks).

    SIGTERM first; a worker still running after ``grace`` seconds (a loaded machine, a worker stuck
    in a system call) is killed, so the parent never leaves an orphan behind. A worker's end is read
    from its sentinel, not from ``is_alive()``: the pool's own thread reaps the workers at the same
    time, and the loser of that race sees a dead worker as alive.
    """
    import time
    from multiprocessing.connection import wait as wait_ready

    procs = list((getattr(pool, "_processes", None) or {}).values())
    for p in procs:
        p.terminate()
    pool.shutdown(wait=False, cancel_futures=True)
    running = {p.sentinel: p for p in procs}
    deadline = time.monotonic() + grace
    while running and (left := deadline - time.monotonic()) > 0:
        for sentinel in wait_ready(list(running), timeout=left):
            running.pop(sentinel)  # type: ignore[call-overload]
    for p in running.values():
        p.kill()


def _run_ray(fn: Callable[[T], R], tasks: Sequence[T], address: str, progress: bool, description: str) -> list[R]:
    try:
        import ray
    except ImportError:
        raise InputError(f"--ray needs the optional dependency: {pip_hint('capnav[ray]')}") from None
    if not ray.is_initialized():
        ray.init(address=None if address == "local" else address, include_dashboard=False,
                 log_to_driver=False, ignore_reinit_error=True)
    remote: Any = ray.remote(num_cpus=1)(_call)
    refs = [remote.remote(fn, t) for t in tasks]
    index = {ref: i for i, ref in enumerate(refs)}
    results: dict[int, R] = {}
    pending = list(refs)
    for _ in track(range(len(tasks)), f"{description} (ray)", enabled=progress):
        done, pending = ray.wait(pending, num_returns=1)
        for ref in done:
            results[index[ref]] = ray.get(ref)
        if not pending:
            break
    return [results[i] for i in range(len(tasks))]


def _call(fn: Callable[[T], R], task: T) -> R:
    """A plain Python function for ``ray.remote`` (which rejects builtins and partials)."""
    return fn(task)
