"""Object words from WordNet 3.0: which category a word names, which categories are related, and
what each category is for.

Why: hand-written synonym tables miss what people say ("cactus", "loveseat", "wing chair",
"credenza"), and a strict category makes "the pink chair" never consider the pink armchair.
``scripts/build_lexicon.py`` builds ``data/lexicon.json`` from WordNet once (its docstring says
which senses were chosen and why); this module only reads that JSON, once per process.
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from typing import Any

from capnav.core.errors import CapNavError

#: Weight of a category that is a kind of the requested one (an armchair for "chair"), of a more
#: general one (a chair for "armchair"), and of a close sibling (a stool for "chair", Wu-Palmer
#: similarity >= ``SIBLING_WUP``): always below 1, so instances of the named category come first.
KIND_OF_WEIGHT = 0.8
GENERAL_WEIGHT = 0.5
SIBLING_WEIGHT = 0.3
SIBLING_WUP = 0.9


@dataclass(frozen=True)
class Lexicon:
    forms: dict[str, str]  # surface form ("loveseat") -> category ("sofa")
    form_alternatives: dict[str, dict[str, float]]  # a form's other senses ("commode": dresser)
    other: frozenset[str]  # compounds that end in a category word but name something else
    relations: dict[str, dict[str, dict[str, Any]]]  # category -> category -> {"kind_of", "wup"}
    glosses: dict[str, tuple[str, ...]]  # category -> definitions (for requests by purpose)
    foreign: frozenset[str]  # function words of other languages that are not English words
    english: frozenset[str]  # English function words that no other of those languages uses
    not_typos: frozenset[str]  # common words that look like a category or colour word ("store")
    sizes: dict[str, str]  # size adjective ("king-size", "tinier") -> "large" / "small"
    #: a word naming a plant's growth form ("cactus", "prickly") -> the growth word the captioner
    #: measures from the points ("slender"; ``capnav.language.form.growth``)
    growth: dict[str, str] = field(default_factory=dict)
    #: a surface form -> the detector class it names, for the detector's classes that are not
    #: categories ("mug" -> "cup", "mobile phone" -> "cell phone"; WordNet's, see build_lexicon)
    labels: dict[str, str] = field(default_factory=dict)
    #: nouns that name a person, with plurals ("kids", "guests": noun.person in WordNet)
    persons: frozenset[str] = frozenset()
    #: a word for a kind of several categories -> those categories ("appliance": refrigerator,
    #: stove, washing machine; WordNet's hypernyms, see build_lexicon)
    kinds: dict[str, tuple[str, ...]] = field(default_factory=dict)
    #: verbs of putting a thing down on a support ("put", "set down", "rest", "plonk")
    placing: frozenset[str] = frozenset()
    #: irregular inflections of the placing verbs ("left" leave, "laid" lay; WordNet's verb.exc)
    placing_past: dict[str, str] = field(default_factory=dict)
    #: a verb of several words -> the definition of its first sense ("do the dishes": "wash dishes")
    verb_phrases: dict[str, str] = field(default_factory=dict)
    #: nouns for parts of the body, with plurals ("feet": noun.body in WordNet)
    body: frozenset[str] = frozenset()
    #: a material word -> the material the surface test knows ("velvety" velvet, "suede" leather,
    #: "teak" wood, "chenille" fabric, "brass" metal; WordNet's, see build_lexicon)
    materials: dict[str, str] = field(default_factory=dict)
    #: a word that is a material as a noun only ("plush": lavish as an adjective, a fabric as a
    #: noun) -> the material, read only where the word is said as a noun (see build_lexicon)
    material_nouns: dict[str, str] = field(default_factory=dict)
    #: nouns for how a whole looks or feels ("feel", "finish", "texture"), never a part of it
    surface_nouns: frozenset[str] = frozenset()
    #: nouns of a piece of an object ("arm", "legs", "base": WordNet's parts of the categories),
    #: whose shape is the piece's, not the object's (see build_lexicon)
    part_nouns: frozenset[str] = frozenset()
    #: a height word ("tall", "stumpy", "lower") -> "large" / "small"; "tallest", "lowest" ->
    #: "largest" / "smallest" (WordNet's, see build_lexicon): compared with the mapped heights
    heights: dict[str, str] = field(default_factory=dict)
    height_superlatives: dict[str, str] = field(default_factory=dict)
    #: a width word ("wide", "broad", "narrower") -> "large" / "small"; "widest", "narrowest" ->
    #: "largest" / "smallest": compared with the mapped footprint's longer side
    widths: dict[str, str] = field(default_factory=dict)
    width_superlatives: dict[str, str] = field(default_factory=dict)
    #: room word -> room type (WordNet's rooms, see build_lexicon): "guest room", "kitchenette"
    rooms: dict[str, str] = field(default_factory=dict)
    #: an adjective WordNet relates to an attribute the map reads -> (kind, value, relation):
    #: "boxy" (shape, rectangular, gloss), "see-through" (material, glass, definition), "azure"
    #: (colour, blue, hypernym), "squishy" (unobserved, soft, similar_to); see build_lexicon
    attributes: dict[str, tuple[str, str, str]] = field(default_factory=dict)
    #: room type -> WordNet's definitions of it ("a room equipped for preparing meals"): the room
    #: an activity implies ("making tea": the kitchen; ``capnav.language.purpose.activity_room``)
    room_glosses: dict[str, tuple[str, ...]] = field(default_factory=dict)
    #: an adjective -> the categories whose definitions say it through its first sense ("cosy":
    #: comfortable, "a comfortable upholstered armchair"): what a place described by it is
    gloss_adjectives: dict[str, tuple[str, ...]] = field(default_factory=dict)
    #: a word whose first sense is something else but which WordNet also has as one category's
    #: furniture ("press": the wardrobe's "clothes press") -> {"category", "synset", "alternatives"}
    furniture_senses: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: words for a kind of plant ("ficus", "rubber plant"): the plant category where a request
    #: names no category otherwise (WordNet's vascular plants; not in ``forms``)
    plant_names: frozenset[str] = frozenset()
    load_seconds: float = 0.0

    def category_alternatives(self, category: str, form: str | None = None) -> dict[str, float]:
        """Other categories a request for ``category`` may be served by, each with a weight < 1."""
        out: dict[str, float] = {}
        for other, rel in self.relations.get(category, {}).items():
            if rel.get("kind_of"):
                out[other] = KIND_OF_WEIGHT
            elif self.relations.get(other, {}).get(category, {}).get("kind_of"):
                out[other] = GENERAL_WEIGHT
            elif float(rel.get("wup", 0.0)) >= SIBLING_WUP:
                out[other] = SIBLING_WEIGHT
        if form is not None:
            for other, w in self.form_alternatives.get(form, {}).items():
                out[other] = max(out.get(other, 0.0), float(w))
        out.pop(category, None)
        return dict(sorted(out.items(), key=lambda kv: (-kv[1], kv[0])))


@lru_cache(maxsize=1)
def load_lexicon() -> Lexicon:
    """The shipped lexicon (read once per process; ``load_seconds`` says how long that took)."""
    t0 = time.perf_counter()
    try:
        raw = json.loads(resources.files("capnav.language").joinpath("data/lexicon.json").read_text("utf-8"))
    except (OSError, ValueError) as e:
        raise CapNavError(f"the word lexicon (capnav/language/data/lexicon.json) cannot be read: {e}; "
                          "rebuild it with `python scripts/build_lexicon.py`") from None
    lex = Lexicon(forms=dict(raw["forms"]), form_alternatives=raw.get("alternatives", {}),
                  other=frozenset(raw.get("other", [])), relations=raw.get("relations", {}),
                  glosses={k: tuple(v) for k, v in raw.get("glosses", {}).items()},
                  foreign=frozenset(raw.get("foreign", [])), english=frozenset(raw.get("english", [])),
                  not_typos=frozenset(raw.get("not_typos", [])), sizes=dict(raw.get("sizes", {})),
                  growth=dict(raw.get("growth", {})), labels=dict(raw.get("labels", {})),
                  persons=frozenset(raw.get("persons", [])),
                  kinds={k: tuple(v) for k, v in raw.get("kinds", {}).items()},
                  placing=frozenset(raw.get("placing", [])), body=frozenset(raw.get("body", [])),
                  placing_past=dict(raw.get("placing_past", {})), verb_phrases=dict(raw.get("verb_phrases", {})),
                  materials=dict(raw.get("materials", {})), material_nouns=dict(raw.get("material_nouns", {})),
                  surface_nouns=frozenset(raw.get("surface_nouns", [])),
                  part_nouns=frozenset(raw.get("part_nouns", [])),
                  heights=dict(raw.get("heights", {})),
                  height_superlatives=dict(raw.get("height_superlatives", {})),
                  widths=dict(raw.get("widths", {})), width_superlatives=dict(raw.get("width_superlatives", {})),
                  rooms=dict(raw.get("rooms", {})),
                  attributes={k: (v[0], v[1], v[2]) for k, v in raw.get("attributes", {}).items()},
                  room_glosses={k: tuple(v) for k, v in raw.get("room_glosses", {}).items()},
                  gloss_adjectives={k: tuple(v) for k, v in raw.get("gloss_adjectives", {}).items()},
                  furniture_senses=dict(raw.get("furniture_senses", {})),
                  plant_names=frozenset(raw.get("plant_names", [])))
    object.__setattr__(lex, "load_seconds", time.perf_counter() - t0)
    return lex


__all__ = ["Lexicon", "load_lexicon"]
