"""The server's map picture: one pixel rule (north up) shared by the PNG and the page's overlay."""

from __future__ import annotations

import io

import numpy as np
from PIL import Image

from capnav.viz.mapimage import map_picture
from language.synth import living_scene, make_map, two_rooms


def test_boxes_land_where_to_pixel_says() -> None:
    cmap = make_map(living_scene(), two_rooms())
    pic = map_picture(cmap, labels=False)
    img = np.asarray(Image.open(io.BytesIO(pic.png)).convert("RGB"))
    assert img.shape == (pic.height, pic.width, 3) and pic.scale >= 1
    bed = cmap.object(3)  # x 6.2-7.8, y 4-6: upper right
    (u0, v1), (u1, v0) = pic.to_pixel(np.array([bed.extent_min[:2], bed.extent_max[:2]]))
    assert pic.width / 2 < u0 < u1 and v0 < v1 < pic.height / 2  # north (+y) is up
    edge = img[round((v0 + v1) / 2), round(u0)]
    assert tuple(edge) == (200, 40, 40)  # the box outline
    wall_u = int(pic.to_pixel(np.array([3.8, 0.0]))[0])
    assert img[pic.height // 2 + 60, wall_u].sum() < img[pic.height // 2 + 60, wall_u + 40].sum()  # the wall is dark
    d = pic.to_dict()
    assert d["pixels_per_metre"] == pic.scale / 0.05 and d["x0"] == cmap.occupancy.spec.x0
