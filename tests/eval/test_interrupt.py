"""Ctrl-C during a parallel run: the parent stops its workers at once instead of waiting for them."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from multiprocessing.connection import wait
from pathlib import Path

import pytest

from capnav.eval.parallel import run_tasks


def test_ctrl_c_stops_the_workers_at_once() -> None:
    """Tasks of 60 s, Ctrl-C after 4 s: the run stops within seconds and leaves no worker alive."""
    import multiprocessing

    # A process started in the background by a non-interactive shell inherits SIGINT ignored (as
    # CI launched with `&` does): Ctrl-C is what this test sends, so it restores Python's handler.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(4.0, os.kill, args=(os.getpid(), signal.SIGINT))  # workers are up by then
    timer.start()
    t0 = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            run_tasks(time.sleep, [60.0, 60.0, 60.0], workers=2, progress=False)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    stopped = time.monotonic() - t0 - 4.0
    assert stopped < 5.0, stopped  # SIGTERM, up to 2 s grace, then SIGKILL: far below the 60 s tasks
    # A worker has ended when its sentinel is readable (is_alive() can race with the pool's thread).
    workers = multiprocessing.active_children()
    assert all(wait([w.sentinel], timeout=1.0) for w in workers), workers


def _children(pid: int) -> set[int]:
    kids = set()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            kids.add(int(stat.parent.name))
    return kids


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc to find the workers")
def test_sigterm_stops_the_workers_too() -> None:
    """``kill PID`` of a parallel run must not leave its workers running as orphans."""
    code = ("import time; from capnav.cli import stop_on_sigterm; from capnav.eval.parallel import run_tasks; "
            "stop_on_sigterm(); run_tasks(time.sleep, [60.0, 60.0, 60.0], workers=2, progress=False)")
    proc = subprocess.Popen([sys.executable, "-c", code], stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60.0
        kids: set[int] = set()
        while time.monotonic() < deadline and len(kids) < 2:  # two workers (and the resource tracker)
            time.sleep(0.2)
            kids = _children(proc.pid)
        assert len(kids) >= 2, kids
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=10)
        time.sleep(1.5)
        alive = [k for k in kids if Path(f"/proc/{k}").exists() and "Z" not in
                 Path(f"/proc/{k}/stat").read_text().rsplit(")", 1)[1].split()[0]]
        assert not alive, alive
    finally:
        if proc.poll() is None:
            proc.kill()
