"""Questions about time on a map fused from several recordings (``capnav map --update``).

Answers come from the latest state: a retired object (its place was observed empty) is never
returned as present. Three readings, recognised by their words and taken out of the text the
rest of retrieval sees:

* ``last seen`` ("where did you last see the X"): present and retired objects compete; a retired
  winner is answered "not found" with where and when it was last seen;
* ``moved`` ("the lamp that was moved"): only objects with a move in their history;
* ``new`` ("what is new in the kitchen"): only objects born in the latest recording.

Without such words a request still looks at the retired objects: when the best match of the
whole history is one that is gone, the answer is "not found" and says when it was last seen,
rather than a lookalike that happens to remain.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from typing import Any

from capnav.mapping.cmap import CapNavMap
from capnav.mapping.objects import MapObject

_LAST = re.compile(r"\b(?:where\s+(?:did|have)\s+(?:you|we|i)\s+(?:last\s+)?(?:see|seen|saw)n?"
                   r"|(?:last|latest)\s+(?:seen|sighting\s+of)|(?:when|where)\s+was\s+(?:the\s+)?(?=\w)"
                   r"(?=.*\blast\s+seen\b))\b", re.I)
_LAST_SEEN_TAIL = re.compile(r"\b(?:last\s+seen|seen\s+last)\b", re.I)
_MOVED = re.compile(r"\b(?:that|which)\s+(?:was|were|has\s+been|got|had\s+been)\s+(?:moved|relocated|shifted)\b"
                    r"|\b(?:moved|relocated)\b", re.I)
_NEW = re.compile(r"\bwhat(?:'s|\s+is)\s+new\b|\b(?:that|which)\s+(?:is|was|are)\s+new\b"
                  r"|\b(?:new|newly\s+added|recently\s+added)\b", re.I)


@dataclass(frozen=True)
class TimeScope:
    kind: str  # "last_seen" | "moved" | "new"
    text: str  # the request without its time words


def read_time(text: str) -> TimeScope | None:
    """The time reading of a request, or None."""
    for kind, pat in (("last_seen", _LAST), ("last_seen", _LAST_SEEN_TAIL), ("moved", _MOVED), ("new", _NEW)):
        if pat.search(text):
            rest = re.sub(r"\s+", " ", pat.sub(" ", text)).strip(" ?.,!")
            rest = re.sub(r"^(?:is|are|the\s+one)\b\s*", "", rest, flags=re.I).strip()
            if kind == "new" and (not rest or re.match(r"(?:in|on|at|near|by)\b", rest, re.I)):
                rest = f"something {rest}".strip()  # "what is new in the kitchen": anything there
            return TimeScope(kind, rest or text)
    return None


def latest_recording(cmap: CapNavMap) -> int:
    recs = cmap.meta.get("recordings")
    return max((int(r.get("index", 1)) for r in recs), default=1) if isinstance(recs, list) and recs else 1


def _moved(o: MapObject) -> bool:
    return any(e.get("event") == "moved" for e in o.history)


def _born_in(o: MapObject, rec: int) -> bool:
    return any(e.get("event") == "born" and int(e.get("recording", 1)) == rec for e in o.history)


def has_time(cmap: CapNavMap) -> bool:
    return bool(cmap.retired) or latest_recording(cmap) > 1


def scoped_map(cmap: CapNavMap, scope: TimeScope | None) -> tuple[CapNavMap, str]:
    """The map whose objects answer ``scope`` (with a note), or the map and "" when nothing narrows."""
    latest = latest_recording(cmap)
    if scope is None:
        return replace(cmap, objects=[*cmap.objects, *_captioned(cmap.retired)]), ""
    if scope.kind == "last_seen":
        return replace(cmap, objects=[*cmap.objects, *_captioned(cmap.retired)]), "last seen"
    if scope.kind == "moved":
        return replace(cmap, objects=[o for o in cmap.objects if _moved(o)]), "moved since an earlier recording"
    return replace(cmap, objects=[o for o in cmap.objects if latest > 1 and _born_in(o, latest)]), \
        f"new in recording {latest}"


def _captioned(objs: list[MapObject]) -> list[MapObject]:
    return [o for o in objs if o.caption and o.embedding is not None]


def when_seen(o: MapObject, cmap: CapNavMap) -> str:
    """'last seen in visit 1 (frame 120) at (1.20, 3.40)'."""
    ls: dict[str, Any] = o.last_seen or {"recording": 1, "frame": o.last_frame}
    rec = int(ls.get("recording", 1))
    label = next((r.get("label") for r in cmap.meta.get("recordings", []) or [] if int(r.get("index", 0)) == rec),
                 None) or f"recording {rec}"
    return f"last seen in {label} (frame {ls.get('frame')}) at ({o.position[0]:.2f}, {o.position[1]:.2f})"


def gone_reason(o: MapObject, cmap: CapNavMap) -> str:
    retired: dict[str, Any] = next((e for e in reversed(o.history) if e.get("event") == "retired"), {})
    rec = retired.get("recording")
    label = next((r.get("label") for r in cmap.meta.get("recordings", []) or [] if r.get("index") == rec),
                 None) or f"recording {rec}"
    by = retired.get("replaced_by")
    if isinstance(by, dict) and by.get("label"):
        return (f"the {o.label} (object {o.id}) is no longer there: {when_seen(o, cmap)}; in {label} another "
                f"{by['label']} stood at its place and it was seen nowhere else")
    return (f"the {o.label} (object {o.id}) is no longer there: {when_seen(o, cmap)}; its place was seen empty "
            f"in {label}")
