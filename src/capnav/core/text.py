"""Small English helpers for every sentence CapNav prints (reasons, reports, console lines), so
counts agree with their nouns and lists read as lists in one place, not in each caller."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

#: Nouns whose plural is not the noun + "s" (the categories and the words reasons use).
_PLURALS = {"shelf": "shelves", "bookshelf": "bookshelves", "couch": "couches", "bench": "benches",
            "person": "people", "child": "children", "box": "boxes", "glass": "glasses",
            "dish": "dishes", "cactus": "cacti", "is": "are", "was": "were", "has": "have",
            "appears": "appear", "agrees": "agree", "matches": "match", "stands": "stand",
            "it": "they", "its": "their", "this": "these", "that": "those"}


def plural(word: str) -> str:
    """The plural of one word or of a phrase's last word ("coffee table" -> "coffee tables")."""
    head, _, last = word.rpartition(" ")
    if last in _PLURALS:
        out = _PLURALS[last]
    elif last.endswith(("s", "x", "z", "ch", "sh")):
        out = last + "es"
    elif last.endswith("y") and len(last) > 1 and last[-2] not in "aeiou":
        out = last[:-1] + "ies"
    else:
        out = last + "s"
    return f"{head} {out}" if head else out


def agree(n: int, word: str) -> str:
    """``word`` in the number ``n`` asks for: agree(1, "appears") -> "appears", agree(3, ...) -> "appear".

    ``word`` is given in its singular form (a noun, or a verb in the third person singular)."""
    if n == 1:
        return word
    return plural(word) if word in _PLURALS or not word.endswith("s") else word[:-1]


def count(n: int, noun: str, number_words: bool = False) -> str:
    """"1 chair", "3 chairs", "0 chairs" (with ``number_words``: "one chair", "no chairs")."""
    words = ("no", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine")
    shown = words[n] if number_words and 0 <= n < len(words) else str(n)
    return f"{shown} {noun if n == 1 else plural(noun)}"


def of_them(n: int, verb: str) -> str:
    """"none of them stands", "1 of them stands", "3 of them stand" (``verb`` in the singular)."""
    return f"none of them {verb}" if n == 0 else f"{n} of them {agree(n, verb)}"


def join(items: Iterable[str], last: str = "and") -> str:
    """"a", "a and b", "a, b and c" (``last``: "and" / "or")."""
    xs = [x for x in items if x]
    if len(xs) <= 1:
        return xs[0] if xs else ""
    return f"{', '.join(xs[:-1])} {last} {xs[-1]}"


def article(noun: str) -> str:
    """"a chair", "an armchair" (by the first letter; good enough for the category names)."""
    return f"{'an' if noun[:1].lower() in 'aeiou' else 'a'} {noun}"


def capitalise(sentence: str) -> str:
    """The first letter upper-case, the rest as written (not ``str.capitalize``, which lowers)."""
    return sentence[:1].upper() + sentence[1:]


def sentences(parts: Sequence[str]) -> str:
    """Clauses joined as sentences: each capitalised and ended with one full stop."""
    out = []
    for p in parts:
        p = p.strip()
        if not p:
            continue
        p = capitalise(p)
        out.append(p if p.endswith((".", "!", "?")) else p + ".")
    return " ".join(out)


def shorten(text: str, limit: int = 80) -> str:
    """``text`` on one line, at most about ``limit`` characters: a long input is cut and says how long
    it was, so a console line never echoes a pasted page."""
    flat = " ".join(text.split())
    if len(flat) <= limit:
        return flat
    return f"{flat[:limit].rstrip()}... ({len(text):,} characters)"
