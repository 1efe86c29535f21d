"""Worker processes: jobs run in real child processes (their own GIL), errors come back with their
type, a full pool is Busy and a late job Overtime, a worker that dies is replaced, and the server
answers the same on processes as on threads while its event loop stays free."""

from __future__ import annotations

import asyncio
import functools
import os
import signal
import time
from pathlib import Path

import httpx
import pytest

from capnav.core.errors import CapNavError, InputError
from capnav.serve import ServeConfig, create_app
from capnav.serve.pool import Busy, Overtime
from capnav.serve.procpool import ProcessPool
from serve.live import live


def tag_state(tag: str, index: int) -> dict[str, object]:
    return {"tag": tag, "index": index, "pid": os.getpid()}


def who(state: dict[str, object], deadline: float) -> tuple[object, int]:
    return state["tag"], os.getpid()


def nap(seconds: float, state: dict[str, object], deadline: float) -> float:
    time.sleep(seconds)
    return seconds


def refuse(why: str, state: dict[str, object], deadline: float) -> None:
    raise InputError(why)


def broken_state(index: int) -> None:
    raise InputError("no map here")


@pytest.fixture
def pool():
    p = ProcessPool(2, 1, functools.partial(tag_state, "made in the child"))
    p.start()
    try:
        assert p.wait_ready(120)
        yield p
    finally:
        p.close(30)


def test_jobs_run_in_child_processes_with_their_state(pool: ProcessPool) -> None:
    async def go() -> list[tuple[object, int]]:
        return await asyncio.gather(*(pool.run(who, 30) for _ in range(3)))

    out = asyncio.run(go())
    assert {tag for tag, _ in out} == {"made in the child"}
    pids = {pid for _, pid in out}
    assert os.getpid() not in pids and pids <= set(pool.pids)
    with pytest.raises(InputError, match="no such object"):
        asyncio.run(pool.run(functools.partial(refuse, "no such object"), 30))


def test_full_pool_is_busy_and_late_job_is_overtime(pool: ProcessPool) -> None:
    async def go() -> list[object]:
        jobs = [asyncio.ensure_future(pool.run(functools.partial(nap, 1.5), 30)) for _ in range(3)]
        await asyncio.sleep(0.3)  # admitted: 2 running, 1 waiting
        assert pool.in_flight == 3
        busy = pool.run(who, 30)
        late = pool.run(functools.partial(nap, 5.0), 0.5)
        return await asyncio.gather(*jobs, busy, late, return_exceptions=True)

    a, b, c, busy, late = asyncio.run(go())
    assert (a, b, c) == (1.5, 1.5, 1.5)
    assert isinstance(busy, Busy) and "busy" in str(busy)
    assert isinstance(late, Busy | Overtime)  # refused at once or given up at its limit: never waited on
    assert pool.in_flight == 0


def test_a_dead_worker_is_replaced(pool: ProcessPool) -> None:
    victim = pool.pids[0]
    os.kill(victim, signal.SIGKILL)
    deadline = time.monotonic() + 60
    while victim in pool.pids or len(pool.pids) < 2:
        assert time.monotonic() < deadline, "the dead worker was not replaced"
        time.sleep(0.2)
    async def go() -> list[tuple[object, int]]:
        return await asyncio.gather(*(pool.run(who, 30) for _ in range(3)))

    out = asyncio.run(go())
    assert all(tag == "made in the child" for tag, _ in out)
    # a worker killed while it runs a job: that job answers at once with the reason
    async def killed() -> BaseException | float:
        job = asyncio.ensure_future(pool.run(functools.partial(nap, 20.0), 60))
        await asyncio.sleep(1.0)
        for pid in pool.pids:
            os.kill(pid, signal.SIGKILL)
        t0 = time.monotonic()
        try:
            return await job
        except Exception as e:
            assert time.monotonic() - t0 < 10
            return e

    err = asyncio.run(killed())
    assert isinstance(err, CapNavError) and "died" in str(err)


def test_a_worker_that_cannot_load_says_why() -> None:
    p = ProcessPool(1, 0, broken_state)
    p.start()
    try:
        with pytest.raises(InputError, match="no map here"):
            p.wait_ready(120)
        assert not p.ready
    finally:
        p.close(10)


def test_the_server_answers_the_same_on_processes_and_threads(served_map: Path) -> None:
    asks = [{"text": "the red sofa", "robot": [6.0, 3.0]}, {"text": "somewhere to sit", "k": 3},
            {"text": "the closest lamp", "robot": [2.0, 2.0]}]
    answers = {}
    for pool_kind in ("processes", "threads"):
        with live(create_app(served_map, ServeConfig(workers=2, rate=0, pool=pool_kind))) as (url, srv):
            with httpx.Client(base_url=url, timeout=60) as c:
                got = [c.post("/api/query", json=a).json() for a in asks]
                assert c.post("/api/plan", json={"object": got[0]["chosen"]["id"], "start": [6.0, 3.0]}
                              ).json()["success"]
                assert c.get("/readyz").json()["workers"] == 2
            if pool_kind == "processes":
                assert os.getpid() not in srv.config.app.state.pool.pids  # type: ignore[union-attr]
        for g in got:
            for timing in ("server_ms", "timings_ms"):
                g.pop(timing)
            if g.get("plan"):
                g["plan"].pop("timings_ms", None)
        answers[pool_kind] = got
    assert answers["processes"] == answers["threads"]


def test_processes_need_map_files(served_map: Path) -> None:
    from capnav.api import CapNav

    with pytest.raises(InputError, match="give map file paths"):
        create_app(CapNav.open(served_map), ServeConfig(pool="processes"))
    with pytest.raises(InputError, match="pool must be one of"):
        ServeConfig(pool="fibres")
