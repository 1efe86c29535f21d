"""The work a server's worker does, as module functions of picklable arguments, so that one job
runs the same on a worker thread (``serve.pool``) and in a worker process (``serve.procpool``).

A job is ``functools.partial(fn, map, ...)`` called as ``job(state, deadline)``: ``map`` is the
``ServedMap`` itself on a thread, its ``MapRef`` in a process; the answer comes back as JSON bytes,
encoded by the worker so the event loop only writes them.
"""

from __future__ import annotations

import json
import time
from collections.abc import Sequence
from typing import Any

from capnav.api import CapNav
from capnav.planning.position import place_robot
from capnav.serve.maps import MapRef, ServedMap, WorkerState

Robot = tuple[float, float, float]


def encode(content: Any) -> bytes:
    """JSON as Starlette's JSONResponse writes it (no NaN: a non-finite number is a bug to see)."""
    return json.dumps(content, ensure_ascii=False, allow_nan=False, indent=None, separators=(",", ":")).encode()


def ask_job(nav: CapNav, text: str, k: int, robot: tuple[float, float, float] | None, deadline: float
            ) -> dict[str, Any]:
    """One ask on a worker: the answer, and with a robot position its goal pose and A* path (the
    path is left out, with a note, when the time limit is reached after the goal pose)."""
    t0, c0 = time.perf_counter(), time.thread_time()
    note, start = "", None
    if robot is not None:
        xy, note = place_robot(nav.occupancy, robot[:2])
        start = (xy[0], xy[1], robot[2])
    ans = nav.ask(text, robot=None if start is None else start[:2], k=k)
    _t1, c1 = time.perf_counter(), time.thread_time()
    plan, plan_note = None, ""
    if start is not None and ans.goal is not None:
        if time.monotonic() < deadline:
            plan = nav.plan(start, ans)
        else:
            plan_note = "no path: the time limit was reached once the goal pose was chosen"
    t2, c2 = time.perf_counter(), time.thread_time()
    out = ans.to_dict()
    out["chosen"] = out["object"]  # the CLI's name; "object" stays one release for older clients
    details = ans.result.details
    for i, r in enumerate(out["runners_up"]):
        d = details[i] if i < len(details) else {}
        r["why"] = d.get("why", "")
        r["terms"] = d.get("terms", {})
    out["robot_note"] = note
    out["plan"] = None if plan is None else plan.to_dict()
    out["plan_note"] = plan_note
    out["server_ms"] = {"wall": round((t2 - t0) * 1e3, 3), "cpu": round((c2 - c0) * 1e3, 3),
                        "ask_cpu": round((c1 - c0) * 1e3, 3), "plan_cpu": round((c2 - c1) * 1e3, 3)}
    return out


def query_job(m: ServedMap | MapRef, text: str, k: int, robot: Robot | None, st: WorkerState, deadline: float
              ) -> bytes:
    """``POST /api/query`` on a worker."""
    sm = st.served(m)
    return encode(ask_job(st.nav(sm), text, k, robot, deadline) | {"map": sm.name, "map_version": sm.version})


def plan_job(m: ServedMap | MapRef, oid: int, start: Robot | None, st: WorkerState, deadline: float) -> bytes:
    """``POST /api/plan`` on a worker."""
    return encode(st.nav(st.served(m)).plan(start, oid).to_dict())


def process_state(refs: Sequence[MapRef], warm: bool, index: int) -> WorkerState:
    """A worker process's state: every served map opened from its file (and warmed up)."""
    st = WorkerState()
    for ref in refs:
        sm = st.served(ref)
        if warm:
            st.warm(sm)
    return st
