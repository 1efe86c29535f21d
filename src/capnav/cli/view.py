"""``capnav view MAP [--query TEXT] -o map.rrd``: the map in 3D for rerun's viewer."""

from __future__ import annotations

import socket
import tempfile
from pathlib import Path
from typing import Annotated
from urllib.parse import urlparse

import typer

from capnav.cli.options import finite_float
from capnav.core.errors import InputError, OutputError


def check_writable(out: Path) -> None:
    """One line, before any work, when the recording cannot be written where asked."""
    parent = out.expanduser().resolve().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile(dir=parent, prefix=".capnav-probe-"):
            pass
    except OSError as e:
        raise OutputError(f"cannot write {out}: {parent} is not writable ({e.strerror or e})") from None


def check_listening(url: str) -> None:
    """One line when nothing listens at the viewer's address (rerun would retry for seconds and
    then print its own errors)."""
    u = urlparse(url)
    if not u.hostname:
        raise InputError(f"--connect must be a rerun gRPC URL like rerun+http://127.0.0.1:9876/proxy, got {url!r}")
    port = u.port or 9876
    try:
        with socket.create_connection((u.hostname, port), timeout=3):
            pass
    except OSError as e:
        raise InputError(f"nothing listens at {u.hostname}:{port} ({e.strerror or e}): start the viewer first "
                         f"(`rerun`), or leave out --connect to write an .rrd file") from None


def register(app: typer.Typer) -> None:
    @app.command("view")
    def view_cmd(
        map_path: Annotated[Path, typer.Argument(help="a map file (capnav map; captions shown when captioned)")],
        out: Annotated[Path, typer.Option("-o", "--out", help="the .rrd file to write (open it with `rerun FILE`)")
                       ] = Path("map.rrd"),
        query: Annotated[list[str] | None, typer.Option(
            "--query", "-q", help="an instruction to answer and show (repeatable)")] = None,
        robot: Annotated[str | None, typer.Option(
            help="robot position X,Y (m) to plan a path to each answer from; default: the map's last camera "
                 "pose, as capnav navigate starts")] = None,
        connect: Annotated[str | None, typer.Option(
            help="send to a running rerun viewer at this gRPC URL instead of writing --out "
                 "(e.g. rerun+http://127.0.0.1:9876/proxy)")] = None,
        max_voxels: Annotated[int, typer.Option(min=1, help="voxels logged at most (a seeded subsample beyond)")
                              ] = 300_000,
        max_z: Annotated[float | None, typer.Option(
            parser=finite_float(),
            help="leave out voxels above this height (m), e.g. 2.0 to drop the ceiling and look in from above")
                         ] = None,
    ) -> None:
        """Log the voxel map, object boxes with ids and captions, the camera path and answers to rerun."""
        from capnav.api import CapNav
        from capnav.cli.query import parse_xy
        from capnav.core.console import make_console
        from capnav.viz.rerun_log import write_rrd

        xy = parse_xy(robot)
        if connect:
            check_listening(connect)
        else:
            check_writable(out)
        nav = CapNav.open(map_path)
        con = make_console(stderr=True)
        if xy is None and query and nav.map.trajectory is not None and len(nav.map.trajectory):
            (x, y, _), source = nav.start_pose()
            xy = (x, y)
            con.print(f"robot at ({x:.2f}, {y:.2f}): {source}", highlight=False)
        answers = []
        for text in query or []:
            ans = nav.ask(text, robot=xy)
            plan = nav.plan(xy, ans) if xy is not None and ans.goal is not None else None
            answers.append((ans, plan))
        try:
            path = write_rrd(nav.map, out, answers, connect=connect, max_voxels=max_voxels, max_z=max_z)
        except RuntimeError as e:  # rerun's own errors (a viewer that went away, a file it cannot create)
            first = str(e).strip().splitlines()[0] if str(e).strip() else type(e).__name__
            raise OutputError(f"rerun could not {'send to ' + connect if connect else 'write ' + str(out)}: "
                              f"{first}") from None
        for ans, plan in answers:
            got = f"object {ans.object.id}: {ans.object.caption}" if ans.object else "not found"
            con.print(f'"{ans.instruction}" -> {got}' + (f"; path {plan.length_m:.2f} m" if plan else ""),
                      highlight=False)
        con.print(f"{path if path else connect}: {len(nav.map.objects)} objects, {len(nav.map.voxels)} voxels",
                  highlight=False)
