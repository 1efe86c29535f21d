"""Things on surfaces stay separate from the surface: a simulated desk / table / counter with cups,
books and a laptop on it, seen by a box detector (true boxes, the COCO detectors' depth masks), so
the table's box holds the things and each thing's box holds the table top."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from _synth_scene import HashEmbedder
from _true_boxes import TrueBoxDetector

from capnav.core.frame import Frame
from capnav.core.geometry import look_at_pose
from capnav.eval.surface_quality import assign, relative_size_error, surface_report
from capnav.mapping import MapperConfig, build_map
from capnav.mapping.lifting import LiftConfig
from capnav.mapping.support import SupportCutConfig
from capnav.perception import create_encoder
from capnav.sim import CameraConfig, LayoutConfig, SimConfig, Simulator


def _look(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    d = target - eye
    return look_at_pose(eye, float(np.arctan2(d[1], d[0])), float(-np.arctan2(d[2], np.hypot(d[0], d[1]))))


def _scene(seed: int) -> tuple[list[Frame], object, int]:
    cfg = SimConfig(layout=LayoutConfig(rooms=3), camera=CameraConfig(width=320, height=240))
    cfg = replace(cfg, furnish=replace(cfg.furnish, surface_items=(3, 4)))
    with Simulator.from_seed(seed, cfg) as sim:
        m = sim.manifest
        items = m.items or []
        flat = [o for o in m.objects if o.category in ("table", "desk", "counter")]
        sup = max(flat, key=lambda o: sum(i.support == o.id for i in items))
        top = max(i.center[2] - i.size[2] / 2 for i in items if i.support == sup.id)
        frames = []
        for a in np.linspace(0.0, 2 * np.pi, 24, endpoint=False):
            for r in (1.3, 1.8):
                e = np.array([sup.center[0] + r * np.cos(a), sup.center[1] + r * np.sin(a), 1.25])
                if sim.collides(float(e[0]), float(e[1])):
                    continue
                T = _look(e, np.array([sup.center[0], sup.center[1], top]))
                frames.append(sim.render(T, index=len(frames)))
        labels = {sup.id: sup.category, **{i.id: i.category for i in items if i.support == sup.id}}
        return frames, m, sup.id if labels else 0


@pytest.fixture(scope="module")
def scene() -> tuple[list[Frame], object, int]:
    return _scene(7)


def _only_on(m, sid: int):  # type: ignore[no-untyped-def]
    """The manifest with only the items standing on ``sid`` (the ones the frames look at)."""
    return m.model_copy(update={"items": [i for i in m.items if i.support == sid]})


def _map(scene: tuple[list[Frame], object, int], cut: bool) -> object:
    frames, m, sid = scene
    labels = {sid: m.object(sid).category, **{i.id: i.category for i in m.items if i.support == sid}}
    cfg = MapperConfig(lift=LiftConfig(support=SupportCutConfig(enabled=cut)))
    return build_map(frames, cfg, TrueBoxDetector(labels), create_encoder("label-embedding", embedder=HashEmbedder()),
                     progress=False)


def test_things_on_a_table_are_not_absorbed_and_the_table_keeps_its_size_and_label(scene) -> None:  # type: ignore[no-untyped-def]
    frames, m, sid = scene
    assert len(frames) >= 12
    sup = m.object(sid)
    cmap = _map(scene, cut=True)
    rep = surface_report(cmap, _only_on(m, sid), None)
    items = [k for k in rep if k.startswith("item:")]
    assert items
    assert sum(rep[k]["absorbed"] for k in items) == 0, rep
    assert sum(rep[k]["found"] for k in items) >= 2, rep
    owner = assign(cmap, m)
    on_sup = [cmap.objects[k] for k, iid in owner.items() if iid == sid]
    assert on_sup, "the table is mapped"
    best = max(on_sup, key=lambda o: o.hits)
    assert best.label == sup.category
    assert relative_size_error(best.extent_max - best.extent_min, sup) <= 0.2
    # Each thing found is the thing: it does not reach down into the table.
    for k, iid in owner.items():
        it = next((i for i in m.items if i.id == iid), None)
        if it is not None:
            o = cmap.objects[k]
            assert o.extent_min[2] >= it.center[2] - it.size[2] / 2 - 0.04, (it.category, o.extent_min)


def test_without_the_cut_the_table_absorbs_its_things(scene) -> None:  # type: ignore[no-untyped-def]
    """The failure the cut fixes, on the same frames (so the test above can fail)."""
    _, m, sid = scene
    rep = surface_report(_map(scene, cut=False), _only_on(m, sid), None)
    assert sum(rep[k]["absorbed"] for k in rep if k.startswith("item:")) >= 1, rep
