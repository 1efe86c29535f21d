"""What an ordinal counts and where the count starts: "the second stool from the fridge", "the
third lamp from the door to the landing", "the plant you reach second", "number three", "skip
the nearest sofa and take the next one".

Why: an ordinal is said in many ways besides an adjective of the object (an adverb after a verb
of reaching, "number N", skipping some and taking the next), and it counts from somewhere: a
landmark object (the count is then the order of distance from it), a door named by the room
behind it ("the door to the landing", "the landing door", "the kitchen doorway"), or a room one comes
from ("walking in from the hall"). A door or a room one comes from is the route's origin
(``constraints/route.py`` orders from the way in); a landmark is a distance landmark
(``constraints/relation.py``). The start phrase is taken out of the words the mapping reads, so
its object is never the target.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from capnav.language.context import room_ending, room_starting
from capnav.retrieval.query.tokens import _ORDINALS, _find_category

#: Cardinal words of a count ("number three", "skip the first two").
NUMBERS = {"one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "1": 1, "2": 2, "3": 3, "4": 4, "5": 5}
#: Nouns of a door (its room is the other side of it).
DOORS = {"door", "doorway", "doors", "entrance", "entry", "archway", "opening", "doorframe"}
#: Verbs and phrases that start a count at something: "starting at", "begin by", "count from".
_START = re.compile(r"\b(?:(?:start|starting|started|begin|beginning|count|counting|work|working)\s+"
                    r"(?:off\s+)?(?:at|from|by|with|beside|next\s+to)|from)\s+(?:the\s+|a\s+|an\s+|my\s+|your\s+|our\s+)?")
#: "pass the closest lamp and take the next", "skip the first two and take the one after".
#: "the chair nearest the hall door", "closest to the kitchen door": the order from that door,
#: as "furthest from the hall door" reverses it (a door only; "nearest the sofa" is a landmark's
#: proximity, read with the other landmarks).
_NEAR = re.compile(r"\b(?:closest|nearest)\s+(?:to\s+)?(?:the\s+|a\s+|an\s+|my\s+|your\s+|our\s+)?")
_SKIP = re.compile(r"\b(?:skip|skipping|pass|passing|ignore|ignoring|miss|missing|bypass|go\s+past|walk\s+past|past)"
                   r"\s+(?:the\s+)?(?:(?P<which>first|nearest|closest)\s+)?(?:(?P<k>one|two|three|four|[1-4])\s+)?")
_NEXT = re.compile(r"\b(?:the\s+)?(?:next(?!\s+to\b)(?:\s+one)?|one\s+after(?:\s+that)?|following\s+one)\b")
_NUMBER = re.compile(r"\b(?:number|no)\s+(?P<k>one|two|three|four|five|[1-5])\b")
#: Words before an ordinal word that make it something else: "for a second", "at first".
_NOT_ORDINAL_BEFORE = {"a", "at", "for"}
_NOT_ORDINAL_AFTER = {"of", "time", "floor", "place", "hand"}


@dataclass
class Count:
    """An ordinal and where it counts from, as read from a goal's words."""

    ordinal: int | None = None
    #: The route's origin: the room behind a named door, or a room one comes in from.
    origin_room: str | None = None
    #: The room the door belongs to ("the office's hall door": the office), when said.
    door_owner: str | None = None
    landmark_category: str | None = None  # "from the fridge": the count is by distance from it
    landmark_phrase: str | None = None
    #: "skip the nearest ...": the order skipped in is distance when no start is said.
    skipped_nearest: bool = False
    spans: list[tuple[int, int]] = field(default_factory=list)  # character spans read (to remove)


def door_room(words: list[str]) -> tuple[str | None, str | None, int] | None:
    """(room behind the door, room it belongs to, words used) of a door phrase at the start of
    ``words``: "hall door", "office hall door" (the office's), "door to the landing", "kitchen
    doorway"; None when ``words`` names no door within its first words."""
    k = next((i for i, w in enumerate(words[:5]) if w in DOORS), None)
    if k is None:
        return None
    behind = room_ending(words, k)
    owner = room_ending(words, k - behind[1]) if behind else None
    used = k + 1
    after = words[k + 1:k + 5]
    if behind is None and after and after[0] in ("to", "into", "of", "from", "for", "onto", "leading"):
        j = 1 + int(after[1:2] == ["to"]) if after[0] == "leading" else 1
        j += int(after[j:j + 1] in (["the"], ["a"], ["my"], ["your"], ["our"]))
        found = room_starting(after, j)
        if found is not None:
            behind = found
            used = k + 1 + j + found[1]
    return (behind[0] if behind else None, owner[0] if owner else None, used)


def read_ordinal(text: str) -> tuple[int | None, bool, list[tuple[int, int]]]:
    """(ordinal, skipped the nearest, character spans that said it) of ``text`` (lower case)."""
    skip, nxt = _SKIP.search(text), _NEXT.search(text)
    if skip and nxt and nxt.start() > skip.start():
        k = NUMBERS.get(skip.group("k") or "one", 1)
        return k + 1, skip.group("which") in ("nearest", "closest"), [(skip.start(), skip.end()),
                                                                        (nxt.start(), nxt.end())]
    m = _NUMBER.search(text)
    if m:
        return NUMBERS[m.group("k")], False, [(m.start(), m.end())]
    words = list(re.finditer(r"[a-z0-9']+", text))
    for k, w in enumerate(words):
        if w.group() not in _ORDINALS:
            continue
        before = words[k - 1].group() if k else ""
        after = words[k + 1].group() if k + 1 < len(words) else ""
        if before in _NOT_ORDINAL_BEFORE or after in _NOT_ORDINAL_AFTER:
            continue
        if _room_after(words, k + 1):
            continue  # "in the second bedroom", "the first small bathroom": the room's, not the target's
        return _ORDINALS[w.group()], False, []
    return None, False, []


def read_count(text: str) -> Count:
    """The ordinal of ``text`` (lower case, normalised) and where it counts from. A door one
    starts from is the route's origin whether or not an ordinal is said ("coming in from the hall
    door, the lamp on your left"); a landmark or a room one starts from only with an ordinal."""
    c = Count()
    c.ordinal, c.skipped_nearest, c.spans = read_ordinal(text)
    starts = [(m, False) for m in _START.finditer(text)] + [(m, True) for m in _NEAR.finditer(text)]
    for m, near in sorted(starts, key=lambda s: s[0].start()):
        rest = text[m.end():].split()
        door = door_room(rest)
        if door is not None:
            behind, owner, used = door
            if behind is None:
                continue  # "from the door": which door is not said
            c.origin_room, c.door_owner = behind, owner
        elif near or c.ordinal is None:
            continue
        elif (room := room_starting(rest, 0)) is not None and not _names_object_after(rest, room[1]):
            c.origin_room, used = room  # "walking in from the hall"
        else:
            cat, span, _ = _find_category(rest[:4])
            if cat is None or span is None or span[0] > 1:
                continue
            c.landmark_category, c.landmark_phrase, used = cat, " ".join(rest[: span[1]]), span[1]
        end = m.end() + len(" ".join(rest[:used]))
        c.spans.append((m.start(), end))
        break
    return c


def _room_after(words: list[re.Match[str]], i: int) -> bool:
    """A room name starts at word ``i`` or the one after it and names no object with the word
    after it ("the second bedroom", but "the first kitchen chair" counts chairs)."""
    toks = [w.group() for w in words]
    for j in (i, i + 1):
        found = room_starting(toks, j) if j < len(toks) else None
        if found is not None and not _names_object_after(toks, j + found[1]):
            return True
    return False


def _names_object_after(words: list[str], n: int) -> bool:
    """"from the kitchen counter": the room word modifies an object noun after it."""
    cat, span, _ = _find_category(words[n:n + 2])
    return cat is not None and span is not None and span[0] == 0


def without(text: str, spans: list[tuple[int, int]]) -> str:
    """``text`` with the character ``spans`` taken out (a space in their place)."""
    for s, e in sorted(spans, reverse=True):
        text = text[:s] + " " + text[e:]
    return " ".join(text.split())
