import subprocess
import sys

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


def test_registry_imports_a_backends_module_when_it_is_first_asked_for() -> None:
    """Backends named with their module register on first use: a query process never imports the
    PyTorch embedders or the remote model clients."""
    code = ("import sys\nfrom capnav.language.embedder import EMBEDDERS\n"
            "from capnav.language.vlm.base import VLMS\n"
            "assert 'bge-m3' in EMBEDDERS and 'gemini' in VLMS and 'flag' in EMBEDDERS.names()\n"
            "assert 'capnav.language.st_embedder' not in sys.modules\n"
            "assert 'capnav.language.vlm.gemini' not in sys.modules\n"
            "assert EMBEDDERS.required('onnx') == ['path']\n"
            "print(sorted(m for m in sys.modules if m.startswith('capnav.language.')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    loaded = out.stdout.strip()
    assert "capnav.language.onnx_embedder" in loaded and "capnav.language.st_embedder" not in loaded
    reg: Registry[int] = Registry("widget", providers={"tiny": "capnav.nonexistent_module"})
    assert "tiny" in reg and reg.names() == ["tiny"]
    with pytest.raises(ModuleNotFoundError):
        reg.create("tiny")


def test_categories_and_synonyms() -> None:
    assert len(CATEGORIES) >= 15
    assert category("couch").name == "sofa"
    assert category("Fridge").name == "refrigerator"
    assert "armchair" in confusable("chair")
    with pytest.raises(InputError, match="unknown category"):
        category("spaceship")
