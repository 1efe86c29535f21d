"""A bounded pool of worker threads for the server's numerical work (asks, plans).

The event loop never runs an ask: it hands the job to one of ``workers`` threads and awaits the
answer, so ``/healthz``, the page and the map picture answer while asks run, and asks of several
clients run side by side (the embedder's ONNX session and the numba planner kernels release the
GIL). Each thread keeps its own state (``make_state``: its own ``CapNav`` per map, its own
embedder), so no stage object is shared between threads.

Two limits keep a busy server honest instead of slow: at most ``workers + queue`` jobs are
admitted (running or waiting; one more is refused at once with ``Busy``), and each job has a time
limit (``Overtime`` when its answer is not ready in time; a job still waiting then never starts,
and a running one is told its deadline so it can skip what is left, e.g. the path after the goal).
"""

from __future__ import annotations

import asyncio
import concurrent.futures
import queue
import threading
import time
from collections.abc import Callable
from typing import Any, Generic, TypeVar

from capnav.core.errors import CapNavError

S = TypeVar("S")


class Busy(CapNavError):
    """The pool is full (every worker busy and the queue full): answer 503 now, not later."""


class Overtime(CapNavError):
    """A job did not finish within its time limit."""


_STOP = object()


class PoolCounters:
    """What both pools (threads here, processes in ``procpool``) say about themselves the same
    way: readiness, the load error, jobs in flight; each sets ``_ready``, ``_load_error`` and
    ``_admitted``."""

    workers: int
    capacity: int
    _admitted: int
    _ready: threading.Event
    _load_error: BaseException | None

    @property
    def ready(self) -> bool:
        """Every worker has made its state (maps opened, embedder loaded)."""
        return self._ready.is_set() and self._load_error is None

    @property
    def load_error(self) -> BaseException | None:
        return self._load_error

    def wait_ready(self, timeout: float | None = None) -> bool:
        self._ready.wait(timeout)
        if self._load_error is not None:
            raise self._load_error
        return self._ready.is_set()

    @property
    def in_flight(self) -> int:
        """Jobs admitted and not finished (running or waiting)."""
        return self._admitted


class WorkPool(PoolCounters, Generic[S]):
    """``workers`` threads, each with the state ``make_state(i)`` made in that thread at start."""

    def __init__(self, workers: int, queue_size: int, make_state: Callable[[int], S], name: str = "capnav-worker"
                 ) -> None:
        if workers < 1 or queue_size < 0:
            raise ValueError("WorkPool needs workers >= 1 and queue_size >= 0")
        self.workers = int(workers)
        self.capacity = int(workers) + int(queue_size)
        self._make_state = make_state
        self._jobs: queue.SimpleQueue[Any] = queue.SimpleQueue()
        self._admitted = 0
        self._lock = threading.Lock()
        self._ready = threading.Event()
        self._loaded = 0
        self._load_error: BaseException | None = None
        self._threads = [threading.Thread(target=self._run, args=(i,), name=f"{name}-{i}", daemon=True)
                         for i in range(self.workers)]
        self._started = False

    # -- life ---------------------------------------------------------------------------------
    def start(self) -> None:
        if not self._started:
            self._started = True
            for t in self._threads:
                t.start()

    def close(self, timeout: float = 30.0) -> None:
        """Let admitted jobs finish, then stop the threads (SIGTERM's drain)."""
        for _ in self._threads:
            self._jobs.put(_STOP)
        deadline = time.monotonic() + timeout
        for t in self._threads:
            if t.is_alive():
                t.join(max(0.0, deadline - time.monotonic()))

    # -- work ---------------------------------------------------------------------------------
    async def run(self, fn: Callable[[S, float], Any], timeout: float) -> Any:
        """``fn(state, deadline)`` on a worker; its result, ``Busy`` when full, ``Overtime`` when late.
        ``deadline`` is a ``time.monotonic()`` instant the job should not work past."""
        with self._lock:
            if self._admitted >= self.capacity:
                raise Busy(f"the server is busy: {self.workers} workers and {self.capacity - self.workers} "
                           "queued asks already; retry shortly")
            self._admitted += 1
        fut: concurrent.futures.Future[Any] = concurrent.futures.Future()
        deadline = time.monotonic() + timeout
        self._jobs.put((fn, fut, deadline))
        try:
            return await asyncio.wait_for(asyncio.wrap_future(fut), timeout)
        except TimeoutError:
            fut.cancel()  # a job still waiting never starts; a running one sees its deadline
            raise Overtime(f"no answer within the time limit of {timeout:g} s (the server is overloaded or the "
                           "ask is unusually costly); retry or raise --time-limit") from None

    def _done(self) -> None:
        with self._lock:
            self._admitted -= 1

    def _run(self, index: int) -> None:
        try:
            state = self._make_state(index)
        except BaseException as e:
            self._load_error = e
            self._ready.set()
            state = None
        else:
            with self._lock:
                self._loaded += 1
                if self._loaded == self.workers:
                    self._ready.set()
        while True:
            job = self._jobs.get()
            if job is _STOP:
                return
            fn, fut, deadline = job
            try:
                if not fut.set_running_or_notify_cancel():
                    continue  # its caller gave up while it waited
                if state is None:
                    fut.set_exception(CapNavError(f"the worker could not load: {self._load_error}"))
                elif time.monotonic() >= deadline:
                    fut.set_exception(Overtime("the ask waited past its time limit in the queue"))
                else:
                    try:
                        fut.set_result(fn(state, deadline))
                    except BaseException as e:
                        fut.set_exception(e)
            finally:
                self._done()
