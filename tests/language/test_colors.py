from __future__ import annotations

import numpy as np
import pytest

from capnav.core.errors import InputError
from capnav.language.colors import canonical_color, ciede2000, color_agreement, object_colors, srgb_to_lab


@pytest.mark.parametrize(("a", "b", "expected"), [
    ((50.0, 2.6772, -79.7751), (50.0, 0.0, -82.7485), 2.0425),  # Sharma, Wu & Dalal (2005) test data
    ((50.0, -1.3802, -84.2814), (50.0, 0.0, -82.7485), 1.0000),
    ((50.0, 2.5, 0.0), (73.0, 25.0, -18.0), 27.1492),
    ((2.0776, 0.0795, -1.1350), (0.9033, -0.0636, -0.5514), 0.9082),
])
def test_ciede2000_reference_pairs(a, b, expected):
    assert float(ciede2000(np.array(a), np.array(b))) == pytest.approx(expected, abs=1e-4)


def test_lab_white_and_black():
    lab = srgb_to_lab(np.array([[255, 255, 255], [0, 0, 0]]))
    np.testing.assert_allclose(lab[0], [100, 0, 0], atol=0.05)
    np.testing.assert_allclose(lab[1], [0, 0, 0], atol=0.05)


def _shaded(rgb, n=800, lo=0.5, seed=0):
    rng = np.random.default_rng(seed)
    lin = (np.array(rgb) / 255.0) ** 2.2 * rng.uniform(lo, 1.0, (n, 1))
    return np.clip(255 * lin ** (1 / 2.2), 0, 255).astype(np.uint8)


@pytest.mark.parametrize(("rgb", "name"), [((178, 34, 34), "red"), ((40, 70, 170), "blue"),
                                           ((128, 128, 128), "grey"), ((28, 28, 30), "black"),
                                           ((20, 120, 120), "teal"), ((225, 130, 160), "pink")])
def test_named_despite_shading(rgb, name):
    cols = object_colors(_shaded(rgb))
    assert cols[0].name == name
    assert cols[0].fraction > 0.9  # lit and shaded faces are one surface, not two colours


def test_two_colours_and_fractions():
    pts = np.concatenate([_shaded((235, 235, 230), 700), _shaded((28, 28, 30), 300, seed=1)])
    cols = object_colors(pts)
    names = [c.name for c in cols]
    assert names[0] in ("white", "light grey", "silver") and "black" in names
    assert cols[0].fraction == pytest.approx(0.7, abs=0.05)


def test_agreement_and_aliases():
    red = srgb_to_lab(np.array([178, 34, 34]))
    assert color_agreement("red", red) > color_agreement("blue", red) + 0.3
    assert canonical_color("Gray") == "grey" and canonical_color("navy blue") == "navy"
    assert canonical_color("sofa") is None
    with pytest.raises(InputError):
        color_agreement("sofa", red)
    with pytest.raises(InputError):
        object_colors(np.zeros((5, 4), np.uint8))
    assert object_colors(np.zeros((0, 3), np.uint8)) == []


def test_seeded_and_deterministic():
    pts = np.concatenate([_shaded((46, 120, 60), 500), _shaded((110, 70, 40), 500, seed=2)])
    assert object_colors(pts) == object_colors(pts)
