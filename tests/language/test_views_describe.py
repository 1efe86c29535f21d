from __future__ import annotations

import io

import numpy as np
from PIL import Image

from capnav.language import ViewConfig, create_captioner, create_embedder, describe_map, select_views

from .synth import SquareReader, living_scene, make_map, make_obj


def _img(png: bytes) -> np.ndarray:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def test_select_views_best_first_diverse_and_rendered():
    reader = SquareReader(n=8)
    obj = make_obj(1, "sofa", (0, 0), (1, 1, 1), (200, 30, 30))
    obj.observations = reader.observations()
    views = select_views(obj, reader)
    assert 1 <= len(views) <= 5
    assert views[0].score == max(v.score for v in views)
    truncated = {o.frame_index for o in obj.observations if o.truncated}
    assert views[0].frame_index not in truncated
    assert len({v.frame_index for v in views}) == len(views)
    v = views[0]
    full, crop = _img(v.frame_png), _img(v.crop_png)
    assert full.shape == (120, 160, 3)
    x0, y0, x1, y1 = (round(c) for c in v.box)
    assert tuple(full[y0, (x0 + x1) // 2]) == (255, 0, 0)  # the box is drawn in red
    assert crop.shape[0] <= (y1 - y0) * 1.3 + 6 and crop.shape[1] <= (x1 - x0) * 1.3 + 6
    assert select_views(obj, reader, ViewConfig(max_views=2)).__len__() == 2


def test_no_observations_no_views():
    obj = make_obj(1, "sofa", (0, 0), (1, 1, 1), (200, 30, 30))
    assert select_views(obj, SquareReader()) == []


def test_describe_map_fills_objects_and_caches():
    objs = living_scene()
    reader = SquareReader(n=6)
    for o in objs[:2]:
        o.observations = reader.observations()[:4]
    cmap = make_map(objs)
    emb = create_embedder("minilm")
    rep = describe_map(cmap, reader, create_captioner("offline"), emb, progress=False)
    assert rep.captions_new == len(objs) and rep.captions_cached == 0
    assert all(o.caption and o.embedding is not None and o.embedding_model == emb.model_id for o in objs)
    assert 1 <= len(objs[0].views) <= 5 and objs[0].views[0].frame_png.startswith(b"\x89PNG")
    assert objs[3].views == []
    np.testing.assert_allclose(np.linalg.norm(objs[0].embedding), 1.0, atol=1e-5)
    assert len(cmap.caches["captions"]) == len(objs)
    assert str(objs[0].id) in cmap.caches["attributes"]
    before = [o.caption for o in objs]
    rep2 = describe_map(cmap, None, create_captioner("offline"), emb, progress=False)
    assert rep2.captions_cached == len(objs) and [o.caption for o in objs] == before
