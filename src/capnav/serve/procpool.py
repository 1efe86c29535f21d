"""Worker processes for the server's asks: the pool ``capnav serve`` runs by default.

Why processes and not threads: retrieval is mostly Python, so worker threads hold the GIL most of
an ask, and the event loop's thread must win it back for every socket call (each ``recv`` and
``send`` releases it); under a burst ``/healthz`` then waits tens of milliseconds per request
and two workers do little more than one. A worker process has a GIL of its own: the event loop's
process only reads requests and writes the answers the workers have already encoded.

Each process opens the map files itself (``make_state``, a picklable callable, run in the child)
and keeps them; a job names its map by ``MapRef`` (name, file, version), so a reload in the server
bumps the version and each process reopens the file on its next job. Jobs and answers cross
pipes, so both must pickle: jobs are ``functools.partial``s of module functions, answers JSON
bytes. Each process has pipes of its own (no queue shared between processes: a process killed
while it holds a shared queue's lock would stall the others), and the server hands a job to an
idle process only, so it knows which job each runs. Admission, the time limit and the errors
(``Busy``, ``Overtime``) are those of ``serve.pool.WorkPool``; a process that dies is replaced and
the job it was running answers at once with the reason.
"""

from __future__ import annotations

import asyncio
import collections
import concurrent.futures
import contextlib
import itertools
import logging
import multiprocessing as mp
import multiprocessing.connection as mpc
import os
import pickle
import signal
import threading
import time
from collections.abc import Callable
from typing import Any

from capnav.core.errors import CapNavError
from capnav.serve.pool import Busy, Overtime, PoolCounters

log = logging.getLogger("capnav.serve")
_STOP = "stop"
#: Worker processes run this much nicer than the server's event loop, and as batch work (a worker
#: woken by a job does not take the core from the loop that handed it over): when asks fill the
#: cores, a /healthz or a page request still gets a core the moment it arrives.
WORKER_NICE = 5


def _portable(e: BaseException) -> BaseException:
    """``e`` if it survives pickling, else a CapNavError with its message."""
    try:
        pickle.loads(pickle.dumps(e))
        return e
    except Exception:
        return CapNavError(f"{type(e).__name__}: {e}")


def _child(index: int, make_state: Callable[[int], Any], conn: Any) -> None:
    """A worker process: make the state, then answer the jobs its pipe brings until told to stop
    (or until the server is gone)."""
    with contextlib.suppress(EOFError, OSError):
        _serve(index, make_state, conn)


def _serve(index: int, make_state: Callable[[int], Any], conn: Any) -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C and SIGHUP are the server's to handle
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    with contextlib.suppress(OSError, AttributeError):
        os.nice(WORKER_NICE)
    with contextlib.suppress(OSError, AttributeError):  # Linux: a woken worker does not preempt the loop
        os.sched_setscheduler(0, os.SCHED_BATCH, os.sched_param(0))
    try:
        state = make_state(index)
    except BaseException as e:
        conn.send(("load_error", _portable(e)))
        return
    conn.send(("ready", None))
    while True:
        job = conn.recv()
        if job == _STOP:
            return
        jid, fn, deadline = job
        if time.monotonic() >= deadline:
            conn.send((jid, (False, Overtime("the ask waited past its time limit in the queue"))))
            continue
        try:
            out = (True, fn(state, deadline))
        except BaseException as e:
            out = (False, _portable(e))
        conn.send((jid, out))


class _Worker:
    def __init__(self, proc: Any, conn: Any) -> None:
        self.proc, self.conn = proc, conn
        self.ready = False
        self.dead = False  # exited and not replaced (the pool is closing, or could not load)
        self.job: int | None = None  # the job it runs, None when idle


class ProcessPool(PoolCounters):
    """``workers`` processes, each with the state ``make_state(i)`` made in it; the face of
    ``WorkPool`` (``start``, ``ready``, ``run``, ``close``, ...)."""

    def __init__(self, workers: int, queue_size: int, make_state: Callable[[int], Any]) -> None:
        if workers < 1 or queue_size < 0:
            raise ValueError("ProcessPool needs workers >= 1 and queue_size >= 0")
        self.workers = int(workers)
        self.capacity = int(workers) + int(queue_size)
        self._make_state = make_state
        self._ctx = mp.get_context("spawn")  # no fork of a process that runs threads and an event loop
        self._procs: list[_Worker] = []
        self._waiting: collections.deque[tuple[int, Callable[[Any, float], Any], float]] = collections.deque()
        self._futures: dict[int, concurrent.futures.Future[Any]] = {}
        self._ids = itertools.count()
        self._admitted = 0
        self._lock = threading.Lock()
        self._ready = threading.Event()
        self._load_error: BaseException | None = None
        self._closing = False
        self._reader: threading.Thread | None = None

    # -- life ---------------------------------------------------------------------------------
    def _spawn(self, index: int) -> _Worker:
        mine, theirs = self._ctx.Pipe(duplex=True)
        p = self._ctx.Process(target=_child, args=(index, self._make_state, theirs), name=f"capnav-worker-{index}",
                              daemon=True)
        p.start()
        theirs.close()
        return _Worker(p, mine)

    def start(self) -> None:
        if self._reader is None:
            self._procs = [self._spawn(i) for i in range(self.workers)]
            self._reader = threading.Thread(target=self._read, name="capnav-results", daemon=True)
            self._reader.start()

    @property
    def pids(self) -> list[int]:
        return [int(w.proc.pid) for w in self._procs if w.proc.pid is not None and w.proc.is_alive()]

    def close(self, timeout: float = 30.0) -> None:
        """Let the running jobs finish, then stop the processes (SIGTERM's drain)."""
        with self._lock:
            self._closing = True
            for w in self._procs:
                with contextlib.suppress(OSError, ValueError):
                    w.conn.send(_STOP)  # read after the job it runs, if any
        deadline = time.monotonic() + timeout
        for w in self._procs:
            w.proc.join(max(0.0, deadline - time.monotonic()))
            if w.proc.is_alive():
                w.proc.terminate()
                w.proc.join(5)
        if self._reader is not None:
            self._reader.join(5)

    # -- work ---------------------------------------------------------------------------------
    async def run(self, fn: Callable[[Any, float], Any], timeout: float) -> Any:
        """``fn(state, deadline)`` in a worker process (``fn`` must pickle); its result, ``Busy``
        when full, ``Overtime`` when late. ``deadline`` is a ``time.monotonic()`` instant."""
        fut: concurrent.futures.Future[Any] = concurrent.futures.Future()
        with self._lock:
            if self._admitted >= self.capacity:
                raise Busy(f"the server is busy: {self.workers} workers and {self.capacity - self.workers} "
                           "queued asks already; retry shortly")
            self._admitted += 1
            jid = next(self._ids)
            self._futures[jid] = fut
            self._waiting.append((jid, fn, time.monotonic() + timeout))
            self._dispatch()
        try:
            return await asyncio.wait_for(asyncio.wrap_future(fut), timeout)
        except TimeoutError:
            raise Overtime(f"no answer within the time limit of {timeout:g} s (the server is overloaded or the "
                           "ask is unusually costly); retry or raise --time-limit") from None
        finally:
            with self._lock:
                self._admitted -= 1
                self._futures.pop(jid, None)  # a job still waiting is then skipped, never sent

    def _dispatch(self) -> None:
        """Hand waiting jobs to idle workers (under ``_lock``)."""
        if self._closing:
            return
        for w in self._procs:
            if not (w.ready and w.job is None):
                continue
            while self._waiting:
                jid, fn, deadline = self._waiting.popleft()
                if jid not in self._futures:
                    continue  # its caller gave up
                try:
                    w.conn.send((jid, fn, deadline))
                except Exception as e:  # fn does not pickle, or the worker just died
                    fut = self._futures.get(jid)
                    if fut is not None and not fut.done():
                        fut.set_exception(_portable(e) if isinstance(e, CapNavError) else
                                          CapNavError(f"the job could not be sent to a worker process: {e}"))
                    continue
                w.job = jid
                break

    def _settle(self, jid: int, ok: bool, value: Any) -> None:
        fut = self._futures.get(jid)
        if fut is not None and not fut.done():
            if ok:
                fut.set_result(value)
            else:
                fut.set_exception(value)

    def _read(self) -> None:
        """Hand answers to their callers and the next jobs to the workers; replace a dead worker."""
        while True:
            with self._lock:
                live = [w for w in self._procs if not w.dead]
                if self._closing and not live:
                    return
                watch: dict[Any, _Worker] = {w.conn: w for w in live}
                watch.update({w.proc.sentinel: w for w in live})
            woke: list[Any] = mpc.wait(list(watch), timeout=1.0)
            for ready in woke:
                w = watch[ready]
                if w.dead:
                    continue
                if ready is w.conn:
                    try:
                        key, value = w.conn.recv()
                    except (EOFError, OSError):
                        continue  # it died: its sentinel says so
                    with self._lock:
                        if key == "ready":
                            w.ready = True
                            if all(x.ready for x in self._procs):
                                self._ready.set()
                        elif key == "load_error":
                            self._load_error = value
                            self._ready.set()
                        else:
                            w.job = None
                            self._settle(key, *value)
                        self._dispatch()
                elif not w.proc.is_alive():
                    self._replace(w)

    def _replace(self, w: _Worker) -> None:
        with self._lock:
            if w not in self._procs:
                return
            i = self._procs.index(w)
            if w.job is not None:
                self._settle(w.job, False, CapNavError(f"the worker process answering this ask died (exit code "
                                                       f"{w.proc.exitcode}); retry"))
            w.conn.close()
            if not w.ready and self._load_error is None and not self._closing:  # no crash loop at start
                self._load_error = CapNavError(f"worker process {i} exited with code {w.proc.exitcode} before it "
                                               "had loaded the maps (see the log above)")
                self._ready.set()
            if self._closing or self._load_error is not None:
                w.dead = True
                return
            log.warning("worker process %d exited with %s; starting another", i, w.proc.exitcode)
            self._procs[i] = self._spawn(i)
