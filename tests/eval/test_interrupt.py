"""Ctrl-C during a parallel run: the parent stops its workers at once instead of waiting for them."""

from __future__ import annotations

import os
import signal
import threading
import time

import pytest

from capnav.eval.parallel import run_tasks


def test_ctrl_c_stops_the_workers_within_two_seconds() -> None:
    import multiprocessing

    timer = threading.Timer(4.0, os.kill, args=(os.getpid(), signal.SIGINT))  # workers are up by then
    timer.start()
    t0 = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            run_tasks(time.sleep, [60.0, 60.0, 60.0], workers=2, progress=False)
    finally:
        timer.cancel()
    stopped = time.monotonic() - t0 - 4.0
    assert stopped < 2.0, stopped
    assert not [p for p in multiprocessing.active_children() if p.is_alive()]
