"""Reading an instruction: validation (empty, too long, not English) and the parts retrieval
uses: the target category (synonyms and small typos allowed), colour / shape / size words, a
spatial predicate (closest / farthest, biggest / smallest, next to / near / in front of Y) and a
room ("in the kitchen"). Parsing is deliberately shallow and predictable; whatever it does not
understand still reaches the embedding similarity."""

from __future__ import annotations

import difflib
import re
import unicodedata
from dataclasses import dataclass, field

from capnav.core.categories import CATEGORIES
from capnav.core.errors import InputError
from capnav.language.colors import ALIASES, LEXICON, canonical_color
from capnav.language.context import ROOM_SYNONYMS

MAX_CHARS = 300
MAX_WORDS = 50

#: Every surface form of every category (names and synonyms), longest first.
_FORMS: list[tuple[str, str]] = sorted(((f, c.name) for c in CATEGORIES for f in (c.name, *c.synonyms)),
                                       key=lambda fc: -len(fc[0]))
_EXTRA_FORMS = {"couches": "sofa", "sofas": "sofa", "chairs": "chair", "tables": "table", "beds": "bed",
                "lamps": "lamp", "plants": "plant", "sinks": "sink", "stools": "stool", "desks": "desk",
                "cabinets": "cabinet", "armchairs": "armchair", "shelves": "bookshelf", "tvs": "tv",
                "bookshelves": "bookshelf", "ottomans": "ottoman", "dressers": "dresser", "toilets": "toilet",
                "refrigerators": "refrigerator", "fridges": "refrigerator", "counters": "counter",
                "stoves": "stove", "nightstands": "nightstand", "wardrobes": "wardrobe", "bathtubs": "bathtub",
                "sofa bed": "sofa", "settees": "sofa", "coffee tables": "coffee table"}
_FORM_MAP: dict[str, str] = {**{f: c for f, c in _FORMS}, **_EXTRA_FORMS}
_FORM_WORDS = {w for f in _FORM_MAP for w in f.split()}
_MULTI_FORMS = sorted(f for f in _FORM_MAP if " " in f)
_SINGLE_FORMS = sorted({f for f in _FORM_MAP if " " not in f and len(f) >= 4})

_PROXIMITY = {"closest": "closest", "nearest": "closest", "near me": "closest", "closest to me": "closest",
              "farthest": "farthest", "furthest": "farthest", "most distant": "farthest"}
_SUPERLATIVE = {"biggest": "largest", "largest": "largest", "largest one": "largest", "widest": "largest",
                "tallest": "largest", "smallest": "smallest", "tiniest": "smallest", "littlest": "smallest",
                "narrowest": "smallest"}
_SIZE_WORDS = {"big": "large", "large": "large", "huge": "large", "larger": "large", "bigger": "large",
               "small": "small", "little": "small", "tiny": "small", "smaller": "small", "compact": "small"}
_SHAPES = {"round": "round", "circular": "round", "l-shaped": "L-shaped", "l shaped": "L-shaped",
           "corner": "L-shaped", "long": "long", "rectangular": "rectangular", "square": "square",
           "curved": "curved", "oval": "round"}
_RELATIONS = ["in front of", "next to", "close to", "beside", "besides", "near", "by", "behind", "opposite",
              "across from", "alongside", "against"]
_MATERIALS = {"wooden", "wood", "leather", "fabric", "velvet", "metal", "glass", "marble", "plastic",
              "ceramic", "stainless", "steel", "laminate", "cotton", "acrylic", "paper", "terracotta"}
_FILLER = {"go", "to", "the", "a", "an", "please", "find", "navigate", "take", "me", "walk", "head", "move",
           "drive", "could", "you", "can", "would", "kindly", "toward", "towards", "over", "there", "that",
           "one", "of", "is", "which", "i", "want", "need", "get", "bring", "robot", "hey", "and", "with",
           "its", "it", "in", "on", "at", "room", "thanks", "thank", "up", "let", "us", "lets", "visit",
           "approach", "reach", "stop", "ok", "okay", "now", "just", "some", "this"}
#: Frequent function words of other languages that are not English words.
_FOREIGN = {"der", "die", "das", "zum", "zur", "und", "bitte", "gehe", "geh", "el", "los", "las", "del", "al",
            "ve", "ir", "por", "favor", "vers", "le", "les", "du", "des", "aller", "va", "il", "lo", "della",
            "alla", "vai", "het", "een", "naar", "ga", "och", "till", "og", "til", "na", "ao",
            "sofá", "weiße", "weißen", "blanco", "blanca", "rojo", "roja", "rouge", "blanc", "canapé", "mesa",
            "silla", "tisch", "stuhl", "cama", "bett", "cucina", "cocina", "küche"}
_ENGLISH_HINTS = _FILLER | set(_FORM_MAP) | set(LEXICON) | set(ALIASES) | set(_SIZE_WORDS) | set(_SUPERLATIVE) \
    | {"closest", "nearest", "farthest", "next", "near", "beside", "behind", "front", "kitchen", "bedroom",
       "bathroom", "living", "office", "where", "show", "locate"}


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

    @property
    def has_attributes(self) -> bool:
        return bool(self.colors or self.materials or self.shapes or self.size_word or self.superlative
                    or self.relation or self.room)

    @property
    def category_only(self) -> bool:
        return self.category is not None and not self.has_attributes and not self.unknown_words

    def to_dict(self) -> dict[str, object]:
        return {k: v for k, v in self.__dict__.items() if v not in (None, [], "")}


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
        raise InputError("instruction does not look like English (non-Latin script); only English is supported")
    words = re.findall(r"[^\W\d_]+", t.lower())
    foreign = sum(w in _FOREIGN for w in words)
    english = sum(w in _ENGLISH_HINTS for w in words)
    if foreign >= 2 and foreign > english:
        raise InputError("instruction does not look like English; only English instructions are supported")
    return t


def _find_category(words: list[str]) -> tuple[str | None, tuple[int, int] | None, bool]:
    """(category, word span, fuzzy) of the first category mention; exact n-grams before typos."""
    for n in (3, 2):
        for i in range(len(words) - n + 1):
            gram = " ".join(words[i:i + n])
            if gram in _FORM_MAP:
                return _FORM_MAP[gram], (i, i + n), False
    # A typo in a multi-word name ("longe chair") before the exact single word inside it ("chair").
    for n in (3, 2):
        for i in range(len(words) - n + 1):
            near = difflib.get_close_matches(" ".join(words[i:i + n]), _MULTI_FORMS, n=1, cutoff=0.88)
            if near:
                return _FORM_MAP[near[0]], (i, i + n), True
    for i in range(len(words)):
        if words[i] in _FORM_MAP:
            return _FORM_MAP[words[i]], (i, i + 1), False
    for i, w in enumerate(words):
        if len(w) < 4 or w in _FILLER or canonical_color(w) or w in _SHAPES or w in _SIZE_WORDS:
            continue
        near = difflib.get_close_matches(w, _SINGLE_FORMS, n=1, cutoff=0.8)
        # A word two or more letters short of a name's start is another word, not a typo ("wash").
        if near and not (near[0].startswith(w) and len(near[0]) - len(w) >= 2):
            return _FORM_MAP[near[0]], (i, i + 1), True
    return None, None, False


def _colors(words: list[str]) -> list[str]:
    out: list[str] = []
    i = 0
    while i < len(words):
        two = " ".join(words[i:i + 2])
        c2 = canonical_color(two) if i + 1 < len(words) else None
        if c2:
            out.append(c2)
            i += 2
            continue
        c = canonical_color(words[i])
        if c:
            out.append(c)
        i += 1
    return list(dict.fromkeys(out))


#: Words whose typos would hide a predicate or attribute ("bseide" for "beside", "yelow" for "yellow").
_KEYWORDS = ["beside", "near", "next", "behind", "opposite", "front", "closest", "nearest", "farthest",
             "furthest", "biggest", "largest", "smallest", "kitchen", "bedroom", "bathroom", "living", "office",
             *sorted(w for w in LEXICON if " " not in w and len(w) >= 5)]
_COMMON_ADJECTIVES = {"shaped", "l", "coloured", "colored", "color", "colour", "light", "dark", "first", "second",
                      "third", "fourth", "last", "other", "left", "right", "main", "old", "new", "nice", "same",
                      "only", "usual", "favourite", "favorite", "pretty", "modern", "classic", "comfy", "comfortable"}


def _ratio(a: str, b: str) -> float:
    return difflib.SequenceMatcher(None, a, b).ratio()


def _fix_keyword_typos(words: list[str]) -> list[str]:
    out = []
    for w in words:
        if len(w) >= 5 and w not in _ENGLISH_HINTS and w not in _FORM_WORDS:
            near = difflib.get_close_matches(w, _KEYWORDS, n=1, cutoff=0.8)
            # Only when no category word is at least as close ("bedsde" is "bedside", not "beside").
            if near and _ratio(w, near[0]) > max((_ratio(w, f) for f in _FORM_WORDS), default=0.0):
                w = near[0]
        out.append(w)
    return out


def _is_compound_modifier(word: str, known: set[str]) -> bool:
    """A word before a category noun that is no colour, material, size, shape or filler word
    (nor a typo of one) and no category word makes a different object ("pool table")."""
    if word in known or word in _FORM_WORDS or word in _KEYWORDS or not word.isalpha() or len(word) < 3:
        return False
    return not difflib.get_close_matches(word, sorted(known | _FORM_WORDS), n=1, cutoff=0.75)


def parse_instruction(text: str) -> ParsedQuery:
    t = validate_instruction(text)
    low = t.lower()
    norm = re.sub(r"[^a-z0-9\-' ]+", " ", low)
    norm = " ".join(_fix_keyword_typos(norm.replace("'s", "").split()))
    q = ParsedQuery(text=t)
    # Room: "in the kitchen", "in the living room".
    head = norm
    for phrase in sorted(ROOM_SYNONYMS, key=len, reverse=True):
        m = re.search(rf"\b(?:in|inside|within|from|of)\s+(?:the\s+|my\s+|our\s+)?{re.escape(phrase)}\b", head)
        if m:
            q.room = ROOM_SYNONYMS[phrase]
            head = (head[:m.start()] + " " + head[m.end():]).strip()
            break
    # Proximity (checked before relations so that "closest to me" is not a relation).
    for phrase in sorted(_PROXIMITY, key=len, reverse=True):
        if re.search(rf"\b{phrase}\b", head):
            q.proximity = _PROXIMITY[phrase]
            head = re.sub(rf"\b{phrase}\b", " ", head)
            break
    # Relation: "<target> next to the <anchor>".
    for rel in _RELATIONS:
        m = re.search(rf"\b{rel}\s+(?:the\s+|a\s+|an\s+|my\s+)?(.+)$", head)
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
        if re.search(rf"\b{phrase}\b", head):
            q.superlative = _SUPERLATIVE[phrase]
            break
    q.size_word = next((_SIZE_WORDS[w] for w in words if w in _SIZE_WORDS), None)
    q.colors = _colors(words)
    if len(q.colors) > 1 and "terracotta" in q.colors:  # "a yellow terracotta pot": a material here
        q.colors.remove("terracotta")
    q.shapes = list(dict.fromkeys(_SHAPES[w] for w in words if w in _SHAPES))
    if "l-shaped" in head or "l shaped" in head:
        q.shapes = list(dict.fromkeys([*q.shapes, "L-shaped"]))
    q.materials = [w for w in words if w in _MATERIALS]
    cat, span, _ = _find_category(words)
    q.category = cat
    known = (set(_FILLER) | set(LEXICON) | set(ALIASES) | set(_SHAPES) | set(_SIZE_WORDS) | set(_SUPERLATIVE)
             | _MATERIALS | _COMMON_ADJECTIVES)
    if span is not None and span[0] > 0 and _is_compound_modifier(words[span[0] - 1], known):
        # "pool table", "picnic table": another object whose name ends in a category word.
        cat, span = None, None
        q.category = None
    rest = [w for k, w in enumerate(words) if (span is None or not span[0] <= k < span[1]) and w not in known]
    if cat is None:
        q.unknown_words = rest
    desc = [*q.colors, *q.materials, *q.shapes]
    noun = cat if cat is not None else " ".join(rest[-2:]) if rest else ""
    q.target_phrase = " ".join([*desc, noun]).strip() or norm
    return q
