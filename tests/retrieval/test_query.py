from __future__ import annotations

import pytest

from capnav.core.errors import InputError
from capnav.language.purpose import normalise_activity
from capnav.retrieval import parse_instruction, validate_instruction


@pytest.mark.parametrize(("text", "expect"), [
    ("go to the white sofa with curved edges", {"category": "sofa", "colors": ["white"], "shapes": ["curved"]}),
    ("Please take me to the biggest couch", {"category": "sofa", "superlative": "largest"}),
    ("closest chair", {"category": "chair", "proximity": "closest"}),
    ("the nearest fridge to me", {"category": "refrigerator", "proximity": "closest"}),
    ("the chair next to the bed", {"category": "chair", "relation": "next to", "anchor_category": "bed"}),
    ("In the kitchen, find the stool.", {"category": "stool", "room": "kitchen"}),
    ("the light blue bedside table", {"category": "nightstand", "colors": ["light blue"]}),
    ("take me to the chiar", {"category": "chair"}),  # a typo
    ("the lamp bseide the stove", {"category": "lamp", "relation": "next to", "anchor_category": "stove"}),
    ("take me to the nearest night table", {"category": "nightstand", "proximity": "closest"}),
    ("the longe chair", {"category": "armchair"}), ("the cofee table", {"category": "coffee table"}),
    ("Navigate to the bedsde table.", {"category": "nightstand"}), ("the wood table", {"category": "table"}),
    ("take me to the chai", {"category": "chair"}),  # one letter short is still a typo
    ("the plant in the yellow terracotta pot", {"category": "plant", "colors": ["yellow"]}),
    ("the gray armchair beside the lamp in the study",
     {"category": "armchair", "colors": ["grey"], "relation": "next to", "anchor_category": "lamp",
      "room": "office"}),
])
def test_parse(text, expect):
    q = parse_instruction(text).to_dict()
    for k, v in expect.items():
        assert q[k] == v, (k, q)


def test_a_truncated_word_is_not_a_typo() -> None:
    assert parse_instruction("somewhere to wash my hands").category is None  # "wash" is no "washer"


@pytest.mark.parametrize(("text", "cat", "unknown"), [
    ("the pool table", None, ["pool", "table"]), ("the grandfather clock", "clock", []),  # a COCO class
    ("the second chair", "chair", []), ("the wooden table", "table", []), ("the yelow sofa", "sofa", []),
])
def test_compound_names_are_other_objects(text, cat, unknown):
    q = parse_instruction(text)
    assert q.category == cat and q.unknown_words == unknown


def test_unknown_target_and_category_only():
    q = parse_instruction("find the piano")
    assert q.category is None and q.unknown_words == ["piano"] and q.target_phrase == "piano"
    assert parse_instruction("the sofa").category_only
    assert not parse_instruction("the red sofa").category_only


@pytest.mark.parametrize(("text", "msg"), [
    ("", "empty"), ("   ", "empty"), ("sofa " * 130, "too long"), ("a" * 900, "too long"),
    ("去白色的沙发", "English"), ("Geh bitte zum weißen Sofa und dann zur Küche", "English"),
    ("ve al sofá blanco por favor", "English"), ("1234 !!", "no words"),
])
def test_bad_instructions(text, msg):
    with pytest.raises(InputError, match=msg):
        validate_instruction(text)


def test_non_string():
    with pytest.raises(InputError):
        validate_instruction(None)


def test_pipeline_never_imports_the_simulator():
    """Captioning and retrieval work from observations only: no scene truth is even importable."""
    import subprocess
    import sys

    code = ("import sys, capnav.language, capnav.retrieval, capnav.language.offline_captioner; "
            "print([m for m in sys.modules if m.startswith('capnav.sim')])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


# -- issue 12: words outside the generator's templates (sentences written for these tests) -----

@pytest.mark.parametrize(("text", "cat"), [
    ("take me to the loveseat", "sofa"), ("the little cactus on the left", "plant"), ("find the credenza", "cabinet"),
    ("go to the recliner", "armchair"), ("the chesterfield please", "sofa"), ("the tallboy", "dresser"),
    ("the wingback armchair", "armchair"), ("the vintage stool", "stool"), ("the scandi-style desk", "desk"),
])
def test_wordnet_words_and_unknown_modifiers_keep_the_noun(text, cat):
    assert parse_instruction(text).category == cat


def test_a_category_request_carries_weighted_alternatives():
    q = parse_instruction("the pink chair in the living room")
    assert q.category == "chair" and q.room == "living room"
    assert 0 < q.category_alternatives["stool"] < q.category_alternatives["armchair"] < 1
    assert {"coffee table", "desk"} <= set(parse_instruction("the round wooden table").category_alternatives)


@pytest.mark.parametrize(("text", "colors"), [
    ("the reddish ottoman", ["reddish"]), ("the whitish sofa", ["whitish"]), ("the off-white armchair", ["cream"]),
    ("the dark wooden desk", ["dark wooden"]), ("a pale pink lamp", ["pale pink"]),
    ("the charcoal sofa", ["dark grey"]),
    ("the mustard-coloured stool", ["mustard"]), ("the greyish-blue bed", []),
])
def test_colour_shades(text, colors):
    q = parse_instruction(text)
    if colors:
        assert q.colors == colors
    assert q.category is not None


@pytest.mark.parametrize(("text", "expect"), [
    ("the lamp closest to the sofa", {"category": "lamp", "anchor_category": "sofa", "proximity": "closest"}),
    ("the stool farthest from the counter", {"category": "stool", "anchor_category": "counter",
                                              "proximity": "farthest"}),
    ("which ottoman is nearest the armchair", {"category": "ottoman", "anchor_category": "armchair"}),
])
def test_landmark_relative_superlatives(text, expect):
    q = parse_instruction(text)
    assert q.proximity_to_anchor and q.relation is None
    for k, v in expect.items():
        assert getattr(q, k) == v


def test_closest_to_the_robot_has_no_anchor():
    q = parse_instruction("the closest lamp to me")
    assert q.proximity == "closest" and q.anchor_category is None and not q.proximity_to_anchor


@pytest.mark.parametrize(("text", "ordinal", "pred"), [
    ("the third nearest lamp", 3, ("proximity", "closest")), ("the 2nd farthest chair", 2, ("proximity", "farthest")),
    ("the second largest bed", 2, ("superlative", "largest")),
])
def test_ordinals(text, ordinal, pred):
    q = parse_instruction(text)
    assert q.ordinal == ordinal and getattr(q, pred[0]) == pred[1]


@pytest.mark.parametrize(("text", "cat", "neg"), [
    ("not the black stool, the other one", "stool", ["black"]), ("the lamp which isn't yellow", "lamp", ["yellow"]),
    ("the armchair that is not in the bedroom", "armchair", ["in the bedroom"]),
    ("any desk except the white one", "desk", ["white"]),
])
def test_negations(text, cat, neg):
    q = parse_instruction(text)
    assert q.category == cat and q.negations == neg and not set(neg) & set(q.colors)
    negated = parse_instruction(neg[0])  # the retriever reads each negation with the parser
    assert negated.colors or negated.room


@pytest.mark.parametrize(("text", "cat", "neg"), [
    ("the vase that is not red or blue", "vase", ["red", "blue"]),
    ("not the white or the grey stool", "stool", ["white", "grey"]),
    ("a lamp which isn't in the kitchen or in the office", "lamp", ["in the kitchen", "in the office"]),
])
def test_negated_alternatives_are_excluded_one_by_one(text, cat, neg):
    q = parse_instruction(text)
    assert q.category == cat and sorted(q.negations) == sorted(neg) and not q.colors


@pytest.mark.parametrize(("text", "cat", "anchor", "phrase"), [
    ("the table the green lamp is standing beside", "table", "lamp", "green lamp"),
    ("the desk that the white stool is tucked under", "desk", "stool", "white stool"),
    ("the sofa the small ottoman sits in front of", "sofa", "ottoman", "small ottoman"),
])
def test_a_landmark_clause_keeps_its_words_off_the_target(text, cat, anchor, phrase):
    q = parse_instruction(text)
    assert (q.category, q.anchor_category, q.anchor_phrase, q.relation) == (cat, anchor, phrase, "next to")
    assert q.colors == [] and q.size_word is None


def test_a_verb_after_the_target_alone_is_no_landmark():
    q = parse_instruction("the chair is in the kitchen")
    assert q.category == "chair" and q.anchor_category is None and q.room == "kitchen"


@pytest.mark.parametrize(("text", "cat"), [
    ("the refrigirator", "refrigerator"), ("the wardobe", "wardrobe"), ("the bookshelff", "bookshelf"),
    ("the wahsing machine", "washing machine"),
])
def test_typos_in_category_words(text, cat):
    assert parse_instruction(text).category == cat


def test_common_words_are_not_typos():
    assert parse_instruction("where do I store my shoes").category is None  # not "stove"
    assert parse_instruction("somewhere I can write").colors == []  # not "white"


@pytest.mark.parametrize("text", ["la chaise rose", "la lampe près du canapé", "el sofá blanco", "der Stuhl",
                                  "vai alla cucina per favore", "ga naar de bank"])
def test_non_english_is_refused_with_one_message(text):
    with pytest.raises(InputError, match=r"^instruction is not in English .*only English instructions"):
        validate_instruction(text)


@pytest.mark.parametrize("text", ["the lamp in the den", "go to the sofa por favor", "the chair by Van's desk"])
def test_one_stray_word_among_english_is_english(text):
    assert validate_instruction(text) == text


@pytest.fixture(scope="module")
def emb():
    from capnav.language import create_embedder

    return create_embedder("minilm")


@pytest.mark.parametrize(("text", "cats"), [
    ("somewhere I could sleep for an hour", {"bed", "sofa"}), ("where can I rinse a cup", {"sink"}),
    ("where do I hang my coat", {"wardrobe"}), ("I would like to keep my juice cold", {"refrigerator"}),
    ("somewhere comfortable to sit in the lounge", {"armchair", "sofa", "chair", "stool", "ottoman"}),
])
def test_requests_by_purpose(text, cats, emb):
    q = parse_instruction(text, emb)
    assert q.purpose and q.category in cats, q.to_dict()
    assert all(0 < w < 1 for w in q.category_alternatives.values())
    assert parse_instruction(text).category is None  # without an embedder: the purpose, no category


@pytest.mark.parametrize(("text", "shapes", "size"), [
    ("the spiny pot plant", ["slender"], None), ("the larger cactus in the study", ["slender"], "large"),
    ("the succulent on the shelf", ["slender"], None), ("the bushy fern", ["leafy"], None),
    ("the thorny armchair", [], None),  # a growth word says something of plants only
])
def test_plant_words_say_the_growth_form(text, shapes, size):
    q = parse_instruction(text)
    assert (q.shapes, q.size_word) == (shapes, size), q.to_dict()
    assert q.category != "plant" or not {"prickly", "cactus", "succulent"} & set(q.unknown_words)


@pytest.mark.parametrize(("activity", "said"), [
    ("take a quick nap", "nap"), ("have a proper soak", "soak"), ("grab a cold drink", "cold drink"),
    ("put my legs up", "put your legs up"), ("we could wash ourselves", "you could wash yourselves"),
    ("do the dishes", "do the dishes"), ("have a", "have a"),  # no noun after the light verb: kept
])
def test_an_activity_is_put_the_way_the_glosses_speak(activity, said):
    assert normalise_activity(activity) == said


@pytest.mark.parametrize(("text", "cats"), [
    ("where could we have a nap", {"bed", "sofa"}), ("where can I take a quick shower", {"bathtub"}),
    ("where can I grab a cold drink", {"refrigerator"}),
])
def test_a_light_verb_does_not_hide_the_activity(text, cats, emb):
    q = parse_instruction(text, emb)
    assert q.category in cats, q.to_dict()


@pytest.mark.parametrize(("text", "cat"), [
    ("the plant in the hallway", "plant"), ("the hall table", "table"), ("the lamp out in the corridor", "lamp"),
    ("the stool in the entrance hall", "stool"),
])
def test_hallway_words_name_a_room_not_an_unknown_word(text, cat):
    q = parse_instruction(text)
    assert q.room == "hallway" and q.category == cat
    assert not {"hall", "hallway", "corridor"} & set(q.unknown_words)


@pytest.mark.parametrize(("text", "cat", "relation", "anchors", "room"), [
    ("the lamp between the blue sofa and the red armchair", "lamp", "between", ("sofa", "armchair"), None),
    ("go to the stool in between the fridge and the cooker", "stool", "between", ("refrigerator", "stove"), None),
    ("the stool at the end of the kitchen counter", "stool", "at the end of", ("counter", None), None),
    ("the armchair facing the telly", "armchair", "facing", ("tv", None), None),
    ("the nightstand in the room with the green wardrobe", "nightstand", "in the room with", ("wardrobe", None), None),
    ("the plant in the office that has the black desk", "plant", "in the room with", ("desk", None), "office"),
])
def test_relations_with_geometry_of_their_own(text, cat, relation, anchors, room):
    q = parse_instruction(text)
    assert (q.category, q.relation, q.anchor_category, q.anchor2_category, q.room) == (cat, relation, *anchors, room)
    assert not q.colors  # the landmarks' colours are theirs, not the target's


@pytest.mark.parametrize(("text", "cat"), [
    ("the coffe tabel", "coffee table"), ("the lounge chiar", "armchair"),
    # a misspelt target before an exactly spelt landmark is still the target
    ("the dreser in the room with the blue bed", "dresser"),
])
def test_misspelt_multi_word_names(text, cat):
    assert parse_instruction(text).category == cat


def test_a_multi_word_typo_needs_words_that_are_no_english_words():
    assert parse_instruction("the washing line").category is None  # not "washing machine"


@pytest.mark.parametrize(("text", "size"), [
    ("the king-size wardrobe", "large"), ("the queen size bed", "large"), ("the oversized armchair", "large"),
    ("the tinier of the two plants", "small"), ("the bigger lamp", "large"), ("a teeny stool", "small"),
    ("I could do with a wee", None), ("move a little", None),  # a size word as a noun
])
def test_size_words(text, size):
    assert parse_instruction(text).size_word == size


@pytest.mark.parametrize(("text", "landmark"), [
    ("somewhere to set my drink down while I watch the tv", "tv"),
    ("where can I leave my glasses when I am in bed", "bed"),
])
def test_a_purpose_with_a_clause_of_its_own_targets_the_object_not_the_landmark(text, landmark, emb):
    q = parse_instruction(text, emb)
    assert q.purpose and q.category not in (None, landmark), q.to_dict()
    assert (q.relation, q.anchor_category) == ("in the room with", landmark)


def test_a_purpose_brings_the_lexicon_s_relatives_of_what_serves_it(emb):
    # a place to sit: a stool is a chair's sibling in WordNet, so it stays a candidate (weighted
    # below the chair) and a room can choose it
    q = parse_instruction("where could I sit for a minute in the office", emb)
    assert {"chair", "stool"} <= {q.category, *q.category_alternatives}, q.to_dict()
    assert q.category_alternatives["stool"] < q.category_alternatives.get("chair", 1.0)


def test_a_purpose_and_its_instruction_are_embedded_in_one_model_run(monkeypatch) -> None:
    """A one-shot query by purpose pays one model run for the activity and the instruction."""
    from capnav.language import create_embedder
    from capnav.language.purpose import gloss_index

    emb = create_embedder("minilm")
    gloss_index(emb)  # the glosses' own (one-off) run
    runs: list[list[str]] = []
    encode = emb._encode
    monkeypatch.setattr(emb, "_encode", lambda texts: runs.append(list(texts)) or encode(texts))
    text = "somewhere I could sleep for an hour"
    assert parse_instruction(text, emb).category is not None
    emb.embed([text])  # what the retriever asks next: served from the cache
    assert len(runs) == 1 and text in runs[0], runs


def test_a_long_spoken_request_is_read_not_refused():
    """Spoken requests ramble: about ninety words, most of them context, still name one target.
    (Which word is the target in such a request is the parser's work; this one is still misread.)"""
    text = ("okay so I have been carrying these groceries up the stairs for what feels like an hour and "
            "my arms are about to give out, my sister is coming over later tonight and I still have not "
            "tidied anything at all, the whole flat is a mess and I do not even know where half of my "
            "things went, but before any of that happens I really just need to put these heavy bags "
            "down somewhere, so could you please take me over to the kitchen counter by the fridge")
    assert 80 < len(text.split()) <= 120
    assert validate_instruction(text) == text  # read, not refused as pasted by mistake
