"""The mapping of a goal's words onto ``ParsedQuery``: the target category (with the other
categories it may denote), colour / shape / size / material words, a spatial predicate (closest /
farthest to the robot or to a landmark, biggest / smallest, next to / near / in front of Y, "the
second closest"), a room ("in the kitchen", "the office lamp"), what the target must not be
("not the white one") and, for requests by purpose ("somewhere to sit"), the categories that serve
it. The phrase patterns here read one goal whose words the parse (``parse.py``) has already
chosen; whatever they do not understand still reaches the embedding similarity."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

from capnav.core.categories import BY_NAME
from capnav.language.colors import ALIASES, LEXICON
from capnav.language.context import ROOM_SYNONYMS
from capnav.language.purpose import (
    MADE_FOR,
    PurposeConfig,
    activity_room,
    find_activity,
    is_placing,
    match_purpose,
    place_adjective,
    purpose_categories,
    room_text,
    split_activity,
)
from capnav.retrieval.query.count import read_count, without
from capnav.retrieval.query.model import ACROSS, BETWEEN, ROOM_WITH, ParsedQuery
from capnav.retrieval.query.parse import _GENERIC, ROOM_ALONG, GoalParse, describe, passed_object
from capnav.retrieval.query.tokens import (
    _COLOUR_OF,
    _COMMON_ADJECTIVES,
    _FILLER,
    _FORM_MAP,
    _GROWTH,
    _GROWTH_TOKENS,
    _LEX,
    _MATERIAL_OF,
    _ORDINALS,
    _PROXIMITY,
    _RELATIONS,
    _SHAPES,
    _SIZE_TOKENS,
    _SUPERLATIVE,
    UNOBSERVED,
    _colors,
    _find_category,
    _fix_keyword_typos,
    _form_follows,
    _other_object,
    _room_before,
    _size_word,
    attribute_word,
    material_of,
    materials_in,
    size_axis,
    size_words,
    validate_instruction,
)

if TYPE_CHECKING:
    from capnav.language.embedder import TextEmbedder

#: "not the white one", "the one that isn't grey", "other than the red one", "except the ...",
#: "neither wood nor metal"; "not the leather one and not the grey one" is two negations.
_NEGATION = re.compile(r"(?:\b(?:that|which|who)\s+)?(?:\bis\s+not\b|\bisn't\b|\bisnt\b|\bnot\b|\bother\s+than\b"
                       r"|\bexcept(?:\s+for)?\b|\bapart\s+from\b|\brather\s+than\b|\binstead\s+of\b"
                       r"|(?:\bis\s+)?\bneither\b(?=.*\bnor\b))"
                       r"\s+(?P<neg>[^,;]+?)(?=\s*(?:[,;]|\bbut\b|\bthe\s+other\b|\b(?:and|or)\s+(?=not\b|isn't\b)|$))")
#: "non-leather", "non wooden": the prefix negates an attribute word.
_NON = re.compile(r"\bnon\s*-?\s*([a-z]+(?:-[a-z]+)?)\b")
#: The robot itself as the reference of closest / farthest.
_SELF = re.compile(r"^(?:me|you|us|here|yourself|the robot|where i am|where you are|my position|"
                   r"your position)\b")
_PROX_WORDS = {"closest": "closest", "nearest": "closest", "farthest": "farthest", "furthest": "farthest",
               "most distant": "farthest"}





#: The comparatives of the distance superlatives ("nearer" of "nearest"), made from them.
_PROX_COMPARATIVES = {w[:-3] + "er": w for w in _PROX_WORDS if " " not in w and w.endswith("est")}
_CMP = "|".join(sorted(_PROX_COMPARATIVES, key=len, reverse=True))
#: A choice among instances said with a comparative: "the nearer of the two sofas", "the closer
#: one of the armchairs", "which lamp is farther away", "which of the beds is closer to me".
_SUP = "|".join(sorted((w for w in _PROX_WORDS if " " not in w), key=len, reverse=True))
_PARTITIVE = re.compile(rf"\bthe\s+(?P<c>{_CMP}|{_SUP})\s+(?:one\s+)?of\s+(?:the\s+|these\s+|those\s+|my\s+)?"
                        r"(?:(?:two|three|four|both|\d+)\s+)?")
_WHICH = re.compile(rf"\bwhich\b[^,;]*?\b(?:is|are|s)\s+(?P<c>{_CMP})\b")


def _comparative_choice(head: str) -> str:
    """``head`` with a choice among instances put as a superlative of the category: "the nearer
    of the two sofas" and "the nearest of the sofas" are "the nearest sofas" (the partitive's
    "of" is no landmark), "which lamp is farther" is "which lamp is farthest". A comparative
    elsewhere stays ("move closer")."""
    m = _PARTITIVE.search(head)
    if m:
        c = m.group("c")
        return f"{head[:m.start()]}the {_PROX_COMPARATIVES.get(c, c)} {head[m.end():]}".strip()
    m = _WHICH.search(head)
    if m:
        return head[:m.start("c")] + _PROX_COMPARATIVES[m.group("c")] + head[m.end("c"):]
    return head


def _landmark_proximity(q: ParsedQuery, head: str) -> str:
    """"the chair closest to the kitchen table", "the plant nearest the bathtub", "the armchair
    farthest from the lamp": an anchor with closest / farthest measured from it. Returns ``head``
    without the landmark phrase."""
    words = "|".join(sorted(_PROX_WORDS, key=len, reverse=True))
    m = re.search(rf"\b(?P<p>{words})\b(?P<mid>(?:\s+\S+)*?)\s*(?:\b(?:to|from|of)\s+|\s+)"
                  rf"(?:the\s+|a\s+|an\s+|my\s+|our\s+)(?P<anchor>.+)$", head)
    if not m or _SELF.match(m.group("anchor")):
        return head
    anchor_words = m.group("anchor").split()
    cat, span, _ = _find_category(anchor_words)
    stand_in = _stand_in_landmark(anchor_words, head[: m.start()]) if cat is None else None
    if stand_in is not None and not stand_in[2]:
        # "the bed nearest the one with the blue cover": another of the target's category.
        q.proximity, q.proximity_to_anchor = _PROX_WORDS[m.group("p")], True
        q.anchor_category, q.anchor_phrase = stand_in[0], stand_in[1]
        return (head[: m.start()] + " " + m.group("mid")).strip()
    if cat is None or span is None:
        return head
    q.proximity = _PROX_WORDS[m.group("p")]
    q.proximity_to_anchor = True
    q.anchor_category = cat
    q.anchor_phrase = " ".join(anchor_words[: span[1]])
    return (head[: m.start()] + " " + m.group("mid") + " " + " ".join(anchor_words[span[1]:])).strip()


#: Verbs of a landmark clause ("the table the grey stool is tucked under", "the bed that the lamp
#: stands beside"): the clause's subject is the landmark, not a description of the target.
_CLAUSE_VERB = re.compile(r"\b(?:is|are|was|were|sits|sit|stands|stand|rests|lies|has\s+been)\b")


_ARTICLE = r"(?:the\s+|a\s+|an\s+|my\s+|our\s+|your\s+)?"
#: Words that may describe a room before its name: not a preposition, article or conjunction
#: (which would start another phrase) and not an object's name (the room's own words come after).
_ROOM_MODIFIERS = r"(?:(?!(?:in|on|at|of|by|to|from|near|next|with|and|or|the|a|an|my|our|your|this|that)\b)" \
    r"[a-z][a-z'-]*\s+){0,2}"
_ROOM_ALT = "|".join(re.escape(r) for r in sorted(ROOM_SYNONYMS, key=len, reverse=True))


def _landmark(words: list[str]) -> tuple[str, str, list[str]] | None:
    """(category, phrase up to its noun, the words after it) of a landmark phrase, else None."""
    cat, span, _ = _find_category(words)
    if cat is None or span is None:
        return None
    return cat, " ".join(words[: span[1]]), words[span[1]:]


def _room_with(q: ParsedQuery, head: str) -> str:
    """"in the room with the green wardrobe", "in the bedroom that has the grey bed": the target
    stands in the landmark's room (``ROOM_WITH``); a named room type is kept as the room too.
    Returns ``head`` without the clause."""
    m = re.search(rf"\b(?:in|inside|within)\s+{_ARTICLE}(?P<room>{_ROOM_ALT}|room)\s+(?:with|that\s+has|which\s+has"
                  rf"|where\s+there\s+is|containing)\s+{_ARTICLE}(?P<anchor>.+)$", head)
    if not m:
        return head
    found = _landmark(m.group("anchor").split())
    if found is None:
        return head
    q.relation, q.anchor_category, q.anchor_phrase = ROOM_WITH, found[0], found[1]
    if m.group("room") != "room":
        q.room = ROOM_SYNONYMS[m.group("room")]
    return " ".join([head[: m.start()], *found[2]]).strip()


#: A clause of its own inside a purpose request: "... while I watch telly", "... when we eat".
_CONTEXT_CLAUSE = re.compile(r"\b(?:while|whilst|when|as|and)\s+(?:i|we|you)\s+(?:(?:can|could|am|are|'m)\s+)?"
                             r"(?P<ctx>.+)$")


def _purpose_context(q: ParsedQuery, head: str) -> str:
    """A purpose request with a clause of its own that names an object ("somewhere to rest my
    plate while we watch the tv"): the object is the setting, not the target; the target is
    looked for in the room with it (``ROOM_WITH``). Returns ``head`` without the clause."""
    if find_activity(head) is None:
        return head
    m = _CONTEXT_CLAUSE.search(head)
    if m is None or find_activity(head[: m.start()]) is None:
        return head
    words = m.group("ctx").split()
    cat, span, _ = _find_category(words)
    if cat is None or span is None:
        return head
    q.relation, q.anchor_category, q.anchor_phrase = ROOM_WITH, cat, " ".join(words[span[0]:span[1]])
    return head[: m.start()].strip()


_REL_ALT = "|".join(re.escape(r) for r in sorted(_RELATIONS, key=len, reverse=True))
#: A landmark between the place word and its purpose: "somewhere right by the bed to put my glass",
#: "anywhere near the sofa where I can set down a book".
_PLACE_LANDMARK = re.compile(
    r"\b(?:somewhere|someplace|anywhere|(?:a|some)\s+(?:place|spot|surface|space)|something|anything)"
    r"(?P<mid>\s+(?:right\s+|just\s+)?(?P<rel>" + _REL_ALT + r")\s+" + _ARTICLE + r"(?P<lm>.+?))"
    r"\s+(?=(?:to|where|for|on\s+which|that)\b)")


def _place_landmark(q: ParsedQuery, head: str) -> str:
    """"somewhere right by the bed to put my glass": the landmark said between the place word and
    the purpose is where the place is, not what is asked for. Returns ``head`` without it."""
    m = _PLACE_LANDMARK.search(head)
    if m is None:
        return head
    found = _landmark(m.group("lm").split())
    if found is None or found[2]:
        return head
    rel = m.group("rel")
    q.relation = relation_name(rel)
    q.anchor_category, q.anchor_phrase = found[0], found[1]
    return (head[: m.start("mid")] + head[m.end("mid"):]).strip()


#: A landmark named by what is done there: "next to where I sleep", "by the spot where we eat".
_ACTIVITY_PLACE = re.compile(
    r"\b(?P<rel>" + "|".join(re.escape(r) for r in sorted(_RELATIONS, key=len, reverse=True)) + r")\s+"
    r"(?:(?:the|a)\s+(?:place|spot|area|bit)\s+)?where\s+(?P<who>(?:i|we|you|one|they|he|she)|(?:the|my|our|your|his"
    r"|her|their)\s+\w+)\s+(?:usually\s+|normally\s+|always\s+)?(?P<act>(?!(?:is|are|was|were)\b)\w+(?:\s+\w+){0,5}?)"
    r"(?=\s*(?:[,;]|$|\b(?:in|and|but|so|please)\b))")


def _activity_landmark(q: ParsedQuery, head: str, embedder: TextEmbedder | None) -> str:
    """"where can I leave my phone next to where I sleep": the landmark is named by the activity
    done at it, resolved like a request by purpose (the furniture made for sleeping); the target
    is what the rest of the sentence asks for. Returns ``head`` without the landmark phrase."""
    if embedder is None or "where" not in head:
        return head
    m = _ACTIVITY_PLACE.search(head)
    if m is None or m.start() == 0:
        return head
    best, _ = purpose_categories(match_purpose(m.group("act"), embedder))
    if best is None:
        return head
    rel = m.group("rel")
    q.relation = relation_name(rel)
    q.anchor_category, q.anchor_phrase = best, best
    q.notes.append(f"'where {m.group('who')} {m.group('act')}' is read as the {best} (what serves it)")
    return (head[: m.start()] + " " + head[m.end():]).strip()


def _between(q: ParsedQuery, head: str) -> str:
    """"the lamp between the black bed and the white wardrobe": two landmarks, each with its
    own words. Returns ``head`` without them."""
    m = re.search(rf"\b(?:in\s+)?between\s+{_ARTICLE}(?P<a>.+?)\s+and\s+{_ARTICLE}(?P<b>.+)$", head)
    if not m or m.start() == 0:
        return head
    first, second = _landmark(m.group("a").split()), _landmark(m.group("b").split())
    if first is None or second is None or first[2]:
        return head
    q.relation = BETWEEN
    q.anchor_category, q.anchor_phrase = first[0], first[1]
    q.anchor2_category, q.anchor2_phrase = second[0], second[1]
    return " ".join([head[: m.start()], *second[2]]).strip()


def _stand_in_landmark(words: list[str], before: str) -> tuple[str, str, list[str]] | None:
    """A landmark said by a word standing in for the target's own category ("the sink opposite
    the black one", "the lamp beside the other one"): (the category named before it, the
    landmark's words, the words after it). The landmark is then another instance of the target's
    category, picked by its own words. None when ``words`` name a category or no stand-in."""
    if _landmark(words) is not None:
        return None
    k = next((i for i, w in enumerate(words) if w in ("one", "ones")), None)
    target = _landmark(before.split())
    if k is None or target is None:
        return None
    after = words[k + 1:]
    if after and after[0] in _STAND_IN_POSTMODIFIERS and not any(
            re.search(rf"\b{re.escape(r)}\b", " ".join(after)) for r in ROOM_SYNONYMS):
        # "next to the one in the navy pot", "nearest the one with the blue cover": a phrase
        # after the stand-in that names no room describes the landmark (the nearer noun), so its
        # colour picks the landmark and is never the target's.
        return target[0], " ".join(words), []
    return target[0], " ".join(words[: k + 1]), after


#: Words that start a phrase describing the noun before them ("the one with ...", "in ...").
_STAND_IN_POSTMODIFIERS = {"in", "with", "that", "which", "having", "wearing", "covered", "made"}


#: "across the coffee table from the grey one", "facing the red one across the coffee table":
#: the target and a landmark on either side of a second landmark.
_ACROSS = [
    re.compile(rf"\b(?:directly\s+|right\s+|straight\s+)?(?:across|over|on\s+the\s+(?:other|far|opposite)\s+side"
               rf"\s+of)\s+{_ARTICLE}(?P<mid>.+?)\s+from\s+{_ARTICLE}"
               rf"(?P<lm>.+)$"),
    re.compile(rf"\b(?:directly\s+|right\s+|straight\s+)?(?:facing|opposite|across\s+from|looking\s+at)\s+"
               rf"{_ARTICLE}(?P<lm>.+?)\s+(?:across|over|on\s+the\s+other\s+side\s+of)\s+{_ARTICLE}(?P<mid>.+)$"),
]


def _across(q: ParsedQuery, head: str) -> str:
    """"the armchair across the coffee table from the light grey one": the landmark (``anchor``)
    and the object between it and the target (``anchor2``); either may be a stand-in for the
    target's category. Returns ``head`` without the phrase."""
    for pat in _ACROSS:
        m = pat.search(head)
        if not m or m.start() == 0:
            continue
        before = head[: m.start()]
        mid = _landmark(m.group("mid").split())
        lm = _landmark(m.group("lm").split()) or _stand_in_landmark(m.group("lm").split(), before)
        if mid is None or lm is None or mid[2] or lm[2]:
            continue
        q.relation = ACROSS
        q.anchor_category, q.anchor_phrase = lm[0], lm[1]
        q.anchor2_category, q.anchor2_phrase = mid[0], mid[1]
        return before.strip()
    return head


def _clause_landmark(q: ParsedQuery, head: str) -> str:
    """"the table the grey stool is tucked under", "the bed that the green lamp stands beside":
    a second noun phrase after the target, followed by a verb, is a landmark next to the target;
    its words (colours, sizes) are the landmark's. Returns ``head`` without the clause."""
    words = head.split()
    cat, span, _ = _find_category(words)
    if cat is None or span is None:
        return head
    k = span[1]
    if k < len(words) and words[k] in ("that", "which", "where"):
        k += 1
    if k >= len(words) or words[k] not in ("the", "a", "an", "my", "our"):
        return head
    rest = " ".join(words[k + 1:])
    m = _CLAUSE_VERB.search(rest)
    if m is None or m.start() == 0:
        return head
    anchor_words = rest[: m.start()].split()
    acat, aspan, _ = _find_category(anchor_words)
    if acat is None or aspan is None or aspan[1] != len(anchor_words):
        return head
    q.relation = "next to"
    q.anchor_category = acat
    q.anchor_phrase = " ".join(anchor_words)
    return " ".join(words[: span[1]])


def _put_down(words: list[str]) -> bool:
    """Whether ``words`` hold a verb of putting a thing down (the lexicon's placing verbs,
    WordNet's, in any inflection; ``is_placing`` reads -ing and -s, the past tense is tried here):
    what follows "on" is where it was put."""
    for i, w in enumerate(words):
        past = [w[:-1], w[:-2]] if w.endswith("ed") else [_LEX.placing_past[w]] if w in _LEX.placing_past else []
        if is_placing(" ".join(words[i:i + 2])) or any(is_placing(stem) for stem in past):
            return True
    return False


def _passed_objects(q: ParsedQuery, head: str) -> str:
    """An object walked past before any object is named (``parse.passed_object``: "go past the
    sofa and stop at the bookshelf") is passed, not the goal, when another object is named after
    it: its phrase is taken out, with a note."""
    words = head.split()
    p = passed_object(words)
    if p is None or _find_category(words[p[1]:])[0] is None:
        return head
    q.notes.append(f"the {' '.join(words[p[0] + 1:p[1]])} is passed on the way, not the goal")
    return " ".join([*words[:p[0]], *words[p[1]:]])


def _shapes(words: list[str]) -> list[str]:
    """The shapes ``words`` name, once each. "Corner" is a shape only right before an object's
    name ("the corner sofa"); "in the corner" says where a thing stands. A shape word before a
    word of direction says how to go ("straight to", "round the back")."""
    def names_object_at(i: int) -> bool:
        span = _find_category(words[i:i + 2])[1]
        return span is not None and span[0] == 0

    def of_the_motion(i: int) -> bool:
        # "go straight to the sofa", "head straight ahead", "come round the back": a shape word
        # before a preposition, an adverb of direction or a determiner says how to go, not a shape.
        return i + 1 < len(words) and words[i + 1] in _MOTION_NEXT

    return list(dict.fromkeys(_SHAPES[w] for i, w in enumerate(words)
                              if w in _SHAPES and (w != "corner" or names_object_at(i + 1)) and not of_the_motion(i)))


_MOTION_NEXT = {"to", "towards", "toward", "for", "ahead", "on", "onto", "through", "into", "over", "across",
                "past", "back", "down", "up", "away", "at", "there", "here", "along", "the", "a", "an", "my",
                "your", "our", "this"}


def relation_name(rel: str) -> str:
    """The relation a phrase says: "beside", "by", "close to" are "next to"; "on the left-hand side
    of", "to the left of" are "left of" (and right); "on" and "atop" are "on top of"; the others as
    said."""
    if rel in ("besides", "beside", "by", "close to", "alongside", "at"):
        return "next to"
    if rel in ("on", "atop"):
        return "on top of"
    for side in ("left", "right"):
        if rel.endswith(" of") and side in rel.split() + rel.replace("-", " ").split():
            return f"{side} of"
    return rel


def negated_relation(phrase: str) -> tuple[str, str, str] | None:
    """(relation, landmark category, landmark phrase) when a negated phrase is a relation to a
    landmark the vocabulary names ("beside the bed", "next to the white counter"), else None."""
    low = phrase.lower().strip()
    for rel in sorted(_RELATIONS, key=len, reverse=True):
        if low.startswith(rel + " "):
            rest = low[len(rel):].split()
            while rest and rest[0] in _DETERMINERS:
                rest = rest[1:]
            cat, _, _ = _find_category(rest)
            return None if cat is None else (rel, cat, " ".join(rest))
    return None


def _split_alternatives(words: list[str]) -> list[list[str]]:
    """"purple or orange", "red nor blue", "the white or the grey one": one negated phrase per
    alternative, so each is excluded on its own (a phrase is excluded only when all of it fits)."""
    parts: list[list[str]] = [[]]
    for w in words:
        if w in ("or", "nor"):
            parts.append([])
        else:
            parts[-1].append(w)
    return [p for p in parts if p]


#: Prepositions of the place where a verb's action happens ("lie down on", "sit at", "relax in").
_VERB_PLACE_PREPS = ("on", "at", "in", "onto", "into")


def _negations(q: ParsedQuery, head: str) -> str:
    """Fill ``q.negations`` with what the target must not be, as short phrases a parse of their own
    reads ("white", "in the bedroom"); returns ``head`` without them. The negated phrase's category
    still names the target ("not the black stove, the other one")."""
    out = head
    for m in list(_NEGATION.finditer(head))[::-1]:
        words = m.group("neg").split()
        if words and words[0] in _VERB_PLACE_PREPS and _find_category(out[: m.start()].split())[0] is None \
                and _find_category(words[1:])[0] is not None:
            # "somewhere to lie down, but not on the orange bed": with no object named before it,
            # "on" is the place of the activity's verb (as "sit on the armchair" is the goal), so
            # the bed is what is excluded, not what stands on it.
            words = words[1:]
        if negated_relation(" ".join(words)) is not None:
            # "the lamp that's not beside the bed": the bed is the excluded relation's landmark,
            # not the target; the phrase is excluded whole (``constraints.negation``).
            out = out[: m.start()] + " " + out[m.end():]
            q.negations.append(" ".join(words))
            continue
        cat, span, _ = _find_category(words)
        before = _find_category(out[: m.start()].split())[0]
        # The wanted one may be said after the negation ("not the desk, the cabinet by the wall",
        # "not either of the desks but the cabinet"): another category there names the target too.
        after = _find_category(_after_negation(out[m.end():]).split())[0]
        # A request by purpose names no category of its own ("somewhere to sit, not the sofa"):
        # the negated one is excluded from the furniture that serves it, not made the target.
        by_use = before is None and after is None and find_activity(out[: m.start()]) is not None
        if cat is not None and ((before is not None and before != cat) or (after is not None and after != cat)
                                or by_use):
            # "the sink, not the bathtub": another kind than the one asked for is excluded whole.
            out = out[: m.start()] + " " + out[m.end():]
            if by_use and span is not None:
                words = words[: span[1]]  # "..., but not on the sofa please": the sofa
            q.negations.append(" ".join(w for w in words if w not in _DETERMINERS))
            continue
        if cat is not None and span is not None:
            out = out[: m.start()] + " " + " ".join(words[span[0]:span[1]]) + " " + out[m.end():]
            words = words[:span[0]] + words[span[1]:]
        else:
            out = out[: m.start()] + " " + out[m.end():]
        for part in _split_alternatives(words)[::-1]:
            while part and part[0] in ("the", "a", "an", "one", "other", "that", "which", "is", "are", "be"):
                part = part[1:]
            part = [w for w in part if w not in ("one", "ones", "other")]
            if part:
                q.negations.append(" ".join(part))
    out = re.sub(r"\bthe\s+other\s+(?:one|of\s+the\s+two)\b", " ", out)
    return " ".join(out.split())


def _material_nouns_after(words: list[str], end: int) -> list[str]:
    """The words of the lexicon's ``material_nouns`` after ``end`` (the target's noun) that follow
    a preposition of what a thing is made of or covered in ("of", "from", "in", "with"); a colour
    word only after one of what it is made of ("of", "from": "made from oak"; "in khaki" is a
    colour)."""
    out, covered, made = [], False, False
    for w in words[end:]:
        covered = covered or w in ("of", "from", "in", "with")
        made = made or w in ("of", "from")
        colour = w in LEXICON or w in ALIASES or w in _COLOUR_OF
        if (made if colour else covered) and w in _LEX.material_nouns and material_of(w) is None:
            out.append(w)
    return out


def _knows(w: str) -> bool:
    """``w`` says an attribute: a colour, shape or material word, or one of the lexicon's."""
    return (w in LEXICON or w in ALIASES or w in _COLOUR_OF or w in _SHAPES or material_of(w) is not None
            or w in _LEX.attributes)


def _joined_compounds(words: list[str]) -> list[str]:
    """A verb and its particle said apart that the lexicon knows as one hyphenated attribute ("a
    table you can see through", "see right through": WordNet's "see-through", glass): the two
    words become that form; an adverb between them ("right", "straight", "clean") goes with them.
    Words that say something alone are read alone ("light blue" stays a light blue, not the
    lexicon's "light-blue"), and a determiner, a conjunction, a preposition ("see into through
    the top": through the top is a part) or an object word between them is another phrase. A word
    of how it looks ("boxy-looking") is its first part when that part is an attribute word."""
    # "boxy-looking", "glassy-seeming": how it looks is what its first part says.
    out = [w.rsplit("-", 1)[0] if re.fullmatch(r"[a-z]+-(?:looking|seeming)", w)
           and _knows(w.rsplit("-", 1)[0]) else w for w in words]
    k = 0
    while k < len(out) - 1:
        for gap in (1, 2):
            if k + gap >= len(out):
                break
            form = f"{out[k]}-{out[k + gap]}"
            said = any(w in LEXICON or w in ALIASES or w in _COLOUR_OF or w in _SHAPES or material_of(w) is not None
                       or _find_category([w])[0] is not None for w in out[k:k + gap + 1])
            apart = any(w in _DETERMINERS or w in _FILLER or w in _PREPOSITIONS for w in out[k + 1:k + gap])
            if form in _LEX.attributes and not said and not apart:
                out[k:k + gap + 1] = [form]
                break
        k += 1
    return out


_PREPOSITIONS = _MOTION_NEXT | {"in", "out", "under", "off", "from", "of", "by", "with", "behind", "inside"}


#: Words that say a part follows: "the dresser with the glass top", "a stool that has a leather seat".
_HAVING = {"with", "has", "having", "have"}
_PART_DETERMINERS = {"a", "an", "the", "its", "their", "some", "two", "three", "four"}


#: "... at it", "... next to it", "... around them": the pronoun that points back at the target.
_BACK_TO_TARGET = re.compile(r"\s+(?:at|by|next to|beside|around|round|in front of|near|under|in|on)\s+(?:it|them)\s*$")


def _with_landmark(q: ParsedQuery, head: str) -> str:
    """"the desk with the blue chair at it", "the table that has the green stools round it": a
    category after "with" / "that has" that is no piece of the target (``_own_piece``: "a chair
    with a velvet seat" is) is another object beside it, a landmark "next to" the target, and
    the words said of it (blue, green) are the landmark's, not the target's. Returns ``head``
    without the phrase."""
    m = re.search(r"\b(?:with|(?:that|which)\s+(?:has|have)|having)\s+(?:the\s+|a\s+|an\s+|some\s+|its\s+)?(.+)$",
                  head)
    if m is None or m.start() == 0:
        return head
    before = head[:m.start()].split()
    points_back = _BACK_TO_TARGET.search(m.group(1)) is not None
    anchor = _BACK_TO_TARGET.sub("", m.group(1)).strip()
    words = anchor.split()
    target, _, _ = _find_category(before)
    cat, span, fuzzy = _find_category(words)
    # Not a word read as a category only by a typo's spelling ("stone" for a stove), nor the
    # target's own category ("the bookshelf with the sparse shelves": its own shelves).
    if target is None or cat is None or span is None or fuzzy or cat == target \
            or _own_piece(words[span[1] - 1], before):
        return head
    # Only when the phrase says it is another object: words of its own ("the blue chair") or a
    # pointer back at the target ("... at it"); "the dresser with the mirror" may be one piece.
    if not points_back and not any(attribute_word(w) for w in words[: span[0]]):
        return head
    q.relation, q.anchor_category, q.anchor_phrase = "next to", cat, anchor
    return head[:m.start()].strip()


def _own_piece(part: str, before: list[str]) -> bool:
    """A category word after "with" is a piece of the target, not another object, when WordNet
    lists it as a part (the lexicon's ``part_nouns``) and it names the target's own category or
    one that may stand in for it: "a chair with a velvet seat" (seat.n.04, a part of seat.n.03 above
    chairs and sofas), "the sofa with the leather seats"; "the counter with the wooden stool" is a
    stool beside it (a stool is a part only of a toilet in WordNet, and no counter's stand-in)."""
    head = _find_category(before)[0]
    named = _find_category([part])[0]
    if head is None or named is None or part not in _LEX.part_nouns:
        return False
    return named == head or named in _LEX.category_alternatives(head, None)


def _without_parts(q: ParsedQuery, words: list[str]) -> list[str]:
    """``words`` without the materials and shapes said of a part ("the dresser with the glass top":
    glass is the top's; "rounded arms"), which go to ``q.part_materials`` / ``q.part_shapes`` with a
    note: the map observes an object's surface and footprint as a whole, not its parts apart, so a
    part's material or shape is neither for nor against it. A part is
    the first word after "with" / "has" and its modifiers that no table of the lexicon holds (not
    a category, colour, material, size or shape word) and no noun of how the whole looks or feels
    ("the sofa with the velvety feel", "a walnut finish": the lexicon's ``surface_nouns``): "the
    table with glass" keeps its glass."""
    out = list(words)
    for k, w in enumerate(words):
        if w not in _HAVING:
            continue
        j = k + 1
        while j < len(words) and words[j] in _PART_DETERMINERS:
            j += 1
        mods = j
        while j < len(words) and (material_of(words[j]) is not None or words[j] in LEXICON or words[j] in ALIASES
                                  or words[j] in _SHAPES or words[j] in _SIZE_TOKENS):
            j += 1
        if j == mods or j >= len(words):
            continue
        part = words[j]
        if not part.isalpha() or part in _FILLER or part in _HAVING or part in _LEX.surface_nouns \
                or (_find_category([part])[0] is not None and not _own_piece(part, words[:k])):
            continue
        mats = materials_in(words[mods:j])
        shapes = list(dict.fromkeys(_SHAPES[w] for w in words[mods:j] if w in _SHAPES)) \
            if part in _LEX.part_nouns else []  # "curved edges": the whole's outline, not a piece
        if not mats and not shapes:
            continue
        for said, table in ((mats, q.part_materials), (shapes, q.part_shapes)):
            if said:
                table.setdefault(part, []).extend(m for m in said if m not in table.get(part, []))
        q.notes.append(f"{'/'.join([*mats, *shapes])} is said of its {part}, which the map does not observe "
                       f"apart (neither for nor against it)")
        for i in range(mods, j):
            if material_of(words[i]) is not None or (shapes and words[i] in _SHAPES):
                out[i] = ""
    return [w for w in out if w]


def _after_negation(rest: str) -> str:
    """The words after a negated phrase up to the next negation: those of the phrase that says
    which one is meant ("..., the cabinet by the wall"; "... but the cabinet")."""
    rest = re.sub(r"^\s*(?:[,;]|\bbut\b)\s*", " ", rest)
    nxt = _NEGATION.search(rest)
    return rest[: nxt.start()] if nxt is not None else rest


_FROM_ROBOT = "the robot"
_DETERMINERS = {"the", "a", "an", "my", "our", "your", "his", "her", "their", "this", "that", "these", "those", "some"}


def _verb_only(before: str) -> bool:
    """Whether the words before a relation are a verb of going and nothing that names a target
    ("swing", "pop", "could you nip"): at most two words besides the request's fillers, no
    determiner (a noun phrase has one: "the piano by the sofa"), no object name."""
    words = [w for w in before.split() if w not in _FILLER or w in _DETERMINERS]
    if not words:
        return True  # "go by the desk", "stop by the sofa"
    if len(words) > 2 or any(w in _DETERMINERS or w in _GENERIC for w in words):
        return False
    cat, _, _ = _find_category(words)
    return cat is None and find_activity(before) is None


def _attributes_outside(q: ParsedQuery, head: str, activity: str) -> None:
    """A request by purpose describes the furniture outside its activity: "where can I chill a
    bottle of wine" asks for no wine-coloured fridge, "somewhere to hang my blue coat" for no blue
    wardrobe. The attributes are read again from the words around the activity."""
    k = head.find(activity)
    if k < 0:
        return
    words = (head[:k] + " " + head[k + len(activity):]).split()
    q.colors = _colors(words)
    q.shapes = _shapes(words)
    q.materials = materials_in(words)
    q.size_word, q.size_axis = _size_word(words)
    q.more_sizes = [(s, a) for s, a in size_words(words) if a != q.size_axis]


def _count(q: ParsedQuery, head: str) -> str:
    """Fill the ordinal and where it counts from (``count.read_count``); returns ``head`` without
    the words that said them, so that a landmark the count starts at is never the target."""
    c = read_count(head)
    if c.ordinal is None and c.origin_room is None:
        return head
    q.ordinal = c.ordinal
    if c.origin_room is not None:
        q.origin_room = c.origin_room
        q.ordinal_from = f"the way in from the {c.origin_room}" if c.ordinal else None
        if c.door_owner is not None and c.door_owner != c.origin_room:
            q.room = c.door_owner  # "the office's hall door": the count is in the office
    elif c.landmark_category is not None:
        q.anchor_category, q.anchor_phrase = c.landmark_category, c.landmark_phrase
        q.proximity, q.proximity_to_anchor = "closest", True
        q.ordinal_from = c.landmark_phrase
    elif c.skipped_nearest:
        # "skip the nearest chair and take the next": the second closest (to the robot, unless
        # the route's origin comes from the parse: ``goal_query``)
        q.proximity, q.ordinal_from = "closest", _FROM_ROBOT
    return without(head, c.spans)


def _without_modifying_categories(act: str) -> str:
    """The activity without a category word that only says what another thing handled is for
    ("put the bath towels on a cycle" -> "put the towels on a cycle"): WordNet's compound names
    the towel, and its "bath" is no furniture the activity asks for."""
    words = act.split()
    out = []
    for k, w in enumerate(words):
        nxt = " ".join(words[k:k + 2])
        if k + 1 < len(words) and w in _LEX.forms and (nxt in _LEX.other or nxt[:-1] in _LEX.other):
            continue
        out.append(w)
    return " ".join(out) or act


def _described_place(q: ParsedQuery, head: str, best: str | None, alts: dict[str, float],
                     scores: dict[str, float]) -> tuple[str | None, dict[str, float]]:
    """"a cosy place to read": the adjective said of the place is what the furniture's own
    definitions say (WordNet: cosy is comfortable, "a comfortable upholstered armchair"), so of
    the categories that serve the activity (within the purpose margin of the best fit, however
    many there are) the ones it describes come first; when no furniture is made for the activity
    (its best fit below ``MADE_FOR``), the furniture the adjective describes is the place."""
    adj = place_adjective(head)
    said = _LEX.gloss_adjectives.get(adj or "", ())
    top = scores.get(best or "", 0.0)
    fit = [c for c in said if c == best or c in alts or scores.get(c, -1.0) >= top - PurposeConfig().margin]
    if not fit and top < MADE_FOR:
        fit = list(said)  # nothing is made for the activity ("read": a lamp allows it): the place as described
    if best is None or not fit or fit[0] == best:
        return best, alts
    new = fit[0]
    out = {best: round(min(0.95, alts.get(new, 0.95)), 3), **{c: w for c, w in alts.items() if c != new}}
    q.notes.append(f"'{adj}' place: WordNet's definitions say it of the {new}, which serves '{q.purpose}' too")
    return new, dict(sorted(out.items(), key=lambda kv: -kv[1]))


#: Two-word forms by their first word ("wing" -> ["wing chair"]).
_FORMS_BY_FIRST: dict[str, list[str]] = {}
for _form in _FORM_MAP:
    _parts = _form.split()
    if len(_parts) == 2 and _parts[0].isalpha():
        _FORMS_BY_FIRST.setdefault(_parts[0], []).append(_form)


def _closed_compound_alone(words: list[str], cat: str | None, span: tuple[int, int] | None, fuzzy: bool
                           ) -> tuple[list[str], str | None, tuple[int, int] | None, bool]:
    """"the wingback": a word no table knows, eight letters or more and no verb's inflection
    (-ing, -ed), whose longest start of four letters or more (leaving four: a second word, not a
    suffix) is the first word of two-word forms of one category only (WordNet's "wing chair")
    names that category, read as that form."""
    for k, w in enumerate(words):
        if len(w) < 8 or not w.isalpha() or w.endswith(("ing", "ed")) or w in _FORM_MAP or _knows(w) \
                or w in _FILLER:
            continue
        for n in range(len(w) - 4, 3, -1):
            forms = _FORMS_BY_FIRST.get(w[:n], [])
            if forms and len({_FORM_MAP[f] for f in forms}) == 1:
                new = [*words[:k], *sorted(forms)[0].split(), *words[k + 1:]]
                c2, s2, f2 = _find_category(new)
                if c2 is not None:
                    return new, c2, s2, f2
                break
    return words, cat, span, fuzzy


def _compound_kind(words: list[str], cat: str | None, span: tuple[int, int] | None, fuzzy: bool
                   ) -> tuple[list[str], str | None, tuple[int, int] | None, bool]:
    """"the wing-back chair", "a wingbacked chair": a compound modifier whose first part, said with
    the object noun, is a form of a kind of the named category (WordNet's "wing chair", an
    armchair) names that kind. The first part is the word before a hyphen, or the longest start
    (four letters or more, leaving three or more) of a closed compound the lexicon does not know."""
    if cat is None and span is None:
        return _closed_compound_alone(words, cat, span, fuzzy)
    if cat is None or span is None or span[0] == 0 or fuzzy:
        return words, cat, span, fuzzy
    prev, noun = words[span[0] - 1], " ".join(words[span[0]:span[1]])
    if "-" in prev:
        parts = [prev.split("-", 1)[0]]
    elif prev in _FORM_MAP or _knows(prev) or not prev.isalpha():
        parts = []
    else:
        parts = [prev[:n] for n in range(len(prev) - 3, 3, -1)]
    kinds = _LEX.relations.get(cat, {})
    for part in parts:
        kind = _FORM_MAP.get(f"{part} {noun}")
        if kind is not None and kind != cat and kinds.get(kind, {}).get("kind_of"):
            new = [*words[:span[0] - 1], part, *words[span[0]:]]
            c2, s2, f2 = _find_category(new)
            if c2 == kind:
                return new, c2, s2, f2
    return words, cat, span, fuzzy


#: What an act is done with, after it: "sit [with my cup of tea]", "lie down [with a book]".
_COMPANY = re.compile(r"\s+with\s+(?:my|a|an|the|some|our|your|his|her|their|this|that)\b.*$")


def _without_company(act: str) -> str:
    """The act without what it is done with ("sit with my morning coffee" -> "sit"): the act says
    the furniture; what accompanies it would draw a category whose definition names that thing
    (a coffee table's "where coffee is served")."""
    bare = _COMPANY.sub("", act).strip()
    return bare or act


def read_goal(text: str, embedder: TextEmbedder | None = None) -> ParsedQuery:
    """Read ``text``. With ``embedder`` (the retriever's), a request by purpose ("somewhere to
    sit") is mapped to categories through the lexicon's glosses; without one it keeps ``purpose``
    and no category."""
    t = validate_instruction(text)
    low = t.lower()
    # Commas and semicolons stay until the negations are read: a negated phrase ends at one
    # ("not the one in the office, the one in the bedroom").
    norm = re.sub(r"[^a-z0-9\-',; ]+", " ", low).replace(",", " , ").replace(";", " ; ")
    norm = re.sub(r"\b(\w+)n't\b", r"\1 not", norm.replace("isn't", "is not").replace("isnt", "is not"))
    norm = " ".join(_fix_keyword_typos(norm.replace("'s", "").split()))
    # "the non-leather sofa": the prefix negates that attribute word alone (not the clause after it).
    non = [x for x in _NON.finditer(norm) if attribute_word(x.group(1))]
    for x in non[::-1]:
        norm = norm[: x.start()] + norm[x.end():]
    norm = " ".join(norm.split())
    q = ParsedQuery(text=t)
    head = " ".join(re.sub(r"[,;]", " ", _negations(q, norm)).split())
    norm = " ".join(re.sub(r"[,;]", " ", norm).split())
    q.negations += [x.group(1) for x in non]
    # "go past the sofa and stop at the bookshelf": the sofa is passed on the way.
    head = _passed_objects(q, head)
    # "somewhere to rest my plate while we watch the tv": the tv is where, not what.
    head = _purpose_context(q, head)
    # "somewhere right by the bed to put my glass": the landmark of the place asked for.
    head = _place_landmark(q, head)
    # "somewhere to leave my phone next to where I sleep": a landmark named by its use.
    if q.anchor_category is None:
        head = _activity_landmark(q, head, embedder)
    # "the lamp in the room with the green wardrobe", "the dresser in the bedroom with the grey bed".
    head = _room_with(q, head)
    # An ordinal and where it counts from: "the second stool from the fridge", "number two from
    # the hall door", "pass the closest lamp and take the next".
    head = _count(q, head)
    # Room: "in the kitchen", "in the living room", and a room walked along ("down the hall"):
    # the parse's reading of the same words (``ROOM_ALONG``), for requests too short to parse.
    # Up to two words between the article and the room name describe the room ("the main
    # bedroom", "the blue bedroom", "the second bedroom"): they go with it, never to the target.
    preps = "|".join(("in", "inside", "within", "from", "of", *ROOM_ALONG))
    for phrase in sorted(ROOM_SYNONYMS, key=len, reverse=True):
        if phrase not in head:  # cheap test first: a one-shot query compiles only the patterns it needs
            continue
        # Not when the room word modifies an object noun ("at the end of the kitchen counter").
        pat = rf"\b(?:{preps})\s+(?:the\s+|my\s+|our\s+)?{_ROOM_MODIFIERS}{re.escape(phrase)}\b"
        m = next((m for m in re.finditer(pat, head) if not _form_follows(head, m.end())), None)
        if m:
            q.room = ROOM_SYNONYMS[phrase]
            # "the yellow bedroom": a colour among the room's own modifiers tells rooms apart.
            said = re.sub(rf"^(?:{preps})\s+(?:the\s+|my\s+|our\s+)?", "", m.group(0))
            q.room_colors = _colors(said[: len(said) - len(phrase)].split())
            head = (head[:m.start()] + " " + head[m.end():]).strip()
            break
    head = _comparative_choice(head)
    # Ordinal: "the second closest", "the 3rd biggest".
    m = re.search(r"\b(first|second|third|fourth|fifth|1st|2nd|3rd|4th|5th)\s+(?=(?:closest|nearest|farthest"
                  r"|furthest|most distant|biggest|largest|smallest|tiniest|tallest|widest|littlest|narrowest)\b)",
                  head)
    if m:
        q.ordinal = _ORDINALS[m.group(1)]
        head = (head[:m.start()] + head[m.end():]).strip()
    # Closest / farthest to a landmark, before relations ("closest to the table" is no "close to").
    head = _landmark_proximity(q, head)
    # Proximity to the robot (checked before relations so that "closest to me" is not a relation).
    if q.proximity is None:
        for phrase in sorted(_PROXIMITY, key=len, reverse=True):
            if phrase in head and re.search(rf"\b{phrase}\b", head):
                q.proximity = _PROXIMITY[phrase]
                head = re.sub(rf"\b{phrase}\b", " ", head)
                break
        head = re.sub(r"\b(?:to|from)\s+(?:me|you|us|here|the robot)\b|\baway\b", " ", head) \
            if q.proximity else head
    # A landmark clause: "the table the grey stool is tucked under".
    if q.anchor_category is None:
        head = _clause_landmark(q, head)
    # "the lamp between the bed and the wardrobe": two landmarks.
    if q.anchor_category is None:
        head = _between(q, head)
    # "the armchair across the coffee table from the grey one": a landmark and what is between.
    if q.anchor_category is None:
        head = _across(q, head)
    # Relation: "<target> next to the <anchor>".
    if q.anchor_category is None:
        for rel in _RELATIONS:
            m = re.search(rf"\b{rel}\s+(?:the\s+|a\s+|an\s+|my\s+)?(.+)$", head) if rel in head else None
            if m and rel == "on" and _put_down(head[:m.start()].split()) \
                    and _find_category(m.group(1).split())[0] is not None:
                head = m.group(1)  # "I put my mug down on the counter": where it was put is the goal
                break
            if m and rel in ("on", "at") and _find_category(head[:m.start()].split())[0] is None:
                continue  # "sit on the armchair", "work at the desk": the place of a verb, the goal
            if m and m.start() > 0:
                anchor_words = m.group(1).split()
                cat, _, _ = _find_category(anchor_words)
                stand_in = _stand_in_landmark(anchor_words, head[: m.start()]) if cat is None else None
                if stand_in is not None and not stand_in[2]:
                    # "the sink opposite the black one": another of the target's category.
                    q.relation = relation_name(rel) if rel in ("besides", "beside", "by", "close to", "alongside",
                                                               "at") else rel
                    q.anchor_category, q.anchor_phrase = stand_in[0], stand_in[1]
                    head = head[: m.start()]
                    break
                before = head[:m.start()].split()
                if cat is not None and _put_down(before) and _find_category(before)[0] is None:
                    # "she left her bag by the bed, go there": a thing the map does not hold was
                    # left or put by the landmark; where it was left is the goal.
                    q.notes.append(f"where it was put ({rel} the {cat}) is the goal")
                    head = m.group(1)
                    break
                if cat is not None and _verb_only(head[:m.start()]):
                    # "swing by the fridge", "pop by the stove": a verb of going with its
                    # preposition, no object before it: the landmark is the goal.
                    head = head[:m.start()] + " " + m.group(1)
                    break
                if cat is not None:
                    q.relation = relation_name(rel)
                    q.anchor_category = cat
                    q.anchor_phrase = m.group(1)
                    head = head[:m.start()]
                    break
    # "the desk with the blue chair at it": another object the target has by it, a landmark.
    if q.anchor_category is None:
        head = _with_landmark(q, head)
    words = _joined_compounds([w for w in re.split(r"\s+", head.strip()) if w])
    for phrase in sorted(_SUPERLATIVE, key=len, reverse=True):
        if phrase in head and re.search(rf"\b{phrase}\b", head):
            q.superlative, q.size_axis = _SUPERLATIVE[phrase], size_axis(phrase)
            break
    if q.superlative is None:
        q.size_word, q.size_axis = _size_word(words)
        q.more_sizes = [(s, a) for s, a in size_words(words) if a != q.size_axis]
    else:
        q.size_word = _size_word(words)[0]
    q.colors = _colors(words)
    if len(q.colors) > 1 and "terracotta" in q.colors:  # "a yellow terracotta pot": a material here
        q.colors.remove("terracotta")
    whole = _without_parts(q, words)  # the words said of the target itself, not of a part of it
    q.shapes = _shapes(whole)
    if ("l-shaped" in head or "l shaped" in head) and "L-shaped" not in {s for v in q.part_shapes.values() for s in v}:
        q.shapes = list(dict.fromkeys([*q.shapes, "L-shaped"]))
    q.materials = materials_in(whole)
    cat, span, fuzzy = _find_category(words)
    words, cat, span, fuzzy = _compound_kind(words, cat, span, fuzzy)
    # A word that is a material only as a noun ("plush": lavish as an adjective; "oak": a colour
    # before a noun) is one when said in a phrase after the target's noun ("the armchair covered
    # in soft plush", "made from solid oak"), not before it.
    said_after = _material_nouns_after(words, span[1]) if span is not None else []
    q.materials = list(dict.fromkeys([*q.materials, *(_LEX.material_nouns[w] for w in said_after)]))
    other = _other_object(words, span) if cat in BY_NAME else None  # a class's own compound names it
    if other is not None:
        # "pool table", "power plant": WordNet names another object ending in a category word.
        cat, span = None, None
    if cat is not None and cat not in BY_NAME and find_activity(head) is not None:
        # "somewhere to leave my phone", "where can I stash my board games": the thing is what the
        # activity is about; the target is the furniture that serves it.
        cat, span = None, None
    q.category = cat
    if cat == "plant":
        # "the cactus", "the spiny pot plant": the growth form the word implies, checked against the points.
        grams = {" ".join(words[i:i + n]) for n in (1, 2, 3) for i in range(len(words) - n + 1)}
        q.shapes = list(dict.fromkeys([*q.shapes, *sorted({_GROWTH[g] for g in grams if g in _GROWTH})]))
    known = (set(_FILLER) | set(LEXICON) | set(ALIASES) | set(_SHAPES) | _SIZE_TOKENS | set(_SUPERLATIVE)
             | set(_MATERIAL_OF) | _COMMON_ADJECTIVES | {w for c in q.colors for w in c.split()}
             | (_GROWTH_TOKENS if cat == "plant" else set())
             | {w for w in words if re.fullmatch(r"[a-z]+-colou?red", w) or material_of(w)}
             | set(UNOBSERVED) | {w for w in words if w in _COLOUR_OF and _COLOUR_OF[w] in q.colors}
             | set(said_after))
    for w in dict.fromkeys(w for w in words if w in UNOBSERVED):
        # "the squishy armchair": WordNet's soft; no map observes it, so it neither confirms nor refuses.
        q.notes.append(f"'{w}' says {UNOBSERVED[w]}, which the map does not observe")
    if cat is not None and span is not None:
        form = " ".join(words[span[0]:span[1]])
        q.category_alternatives = _LEX.category_alternatives(cat, None if fuzzy else form)
        sense = next((_LEX.furniture_senses[f] for f in (form, form[:-1], form[:-2]) if f in _LEX.furniture_senses),
                     None)
        if sense is not None and _LEX.forms.get(form) is None:
            # "the kitchen press": WordNet's one furniture sense of a word that is first another thing.
            for other, w in dict(sense.get("alternatives", {})).items():
                q.category_alternatives[other] = max(q.category_alternatives.get(other, 0.0), float(w))
            q.notes.append(f"'{form}' is read as the {cat}: its only furniture sense in WordNet "
                           f"({sense['synset']}); its first sense is another thing")
        if cat in _LEX.kinds:
            # "the appliance on your left": every category of the kind is the named one.
            q.category, q.category_alternatives = None, dict.fromkeys(_LEX.kinds[cat], 1.0)
        if q.room is None:
            room, start = _room_before(words, span[0])
            if room is not None:
                q.room = room
                words = words[:start] + words[span[0]:]
                span = (start, start + span[1] - span[0])
    rest = [w for k, w in enumerate(words) if (span is None or not span[0] <= k < span[1]) and w not in known]
    if cat is not None and q.category is None:  # a kind of several categories
        q.unknown_words = rest
    elif cat is None:
        q.unknown_words = rest
        # "the bath towels need a wash, where can I put them": the other object is what the
        # activity handles, not a reason to read none.
        activity = find_activity(head)
        if activity is not None:
            q.purpose = activity
            _attributes_outside(q, head, activity)
            if embedder is not None:
                # The retriever embeds the instruction next: one batch for both.
                # The act says the furniture; what it is done for ("before making tea") the room.
                parts = split_activity(activity) or [activity]
                act = _without_company(_without_modifying_categories(parts[0]))
                # What it is done for says the room: embedded in the same run.
                match = match_purpose(act, embedder, along=(q.text, *(room_text(p) for p in parts[1:])))
                best, alts = purpose_categories(match)
                q.placing = is_placing(act, scores=match.scores)
                best, alts = _described_place(q, head, best, alts, match.scores)
                if best is not None:
                    # The lexicon's relatives of each category that serves (a stool beside a chair),
                    # weighted below it: a room or a landmark can then choose among them.
                    for c, wt in [(best, 1.0), *alts.items()]:
                        for other, w2 in _LEX.category_alternatives(c).items():
                            if other != best:
                                alts[other] = max(alts.get(other, 0.0), round(wt * w2, 3))
                    q.category, q.category_alternatives, q.unknown_words = best, alts, []
                    q.purpose_room = activity_room(activity, embedder)
    else:
        q.unknown_words = rest
    if q.category is None and q.purpose is None and any(w in _GENERIC for w in words):
        q.generic, q.unknown_words = True, []
    if q.category is None and q.purpose is None and not q.generic and not q.category_alternatives and rest:
        # "where's the dunny": a name neither WordNet nor the category table has; said plainly, and
        # never answered by a lookalike word ("khaki").
        q.notes.append(f"no object word here is known to the lexicon (WordNet 3.0 and the category table): "
                       f"{rest[-1]!r}")
    desc = list(dict.fromkeys(w for part in (*q.colors, *q.materials, *q.shapes) for w in part.split()))
    noun = q.category if q.category is not None else cat if cat is not None else " ".join(rest[-2:]) if rest else ""
    q.target_phrase = " ".join([*desc, noun]).strip() or norm
    return q



#: The end of an order met along a route ("the last lamp", "the final plant", "you reach last").
_LAST = {"last", "final"}
_REACHED_LAST = re.compile(r"\b(?:reach|pass|get\s+to|come\s+to|meet|see|walk\s+past)(?:es|ed|s)?\s+(?:last|final)\b")


def goal_query(g: GoalParse, embedder: TextEmbedder | None = None) -> ParsedQuery:
    """``ParsedQuery`` of one parsed goal: the mapping reads the words the parse attached to the
    target (``g.core``); the text embedded for similarity is the same words when the parse
    dropped any (an idiom's "blue" must not pull a blue object up), else the goal as said."""
    q = read_goal(g.core, embedder)
    if not g.dropped:
        q.text = validate_instruction(g.text)
    q.parser, q.notes, q.dropped_words = g.parser, [*g.notes, *q.notes], list(g.dropped)
    q.origin_room = g.origin_room or q.origin_room
    q.side = g.side
    q.structure = describe(g)
    if q.ordinal is None:
        # "the third lamp from the door", "the first armchair you reach": an ordinal on the head,
        # counted in the order a route or a predicate gives.
        q.ordinal = next((_ORDINALS[m.lower()] for m in g.modifiers if m.lower() in _ORDINALS), None)
    if q.ordinal is None and q.proximity is None and q.origin_room is not None and (
            any(m.lower() in _LAST for m in g.modifiers) or _REACHED_LAST.search(g.core)):
        # "the last thing on your left coming in", "the lamp you reach last": the end of the
        # order met from the way in, which the route reverses for "farthest".
        q.proximity = "farthest"
    if q.generic and not (q.has_attributes or q.ordinal or q.origin_room or q.side):
        q.generic = False  # "the thing" alone says nothing that could pick one object
    if q.room is None:
        # "going along the corridor from the kitchen door": a room walked along is where the
        # target stands when the route names no room it goes into.
        q.room = next((r for role, r in g.rooms if role == "along" and r != q.origin_room), None)
    if q.origin_room is not None and q.ordinal_from == _FROM_ROBOT:
        q.proximity, q.ordinal_from = None, f"the way in from the {q.origin_room}"  # skipped from the door
    if q.origin_room is not None and q.room == q.origin_room:
        q.room = next((r for role, r in g.rooms if role == "target" and r != q.origin_room), None)
    return q
