"""A whole simulated apartment through the real pipeline: simulator frames, the simulator
detector at default noise, MiniLM label embeddings, SG3DTracker, persistence, occupancy, map file."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from capnav.core.grid import OCCUPIED
from capnav.eval.map_quality import evaluate_map, inside_box, visible_frames
from capnav.io.mapfile import load_map, save_map
from capnav.mapping import CapNavMap, Mapper, MapperConfig
from capnav.perception import create_detector, create_encoder

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def run() -> tuple[CapNavMap, object, object, list]:
    from capnav.language import create_embedder
    from capnav.sim.explore import ExploreConfig, explore
    from capnav.sim.simulator import Simulator

    sim = Simulator.from_seed(1)
    frames = list(explore(sim, ExploreConfig(seed=0, stride=2)))
    emb = create_embedder("minilm")
    m = Mapper(MapperConfig(), create_detector("sim", noise="default", seed=0), create_encoder("label-embedding",
                                                                                              embedder=emb))
    for f in frames:
        m.integrate(f)
    cmap = m.finish()
    yield cmap, sim, emb, frames
    sim.close()


def test_quality_on_an_apartment(run) -> None:  # type: ignore[no-untyped-def]
    cmap, sim, _, frames = run
    q = evaluate_map(cmap, sim.manifest, visible_frames(frames), sim.obstacles())
    assert q.recall >= 0.9
    assert q.duplicate_rate <= 0.1
    assert q.category_accuracy >= 0.85
    assert q.median_centroid_error <= 0.15
    assert q.occupancy_iou is not None and q.occupancy_iou > 0.3
    assert cmap.meta["frames_used"] == len(frames)


def test_dense_text_query_finds_the_category(run) -> None:  # type: ignore[no-untyped-def]
    cmap, sim, emb, _ = run
    target = max(sim.manifest.objects, key=lambda o: o.size[0] * o.size[1])  # the largest object
    scores = cmap.voxels.query(emb.embed([target.category])[0])
    top = cmap.voxels.centers()[np.argsort(scores)[-200:]]
    same = [o for o in sim.manifest.objects if o.category == target.category]
    hit = np.any([inside_box(top, o, 0.15) for o in same], axis=0)
    assert hit.mean() > 0.7
    grid = cmap.occupancy.spec
    td = cmap.voxels.topdown_scores(emb.embed([target.category])[0], grid)
    rc = np.argwhere(td >= 0.9)  # cells whose best voxel reads as the category
    xy = grid.to_world(rc)
    near = np.min([np.linalg.norm(xy - np.array(o.center[:2]), axis=1) - max(o.size[:2]) / 2 for o in same], axis=0)
    assert len(rc) > 20 and (near < 0.3).mean() > 0.6  # single stray cells exist (false positives)


def test_occupancy_marks_objects_and_round_trips(run, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    cmap, _, _, _ = run
    occ = cmap.occupancy
    for o in cmap.objects:
        if o.extent_max[2] > 0.3:
            rc = occ.spec.to_cell(o.position[:2])
            r0, c0 = max(rc[0] - 6, 0), max(rc[1] - 6, 0)
            assert (occ.cells[r0: rc[0] + 7, c0: rc[1] + 7] == OCCUPIED).any(), o.label
    back = load_map(save_map(cmap, tmp_path / "apt.capnav"))
    assert [o.label for o in back.objects] == [o.label for o in cmap.objects]
    np.testing.assert_array_equal(back.voxels.features, cmap.voxels.features.astype(np.float16).astype(np.float32))
