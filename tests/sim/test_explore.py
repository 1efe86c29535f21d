"""The exploration pass: every room visited, every object seen several times, deterministic, capped."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.sim import ExploreConfig, Simulator, explore
from capnav.sim.explore import plan_exploration


def test_exploration_covers_rooms_and_objects(small_sim: Simulator) -> None:
    frames = list(explore(small_sim, ExploreConfig(seed=1)))
    assert 60 <= len(frames) <= 400
    assert [f.index for f in frames] == list(range(len(frames)))
    plan = small_sim.apartment.plan
    rooms = {plan.room_of(float(f.T_wc[0, 3]), float(f.T_wc[1, 3])) for f in frames}
    assert rooms == set(range(len(plan.rooms)))
    # every object is seen (>= 100 pixels) in at least 2 frames, from different distances
    seen: Counter[int] = Counter()
    dists: dict[int, list[float]] = {}
    for f in frames:
        ids, counts = np.unique(f.gt_instance, return_counts=True)
        for i, c in zip(ids.tolist(), counts.tolist(), strict=True):
            if i > 0 and c >= 100:
                seen[i] += 1
                o = small_sim.manifest.object(i)
                dists.setdefault(i, []).append(float(np.hypot(f.T_wc[0, 3] - o.center[0], f.T_wc[1, 3] - o.center[1])))
    for o in small_sim.manifest.objects:
        assert seen[o.id] >= 2, f"object {o.id} ({o.category}) seen in {seen[o.id]} frames"
        assert max(dists[o.id]) - min(dists[o.id]) > 0.5
    # the camera always stands where the agent may stand
    xy = np.array([f.T_wc[:2, 3] for f in frames])
    assert not small_sim.collides_many(xy).any()


def test_exploration_is_deterministic_and_capped(small_sim: Simulator) -> None:
    a = plan_exploration(small_sim, ExploreConfig(seed=2))
    b = plan_exploration(small_sim, ExploreConfig(seed=2))
    assert len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    capped = plan_exploration(small_sim, ExploreConfig(seed=2, max_frames=25))
    assert len(capped) == 25
    strided = plan_exploration(small_sim, ExploreConfig(seed=2, stride=3))
    assert len(strided) == len(a[::3])
    with pytest.raises(InputError):
        ExploreConfig(stride=0)
    with pytest.raises(InputError):
        ExploreConfig(max_frames=0)
