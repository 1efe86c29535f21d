"""Tokens and lexicon look-ups of an instruction: validation (empty, too long, not English),
every surface form of every category (WordNet's and the vocabulary's, with plurals), typos of
category names and keywords, colour, size, shape and material words, ordinals.

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

from rapidfuzz import fuzz, process
from rapidfuzz.distance import OSA

from capnav.core.categories import CATEGORIES
from capnav.core.errors import InputError
from capnav.language.colors import ALIASES, LEXICON, SHADES, canonical_color, color_lab
from capnav.language.context import room_ending
from capnav.language.lexicon import load_lexicon
from capnav.retrieval.query.model import END_OF

# A spoken request that rambles runs to about a hundred words; past these limits the text is more
# likely pasted by mistake, and MiniLM reads only its first 256 word pieces (about 190 words).
MAX_CHARS = 800
MAX_WORDS = 120

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
#: Words for a kind of several categories ("appliance", "furniture") name themselves here; the
#: mapping asks for every category of the kind (``Lexicon.kinds``).
for _f in _LEX.kinds:
    _FORM_MAP.setdefault(_f, _f)
    _FORM_MAP.setdefault(_plural(_f), _f)
#: The detector's classes that are not categories, by their everyday names (WordNet's, the
#: lexicon's ``labels``): "the mug on the table" asks for a cup, not the table.
LABEL_MAP: dict[str, str] = {}
for _f, _c in sorted(_LEX.labels.items()):
    if _f not in _FORM_MAP:
        LABEL_MAP[_f] = _c
        LABEL_MAP.setdefault(_plural(_f), _c)
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

#: Misspelt multi-word names are matched against the vocabulary's own names.
_TYPO_FORMS = {f: c.name for c in CATEGORIES for f0 in (c.name, *c.synonyms) for f in (f0, _plural(f0))}
_MULTI_FORMS = sorted(f for f in _TYPO_FORMS if " " in f)
_TYPO_WORDS = {w for f in _TYPO_FORMS for w in f.split()}
#: A misspelt single word is matched against every single-word form (WordNet's and the
#: vocabulary's, with plurals: "cacuts" is a cactus), by first letter: typos rarely change the
#: first letter of a word, and "wellies" is no "tellies". The vocabulary's own names come first,
#: so they win a tie.
_SINGLE_BY_LETTER: dict[str, list[str]] = {}
for _f in [*sorted(f for f in _TYPO_FORMS if " " not in f), *sorted(f for f in _FORM_MAP if " " not in f)]:
    if len(_f) >= 4 and _f.isalpha() and _f not in _SINGLE_BY_LETTER.get(_f[0], []):
        _SINGLE_BY_LETTER.setdefault(_f[0], []).append(_f)


def typo_distance(word: str) -> int:
    """The edit distance (optimal string alignment: two swapped letters are one edit) within which
    ``word`` is read as a typo of a known word: 1 up to five letters, else 2 (the lexicon's
    ``not_typos``, the real words that near, is built with the same rule)."""
    return 1 if len(word) <= 5 else 2


def _nearest(word: str, pool: list[str]) -> str | None:
    """The word of ``pool`` (sharing ``word``'s first letter) within ``typo_distance`` of it, the
    nearest first, else None."""
    hit = process.extractOne(word, pool, scorer=OSA.distance, score_cutoff=typo_distance(word))
    return None if hit is None else str(hit[0])
#: rapidfuzz ratio (0-100) at which a misspelt multi-word name is read as that name: two letters
#: wrong in "washing machine" (89.7) pass, a different word ("washing line") does not.
_MULTI_TYPO_SCORE = 86.0


def nearly_named(text: str, category: str) -> str | None:
    """The multi-word name of ``category`` some words of ``text`` nearly say (rapidfuzz's ratio at
    least ``_MULTI_TYPO_SCORE``, the parser's rule for a misspelt name) although the parser did not
    read them as it, since a changed word is an English word of its own ("the brown lunge chair":
    'lunge' is a word, so the parse is a chair, and the words nearly say "lounge chair", an
    armchair), else None. A weaker reading than the parser's: for judging a stand-in only."""
    words = re.findall(r"[a-z]+", text.lower())
    forms = [f for f in _MULTI_FORMS if _TYPO_FORMS[f] == category]
    for n in (3, 2):
        pool = [f for f in forms if len(f.split()) == n]
        for i in range(len(words) - n + 1) if pool else ():
            hit = process.extractOne(" ".join(words[i:i + n]), pool, scorer=fuzz.ratio,
                                     score_cutoff=_MULTI_TYPO_SCORE)
            if hit is not None:
                return str(hit[0])
    return None


_PROXIMITY = {"closest": "closest", "nearest": "closest", "near me": "closest", "closest to me": "closest",
              "farthest": "farthest", "furthest": "farthest", "most distant": "farthest"}
_SUPERLATIVE = {"biggest": "largest", "largest": "largest", "largest one": "largest",
                "smallest": "smallest", "tiniest": "smallest", "littlest": "smallest"}
#: "widest", "narrowest", "broadest" (the lexicon's ``width_superlatives``): by the footprint's longer side.
_SUPERLATIVE.update(_LEX.width_superlatives)
#: "tallest", "lowest" (the lexicon's ``height_superlatives``): ordered by the mapped height.
_SUPERLATIVE.update(_LEX.height_superlatives)
_SIZE_WORDS = {"big": "large", "large": "large", "huge": "large", "larger": "large", "bigger": "large",
               "small": "small", "little": "small", "tiny": "small", "smaller": "small", "compact": "small"}
#: WordNet's size adjectives and their comparatives ("king-size", "oversized", "tinier"; the lexicon).
_SIZE_WORDS.update(_LEX.sizes)
#: Words of height ("tall", "short", "lanky", "lower"; the lexicon's ``heights``): compared with
#: the mapped heights of the category rather than the volumes. A size word of both tables stays a size.
_SIZE_WORDS.update({w: s for w, s in _LEX.heights.items() if w not in _SIZE_WORDS})
_HEIGHT_WORDS = {w for w in _LEX.heights if w not in _LEX.sizes} | set(_LEX.height_superlatives)
#: Words of width ("wide", "narrow", "broader"; the lexicon's ``widths``): compared with the mapped
#: footprint's longer side ("the narrow wardrobe" of a two-door and a three-door one).
_SIZE_WORDS.update({w: s for w, s in _LEX.widths.items() if w not in _SIZE_WORDS})
_WIDTH_WORDS = {w for w in _LEX.widths if w not in _LEX.sizes and w not in _LEX.heights} \
    | set(_LEX.width_superlatives)
_SIZE_TOKENS = {w for f in _SIZE_WORDS for w in f.split()}
_SHAPES = {"round": "round", "circular": "round", "l-shaped": "L-shaped", "l shaped": "L-shaped",
           "corner": "L-shaped", "long": "long", "rectangular": "rectangular", "square": "square",
           "curved": "curved", "oval": "round",
           # the growth words the offline captioner says of a plant (capnav.language.form): a bush
           # is leafy (its points do not tell it from a leafy crown on a stem)
           "leafy": "leafy", "bushy": "leafy", "slender": "slender"}
#: Adjectives WordNet relates to a shape word ("boxy", "oblong", "disc-shaped", "rounded"; the
#: lexicon's ``attributes``); the hand table above wins where both have a word.
_SHAPES = {**{w: v for w, (kind, v, _) in _LEX.attributes.items() if kind == "shape" and " " not in w}, **_SHAPES}
#: Words of a property no map observes ("squishy", "padded": soft): read, neither confirm nor refuse.
UNOBSERVED = {w: v for w, (kind, v, _) in _LEX.attributes.items() if kind == "unobserved" and " " not in w}
#: Colour words beyond the colour tables, as their nearest colour ("vermilion" scarlet, "azure"
#: light blue, "tangerine" reddish orange; the lexicon's ``attributes``).
_COLOUR_OF = {w: v for w, (kind, v, _) in _LEX.attributes.items() if kind == "colour"}
#: Words that name a plant's growth form ("cactus", "succulent", "prickly"; WordNet's, the lexicon)
#: -> the growth word the captioner measures ("slender").
_GROWTH = _LEX.growth
_GROWTH_TOKENS = {w for f in _GROWTH for w in f.split()}
_RELATIONS = [END_OF, "in front of", "facing", "next to", "close to", "beside", "besides", "near", "by", "behind",
              "opposite", "across from", "alongside", "against",
              # above or below the landmark: on the floor plan the two touch (ranked by the gap
              # between footprints, as "next to"); the thing hung over a sink is not the sink
              "on top of", "above", "below", "underneath", "beneath", "under", "atop",
              # standing on the landmark ("the vase on the table"): "on top of"; tried after every
              # longer relation that starts with it ("on the left of")
              # a side of the landmark, as the speaker sees it ("the chair to the left of the desk")
              *(f"{prep}{side} of" for side in ("left", "right", "left-hand side", "right-hand side", "left side",
                                                "right side", "left hand side", "right hand side")
                for prep in ("to the ", "on the ", "at the ", "")), "on",
              # "the stool at the counter", "a seat at the kitchen table": beside it (last, after
              # every longer relation that starts with it: "at the end of", "at the left of")
              "at"]
_MATERIALS = {"wooden", "wood", "leather", "fabric", "velvet", "metal", "glass", "marble", "plastic",
              "ceramic", "stainless", "steel", "laminate", "cotton", "acrylic", "paper", "terracotta", "chrome"}
#: Every other material word WordNet has, spoken as the material the surface test knows
#: ("velvety" -> velvet, "suede" -> leather, "teak" -> wood; the lexicon's ``materials``).
#: Adjectives and nouns WordNet relates to a material otherwise ("see-through": glass, its
#: definition's "transparent"; "timber": wood, its definition's genus; the lexicon's ``attributes``).
_MATERIAL_OF = {**{w: v for w, (kind, v, _) in _LEX.attributes.items() if kind == "material" and " " not in w},
                **_LEX.materials, **{w: w for w in _MATERIALS}}


def material_of(word: str) -> str | None:
    """The material ``word`` names: a material word, or a hyphenated modifier whose first part is
    one and whose last is a participle ("wooden-topped", "leather-covered", "glass-fronted")."""
    if word in _MATERIAL_OF:
        return _MATERIAL_OF[word]
    parts = word.split("-")
    if len(parts) > 1 and parts[0] in _MATERIAL_OF and parts[-1].endswith("ed") and len(parts[-1]) > 3:
        return _MATERIAL_OF[parts[0]]
    return None


def materials_in(words: list[str]) -> list[str]:
    """The materials ``words`` name, once each, in order: the plain words as spoken, the others
    as the material they are ("a velvety suede chair" -> velvet, leather; "wooden-topped" wood)."""
    return list(dict.fromkeys(m for w in words if (m := material_of(w)) is not None))
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
    """(category, word span, fuzzy) of the first object mention: a category (exact n-grams before
    typos), or a detector class named before it ("the mug on the table": a cup)."""
    cat, span, fuzzy = _find_vocabulary(words)
    while span is not None and (nxt := _exact_at(words, span[1])) is not None:
        # A noun compound's head is its last noun: "the desk chair" is a chair, "the tv cabinet"
        # a cabinet; the category word before it says what kind. A word read as a typo right
        # before an exact name is its modifier ("the stone counter" is no stove).
        cat, span = nxt
        fuzzy = False
    # A class's exact name also beats a typo read at the same place ("hair drier" is no "chair").
    label = _find_label(words, len(words) if span is None else span[0] + int(fuzzy))
    if label is None and fuzzy and span is not None:
        # ... and a class's exact name right after a typo read ("the stone bench": a bench).
        label = _find_label(words[span[1]:], 1)
        label = None if label is None else (label[0], (span[1] + label[1][0], span[1] + label[1][1]), False)
    if label is None and cat is None:
        found = furniture_sense(words)
        return found if found[0] is not None else plant_name(words)
    return label if label is not None else (cat, span, fuzzy)


_DET = {"the", "a", "an", "my", "our", "your", "his", "her", "their", "this", "that", "these", "those"}


def furniture_sense(words: list[str]) -> tuple[str | None, tuple[int, int] | None, bool]:
    """A word WordNet has as one category's furniture although its first sense is another thing
    ("the kitchen press": the wardrobe's "clothes press"), read only where an object's name
    stands (within two words after a determiner, not before "of") in words that name no
    category otherwise; (None, None, False) when there is none."""
    for k, w in enumerate(words):
        base = w if w in _LEX.furniture_senses else w[:-2] if w.endswith("es") and w[:-2] in _LEX.furniture_senses \
            else w[:-1] if w.endswith("s") and w[:-1] in _LEX.furniture_senses else None
        if base is None or not any(x in _DET for x in words[max(0, k - 2):k]):
            continue
        if k + 1 < len(words) and words[k + 1] in ("of", "to", "up", "down", "on", "off"):
            continue
        return str(_LEX.furniture_senses[base]["category"]), (k, k + 1), False
    return None, None, False


def plant_name(words: list[str]) -> tuple[str | None, tuple[int, int] | None, bool]:
    """A kind of plant ("the ficus", "the rubber plant", "the yucca by the door") in words that
    name no category otherwise: the plant category (``Lexicon.plant_names``, from WordNet's
    vascular plants); the longest name first, a plural read as its singular."""
    for n in (3, 2, 1):
        for k in range(len(words) - n + 1):
            gram = words[k:k + n]
            last = gram[-1]
            for tail in (last, last[:-1] if last.endswith("s") else None, last[:-2] if last.endswith("es") else None):
                if tail and " ".join([*gram[:-1], tail]) in _LEX.plant_names:
                    return "plant", (k, k + n), False
    return None, None, False


def _exact_at(words: list[str], i: int) -> tuple[str, tuple[int, int]] | None:
    """The category whose exact name starts at word ``i`` (longest first), else None."""
    for n in (3, 2, 1):
        gram = " ".join(words[i:i + n])
        if i + n <= len(words) and gram in _FORM_MAP:
            return _FORM_MAP[gram], (i, i + n)
    return None


def _find_label(words: list[str], before: int) -> tuple[str, tuple[int, int], bool] | None:
    """The first detector-class name starting before word ``before`` (longest first), else None."""
    for i in range(min(before, len(words))):
        for n in (3, 2, 1):
            gram = " ".join(words[i:i + n])
            if i + n <= len(words) and gram in LABEL_MAP:
                return LABEL_MAP[gram], (i, i + n), False
    return None


def _find_vocabulary(words: list[str]) -> tuple[str | None, tuple[int, int] | None, bool]:
    """(category, word span, fuzzy) of the first category mention, exact or misspelt; at the same
    word a longer name before a shorter one and an exact name before a typo."""
    found: list[tuple[int, int, tuple[str, tuple[int, int], bool]]] = []  # (start, preference, hit)
    for n in (3, 2):
        for i in range(len(words) - n + 1):
            gram = " ".join(words[i:i + n])
            if gram in _FORM_MAP:
                found.append((i, 3 - n, (_FORM_MAP[gram], (i, i + n), False)))
                break
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
                found.append((i, 2, (_TYPO_FORMS[hit[0]], (i, i + n), True)))
                break
    for i in range(len(words)):
        if words[i] in _FORM_MAP:
            found.append((i, 3, (_FORM_MAP[words[i]], (i, i + 1), False)))
            break
    for i, w in enumerate(words):
        if len(w) < 4 or w in _FILLER or canonical_color(w) or w in _SHAPES or w in _SIZE_WORDS \
                or w in _LEX.not_typos or w in LABEL_MAP or w in _FORM_MAP or not w.isalpha() \
                or w in _COMMON_ADJECTIVES or w in _ENGLISH_HINTS or w in _LEX.attributes:
            continue
        near = _nearest(w, _SINGLE_BY_LETTER.get(w[0], []))
        # A word two or more letters short of a name's start is another word, not a typo ("wash").
        if near and not (near.startswith(w) and len(near) - len(w) >= 2):
            found.append((i, 4, (_FORM_MAP.get(near) or _TYPO_FORMS[near], (i, i + 1), True)))
            break
    if not found:
        return None, None, False
    return min(found, key=lambda t: (t[0], t[1]))[2]


_COLOR_NOT_ALONE = {"light", "dark", "pale", "deep", "bright", "soft", "rich", "vivid", "dull", "muted", "dusty",
                    "faded", "pastel"}


def _color_name(phrase: str) -> str | None:
    """The palette name of a colour phrase when it has one ("gray" -> "grey"), else the phrase
    itself when it names a colour ("reddish", "pale pink", "dark wooden"), else None."""
    if phrase in _COLOR_NOT_ALONE or phrase in _FORM_MAP or phrase in LABEL_MAP:
        return None
    if phrase in _MATERIALS and phrase != "terracotta":
        return None  # "stainless steel", "chrome": what it is made of, not a colour (the material says it)
    name = canonical_color(phrase)
    if name is not None:
        return name
    if color_lab(phrase) is not None:
        return phrase
    return _COLOUR_OF.get(phrase)


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


#: Short keywords and colours a three- or four-letter typo drops a letter of ("nxt" next, "blu"
#: blue, "gren" green).
_SHORT_KEYWORDS = sorted({w for w in ("next", "near", "hall", "room", "front", "behind", *LEXICON, *SHADES)
                          if len(w) in (4, 5) and w.isalpha()})


_DETERMINERS = {"the", "a", "an", "my", "our", "your", "his", "her", "their", "this", "that"}


def _noun_place(words: list[str], k: int) -> bool:
    """Whether ``words[k]`` follows a determiner and ends the request (but for "please" or
    punctuation), where the object's name stands, and is no word the vocabulary knows there."""
    rest = [w for w in words[k + 1:] if w not in ("please", "?", ".", "!", ",")]
    w = words[k]
    return k > 0 and words[k - 1] in _DETERMINERS and not rest and not _FORM_WORDS.intersection(words) \
        and bool(difflib.get_close_matches(w, [c for c in _KEYWORDS if c in LEXICON or c in SHADES], n=1, cutoff=0.8)) \
        and not canonical_color(w)


def _fix_keyword_typos(words: list[str]) -> list[str]:
    """``words`` with misspelt keywords, colours, rooms and category names corrected: a word no
    list knows as English, within ``typo_distance`` of a known word that starts with the same
    letter ("ofice" office, "yelow" yellow, "cacuts" cactus, "plnat" plant); a three-letter word
    or four-letter word that drops one letter of a keyword ("nxt" next, "blu" blue, "gren" green)."""
    out = []
    for k, w in enumerate(words):
        if _noun_place(words, k):
            # "where's the khazi": a word after an article that ends the request stands where the
            # object's name does; an unknown noun there is no misspelt colour ("khaki").
            out.append(w)
            continue
        if w in _ENGLISH_HINTS or w in _FORM_WORDS or w in _LEX.not_typos or w in _COMMON_ADJECTIVES \
                or w in _LEX.attributes or not w.isalpha() or len(w) < 3:
            out.append(w)
            continue
        fixed = None
        if len(w) >= 5:
            near = difflib.get_close_matches(w, _KEYWORDS, n=1, cutoff=0.8)
            # Only when no category word is at least as close ("bedsde" is "bedside", not "beside").
            if near and _ratio(w, near[0]) > max((_ratio(w, f) for f in _TYPO_WORDS if f != near[0]), default=0.0):
                fixed = near[0]
        if fixed is None and len(w) in (3, 4):
            fixed = next((k for k in _SHORT_KEYWORDS if len(k) == len(w) + 1 and k[0] == w[0]
                          and OSA.distance(w, k) == 1), None)
        if fixed is None and len(w) >= 4 and not canonical_color(w) and w not in LABEL_MAP and w not in _SHAPES \
                and w not in _SIZE_WORDS:
            near_form = _nearest(w, _SINGLE_BY_LETTER.get(w[0], []))
            if near_form and abs(len(near_form) - len(w)) <= 1:
                fixed = near_form
        out.append(fixed or w)
    return out


_ORDINALS = {"first": 1, "1st": 1, "second": 2, "2nd": 2, "third": 3, "3rd": 3, "fourth": 4, "4th": 4,
             "fifth": 5, "5th": 5}


def _room_before(words: list[str], start: int) -> tuple[str | None, int]:
    """A room named just before the target noun ("the office lamp"): (room, its first word)."""
    found = room_ending(words, start)
    return (found[0], start - found[1]) if found else (None, start)


def _size_word(words: list[str]) -> tuple[str | None, str | None]:
    """"large" / "small" from the first size word ("king size" and "king-size" alike), with what it
    measures (``size_axis``); a size word right after "a" / "an" that ends the sentence is a noun
    ("I need a wee", "move a little")."""
    for i in range(len(words)):
        for n in (2, 1):
            gram = " ".join(words[i:i + n])
            if i + n <= len(words) and gram in _SIZE_WORDS:
                if i + n == len(words) and i > 0 and words[i - 1] in ("a", "an"):
                    continue
                return _SIZE_WORDS[gram], size_axis(gram)
    return None, None


def size_words(words: list[str]) -> list[tuple[str, str | None]]:
    """Every dimension a size word says, the first word of each ("the tall narrow bookcase":
    large by height, small by width), in the order said; the first is ``_size_word``'s."""
    out: dict[str | None, str] = {}
    rest = list(words)
    while True:
        size, axis = _size_word(rest)
        if size is None:
            return [(s, a) for a, s in out.items()]
        out.setdefault(axis, size)
        k = next(i for i in range(len(rest)) if any(" ".join(rest[i:i + n]) in _SIZE_WORDS
                                                    and _SIZE_WORDS[" ".join(rest[i:i + n])] == size
                                                    and size_axis(" ".join(rest[i:i + n])) == axis for n in (2, 1)))
        rest = rest[k + 1:]


def size_axis(word: str) -> str | None:
    """What a size word or superlative measures: "height" ("tall", "lowest"), "width" ("narrow",
    "widest": the footprint's longer side), or None for the volume."""
    return "height" if word in _HEIGHT_WORDS else "width" if word in _WIDTH_WORDS else None


def _other_object(words: list[str], span: tuple[int, int] | None) -> str | None:
    """A WordNet compound around the category span that names something else ("pool table")."""
    if span is None:
        return None
    for n in (3, 2):
        for i in range(max(0, span[1] - n), span[0] + 1):
            gram = " ".join(words[i:i + n])
            if i + n >= span[1] and (gram in _LEX.other or (gram.endswith("s") and gram[:-1] in _LEX.other)):
                return gram  # "bath towels": a plural too
    return None


def attribute_word(word: str) -> bool:
    """Whether the mapping would read ``word`` as an attribute of the target: a colour, shape,
    size, material or growth word ("blue", "round", "big", "velvet", "prickly")."""
    w = word.lower()
    return bool(w in _SHAPES or w in _SIZE_WORDS or w in _SUPERLATIVE or material_of(w) or w in _GROWTH
                or _color_name(w))
