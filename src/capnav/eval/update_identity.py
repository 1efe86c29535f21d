"""Did a map update keep each object's identity? (evaluation only: it reads both visits'
manifests and the change list; the update never does).

Each object of the map before the update and of the updated map is matched to the instance whose
box holds most of its points (``map_quality.match_objects``: the same rule as the mapping
figures, so a real detector's map, whose objects carry no instance ids, is scored like the
simulator's). Then, per change class of the instance:

* ``unchanged``: ``kept`` (the same map id on the same instance), ``renamed`` (another id on it,
  the old one gone or elsewhere), ``retired`` (its id retired though it stayed), ``lost``;
* ``moved``: ``kept`` (the old id at the new place), ``reborn`` (a new id there: the map is right,
  the history is not), ``stale`` (the old id still present, on nothing), ``retired``, ``lost``;
* ``removed``: ``retired`` (right) or ``stale`` (still present);
* ``added``: ``born`` (a new id on it), ``taken`` (an old id moved onto it), ``missed``, or
  ``undetectable`` (a category the map's detector has no class for: a cabinet for a COCO model),
  which is listed but not counted.

Instances the first map never held are left out of the first three classes (nothing to keep).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import Any

from capnav.eval.map_quality import QualityConfig, match_objects
from capnav.mapping.cmap import CapNavMap
from capnav.retrieval.constraints.classes import detector_labels
from capnav.sim.manifest import SceneManifest

#: Outcomes that count as right, per change class.
RIGHT: dict[str, tuple[str, ...]] = {"unchanged": ("kept",), "moved": ("kept",), "removed": ("retired",),
                                     "added": ("born",)}
#: Outcomes listed but left out of the totals.
UNCOUNTED = ("undetectable",)


@dataclass
class IdentityReport:
    """Outcome counts per change class, and each instance's outcome."""

    counts: dict[str, Counter[str]] = field(default_factory=dict)
    per_instance: list[dict[str, Any]] = field(default_factory=list)

    def add(self, cls: str, outcome: str, **info: Any) -> None:
        self.counts.setdefault(cls, Counter())[outcome] += 1
        self.per_instance.append({"class": cls, "outcome": outcome, **info})

    def right(self, cls: str) -> tuple[int, int]:
        """(right, total) for one change class."""
        c = self.counts.get(cls, Counter())
        return sum(c[o] for o in RIGHT[cls]), sum(v for o, v in c.items() if o not in UNCOUNTED)

    def to_dict(self) -> dict[str, Any]:
        return {"counts": {k: dict(v) for k, v in self.counts.items()},
                "right": {k: list(self.right(k)) for k in RIGHT}, "per_instance": self.per_instance}


def identity_report(before: CapNavMap, after: CapNavMap, visit1: SceneManifest, visit2: SceneManifest,
                    config: QualityConfig | None = None) -> IdentityReport:
    """Score ``after`` (``before`` updated with visit 2's recording) against both visits' truth."""
    cfg = config or QualityConfig()
    m1 = dict(zip((o.id for o in before.objects), match_objects(before.objects, visit1.objects, cfg), strict=True))
    m2 = dict(zip((o.id for o in after.objects), match_objects(after.objects, visit2.objects, cfg), strict=True))
    on2: dict[int, set[int]] = {}
    for oid, inst in m2.items():
        if inst is not None:
            on2.setdefault(inst, set()).add(oid)
    retired = {o.id for o in after.retired}
    kind = {c.id: c.kind for c in visit2.changes}
    old_ids = set(m1)
    labels = detector_labels(after.meta or {})
    rep = IdentityReport()
    for g in visit1.objects:
        cls = kind.get(g.id, "unchanged")
        if cls not in ("unchanged", "moved", "removed"):
            continue  # hidden: not on this track
        ids = [oid for oid, inst in m1.items() if inst == g.id]
        if not ids:
            continue
        now = on2.get(g.id, set()) if cls != "removed" else set()
        if cls == "removed":
            out = "retired" if all(i in retired for i in ids) else "stale"
        elif now & set(ids):
            out = "kept"
        elif now:
            out = "reborn" if cls == "moved" else "renamed"
        elif all(i in retired for i in ids):
            out = "retired"
        elif cls == "moved" and any(i in m2 for i in ids):
            out = "stale"
        else:
            out = "lost"
        rep.add(cls, out, instance=g.id, category=g.category, before=ids, after=sorted(now))
    for c in visit2.changes:
        if c.kind != "added":
            continue
        now = on2.get(c.id, set())
        out = "missed" if not now else ("born" if now - old_ids else "taken")
        if out == "missed" and labels is not None and c.category not in labels:
            out = "undetectable"
        rep.add("added", out, instance=c.id, category=c.category, after=sorted(now))
    return rep
