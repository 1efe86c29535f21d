"""A picture of an ``.rrd`` as rerun's own viewer draws it, with no window and no GPU.

``rerun --headless`` (the viewer the ``viz`` extra installs) renders with whatever Vulkan adapter
the machine has: Mesa's lavapipe (Debian's ``mesa-vulkan-drivers``) does on a machine without a
GPU. It is started on a free loopback port, opens the recording with the layout stored in it (the
``map_blueprint`` that ``capnav view`` writes) and is asked for a screenshot over its control API
(``rerun.experimental.ViewerClient``, pinned with the rest of the viz code to rerun-sdk 0.41).
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from capnav.core.errors import CapNavError, InputError, pip_hint
from capnav.viz.rerun_log import _rerun

_ANSI = re.compile(r"\x1b\[[0-9;]*m")


@dataclass(frozen=True)
class ViewerShot:
    """A screenshot (PNG bytes) and the views the viewer showed, as (name, kind) pairs."""

    png: bytes
    views: tuple[tuple[str, str], ...]
    frame: int | None  # where the ``frame`` time cursor stood, when the recording has that timeline
    viewer_pids: tuple[int, ...]  # the viewer's processes (its group, on Linux), all ended before this returns


@dataclass(frozen=True)
class HeadlessViewer:
    """A running headless viewer: its control client, its process group id and the processes in
    that group once it answered (from /proc; empty elsewhere)."""

    client: Any
    pid: int
    members: tuple[int, ...]


def rerun_executable() -> Path:
    """The ``rerun`` viewer binary: beside this Python (a venv's bin/) or on PATH."""
    here = Path(sys.executable).parent / "rerun"
    found = here if here.exists() else shutil.which("rerun")
    if found is None:
        raise InputError(f"no rerun viewer binary found beside Python or on PATH: {pip_hint('capnav[viz]')}")
    return Path(found)


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@contextlib.contextmanager
def headless_viewer(size: tuple[int, int] = (1280, 800), timeout: float = 60.0) -> Iterator[HeadlessViewer]:
    """A ``rerun --headless`` viewer of ``size`` (points) on a free loopback port with a connected
    ``ViewerClient``, stopped on exit. It runs in a process group of its own, ended whole (the
    ``rerun`` entry point is a Python launcher that starts the viewer binary as its child). A viewer
    that dies (no graphics adapter) raises ``CapNavError`` with the lines it printed about it."""
    rr = _rerun()
    from rerun.experimental import ViewerClient

    port = _free_port()
    cmd = [str(rerun_executable()), "--headless", "--bind", "127.0.0.1", "--port", str(port),
           "--window-size", f"{size[0]}x{size[1]}", "--hide-welcome-screen"]
    with tempfile.TemporaryFile() as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)

        def died() -> str:  # the panic or error lines (a backtrace follows them), else the last lines
            log.seek(0)
            lines = [_ANSI.sub("", ln).strip() for ln in log.read().decode(errors="replace").splitlines()]
            lines = [ln for ln in lines if ln]
            key = [ln for ln in lines if "panicked" in ln or "ERROR" in ln or "error:" in ln.lower()]
            return (f"the rerun viewer {rr.__version__} exited with {proc.returncode}: "
                    + " | ".join((key or lines)[-5:]))

        try:
            deadline = time.monotonic() + timeout
            while True:
                if proc.poll() is not None:
                    raise CapNavError(died())
                try:
                    client = ViewerClient.connect(f"rerun+http://127.0.0.1:{port}/proxy")
                    client.get_state()
                    break
                except Exception:  # not listening yet
                    if time.monotonic() > deadline:
                        raise CapNavError(f"the rerun viewer did not answer on port {port} within "
                                          f"{timeout:.0f} s") from None
                    time.sleep(0.3)
            try:
                yield HeadlessViewer(client, proc.pid, _group_members(proc.pid))
            except Exception as e:
                time.sleep(0.5)
                if proc.poll() is not None and not isinstance(e, CapNavError):  # it died under us
                    raise CapNavError(died()) from e
                raise
        finally:
            _end_group(proc)


def _group_members(pgid: int) -> tuple[int, ...]:
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        with contextlib.suppress(OSError, ValueError, IndexError):
            fields = stat.read_text().rsplit(")", 1)[1].split()  # after "pid (comm)": state ppid pgrp ...
            if int(fields[2]) == pgid:
                out.append(int(stat.parent.name))
    return tuple(sorted(out))


def _end_group(proc: subprocess.Popen[bytes]) -> None:
    """SIGTERM to the viewer's process group, SIGKILL after 10 s; the launcher is reaped."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, sig)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            continue
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:  # the binary may outlive its launcher by a moment
            try:
                os.killpg(proc.pid, 0)
            except ProcessLookupError:
                return
            time.sleep(0.1)


def screenshot_rrd(rrd: str | Path, *, size: tuple[int, int] = (1280, 800), frame: int | None = None,
                   view: str | None = None, settle: float = 0.0, timeout: float = 60.0) -> ViewerShot:
    """Open ``rrd`` in a headless viewer and take a screenshot of the whole viewer, or of the view
    named ``view``. ``frame``: where to put the ``frame`` time cursor (default: the last frame);
    ``settle``: seconds to wait before the shot (the viewer's start-up notices fade after ~10 s)."""
    path = Path(rrd).resolve()
    if not path.is_file():
        raise InputError(f"no recording at {path}")
    with headless_viewer(size, timeout) as viewer:
        client = viewer.client
        client.open(str(path))
        deadline = time.monotonic() + timeout
        while True:
            state = client.get_state()
            if state.recordings and not state.loading:
                break
            if time.monotonic() > deadline:
                raise CapNavError(f"the rerun viewer did not load {path} within {timeout:.0f} s")
            time.sleep(0.3)
        rec = state.recordings[0]
        client.set_location(rec.location)  # the recording, not the catalog page the file was filed under
        cursor = None
        line = next((t for t in rec.timelines if t.name == "frame"), None)
        if line is not None and line.end is not None:
            cursor = int(line.end if frame is None else frame)
            client.set_time("frame", sequence=cursor, play_state="paused")
        while True:
            views = client.get_state().views
            if views or time.monotonic() > deadline:
                break
            time.sleep(0.3)
        if view is not None and not any(v.name == view for v in views):
            raise InputError(f"the recording shows no view named {view!r} (views: {[v.name for v in views]})")
        if settle > 0:
            time.sleep(settle)
        vid = next((v.view_id for v in views if v.name == view), None)
        png = client.take_screenshot(vid)
    return ViewerShot(png, tuple((v.name, v.view_class) for v in views), cursor, viewer.members)
