"""Reading an instruction: validation (empty, too long, not English) and the parts retrieval
uses: the target category (WordNet's words for it, small typos allowed) with the other categories
it may denote, colour / shape / size words (shades as people say them: "reddish", "off-white"),
a spatial predicate (closest / farthest to the robot or to a landmark, biggest / smallest, next
to / near / in front of Y, "the second closest"), a room ("in the kitchen", "the kitchen stool"),
what the target must not be ("not the white one") and, for requests by purpose ("somewhere to
sit"), the categories that serve it. Parsing is deliberately shallow and predictable; whatever it
does not understand still reaches the embedding similarity.

Language policy: CapNav understands English only. An instruction with two or more words of another
language (function words of French, Spanish, German, Italian, Portuguese or Dutch that English
does not use, or words with letters English does not use), or with one and no English function
word, is refused with one message: "instruction is not in English (...); only English
instructions are supported". So "la lampe près du canapé" and "la chaise rose" are refused alike;
one stray word among English ones ("the lamp in the den", "go to the sofa por favor") is read as
English, the stray word as an unknown word."""

from __future__ import annotations

import difflib
import re
import unicodedata
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from rapidfuzz import fuzz, process

from capnav.core.categories import CATEGORIES
from capnav.core.errors import InputError
from capnav.language.colors import ALIASES, LEXICON, SHADES, canonical_color, color_lab
from capnav.language.context import ROOM_SYNONYMS
from capnav.language.lexicon import load_lexicon
from capnav.language.purpose import find_activity, match_purpose, purpose_categories

if TYPE_CHECKING:
    from capnav.language.embedder import TextEmbedder

MAX_CHARS = 300
MAX_WORDS = 50

_LEX = load_lexicon()


def _plural(form: str) -> str:
    *head, last = form.split()
    if last.endswith("f"):
        last = last[:-1] + "ves"
    elif last.endswith(("s", "x", "ch", "sh")):
        last += "es"
    elif last.endswith("y") and last[-2:-1] not in "aeiou":
        last = last[:-1] + "ies"
    else:
        last += "s"
    return " ".join([*head, last])


#: Every surface form of every category: WordNet's (the lexicon) and the vocabulary's own names
#: and synonyms, with plurals.
_FORM_MAP: dict[str, str] = {}
for _f, _c in sorted(_LEX.forms.items()):
    _FORM_MAP.setdefault(_plural(_f), _c)
_FORM_MAP.update(_LEX.forms)
for _cat in CATEGORIES:
    for _f in (_cat.name, *_cat.synonyms):
        _FORM_MAP[_f] = _cat.name
        _FORM_MAP.setdefault(_plural(_f), _cat.name)
_FORM_WORDS = {w for f in _FORM_MAP for w in f.split()}
_FORM_LENGTHS = sorted({len(f) for f in _FORM_MAP})


def _form_follows(text: str, pos: int) -> bool:
    """Whether an object noun follows ``text[pos:]`` after white space ("the kitchen| counter").
    Dictionary look-ups of each form length: one regular expression of all ~2,500 forms took
    0.1 s to compile in every process."""
    rest = text[pos:]
    word = rest.lstrip()
    if len(word) == len(rest):
        return False
    return any(word[:n] in _FORM_MAP and (len(word) == n or not (word[n].isalnum() or word[n] == "_"))
               for n in _FORM_LENGTHS if n <= len(word))

#: Typos are matched against the vocabulary's own words only (not WordNet's 600 rarer ones).
_TYPO_FORMS = {f: c.name for c in CATEGORIES for f0 in (c.name, *c.synonyms) for f in (f0, _plural(f0))}
_MULTI_FORMS = sorted(f for f in _TYPO_FORMS if " " in f)
_SINGLE_FORMS = sorted({f for f in _TYPO_FORMS if " " not in f and len(f) >= 4})
_TYPO_WORDS = {w for f in _TYPO_FORMS for w in f.split()}
#: rapidfuzz ratio (0-100) at which a misspelt multi-word name is read as that name: two letters
#: wrong in "washing machine" (89.7) pass, a different word ("washing line") does not.
_MULTI_TYPO_SCORE = 86.0

_PROXIMITY = {"closest": "closest", "nearest": "closest", "near me": "closest", "closest to me": "closest",
              "farthest": "farthest", "furthest": "farthest", "most distant": "farthest"}
_SUPERLATIVE = {"biggest": "largest", "largest": "largest", "largest one": "largest", "widest": "largest",
                "tallest": "largest", "smallest": "smallest", "tiniest": "smallest", "littlest": "smallest",
                "narrowest": "smallest"}
_SIZE_WORDS = {"big": "large", "large": "large", "huge": "large", "larger": "large", "bigger": "large",
               "small": "small", "little": "small", "tiny": "small", "smaller": "small", "compact": "small"}
#: WordNet's size adjectives and their comparatives ("king-size", "oversized", "tinier"; the lexicon).
_SIZE_WORDS.update(_LEX.sizes)
_SIZE_TOKENS = {w for f in _SIZE_WORDS for w in f.split()}
_SHAPES = {"round": "round", "circular": "round", "l-shaped": "L-shaped", "l shaped": "L-shaped",
           "corner": "L-shaped", "long": "long", "rectangular": "rectangular", "square": "square",
           "curved": "curved", "oval": "round",
           # the growth words the offline captioner says of a plant (capnav.language.form): a bush
           # is leafy (its points do not tell it from a leafy crown on a stem)
           "leafy": "leafy", "bushy": "leafy", "slender": "slender"}
#: Words that name a plant's growth form ("cactus", "succulent", "prickly"; WordNet's, the lexicon)
#: -> the growth word the captioner measures ("slender").
_GROWTH = _LEX.growth
_GROWTH_TOKENS = {w for f in _GROWTH for w in f.split()}
#: Relations whose geometry the retriever measures beyond the gap: "between" two landmarks
#: (``anchor2_category``), "at the end of" a long object (the ends of its long axis), and
#: "in the room with" a landmark (its room region).
BETWEEN = "between"
END_OF = "at the end of"
ROOM_WITH = "in the room with"
_RELATIONS = [END_OF, "in front of", "facing", "next to", "close to", "beside", "besides", "near", "by", "behind",
              "opposite", "across from", "alongside", "against"]
_MATERIALS = {"wooden", "wood", "leather", "fabric", "velvet", "metal", "glass", "marble", "plastic",
              "ceramic", "stainless", "steel", "laminate", "cotton", "acrylic", "paper", "terracotta"}
_FILLER = {"go", "to", "the", "a", "an", "please", "find", "navigate", "take", "me", "walk", "head", "move",
           "drive", "could", "you", "can", "would", "kindly", "toward", "towards", "over", "there", "that",
           "one", "of", "is", "which", "i", "want", "need", "get", "bring", "robot", "hey", "and", "with",
           "its", "it", "in", "on", "at", "room", "thanks", "thank", "up", "let", "us", "lets", "visit",
           "approach", "reach", "stop", "ok", "okay", "now", "just", "some", "this"}
_ENGLISH_HINTS = _FILLER | set(_FORM_MAP) | set(LEXICON) | set(ALIASES) | set(_SIZE_WORDS) | set(_SUPERLATIVE) \
    | {"closest", "nearest", "farthest", "next", "near", "beside", "behind", "front", "kitchen", "bedroom",
       "bathroom", "living", "office", "where", "show", "locate"}
#: Letters with diacritics that English words do not carry (a word with one is not English).
_ENGLISH_LETTERS = set("abcdefghijklmnopqrstuvwxyz")


@dataclass
class ParsedQuery:
    text: str  # normalised instruction
    category: str | None = None  # canonical vocabulary category of the target
    target_phrase: str = ""  # what to look for, in words ("white couch", "piano")
    colors: list[str] = field(default_factory=list)
    materials: list[str] = field(default_factory=list)
    shapes: list[str] = field(default_factory=list)
    size_word: str | None = None  # "large" / "small"
    superlative: str | None = None  # "largest" / "smallest"
    proximity: str | None = None  # "closest" / "farthest"
    relation: str | None = None  # "next to", ...
    anchor_category: str | None = None
    anchor_phrase: str | None = None
    room: str | None = None
    unknown_words: list[str] = field(default_factory=list)
    #: Other categories the target words may denote, with a weight below 1 (a chair request may
    #: be served by an armchair or a stool, ranked below chairs; a purpose maps to several).
    category_alternatives: dict[str, float] = field(default_factory=dict)
    purpose: str | None = None  # the request named a use ("somewhere to sit"), not an object
    negations: list[str] = field(default_factory=list)  # phrases the target must NOT match ("white")
    ordinal: int | None = None  # 2 for "the second closest"
    proximity_to_anchor: bool = False  # "the chair closest to the table": distance to the anchor
    anchor2_category: str | None = None  # the second landmark of "between the sofa and the armchair"
    anchor2_phrase: str | None = None

    @property
    def has_attributes(self) -> bool:
        return bool(self.colors or self.materials or self.shapes or self.size_word or self.superlative
                    or self.relation or self.room)

    @property
    def category_only(self) -> bool:
        return self.category is not None and not self.has_attributes and not self.unknown_words

    def to_dict(self) -> dict[str, object]:
        return {k: v for k, v in self.__dict__.items() if v not in (None, [], "", {}, False)}


def _foreign_words(text: str) -> list[str]:
    """Words of another language: function words of French, Spanish, German, Italian, Portuguese
    or Dutch that are not English (from the lexicon), and words with letters English does not use
    ("canapé", "weiße") unless the lexicon knows them."""
    out = []
    for k, w in enumerate(re.findall(r"[^\W\d_]+(?:'[^\W\d_]+)?", text)):
        low = w.lower()
        if low in _LEX.foreign:
            if k == 0 or not w[0].isupper():  # a capitalised word inside a sentence is a name ("Van")
                out.append(low)
        elif not set(low) <= _ENGLISH_LETTERS | {"'"} and low not in _FORM_MAP:
            out.append(low)
    return out


def validate_instruction(text: object) -> str:
    """Normalise whitespace; raise ``InputError`` for empty, very long or non-English text."""
    if not isinstance(text, str):
        raise InputError(f"instruction must be a string, got {type(text).__name__}")
    t = " ".join(text.split())
    if not t:
        raise InputError("empty instruction: say what to look for, e.g. 'go to the white sofa'")
    if len(t) > MAX_CHARS or len(t.split()) > MAX_WORDS:
        raise InputError(f"instruction too long ({len(t)} characters, {len(t.split())} words); "
                         f"keep it under {MAX_CHARS} characters and {MAX_WORDS} words")
    letters = [ch for ch in t if ch.isalpha()]
    if not letters:
        raise InputError("instruction has no words")
    non_latin = sum(1 for ch in letters if not unicodedata.name(ch, "").startswith("LATIN"))
    if non_latin / len(letters) > 0.3:
        raise InputError("instruction is not in English (non-Latin script); only English instructions are "
                         "supported")
    foreign = _foreign_words(t)
    words = re.findall(r"[^\W\d_]+(?:'[^\W\d_]+)?", t.lower())
    english = [w for w in words if w in _LEX.english]
    if len(foreign) >= 2 or (foreign and not english):
        raise InputError(f"instruction is not in English ({', '.join(repr(w) for w in foreign[:4])} "
                         f"{'is' if len(foreign) == 1 else 'are'} not English); only English instructions are "
                         "supported")
    return t


def _find_category(words: list[str]) -> tuple[str | None, tuple[int, int] | None, bool]:
    """(category, word span, fuzzy) of the first category mention; exact n-grams before typos."""
    for n in (3, 2):
        for i in range(len(words) - n + 1):
            gram = " ".join(words[i:i + n])
            if gram in _FORM_MAP:
                return _FORM_MAP[gram], (i, i + n), False
    # A typo in a multi-word name ("longe chair", "dinning tabel") before the exact single word
    # inside it ("chair"): rapidfuzz's normalised edit similarity (symmetric, unlike difflib's),
    # and only when every changed word is no English word of its own ("dining cable" is not a typo).
    for n in (3, 2):
        for i in range(len(words) - n + 1):
            part = words[i:i + n]
            hit = process.extractOne(" ".join(part), _MULTI_FORMS, scorer=fuzz.ratio, score_cutoff=_MULTI_TYPO_SCORE)
            if hit is not None and len(hit[0].split()) == n and all(
                    w == f or (w not in _FORM_WORDS and w not in _LEX.not_typos and w not in _ENGLISH_HINTS)
                    for w, f in zip(part, hit[0].split(), strict=True)):
                return _TYPO_FORMS[hit[0]], (i, i + n), True
    for i in range(len(words)):
        if words[i] in _FORM_MAP:
            return _FORM_MAP[words[i]], (i, i + 1), False
    for i, w in enumerate(words):
        if len(w) < 4 or w in _FILLER or canonical_color(w) or w in _SHAPES or w in _SIZE_WORDS \
                or w in _LEX.not_typos:
            continue
        near = difflib.get_close_matches(w, _SINGLE_FORMS, n=1, cutoff=0.8)
        # A word two or more letters short of a name's start is another word, not a typo ("wash").
        if near and not (near[0].startswith(w) and len(near[0]) - len(w) >= 2):
            return _TYPO_FORMS[near[0]], (i, i + 1), True
    return None, None, False


_COLOR_NOT_ALONE = {"light", "dark", "pale", "deep", "bright", "soft", "rich", "vivid", "dull", "muted", "dusty",
                    "faded", "pastel"}


def _color_name(phrase: str) -> str | None:
    """The palette name of a colour phrase when it has one ("gray" -> "grey"), else the phrase
    itself when it names a colour ("reddish", "pale pink", "dark wooden"), else None."""
    if phrase in _COLOR_NOT_ALONE or phrase in _FORM_MAP:
        return None
    name = canonical_color(phrase)
    if name is not None:
        return name
    return phrase if color_lab(phrase) is not None else None


def _colors(words: list[str]) -> list[str]:
    out: list[str] = []
    i = 0
    while i < len(words):
        for n in (3, 2, 1):
            if i + n > len(words):
                continue
            gram = " ".join(words[i:i + n]).replace("-coloured", "").replace("-colored", "")
            if n > 1 and gram in _FORM_MAP:
                continue
            c = _color_name(gram)
            if c:
                out.append(c)
                i += n
                break
        else:
            i += 1
    return list(dict.fromkeys(out))


#: Words whose typos would hide a predicate or attribute ("bseide" for "beside", "yelow" for "yellow").
_KEYWORDS = ["beside", "near", "next", "behind", "opposite", "front", "closest", "nearest", "farthest",
             "furthest", "biggest", "largest", "smallest", "kitchen", "bedroom", "bathroom", "living", "office",
             *sorted(w for w in (*LEXICON, *SHADES) if " " not in w and len(w) >= 5)]
_COMMON_ADJECTIVES = {"shaped", "l", "coloured", "colored", "color", "colour", "first", "second",
                      "third", "fourth", "last", "other", "left", "right", "main", "old", "new", "nice", "same",
                      "only", "usual", "favourite", "favorite", "pretty", "modern", "classic", "comfy", "comfortable",
                      *_COLOR_NOT_ALONE}


def _ratio(a: str, b: str) -> float:
    return difflib.SequenceMatcher(None, a, b).ratio()


def _fix_keyword_typos(words: list[str]) -> list[str]:
    out = []
    for w in words:
        if len(w) >= 5 and w not in _ENGLISH_HINTS and w not in _FORM_WORDS and w not in _LEX.not_typos:
            near = difflib.get_close_matches(w, _KEYWORDS, n=1, cutoff=0.8)
            # Only when no category word is at least as close ("bedsde" is "bedside", not "beside").
            if near and _ratio(w, near[0]) > max((_ratio(w, f) for f in _TYPO_WORDS), default=0.0):
                w = near[0]
        out.append(w)
    return out


_ORDINALS = {"first": 1, "1st": 1, "second": 2, "2nd": 2, "third": 3, "3rd": 3, "fourth": 4, "4th": 4,
             "fifth": 5, "5th": 5}
#: "not the white one", "the one that isn't grey", "other than the red one", "except the ...".
_NEGATION = re.compile(r"(?:\b(?:that|which|who)\s+)?(?:\bis\s+not\b|\bisn't\b|\bisnt\b|\bnot\b|\bother\s+than\b"
                       r"|\bexcept(?:\s+for)?\b|\bapart\s+from\b|\brather\s+than\b|\binstead\s+of\b)"
                       r"\s+(?P<neg>[^,;]+?)(?=\s*(?:[,;]|\bbut\b|\bthe\s+other\b|$))")
#: The robot itself as the reference of closest / farthest.
_SELF = re.compile(r"^(?:me|you|us|here|yourself|the robot|where i am|where you are|my position|"
                   r"your position)\b")
_PROX_WORDS = {"closest": "closest", "nearest": "closest", "farthest": "farthest", "furthest": "farthest",
               "most distant": "farthest"}


def _room_before(words: list[str], start: int) -> tuple[str | None, int]:
    """A room named just before the target noun ("the kitchen stool"): (room, its first word)."""
    for n in (2, 1):
        if start - n >= 0:
            gram = " ".join(words[start - n:start])
            if gram in ROOM_SYNONYMS:
                return ROOM_SYNONYMS[gram], start - n
    return None, start


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
    if cat is None or span is None:
        return head
    q.proximity = _PROX_WORDS[m.group("p")]
    q.proximity_to_anchor = True
    q.anchor_category = cat
    q.anchor_phrase = " ".join(anchor_words[: span[1]])
    return (head[: m.start()] + " " + m.group("mid") + " " + " ".join(anchor_words[span[1]:])).strip()


#: Verbs of a landmark clause ("the desk the pink chair is pulled up to", "the table that the lamp
#: stands beside"): the clause's subject is the landmark, not a description of the target.
_CLAUSE_VERB = re.compile(r"\b(?:is|are|was|were|sits|sit|stands|stand|rests|lies|has\s+been)\b")


_ARTICLE = r"(?:the\s+|a\s+|an\s+|my\s+|our\s+|your\s+)?"
_ROOM_ALT = "|".join(re.escape(r) for r in sorted(ROOM_SYNONYMS, key=len, reverse=True))


def _landmark(words: list[str]) -> tuple[str, str, list[str]] | None:
    """(category, phrase up to its noun, the words after it) of a landmark phrase, else None."""
    cat, span, _ = _find_category(words)
    if cat is None or span is None:
        return None
    return cat, " ".join(words[: span[1]]), words[span[1]:]


def _room_with(q: ParsedQuery, head: str) -> str:
    """"in the room with the pink dresser", "in the bedroom that has the yellow bed": the target
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
    """A purpose request with a clause of its own that names an object ("somewhere to put my
    coffee down while I watch telly"): the object is the setting, not the target; the target is
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


def _between(q: ParsedQuery, head: str) -> str:
    """"the table between the green sofa and the purple armchair": two landmarks, each with its
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


def _clause_landmark(q: ParsedQuery, head: str) -> str:
    """"the desk the pink chair is pulled up to", "the table that the green lamp stands beside":
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


def _negations(q: ParsedQuery, head: str) -> str:
    """Fill ``q.negations`` with what the target must not be, as short phrases a parse of their own
    reads ("white", "in the bedroom"); returns ``head`` without them. The negated phrase's category
    still names the target ("not the white washer, the other one")."""
    out = head
    for m in list(_NEGATION.finditer(head))[::-1]:
        words = m.group("neg").split()
        cat, span, _ = _find_category(words)
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


def parse_instruction(text: str, embedder: TextEmbedder | None = None) -> ParsedQuery:
    """Read ``text``. With ``embedder`` (the retriever's), a request by purpose ("somewhere to
    sit") is mapped to categories through the lexicon's glosses; without one it keeps ``purpose``
    and no category."""
    t = validate_instruction(text)
    low = t.lower()
    norm = re.sub(r"[^a-z0-9\-' ]+", " ", low)
    norm = re.sub(r"\b(\w+)n't\b", r"\1 not", norm.replace("isn't", "is not").replace("isnt", "is not"))
    norm = " ".join(_fix_keyword_typos(norm.replace("'s", "").split()))
    q = ParsedQuery(text=t)
    head = _negations(q, norm)
    # "somewhere to put my coffee down while I watch telly": the telly is where, not what.
    head = _purpose_context(q, head)
    # "the bed in the room with the pink dresser", "the wardrobe in the bedroom with the yellow bed".
    head = _room_with(q, head)
    # Room: "in the kitchen", "in the living room".
    for phrase in sorted(ROOM_SYNONYMS, key=len, reverse=True):
        if phrase not in head:  # cheap test first: a one-shot query compiles only the patterns it needs
            continue
        # Not when the room word modifies an object noun ("at the end of the kitchen counter").
        pat = rf"\b(?:in|inside|within|from|of)\s+(?:the\s+|my\s+|our\s+)?{re.escape(phrase)}\b"
        m = next((m for m in re.finditer(pat, head) if not _form_follows(head, m.end())), None)
        if m:
            q.room = ROOM_SYNONYMS[phrase]
            head = (head[:m.start()] + " " + head[m.end():]).strip()
            break
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
    # A landmark clause: "the desk the pink chair is pulled up to".
    if q.anchor_category is None:
        head = _clause_landmark(q, head)
    # "the table between the sofa and the armchair": two landmarks.
    if q.anchor_category is None:
        head = _between(q, head)
    # Relation: "<target> next to the <anchor>".
    if q.anchor_category is None:
        for rel in _RELATIONS:
            m = re.search(rf"\b{rel}\s+(?:the\s+|a\s+|an\s+|my\s+)?(.+)$", head) if rel in head else None
            if m and m.start() > 0:
                anchor_words = m.group(1).split()
                cat, _, _ = _find_category(anchor_words)
                if cat is not None:
                    q.relation = "next to" if rel in ("besides", "beside", "by", "close to", "alongside") else rel
                    q.anchor_category = cat
                    q.anchor_phrase = m.group(1)
                    head = head[:m.start()]
                    break
    words = [w for w in re.split(r"\s+", head.strip()) if w]
    for phrase in sorted(_SUPERLATIVE, key=len, reverse=True):
        if phrase in head and re.search(rf"\b{phrase}\b", head):
            q.superlative = _SUPERLATIVE[phrase]
            break
    q.size_word = _size_word(words)
    q.colors = _colors(words)
    if len(q.colors) > 1 and "terracotta" in q.colors:  # "a yellow terracotta pot": a material here
        q.colors.remove("terracotta")
    q.shapes = list(dict.fromkeys(_SHAPES[w] for w in words if w in _SHAPES))
    if "l-shaped" in head or "l shaped" in head:
        q.shapes = list(dict.fromkeys([*q.shapes, "L-shaped"]))
    q.materials = [w for w in words if w in _MATERIALS]
    cat, span, fuzzy = _find_category(words)
    other = _other_object(words, span)
    if other is not None:
        # "pool table", "power plant": WordNet names another object ending in a category word.
        cat, span = None, None
    q.category = cat
    if cat == "plant":
        # "the cactus", "the prickly plant": the growth form the word implies, checked against the points.
        grams = {" ".join(words[i:i + n]) for n in (1, 2, 3) for i in range(len(words) - n + 1)}
        q.shapes = list(dict.fromkeys([*q.shapes, *sorted({_GROWTH[g] for g in grams if g in _GROWTH})]))
    known = (set(_FILLER) | set(LEXICON) | set(ALIASES) | set(_SHAPES) | _SIZE_TOKENS | set(_SUPERLATIVE)
             | _MATERIALS | _COMMON_ADJECTIVES | {w for c in q.colors for w in c.split()}
             | (_GROWTH_TOKENS if cat == "plant" else set())
             | {w for w in words if re.fullmatch(r"[a-z]+-colou?red", w)})
    if cat is not None and span is not None:
        form = " ".join(words[span[0]:span[1]])
        q.category_alternatives = _LEX.category_alternatives(cat, None if fuzzy else form)
        if q.room is None:
            room, start = _room_before(words, span[0])
            if room is not None:
                q.room = room
                words = words[:start] + words[span[0]:]
                span = (start, start + span[1] - span[0])
    rest = [w for k, w in enumerate(words) if (span is None or not span[0] <= k < span[1]) and w not in known]
    if cat is None:
        q.unknown_words = rest
        activity = find_activity(head) if other is None else None
        if activity is not None:
            q.purpose = activity
            if embedder is not None:
                # The retriever embeds the instruction next: one batch for both.
                best, alts = purpose_categories(match_purpose(activity, embedder, along=(q.text,)))
                if best is not None:
                    # The lexicon's relatives of each category that serves (a stool beside a chair),
                    # weighted below it: a room or a landmark can then choose among them.
                    for c, w in [(best, 1.0), *alts.items()]:
                        for other, w2 in _LEX.category_alternatives(c).items():
                            if other != best:
                                alts[other] = max(alts.get(other, 0.0), round(w * w2, 3))
                    q.category, q.category_alternatives, q.unknown_words = best, alts, []
    else:
        q.unknown_words = rest
    desc = list(dict.fromkeys(w for part in (*q.colors, *q.materials, *q.shapes) for w in part.split()))
    noun = q.category if q.category is not None else " ".join(rest[-2:]) if rest else ""
    q.target_phrase = " ".join([*desc, noun]).strip() or norm
    return q


def _size_word(words: list[str]) -> str | None:
    """"large" / "small" from the first size word ("king size" and "king-size" alike); a size word
    right after "a" / "an" that ends the sentence is a noun ("I need a wee", "move a little")."""
    for i in range(len(words)):
        for n in (2, 1):
            gram = " ".join(words[i:i + n])
            if i + n <= len(words) and gram in _SIZE_WORDS:
                if i + n == len(words) and i > 0 and words[i - 1] in ("a", "an"):
                    continue
                return _SIZE_WORDS[gram]
    return None


def _other_object(words: list[str], span: tuple[int, int] | None) -> str | None:
    """A WordNet compound around the category span that names something else ("pool table")."""
    if span is None:
        return None
    for n in (3, 2):
        for i in range(max(0, span[1] - n), span[0] + 1):
            gram = " ".join(words[i:i + n])
            if i + n >= span[1] and gram in _LEX.other:
                return gram
    return None
