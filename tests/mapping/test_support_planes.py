"""The support cut on box scenes: the thing above the plane is the thing, the plane and below the
support; a chair's backrest is no thing on its seat; a TV on its cabinet stays the TV; label votes
weigh 3D support, not box counts; a bowl on a desk stands on it (never merged into it)."""

from __future__ import annotations

import numpy as np
from _synth_scene import Box, look_at, render

from capnav.core.geometry import Intrinsics
from capnav.mapping.support import cut_at_support, stands_on
from capnav.mapping.tracker import Track, vote_all
from capnav.perception import Detection, box_from_mask

K = Intrinsics.from_fov(320, 240, 70.0)


def _table_with_cup() -> list[Box]:
    parts = [Box((-0.6, -0.4, 0.71), (0.6, 0.4, 0.75), 1, 5, (150, 100, 60))]
    parts += [Box((x - 0.03, y - 0.03, 0.0), (x + 0.03, y + 0.03, 0.71), 1, 5, (150, 100, 60))
              for x in (-0.55, 0.55) for y in (-0.35, 0.35)]
    parts.append(Box((0.1, -0.05, 0.75), (0.18, 0.03, 0.85), 2, 0, (230, 30, 30)))  # a cup
    return parts


def _cut(frame, ids: set[int], thing: bool, box_of: set[int] | None = None) -> tuple[np.ndarray, np.ndarray]:  # type: ignore[no-untyped-def]
    inst = frame.gt_instance
    bx0, by0, bx1, by1 = box_from_mask(np.isin(inst, list(box_of or ids)))
    g = 0.2 * max(bx1 - bx0, by1 - by0)  # a detector's box is looser than the object
    h, w = inst.shape
    boxed = (max(0.0, bx0 - g), max(0.0, by0 - g), min(float(w), bx1 + g), min(float(h), by1 + g))
    x0, y0, x1, y1 = (int(v) for v in boxed)
    inbox = np.zeros(inst.shape, dtype=bool)
    inbox[y0:y1, x0:x1] = True
    mask = inbox & np.isin(inst, list(ids))
    return mask, cut_at_support(mask, frame.depth, frame.K, frame.T_wc, (0, 0), boxed, thing)


def test_a_cup_box_keeps_the_cup_and_a_table_box_sheds_it() -> None:
    f = render(_table_with_cup(), look_at((1.6, -1.2, 1.3), (0.0, 0.0, 0.75)), K)
    inst = f.gt_instance
    assert inst is not None and (inst == 2).sum() > 30
    # The cup's box also shows the table top around it: the cup is what stands on the plane.
    mask, cut = _cut(f, {1, 2}, thing=True, box_of={2})
    assert (mask & (inst == 1)).sum() > 20
    assert cut[inst == 2].mean() > 0.8 and cut[inst == 1].sum() <= 0.1 * cut.sum()
    # The table's mask holds the cup: it is shed (but for its foot, in the plane's noise band), the
    # whole table kept.
    mask, cut = _cut(f, {1, 2}, thing=False)
    assert cut[inst == 2].sum() <= 0.3 * (inst == 2).sum() and cut[mask & (inst == 1)].all()


def test_a_chair_keeps_its_backrest_and_a_tv_keeps_itself() -> None:
    chair = [Box((-0.22, -0.22, 0.42), (0.22, 0.22, 0.47), 1, 3, (90, 60, 40))]
    chair += [Box((x - 0.02, y - 0.02, 0.0), (x + 0.02, y + 0.02, 0.42), 1, 3, (90, 60, 40))
              for x in (-0.2, 0.2) for y in (-0.2, 0.2)]
    chair.append(Box((-0.22, 0.18, 0.47), (0.22, 0.22, 0.92), 1, 3, (90, 60, 40)))  # backrest on the back legs
    f = render(chair, look_at((1.3, -1.5, 1.25), (0.0, 0.0, 0.5)), K)
    mask, cut = _cut(f, {1}, thing=False)
    assert mask.sum() > 200 and (cut == mask).all()
    tv = [Box((-0.6, -0.2, 0.0), (0.6, 0.2, 0.5), 1, 12, (60, 40, 30)),
          Box((-0.45, -0.05, 0.5), (0.45, 0.0, 1.0), 2, 14, (20, 20, 20))]
    f = render(tv, look_at((0.3, -2.0, 1.25), (0.0, 0.0, 0.6)), K)
    inst = f.gt_instance
    mask, cut = _cut(f, {1, 2}, thing=False, box_of={2})  # the TV's box with the cabinet top in it
    assert cut[mask & (inst == 2)].all()


def _det(label: str, score: float, support: float):  # type: ignore[no-untyped-def]
    from types import SimpleNamespace

    m = np.zeros((4, 4), dtype=bool)
    m[1:3, 1:3] = True
    d = Detection(box_from_mask(m), 5 if label == "table" else 0, label, score, m)
    return SimpleNamespace(detection=d, class_id=d.class_id, support=support)


def test_votes_weigh_3d_support_not_box_counts() -> None:
    t = Track(id=1, position=np.zeros(3), velocity=np.zeros(3), box=np.zeros(4), feature=np.zeros(2, np.float32),
              class_id=5, label="table")
    vote_all(t, _det("table", 0.5, 1.2))  # type: ignore[arg-type]
    for _ in range(4):
        vote_all(t, _det("cup", 0.9, 0.01))  # type: ignore[arg-type]
    assert t.label == "table"


def test_a_bowl_stands_on_a_desk_but_an_armrest_does_not_stand_on_its_chair() -> None:
    g = np.mgrid[0:1.2:0.03, 0:0.6:0.03].reshape(2, -1).T
    desk = np.c_[g, np.full(len(g), 0.75)]
    a = np.linspace(0, 2 * np.pi, 40)
    bowl = np.concatenate([np.c_[0.5 + r * np.cos(a), 0.3 + r * np.sin(a), np.full(40, z)]
                           for r, z in ((0.085, 0.82), (0.07, 0.8), (0.04, 0.76))])
    assert stands_on(bowl, desk)
    chair = np.c_[g * 0.5, np.full(len(g), 0.45)]
    armrest = chair[chair[:, 0] < 0.05] + [0.0, 0.0, 0.005]
    assert not stands_on(armrest, chair)


def test_a_plane_one_height_bin_thick_is_found_without_empty_bins() -> None:
    """Up-facing points all within one height bin (a histogram shorter than the peak window) give
    that plane for the thing above it, with no peak placed on an empty bin (no empty-median NaN)."""
    import warnings

    from capnav.mapping.support import SupportCutConfig, support_plane

    cfg = SupportCutConfig()
    plane = np.full(400, 0.75)
    thing = np.linspace(0.80, 0.95, 40)
    z = np.concatenate([plane, thing])
    up = np.concatenate([np.ones(400, bool), np.zeros(40, bool)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for highest in (True, False):
            assert support_plane(z, up, cfg, highest=highest) == 0.75
