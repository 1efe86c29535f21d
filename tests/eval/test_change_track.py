"""The change track's episodes: one class per protocol, written from the truth the user holds."""

from __future__ import annotations

from capnav.core.grid import FREE
from capnav.eval.change_track import CLASSES, ChangeTrackConfig, _episodes, table
from capnav.eval.generate import SceneTruth
from capnav.sim import Simulator
from capnav.sim.changes import ChangeSpec
from capnav.sim.config import CameraConfig, LayoutConfig, SimConfig


def test_episodes_per_change_class() -> None:
    cfg = ChangeTrackConfig(scenes=1, changes=ChangeSpec(moved=2, removed=1, added=1), per_class=8)
    sc = SimConfig(layout=LayoutConfig(rooms=3), camera=CameraConfig(width=64, height=48))
    with Simulator.from_seed(2, sc) as s1, Simulator.from_seed(2, sc, visit=2, changes=cfg.changes) as s2:
        nav = s2.navigable()
        truth = SceneTruth.from_manifest(s2.manifest, nav.spec, nav.cells == FREE)
        eps = _episodes(2, cfg, s1.manifest, s2.manifest, truth)
        kinds = {c.id: c.kind for c in s2.manifest.changes}
        present = {o.id for o in s2.manifest.objects}
        cats = {v: [o.category for o in s.manifest.objects] for v, s in ((1, s1), (2, s2))}
    assert set(eps) == set(CLASSES) and all(len(e) == 8 for e in eps.values())
    for cls, episodes in eps.items():
        for ep in episodes:
            (g,) = ep.subgoals
            if g.kind == "category":  # a bare kind only when it names one object of the home described
                assert cats[1 if cls == "removed" else 2].count(g.category) == 1, (cls, g.text)
            if cls == "removed":  # described as at visit 1; the right answer is "not found"
                assert g.absent
            else:
                assert len(g.target_ids) == 1 and g.target_ids[0] in present
                assert kinds.get(g.target_ids[0], "unchanged") == cls
    assert {ep.subgoals[0].text for ep in eps["moved"]}  # texts exist
    res = {"summaries": [{"method": "capnav", "protocol": "description/moved", "independent": 0.5, "subgoals": 4}],
           "cpu_seconds": {"update_cpu_s": 1.0, "remap_visit2_cpu_s": 2.0}}
    assert "| capnav | 50.0 (4) |" in table(res)
