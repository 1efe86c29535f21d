"""The English helpers every printed sentence uses."""

from __future__ import annotations

from capnav.core.text import agree, article, capitalise, count, join, of_them, plural, sentences, shorten


def test_plurals_and_agreement() -> None:
    assert [plural(w) for w in ("chair", "bookshelf", "couch", "coffee table", "box", "story", "tray")] == [
        "chairs", "bookshelves", "couches", "coffee tables", "boxes", "stories", "trays"]
    assert count(1, "armchair") == "1 armchair" and count(3, "bookshelf") == "3 bookshelves"
    assert count(0, "sofa", number_words=True) == "no sofas" and count(2, "lamp", number_words=True) == "two lamps"
    assert (agree(1, "is"), agree(2, "is"), agree(1, "appears"), agree(3, "appears"), agree(4, "stands")) == (
        "is", "are", "appears", "appear", "stand")
    assert of_them(0, "appears") == "none of them appears" and of_them(1, "appears") == "1 of them appears"
    assert of_them(2, "stands") == "2 of them stand"


def test_lists_articles_and_sentences() -> None:
    assert join([]) == "" and join(["a"]) == "a" and join(["a", "b"]) == "a and b"
    assert join(["a", "b", "c"], "or") == "a, b or c" and join(["a", "", "b"]) == "a and b"
    assert article("armchair") == "an armchair" and article("sofa") == "a sofa"
    assert capitalise("tV stand") == "TV stand"
    assert sentences(["the chair is red", "", "it is near. ", "why?"]) == "The chair is red. It is near. Why?"


def test_shorten_keeps_a_line_short_and_says_how_long_it_was() -> None:
    assert shorten("go to\n the  chair") == "go to the chair"
    long = "go to the chair " * 1000
    out = shorten(long, 40)
    assert len(out) < 80 and out.endswith("(16,000 characters)") and "\n" not in out
