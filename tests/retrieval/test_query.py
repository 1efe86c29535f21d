from __future__ import annotations

import pytest

from capnav.core.errors import InputError
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
    ("the closest bedside table", {"category": "nightstand", "proximity": "closest"}),
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
    ("the pool table", None, ["pool", "table"]), ("the grandfather clock", None, ["grandfather", "clock"]),
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
    ("", "empty"), ("   ", "empty"), ("sofa " * 80, "too long"), ("a" * 400, "too long"),
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
