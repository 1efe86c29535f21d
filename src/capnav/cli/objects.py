"""``capnav objects MAP [--json] [--history]``: what a map holds, object by object, and what changed.

One row per present object (id, label, label votes, size, position, caption, views, when it was
last seen); ``--history`` adds the recordings fused into the map, each object's moves, births and
retirements, and the retired objects (kept with when they were last seen).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import typer

from capnav.cli.options import check_input_path
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.objects import MapObject


def _last_seen(o: MapObject, recs: dict[int, dict[str, Any]]) -> dict[str, Any]:
    ls: dict[str, Any] = dict(o.last_seen) if o.last_seen else {
        "recording": min(recs) if recs else 1, "frame": int(o.last_frame), "timestamp": None}
    rec = recs.get(int(ls["recording"]), {})
    ls["label"] = rec.get("label") or f"recording {ls['recording']}"
    return ls


def object_record(o: MapObject, recs: dict[int, dict[str, Any]], status: str) -> dict[str, Any]:
    """The JSON-able row of one object (``capnav objects --json``)."""
    return {"id": o.id, "status": status, "label": o.label,
            "votes": {k: round(float(v), 3) for k, v in sorted(o.label_votes.items(), key=lambda kv: -kv[1])},
            "size": np.round(o.size, 3).tolist(), "position": np.round(o.position, 3).tolist(),
            "caption": o.caption, "views": len(o.views), "observations": len(o.observations),
            "last_seen": _last_seen(o, recs), "history": list(o.history)}


def describe_event(e: dict[str, Any], recs: dict[int, dict[str, Any]]) -> str:
    rec = recs.get(int(e.get("recording", 0)), {})
    when = rec.get("label") or f"recording {e.get('recording')}"
    pos = e.get("position")
    at = f"({pos[0]:.2f}, {pos[1]:.2f})" if isinstance(pos, list) and len(pos) >= 2 else "?"
    if e.get("event") == "moved":
        fr = e.get("from") or [float("nan")] * 2
        return f"moved from ({fr[0]:.2f}, {fr[1]:.2f}) to {at} in {when}"
    if e.get("event") == "retired":
        return f"gone from {at} in {when} (its place seen empty in {e.get('frames_empty', '?')} frames)"
    if e.get("event") == "shrunk":
        return (f"smaller in {when}: {e.get('points_seen_empty', '?')} of its points were seen empty "
                f"(now centred at {at})")
    return f"first seen at {at} in {when}"


def objects_report(cmap: CapNavMap, history: bool) -> dict[str, Any]:
    from capnav.mapping.update import recordings

    recs = {int(r["index"]): r for r in recordings(cmap)}
    out: dict[str, Any] = {"recordings": list(recs.values()),
                           "objects": [object_record(o, recs, "present") for o in cmap.objects]}
    if history:
        out["retired"] = [object_record(o, recs, "retired") for o in cmap.retired]
        out["changes"] = sorted(
            ({"id": o.id, "label": o.label, **e, "text": describe_event(e, recs)}
             for o in [*cmap.objects, *cmap.retired] for e in o.history
             if e.get("event") != "born" or int(e.get("recording", 1)) > min(recs)),
            key=lambda c: (int(c.get("recording", 0)), int(c["id"])))
    return out


def register(app: typer.Typer) -> None:
    @app.command("objects")
    def objects_cmd(
        map_path: Path = typer.Argument(..., help="map file"),
        as_json: bool = typer.Option(False, "--json", help="print JSON instead of a table"),
        history: bool = typer.Option(False, "--history", help="also the recordings, each object's changes "
                                                             "(moved, new, gone) and the retired objects"),
    ) -> None:
        """List the map's objects: id, label, votes, size, position, caption, views, last seen."""
        from rich.table import Table

        from capnav.core.console import make_console
        from capnav.io.mapfile import load_map

        check_input_path(map_path, "map file")
        cmap = load_map(map_path, voxels=False)
        rep = objects_report(cmap, history)
        if as_json:
            typer.echo(json.dumps({"map": str(map_path), **rep}, indent=1))
            return
        con = make_console()
        t = Table(title=f"{map_path}: {len(cmap.objects)} objects"
                        + (f", {len(cmap.retired)} retired" if cmap.retired else ""))
        for col in ("id", "label", "votes", "size (m)", "position (m)", "views", "last seen", "caption"):
            t.add_column(col, overflow="fold")
        for r in rep["objects"]:
            votes = ", ".join(f"{k} {v:.1f}" for k, v in list(r["votes"].items())[:3])
            ls = r["last_seen"]
            t.add_row(str(r["id"]), r["label"], votes, " x ".join(f"{v:.2f}" for v in r["size"]),
                      ", ".join(f"{v:.2f}" for v in r["position"]), str(r["views"]),
                      f"{ls['label']}, frame {ls['frame']}", (r["caption"] or "-")[:80])
        con.print(t)
        if history:
            con.print("[bold]recordings[/]")
            for rec in rep["recordings"]:
                con.print(f"  {rec['index']}: {rec.get('label')} ({rec.get('dataset')}, {rec.get('frames')} frames)",
                          highlight=False)
            con.print("[bold]changes[/]" if rep["changes"] else "no changes: the map holds one recording")
            for c in rep["changes"]:
                con.print(f"  {c['id']} {c['label']}: {c['text']}", highlight=False)
