import numpy as np
import pytest

from capnav.core.categories import CATEGORIES, category, confusable
from capnav.core.errors import InputError
from capnav.core.grid import FREE, OCCUPIED, GridSpec, OccupancyGrid
from capnav.core.registry import Registry


def test_grid_cell_roundtrip_and_convention() -> None:
    g = GridSpec.covering(-1.0, -2.0, 3.0, 2.0, 0.1)
    assert (g.rows, g.cols) == (40, 40)
    rc = g.to_cell(np.array([[0.05, -1.95]]))
    assert rc.tolist() == [[0, 10]]  # row from y, col from x
    np.testing.assert_allclose(g.to_world(rc), [[0.05, -1.95]])
    assert not g.inside(np.array([-1, 0]))


def test_inflation_is_a_disk() -> None:
    g = GridSpec(0, 0, 0.1, 21, 21)
    cells = np.full((21, 21), FREE, np.uint8)
    cells[10, 10] = OCCUPIED
    inf = OccupancyGrid(g, cells).inflated(0.3)
    occ = inf.cells == OCCUPIED
    assert occ[10, 13] and occ[13, 10] and not occ[10, 14]
    assert not occ[13, 13]  # diagonal 0.42 m > 0.3 m
    assert occ.sum() == 29  # cells within 3 cells of the centre


def test_registry_errors_list_choices() -> None:
    reg: Registry[int] = Registry("widget")
    reg.register("a")(lambda: 1)
    assert reg.create("a") == 1
    with pytest.raises(InputError, match="available: a"):
        reg.create("b")


def test_categories_and_synonyms() -> None:
    assert len(CATEGORIES) >= 15
    assert category("couch").name == "sofa"
    assert category("Fridge").name == "refrigerator"
    assert "armchair" in confusable("chair")
    with pytest.raises(InputError, match="unknown category"):
        category("spaceship")
