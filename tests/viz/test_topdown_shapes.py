"""How objects are drawn from above: a box seen from one corner (a triangular hull) as its box on
the two seen faces, a round hull as itself, tall objects hatched with their height."""

from __future__ import annotations

import numpy as np
import pytest

from capnav.viz.topdown import TALL_M, drawn_footprint, min_area_rectangle, object_height


class _Obj:
    def __init__(self, footprint: list[tuple[float, float]], height: float) -> None:
        self.footprint = np.array(footprint, dtype=np.float64)
        self.extent_min = np.array([0.0, 0.0, 0.0])
        self.extent_max = np.array([1.0, 1.0, height])


def _rot(deg: float) -> np.ndarray:
    t = np.radians(deg)
    return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])


@pytest.mark.parametrize("deg", [0.0, 17.0, 90.0, 131.0])
def test_a_corner_view_triangle_becomes_the_box_on_its_seen_faces(deg: float) -> None:
    tri = np.array([[0.0, 0.0], [1.2, 0.0], [0.0, 0.6]]) @ _rot(deg).T + [3.0, 2.0]
    rect = min_area_rectangle(tri) - [3.0, 2.0]
    back = np.round(rect @ _rot(deg), 6)  # in the box's own frame: the legs' rectangle, not the diagonal's
    assert sorted(map(tuple, back + 0.0)) == sorted([(0.0, 0.0), (1.2, 0.0), (1.2, 0.6), (0.0, 0.6)])
    drawn = drawn_footprint(_Obj([tuple(p) for p in tri], 2.0))  # type: ignore[arg-type]
    assert drawn is not None and len(drawn) == 4


def test_round_and_square_hulls_are_drawn_as_they_are() -> None:
    circle = [(np.cos(a), np.sin(a)) for a in np.linspace(0, 2 * np.pi, 16, endpoint=False)]
    assert len(drawn_footprint(_Obj(circle, 0.8))) == 16  # type: ignore[arg-type]
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    assert np.allclose(drawn_footprint(_Obj(square, 0.5)), square)  # type: ignore[arg-type]
    assert drawn_footprint(_Obj([(0, 0), (1, 0)], 0.5)) is None  # type: ignore[arg-type]


def test_tall_objects_are_labelled_with_their_height(tmp_path) -> None:  # type: ignore[no-untyped-def]
    from capnav.core.grid import FREE, GridSpec, OccupancyGrid
    from capnav.viz.topdown import draw_navigation

    assert object_height(_Obj([], 2.0)) == 2.0 >= TALL_M  # type: ignore[arg-type]
    spec = GridSpec(0.0, 0.0, 0.05, 60, 60)
    occ = OccupancyGrid(spec, np.full((60, 60), FREE, dtype=np.uint8))
    import matplotlib.text

    seen: list[str] = []
    orig = matplotlib.text.Text.__init__

    def spy(self, *a, **k):  # type: ignore[no-untyped-def]
        orig(self, *a, **k)
        seen.append(self.get_text())

    wardrobe = _Obj([(0.5, 0.5), (1.7, 0.5), (0.5, 1.1)], 2.05)
    wardrobe.id, wardrobe.label = 22, "wardrobe"  # type: ignore[attr-defined]
    stool = _Obj([(2.0, 2.0), (2.4, 2.0), (2.4, 2.4), (2.0, 2.4)], 0.6)
    stool.id, stool.label = 15, "stool"  # type: ignore[attr-defined]
    matplotlib.text.Text.__init__ = spy  # type: ignore[method-assign]
    try:
        out = draw_navigation(occ, [wardrobe, stool], None, None, None, None, None, "t",  # type: ignore[list-item]
                              tmp_path / "n.png")
    finally:
        matplotlib.text.Text.__init__ = orig  # type: ignore[method-assign]
    assert out.stat().st_size > 1000
    assert "22 wardrobe\n2.0 m tall" in seen and "15 stool" in seen


def test_a_ragged_corner_hull_keeps_the_box_on_its_faces() -> None:
    """A fridge's hull as the map measured it: two faces in many short, slightly bent edges and the
    unseen diagonal; the box lies on the faces, not on the diagonal (whose rectangle is 5% smaller)."""
    hull = np.array([[7.58, 4.0], [6.86, 3.21], [6.87, 3.21], [7.02, 3.21], [7.47, 3.21], [7.58, 3.21],
                     [7.59, 3.29], [7.61, 3.57], [7.61, 3.67], [7.59, 3.9]])
    rect = min_area_rectangle(hull)
    assert np.allclose(sorted(map(tuple, rect.round(2))), sorted([(6.86, 3.21), (7.61, 3.21), (7.61, 4.0),
                                                                  (6.86, 4.0)]))
