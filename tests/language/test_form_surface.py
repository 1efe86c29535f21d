"""Shape words from points and surface words from pixels: said when clear, nothing when weak.

Inputs are synthetic: point sets drawn for each shape, and view crops of the simulator's procedural
material textures (the pixels the renderer samples), never a scene's truth.
"""

from __future__ import annotations

import numpy as np

from capnav.language import SceneContext
from capnav.language.form import growth, outline, shape_conflict
from capnav.language.offline_captioner import ObservationCaptioner
from capnav.language.surface import Surface, grain_agrees, material_conflict, surface_of

from .synth import disc_points, make_obj, plant_points, textured_view


def _board(w: float, d: float, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.stack([rng.uniform(0, w, 3000), rng.uniform(0, d, 3000), rng.uniform(0, 0.7, 3000)],
                    1).astype(np.float32)


def test_outline_round_rectangular_long():
    assert outline(disc_points((0, 0), 0.45, 0.5)) == "round"
    assert outline(_board(1.0, 0.6)) == "rectangular"  # a coffee table's top
    assert outline(_board(0.5, 0.5)) == "rectangular"  # a square stool is not round
    assert outline(_board(2.4, 0.6)) == "long"
    assert outline(_board(1.0, 0.6)[:20]) is None  # too few points to say


def test_a_plant_is_leafy_when_its_foliage_spreads_wider_than_its_pot_and_slender_when_narrower():
    assert growth(plant_points((0, 0), 0.35)) == "leafy"
    assert growth(plant_points((0, 0), 0.06)) == "slender"  # a columnar cactus
    assert growth(plant_points((0, 0), 0.14)) is None  # about the pot's width: nothing clear


def test_weave_is_woven_and_grain_mottle_veins_and_pile_are_smooth():
    cap = ObservationCaptioner()
    words = {}
    for k, pattern in enumerate(("fabric", "cotton", "leather", "wood", "marble", "metal")):
        o = textured_view(make_obj(k + 1, "armchair", (0, 0), (0.8, 0.8, 0.9), (170, 60, 70),
                                   shading=(1.0, 1.0)), pattern)
        words[pattern] = cap.surface(o).word
    assert words == {"fabric": "woven", "cotton": "woven", "leather": "smooth", "wood": "smooth",
                     "marble": "smooth", "metal": "smooth"}


def test_simulator_textures_drawn_texel_by_texel_show_their_family():
    # The renderer draws a near face's texels as blocks of pixels: a weave, wood's grain and
    # leather's mottle, velvet's pile and the flat plastics each land in their family, on a
    # bright, a saturated and a dark colour alike.
    cap = ObservationCaptioner()
    families = {"fabric": "woven", "cotton": "woven", "wood": "grainy", "leather": "grainy", "velvet": "plain",
                "plastic": "plain", "ceramic": "plain", "acrylic": "plain"}
    for rgb in ((200, 190, 170), (170, 60, 70), (60, 45, 35)):
        for k, pattern in enumerate(families):
            o = textured_view(make_obj(k + 1, "stool", (0, 0), (0.5, 0.5, 0.7), rgb, shading=(1.0, 1.0)), pattern,
                              texel=2)
            assert cap.surface(o).grain == families[pattern], (rgb, pattern, cap.surface(o))


def test_a_spoken_material_against_the_grain():
    assert material_conflict("wooden", "smooth", "plain") and material_conflict("leather", None, "plain")
    assert material_conflict("velvet", "smooth", "grainy") and material_conflict("plastic", None, "woven")
    assert material_conflict("cotton", "smooth", "grainy") and material_conflict("leather", None, "woven")
    assert material_conflict("wood", "smooth", "grainy") is False and grain_agrees("wood", "grainy")
    assert material_conflict("ceramic", None, "plain") is False and grain_agrees("ceramic", "plain")
    # Metal's brushed streaks and marble's veins sit between grainy and plain: only a weave refutes them.
    assert material_conflict("metal", "smooth", "grainy") is False
    assert material_conflict("marble", None, "plain") is False
    assert not grain_agrees("metal", "grainy") and material_conflict("steel", None, "woven")
    # Nothing measured: the weave word decides, as before.
    assert material_conflict("leather", "woven", None) and material_conflict("wooden", None, None) is None


def test_surfaces_of_maps_described_before_grain_still_read():
    old = Surface.from_list(["smooth", 1.02, 0.2, 900])
    assert old.word == "smooth" and old.grain is None and old.detail == 0.0
    s = Surface("smooth", 0.9, 0.2, 5000, "grainy", 14.2, 6.1)
    assert Surface.from_list(s.to_list()) == s


def test_a_plain_painted_surface_is_smooth():
    o = textured_view(make_obj(1, "cabinet", (0, 0), (1.0, 0.5, 0.9), (90, 120, 200), shading=(1.0, 1.0)), "plain")
    assert ObservationCaptioner().surface(o).word == "smooth"


def test_nothing_is_said_without_views_or_when_no_pixel_has_the_objects_colour():
    o = make_obj(1, "sofa", (0, 0), (2.0, 0.9, 0.8), (40, 140, 50))
    assert ObservationCaptioner().surface(o).word is None  # no views
    textured_view(o, "fabric")
    assert surface_of(o, (50.0, -60.0, 60.0)).word is None  # crops show another colour only


def test_surface_round_trips_through_the_attribute_cache():
    s = Surface("woven", 1.734, 0.61, 5000)
    assert Surface.from_list(s.to_list()) == s
    none = Surface(None, float("nan"), 0.0, 0)
    back = Surface.from_list(none.to_list())
    assert back.word is None and np.isnan(back.ratio)


def test_conflicts_are_only_the_measured_ones():
    assert material_conflict("leather", "woven") and material_conflict("cotton", "smooth")
    assert material_conflict("velvet", "smooth") is False  # a pile hides its weave
    assert material_conflict("fabric", None) is None and material_conflict("gold", "smooth") is None
    assert shape_conflict("round", ["rectangular"]) == "rectangular"
    assert shape_conflict("square", ["round"]) is None  # "round" was said of some square stools
    assert shape_conflict("slender", ["leafy"]) == "leafy"


def test_the_caption_says_the_surface_and_shape_it_observed():
    table = make_obj(1, "table", (0, 0), (0.9, 0.9, 0.75), (150, 110, 70), shading=(1.0, 1.0))
    table.points = disc_points((0, 0), 0.45, 0.75)
    sofa = textured_view(make_obj(2, "sofa", (3, 0), (2.0, 0.9, 0.8), (40, 140, 50), shading=(1.0, 1.0)), "fabric")
    plant = make_obj(3, "plant", (5, 0), (0.7, 0.7, 1.1), (50, 125, 45))
    plant.points = plant_points((5, 0), 0.35)
    scene = SceneContext([table, sofa, plant])
    cap = ObservationCaptioner()
    texts = {o.id: cap.caption(o, scene).text for o in (table, sofa, plant)}
    assert "round table" in texts[1]
    assert "green fabric" in texts[2] and "sofa" in texts[2]
    assert "leafy plant" in texts[3]


def test_the_caption_says_grainy_or_smooth_only_when_the_pixels_show_it():
    stool = textured_view(make_obj(1, "stool", (0, 0), (0.4, 0.4, 0.7), (120, 80, 50), shading=(1.0, 1.0)), "wood",
                          texel=2)
    chair = textured_view(make_obj(2, "armchair", (2, 0), (0.8, 0.8, 0.9), (200, 180, 150), shading=(1.0, 1.0)),
                          "velvet", texel=2)
    unseen = make_obj(3, "stool", (4, 0), (0.4, 0.4, 0.7), (120, 80, 50))  # no views: nothing to say
    scene = SceneContext([stool, chair, unseen])
    cap = ObservationCaptioner()
    texts = {o.id: cap.caption(o, scene).text for o in (stool, chair, unseen)}
    assert "grainy stool" in texts[1] and "smooth armchair" in texts[2]
    assert "grainy" not in texts[3] and "smooth" not in texts[3]


def test_a_noisy_camera_leaves_the_grain_unsaid():
    # A camera's sensor noise covers the wall behind the object as well: no grain or plain surface
    # is claimed, while the same rendered (noiseless) crop is grainy.
    import io

    from PIL import Image

    o = textured_view(make_obj(1, "stool", (0, 0), (0.5, 0.5, 0.7), (150, 110, 70), shading=(1.0, 1.0)), "wood",
                      texel=2)
    assert ObservationCaptioner().surface(o).grain == "grainy"
    img = np.asarray(Image.open(io.BytesIO(o.views[0].crop_png)).convert("RGB")).astype(np.float64)
    noisy = np.clip(img + np.random.default_rng(0).normal(0, 2.5, img.shape), 0, 255).astype(np.uint8)
    buf = io.BytesIO()
    Image.fromarray(noisy).save(buf, format="PNG")
    o.views[0].crop_png = buf.getvalue()
    s = ObservationCaptioner().surface(o)
    assert s.grain is None and s.detail > 0


def test_on_a_near_black_surface_no_grain_is_claimed():
    # Near black, one step of the measured brightness (a third of an 8-bit code of the mean of R, G
    # and B) is as large in log brightness as the detail a grain is called at, so a face's rounding
    # and a minified texture's aliasing read as a weave or a grain: a black wooden stool seen from
    # afar, a black metal shade. Nothing is said there; what it is not (a weave on black plastic)
    # still needs no texture to be read.
    cap = ObservationCaptioner()
    for rgb in ((24, 22, 22), (18, 18, 20)):
        for k, pattern in enumerate(("wood", "metal", "leather", "marble")):
            o = textured_view(make_obj(k + 1, "stool", (0, 0), (0.4, 0.4, 0.5), rgb, shading=(1.0, 1.0)), pattern)
            s = cap.surface(o)
            assert s.grain in (None, "plain"), (rgb, pattern, s)
            assert not material_conflict({"wood": "wooden", "marble": "stone"}.get(pattern, pattern), s.word, s.grain)
    # A dark brown and a bright surface keep their grain.
    for rgb in ((60, 45, 35), (200, 190, 170)):
        o = textured_view(make_obj(9, "stool", (0, 0), (0.4, 0.4, 0.5), rgb, shading=(1.0, 1.0)), "wood", texel=2)
        assert cap.surface(o).grain == "grainy", rgb


def test_a_stored_grain_on_a_near_black_object_is_read_as_unobserved():
    # Maps described before the rule hold the grain the pixels gave; reading them applies it.
    from capnav.language.surface import resolved_grain

    s = Surface("smooth", 1.0, 0.4, 900, "woven", 22.7, 14.0)
    assert resolved_grain(s, 5.0).grain is None  # L* 5: near black
    assert resolved_grain(s, 40.0) == s
    assert resolved_grain(Surface("smooth", 1.0, 0.4, 900, "plain", 1.0, 0.2), 5.0).grain == "plain"
