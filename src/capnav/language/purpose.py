"""Requests by purpose ("somewhere to sit", "where can I brush my teeth?") -> candidate categories.

Why: people often name what they want to do, not the object. The activity is compared, with the
text embedder, to what WordNet says each category is for (the lexicon's glosses: a bed "provides a
place to sleep", a washbasin is "where you can wash your hands and face"), so no hand table maps
activities to objects. The best category becomes the target; close runners-up become weighted
alternatives (a place to sit: chair, then armchair, sofa, stool).

The activity is put the way the glosses speak before it is embedded: a light verb and its article
go ("have a lie down" -> "lie down", "take a nap" -> "nap": the noun carries the meaning) and the
speaker's pronouns become the generic "you" of the template ("put my feet up" -> "put your feet
up"). A category scores the mean of its ``top_k`` best gloss cosines, not its single best: one
hyponym's gloss that shares a word with the activity (a foot bath's "feet") no longer outranks a
category whose definitions all fit.

Embedding the ~100 glosses takes about 1 s, so ``describe_map`` stores them in the map
(``cmap.caches["glosses"]``: the vectors with the embedder's ``model_id`` and a digest of the gloss
texts) and the retriever hands them to ``use_stored_glosses``. They are used only when the query
embedder's ``model_id`` and the current lexicon's texts give the same digest; otherwise (another
embedder, a rebuilt lexicon, a map captioned before they were stored) they are computed as before.
"""

from __future__ import annotations

import base64
import hashlib
import re
import weakref
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.categories import BY_NAME
from capnav.language.embedder import TextEmbedder
from capnav.language.lexicon import Lexicon, load_lexicon

#: A purpose clause: "somewhere (comfy) to X", "a place where I can X", "where can I X",
#: "I need to X", "something to X on". The activity is group ``act``.
_PURPOSE = [
    re.compile(r"\b(?:somewhere|someplace|some place|anywhere|(?:a|some)(?:\s+(?!to\b|for\b|where\b)\w+)?\s+"
               r"(?:place|spot|surface|nook|corner)|something|anything|a thing)"
               r"(?:\s+\w+)?\s+(?:where\s+)?(?:(?:i|we|you|one)\s+(?:can|could|might|may)|to|for\s+(?:me\s+)?to"
               r"|for|that\s+i\s+can)\s+(?P<act>.+)"),
    re.compile(r"\bwhere\s+(?:can|could|do|should|might|would|may)\s+(?:i|we|one|you|(?:the|my|our|your|his|her|"
               r"their)\s+\w+)\s+(?P<act>(?!be\b|get\b).+)"),
    re.compile(r"\b(?:i|we)\s*(?:'d|would)?\s*(?:need|want|like|wanna|have|fancy)\s+(?:to\s+)?(?P<act>(?!go\b|find\b"
               r"|see\b"
               r"|get to\b|visit\b).+)"),
    re.compile(r"\b(?:i'm|i am|we're|we are)\s+(?P<act>(?:tired|sleepy|hungry|thirsty|cold|dirty)\b.*)"),
]
#: What is kept somewhere, not the furniture: "where are the towels kept", "where do my socks
#: go", "the thing that holds the plates", "wherever the spoons live". The activity becomes
#: "keep <things>", which the storage furniture's definitions state.
_KEPT = [
    re.compile(r"\bwhere(?:ver)?\s+(?:(?:are|is|do|does|did|should|would|can)\s+)?"
               r"(?P<obj>(?:the|my|our|your|his|her|their|these|those|this|that|all|some)\s+.+?)"
               r"(?:\s+(?:is|are|get|gets))?\s+(?:usually\s+|normally\s+)?"
               r"(?:kept|stored|put away|go|goes|live|lives|belong|belongs|sit|sits)\b"),
    re.compile(r"\b(?:thing|place|furniture|one|piece|spot)\s+(?:that|which|where)?\s*(?:holds?|stores?|keeps?|has)"
               r"\s+(?P<obj>.+)"),
    re.compile(r"\b(?:keeps?|holds?|stores?)\s+(?P<obj>(?:the|my|our|your|all)\s+.+)"),
]
#: What is done to a thing after the verb of where it goes: "(go) to get washed", "to be dried",
#: "to dry off" (a passive's participle, or the verb itself).
_DONE_TO = re.compile(r"^\s+to\s+(?:(?P<passive>get|be)\s+)?(?P<verb>[a-z]+)(?P<tail>(?:\s+(?:up|off|out|down))?)\b")
#: A light verb with its article ("have a", "take a quick"): the noun after it names the activity.
_LIGHT_VERB = re.compile(r"^(?:have|take|get|grab|catch|go\s+for|do)\s+(?:a|an|some)\s+"
                         r"(?:(?:quick|little|short|long|good|proper|nice)\s+)?(?=\w)")
#: First-person words -> the template's generic "you".
_PERSON = {"my": "your", "me": "you", "myself": "yourself", "i": "you", "our": "your", "us": "you",
           "ourselves": "yourselves", "we": "you", "mine": "yours"}
#: Words after the activity that belong to the rest of the description, not to the activity.
_TAIL = re.compile(r"\b(?:in|inside|near|next to|by|beside|close to|closest|nearest|farthest|furthest)\b.*$")
_PLACEHOLDERS = {"somewhere", "someplace", "anywhere", "place", "spot", "something", "thing", "where"}


@dataclass(frozen=True)
class PurposeConfig:
    template: str = "a place where you can {activity}"  # how the activity is embedded
    normalise: bool = True  # drop a light verb, "you" for the speaker (``normalise_activity``)
    top_k: int = 2  # a category's score: the mean of its top_k gloss cosines
    #: Runners-up within this of the best score become alternatives (ranked below it, used when it
    #: is absent or a room or landmark decides). 0.16, twice the glosses-only margin: the stated
    #: purpose spreads the scores (a nap: bed 0.52, armchair 0.37, sofa 0.35).
    margin: float = 0.16
    min_score: float = 0.2  # below this best score no category serves the activity
    max_alternatives: int = 4
    #: Share of a category's score that comes from the purpose its definitions state (made for
    #: the activity) rather than from all its glosses (which also match what merely allows it).
    #: 0.3: on the activities of tests/language/test_purpose_fit.py the best of 0, 0.3, 0.4, 0.5,
    #: 0.7, 1 (28, 32, 31, 31, 26, 25 of 34 right); the glosses alone let a foot bath's "feet"
    #: outrank the footstool and a sofa bed's "bed" outrank the bed.
    stated_weight: float = 0.3


@dataclass(frozen=True)
class PurposeMatch:
    activity: str  # "brush my teeth"
    scores: dict[str, float]  # category -> mean cosine of the activity to its top_k glosses, best first


def normalise_activity(activity: str) -> str:
    """The activity as the template and the glosses say it: without a light verb ("have a lie
    down" -> "lie down") and with "you" for the speaker ("put my feet up" -> "put your feet up")."""
    act = " ".join(activity.lower().split())
    stripped = _LIGHT_VERB.sub("", act)
    act = stripped if stripped.strip() else act
    return " ".join(_PERSON.get(w, w) for w in act.split())


def explain_activity(activity: str) -> str:
    """The activity with what its idiom means, when it starts with one of WordNet's light-verb
    idioms ("do the dishes" -> "do the dishes: wash dishes"; "doing the dishes" too)."""
    words = activity.split()
    if not words:
        return activity
    phrases = load_lexicon().verb_phrases
    for verb in _verb_forms(words[0]):
        for n in (4, 3, 2):
            gram = " ".join([verb, *words[1:n]])
            if len(words) >= n and gram in phrases:
                return f"{activity}: {phrases[gram]}"
    return activity


def find_activity(text: str) -> str | None:
    """The activity of a purpose request, lower case, or None when the text names none."""
    low = text.lower().strip().rstrip("?.!")
    persons = load_lexicon().persons
    for pat in _KEPT:
        m = pat.search(low)
        if m:
            obj = _TAIL.sub("", m.group("obj")).strip(" ,?.!")
            # "where can the kids sit": people doing something, not a thing kept somewhere
            if obj and obj.split()[-1] not in _PLACEHOLDERS and obj.split()[-1] not in persons:
                done = _DONE_TO.match(low[m.end():])
                if done is not None:
                    # "where do the wet towels go to get dried": what is done to the thing, not
                    # where it is kept.
                    verb, tail = done.group("verb"), _TAIL.sub("", done.group("tail")).strip(" ,?.!")
                    if done.group("passive"):
                        return " ".join(p for p in ("get", obj, verb, tail) if p)
                    return " ".join(p for p in (verb, tail, obj) if p)
                return f"keep {obj}"
    said = _construction_activity(low)
    if said is not None:
        return said
    m = _THING_SAID.search(low)
    if m and m.group("adj") not in _PLACEHOLDERS:
        # "anything cold to drink": the word is said of the thing the act handles.
        act = _TAIL.sub("", m.group("act")).strip(" ,?.!")
        if act:
            return f"{act} {m.group('thing')} {m.group('adj')}"
    for pat in _PURPOSE:
        m = pat.search(low)
        if m:
            act = _TAIL.sub("", m.group("act")).strip(" ,?.!")
            act = re.sub(r"^(?:please|just|quickly)\s+", "", act)
            act = re.sub(r"\s+(?:right|just|somewhere|anywhere)$", "", act)  # "... right next to the bed"
            if act and act not in _PLACEHOLDERS:
                return _with_antecedent(act, low[: m.start()])

    return None


#: A thing with a word said of it before its use: "something cold to drink", "anything soft to sit on".
_THING_SAID = re.compile(r"\b(?P<thing>something|anything)\s+(?P<adj>(?!to\b|for\b|where\b|that\b|which\b|i\b|we\b)"
                         r"[a-z]+)\s+(?:to|for)\s+(?P<act>.+)$")
#: A task one has (got) to do: "I've got to V ...", "we have got NP to V ...", "I have NP to V".
_GOT = re.compile(r"\b(?:i|we)\s*(?:'ve|\s+have|\s+has)?\s+got\s+(?P<rest>.+)"
                  r"|\b(?:i|we)\s*(?:'ve|\s+have)\s+(?P<np_rest>(?:a|an|some|the|my|our|loads|lots|a\s+lot)\b.+)")
#: The thing before "to V": a noun phrase, then the verb and what follows it.
_NP_TO_V = re.compile(r"^(?P<np>.+?)\s+to\s+(?P<verb>[a-z]+)\b(?P<tail>.*)$")
#: A causative "get NP done" / "get NP written": the participle says the act done to the thing.
_GET_DONE = re.compile(r"\bwhere\s+(?:can|could|do|should|might|would|may)\s+(?:i|we|one|you)\s+get\s+"
                       r"(?P<np>(?:the|my|our|your|some|this|these|that|those|a|an)\s+.+?)\s+"
                       r"(?P<part>done|[a-z]+(?:ed|en))\b(?P<tail>.*)$")
#: A question about someone in the act: "where is SUBJ V-ing ..." (the copula may have gone with
#: the reader's "'s": "where everyone having lunch").
_PROGRESSIVE = re.compile(r"\bwhere(?:'s|\s+is|\s+are|\s+was|\s+were|\s+will)?\s+(?:be\s+)?"
                          r"(?P<subj>(?:[a-z']+\s+){0,2}?[a-z']+)\s+(?P<act>[a-z]+ing\b.*)$")


def _construction_activity(low: str) -> str | None:
    """The activity of a task said as had or got to do ("I've got a pile of ironing to do" -> "do
    a pile of ironing"), a thing got done ("where can I get my accounts done" -> "do my accounts")
    or someone asked about in the act ("where are the kids eating" -> "eating"). Its subject or
    object naming a category the map knows ("where's the lamp standing") is a thing, no act."""
    forms = load_lexicon().forms
    m = _GOT.search(low)
    if m:
        rest = (m.group("rest") or m.group("np_rest") or "").strip(" ,?.!")
        if rest.startswith("to "):
            act = rest[3:].strip()
            return _TAIL.sub("", act).strip(" ,?.!") or None
        n = _NP_TO_V.match(rest)
        if n:
            tail = _TAIL.sub("", n.group("tail")).strip(" ,?.!")
            return " ".join(p for p in (n.group("verb"), n.group("np").strip(), tail) if p)
        return None
    m = _GET_DONE.search(low)
    if m:
        part = "do" if m.group("part") == "done" else m.group("part")
        tail = _TAIL.sub("", m.group("tail")).strip(" ,?.!")
        return " ".join(p for p in (part, m.group("np"), tail) if p)
    m = _PROGRESSIVE.search(low)
    if m:
        subj = m.group("subj").split()
        if any(" ".join(subj[i:j]) in forms for i in range(len(subj)) for j in range(i + 1, len(subj) + 1)):
            return None
        act = _TAIL.sub("", m.group("act")).strip(" ,?.!")
        return act or None
    return None


_PLACE_WORD = re.compile(r"\b(?:a|some|any)\s+(?P<adj>[a-z]+(?:-[a-z]+)?)\s+(?:little\s+)?(?:place|spot|nook|corner"
                         r"|surface)\b")


_SOMEWHERE_ADJ = re.compile(r"\b(?:somewhere|someplace|anywhere)\s+(?P<adj>[a-z]+)\s+(?:to|where|for)\b")


def place_adjective(text: str) -> str | None:
    """The adjective said of the place asked for ("a cosy place to read", "somewhere comfy to
    read" -> "cosy", "comfy"), or None."""
    m = _PLACE_WORD.search(text.lower()) or _SOMEWHERE_ADJ.search(text.lower())
    return m.group("adj") if m else None


#: What an activity is done for, after the act itself: "rinse a cup [before making tea]".
_FOR_WHAT = re.compile(r"\s+(?:before|after|while|whilst|once|until|so\s+that|so|when|then|and\s+then)\s+")


def split_activity(activity: str) -> list[str]:
    """The act and what it is done for, in order ("rinse a cup before making tea" -> "rinse a cup",
    "making tea"): the act says the furniture, and either may say the room."""
    return [p.strip() for p in _FOR_WHAT.split(activity.strip()) if p.strip()]


@dataclass(frozen=True)
class RoomFitConfig:
    template: str = "a place where you can {activity}"
    #: The best room's cosine must lead the next by this much for the activity to imply it. 0.05
    #: on the activities of tests/retrieval/test_activities.py: the kitchen and bathroom ones lead
    #: by 0.06-0.37, the ones done in any room ("keep my socks", "put my drink down") by 0.04 or
    #: less.
    margin: float = 0.05
    min_score: float = 0.3


def room_scores(activity: str, embedder: TextEmbedder, config: RoomFitConfig | None = None) -> dict[str, float]:
    """Room type -> cosine of the activity (in the purpose template) to WordNet's definitions of
    the room (the best of them), best first."""
    cfg = config or RoomFitConfig()
    idx = gloss_index(embedder)
    rooms, E = idx.room_names, idx.room_E
    if not rooms:
        return {}
    q = embedder.embed([room_text(activity, cfg)])[0]
    out: dict[str, float] = {}
    for r, v in zip(rooms, E @ q, strict=True):
        out[r] = max(out.get(r, -1.0), float(v))
    return dict(sorted(out.items(), key=lambda kv: -kv[1]))


def room_text(activity: str, config: RoomFitConfig | None = None) -> str:
    """The text an activity (or a part of it) is embedded as to say its room."""
    return (config or RoomFitConfig()).template.format(activity=explain_activity(normalise_activity(activity)))


def activity_room(activity: str, embedder: TextEmbedder, config: RoomFitConfig | None = None) -> str | None:
    """The room an activity implies, or None when it could be done in several: each part of the
    activity (``split_activity``) is compared with WordNet's definitions of the rooms; what it is
    done for speaks first ("rinse a cup before making tea": the tea says the kitchen, although
    rinsing alone would be the bathroom's as much), then the act."""
    cfg = config or RoomFitConfig()
    parts = split_activity(activity)
    for part in [*parts[1:][::-1], parts[0]] if parts else []:
        sc = list(room_scores(part, embedder, cfg).items())
        if len(sc) >= 2 and sc[0][1] >= cfg.min_score and sc[0][1] - sc[1][1] >= cfg.margin:
            return sc[0][0]
    return None


#: Pronouns that stand for a thing named before the purpose clause.
_BACK = {"it", "them", "these", "those", "they"}


def _with_antecedent(act: str, before: str) -> str:
    """"these sheets need a hot wash, where can I put them on a cycle": the activity's pronoun
    stands for what the clause before it tells about, so that clause is part of the activity
    ("these sheets need a hot wash, put them on a cycle")."""
    before = before.strip(" ,;.")
    if not _BACK.intersection(act.split()) or len(before.split()) < 2:
        return act
    return f"{before}, {act}"


#: Words after a placing verb that put the thing away or inside it: storage, not a surface
#: ("put my jumpers away", "put the milk in").
_AWAY = {"away", "in", "into", "inside", "up", "back", "under", "within"}


def _verb_forms(word: str) -> list[str]:
    """``word`` and the base forms it may be inflected from ("putting" -> put, "resting" -> rest,
    "placing" -> place, "sets" -> set)."""
    out = [word]
    if word.endswith("ing") and len(word) > 4:
        stem = word[:-3]
        out += [stem, stem + "e"] + ([stem[:-1]] if len(stem) > 2 and stem[-1] == stem[-2] else [])
    elif word.endswith("s") and len(word) > 3:
        out.append(word[:-1])
    return out


#: Prepositions that say where a thing is put ("put the towels [on] a wash cycle").
_PLACE_PREPS = {"on", "onto", "in", "into", "under", "through"}
#: Below this best fit no furniture is made for an activity done with a thing handled ("charge my
#: phone" 0.24, "recharge my laptop" 0.29), so the thing is put down somewhere; furniture made
#: for such activities reaches 0.45 ("rinse a cup", "read a book"): tests/retrieval/test_activities.py.
HANDLED_MIN = 0.35
#: From this best fit up some furniture is made for the activity ("sleep": the bed, "rinse a cup":
#: the sink, 0.45 and more); below it the furniture only allows it ("read": a lamp 0.39), and a
#: place said with an adjective ("a cosy place to read") is the furniture the adjective describes.
MADE_FOR = 0.45


#: Words that may follow the thing handled without naming another thing ("charge my phone
#: overnight", "... for the night"); any other word makes it a modifier ("a phone call").
_AFTER_THING = {"for", "on", "in", "at", "by", "near", "next", "beside", "overnight", "tonight", "again", "now", "up",
                "while", "whilst", "before", "after", "when", "so", "then", "and", "somewhere", "please", "safely"}


def _handled(words: list[str], anywhere: bool = False) -> bool:
    """Whether ``words`` name a thing the detector sees that one carries ("phone", "laptop", "mug"):
    a label of the lexicon, or the last word of one ("mobile phone"), as the head of its phrase
    (not "make a [phone] call"), or ``anywhere`` in a clause a pronoun points back at."""
    lex = load_lexicon()
    heads = {f.split()[-1] for f in lex.labels}
    return any((w in lex.labels or w in heads or (w.endswith("s") and w[:-1] in heads))
               and (anywhere or k + 1 == len(words) or words[k + 1] in _AFTER_THING) for k, w in enumerate(words))


def is_placing(activity: str, embedder: TextEmbedder | None = None,
               scores: dict[str, float] | None = None) -> bool:
    """Whether the activity puts a thing down on a support ("rest my cup", "set down a book",
    "plonk my keys", "leave my glasses"): its verb is one of the lexicon's placing verbs
    (WordNet's), the thing is no part of the speaker's body ("rest my feet" rests the person) nor a
    room ("leave the kitchen"), nothing puts it away, and the place it is put is no thing that is
    not a category ("put the towels on a wash cycle": a washing, the glosses decide). With the
    activity's fit (``scores``, or computed with ``embedder``), an activity done with a thing one
    carries that no furniture is made for ("charge my phone") puts that thing down too."""
    told, _, said = normalise_activity(activity).rpartition(", ")
    words = said.split()
    if not words:
        return False
    lex = load_lexicon()
    rooms = {w for r in lex.rooms for w in r.split()} | {"kitchen", "bedroom", "bathroom", "room", "office",
                                                         "hall", "hallway", "lounge", "house", "flat", "home"}
    verbs = [*_verb_forms(words[0]), *([lex.placing_past[words[0]]] if words[0] in lex.placing_past else [])]
    if any(v in lex.placing or f"{v} {words[1] if len(words) > 1 else ''}".strip() in lex.placing for v in verbs):
        if any(w in _AWAY or w in lex.body or w in rooms for w in words[1:]):
            return False
        k = next((i for i, w in enumerate(words[1:], 1) if w in _PLACE_PREPS), None)
        if k is not None:
            place = [w for w in words[k + 1:] if w not in ("a", "an", "the", "your", "some")]
            if place and not any(" ".join(place[i:]) in lex.forms or place[i] in lex.forms
                                 for i in range(len(place))):
                return False
        return True
    if scores is None and embedder is not None:
        scores = gloss_index(embedder).scores(activity)
    # "my laptop is running low, charge it": the pronoun stands for the thing the clause before tells of.
    handled = _handled(words[1:]) or (bool(told) and bool(_BACK.intersection(words)) and _handled(told.split(), True))
    if scores and handled:
        return max(scores.values()) < HANDLED_MIN
    return False


def surfaces(lexicon: Lexicon | None = None) -> list[str]:
    """The categories a thing is put down on: the table and its kinds in the lexicon (WordNet's
    table: "a piece of furniture having a smooth flat top")."""
    lex = lexicon or load_lexicon()
    return ["table", *sorted(c for c, rel in lex.relations.get("table", {}).items() if rel.get("kind_of"))]


#: ``CapNavMap.caches`` key of the stored gloss embeddings.
CACHE_KEY = "glosses"


#: The purpose a definition states: what follows "used for", "for", "where", "on which to",
#: "provides a place to", "to" ("a bed: a piece of furniture that provides a place to sleep" ->
#: "sleep"). The first such phrase of the gloss; a gloss that states none (what it looks like
#: only) is judged as a whole.
_STATED = re.compile(r"\b(?:used (?:for|to)|designed (?:for|to)|intended for|provides? a place to|on which to|in which"
                     r"|where|for|to)\s+(?P<clause>.+)$")


def stated_purpose(gloss: str) -> str | None:
    """The purpose a gloss states ("to rest the feet of a seated person" -> "rest the feet of a
    seated person"), or None."""
    m = _STATED.search(gloss)
    return m.group("clause").strip(" ;,.") if m else None


class GlossIndex:
    """Gloss embeddings of every category for one embedder (built on first use, then reused);
    ``stored`` (``to_store``'s output) replaces embedding them when its digest matches.

    Besides each gloss it embeds the purpose the gloss states (``stated_purpose``) in the
    activity's template, so an activity is compared with what a piece of furniture is made for,
    not only with everything its definitions mention."""

    @property
    def embedder(self) -> TextEmbedder:
        e = self._embedder()
        if e is None:
            raise RuntimeError("the embedder of this gloss index was collected")
        return e

    def __init__(self, embedder: TextEmbedder, lexicon: Lexicon | None = None, max_glosses: int = 6,
                 stored: dict[str, Any] | None = None) -> None:
        lex = lexicon or load_lexicon()
        # Held weakly: the process-wide table of indexes (``gloss_index``) must not keep every
        # embedder ever used alive (a test session or a server opening maps grew ~130 MB each).
        self._embedder = weakref.ref(embedder)
        self.cats: list[str] = []
        texts: list[str] = []
        stated: list[tuple[str, str]] = []
        for cat, glosses in lex.glosses.items():
            names = ", ".join([cat, *BY_NAME[cat].synonyms]) if cat in BY_NAME else cat
            for g in glosses[:max_glosses]:
                self.cats.append(cat)
                texts.append(f"{names}: {g}")
                clause = stated_purpose(g)
                if clause:
                    stated.append((cat, clause))
        self.n_glosses = len(texts)
        #: Per stated purpose (rows after the glosses): its category.
        self.stated_cats = [c for c, _ in stated]
        said = [PurposeConfig().template.format(activity=clause) for _, clause in stated]
        self.cats_arr = np.array(self.cats, dtype=object)
        # Two blocks, each with its digest: maps captioned before stated purposes were embedded
        # keep their gloss vectors valid and compute only the stated ones.
        self.digest = _digest(embedder, texts)
        self.stated_digest = _digest(embedder, said)
        E = _decode(stored, self.digest, (len(texts), embedder.dim)) if stored else None
        block = stored.get("stated") if stored else None
        S = _decode(block, self.stated_digest, (len(said), embedder.dim)) if isinstance(block, dict) else None
        # The rooms' definitions (``activity_room``) are few: embedded with whatever else is run.
        self.room_names = [r for r, gl in lex.room_glosses.items() for _ in gl]
        rooms = [f"{r}: {g}" for r, gl in lex.room_glosses.items() for g in gl]
        todo = ([] if E is not None else texts) + ([] if S is not None else said) + rooms
        new = embedder.embed(todo) if todo else np.zeros((0, embedder.dim), np.float32)
        if E is None:
            E, new = new[: len(texts)], new[len(texts):]
        if S is None:
            S, new = new[: len(said)], new[len(said):]
        self.room_E: NDArray[np.float32] = np.asarray(new[: len(rooms)], dtype=np.float32)
        self.E: NDArray[np.float32] = np.vstack([E, S]).astype(np.float32) if len(S) else E

    def to_store(self) -> dict[str, Any]:
        """JSON-able: model, digest, shape and the float32 vectors (little-endian, base64) of the
        glosses, and the same under ``stated`` for the stated purposes."""
        def block(E: NDArray[np.float32], digest: str) -> dict[str, Any]:
            return {"model": self.embedder.model_id, "digest": digest, "shape": list(E.shape),
                    "float32_le": base64.b64encode(np.ascontiguousarray(E, dtype="<f4").tobytes()).decode("ascii")}

        out = block(self.E[: self.n_glosses], self.digest)
        out["stated"] = block(self.E[self.n_glosses:], self.stated_digest)
        return out

    def scores(self, activity: str, config: PurposeConfig | None = None,
               along: Sequence[str] = ()) -> dict[str, float]:
        """Category -> mean cosine of the (normalised) activity to its ``top_k`` best glosses.

        ``along``: texts the caller embeds next (the instruction itself), run in the same batch so
        that the embedder's cache serves them: one model run instead of two, which is most of a
        one-shot query's model time."""
        cfg = config or PurposeConfig()
        act = normalise_activity(activity) if cfg.normalise else activity
        q = self.embedder.embed([cfg.template.format(activity=explain_activity(act)), *along])[0]
        sims = self.E @ q
        per: dict[str, list[float]] = {}
        for cat, s in zip(self.cats, sims[: self.n_glosses], strict=True):
            per.setdefault(cat, []).append(float(s))
        out = {c: float(np.mean(sorted(v, reverse=True)[: max(1, cfg.top_k)])) for c, v in per.items()}
        made: dict[str, float] = {}
        for cat, s in zip(self.stated_cats, sims[self.n_glosses:], strict=True):
            made[cat] = max(made.get(cat, -1.0), float(s))
        # How directly it serves: the purpose its definitions state, mixed in; a category whose
        # definitions state none is judged by its glosses alone. A stated purpose is embedded in
        # the activity's own template, which lifts every cosine alike: that lift (the mean over
        # categories of stated minus gloss score) is taken off first.
        if made:
            lift = float(np.mean([made[c] - out[c] for c in made]))
            made = {c: v - lift for c, v in made.items()}
        w = cfg.stated_weight
        out = {c: (1.0 - w) * v + w * made.get(c, v) for c, v in out.items()}
        return dict(sorted(out.items(), key=lambda kv: -kv[1]))


def _digest(embedder: TextEmbedder, texts: list[str]) -> str:
    h = hashlib.sha256(f"{embedder.model_id}\n{embedder.dim}\n".encode())
    h.update("\n".join(texts).encode())
    return h.hexdigest()


def _decode(stored: dict[str, Any], digest: str, shape: tuple[int, int]) -> NDArray[np.float32] | None:
    """The stored vectors when they are the ones ``digest`` names, else None."""
    try:
        if stored.get("digest") != digest or tuple(stored.get("shape", ())) != shape:
            return None
        E = np.frombuffer(base64.b64decode(stored["float32_le"], validate=True), dtype="<f4")
        return E.astype(np.float32).reshape(shape) if E.size == shape[0] * shape[1] else None
    except (KeyError, TypeError, ValueError, AttributeError):
        return None


#: One index per live embedder; an entry goes when its embedder is collected.
_INDEXES: weakref.WeakKeyDictionary[TextEmbedder, GlossIndex] = weakref.WeakKeyDictionary()
_STORED: weakref.WeakKeyDictionary[TextEmbedder, dict[str, Any]] = weakref.WeakKeyDictionary()


def use_stored_glosses(embedder: TextEmbedder, stored: dict[str, Any] | None) -> None:
    """Offer a map's stored gloss embeddings (``caches["glosses"]``) to ``embedder``'s index, built
    on the first request by purpose; ignored if the index exists or they do not match."""
    if stored and embedder not in _INDEXES:
        _STORED[embedder] = stored


def gloss_index(embedder: TextEmbedder) -> GlossIndex:
    """One gloss index per embedder, for as long as it lives."""
    if embedder not in _INDEXES:
        _INDEXES[embedder] = GlossIndex(embedder, stored=_STORED.pop(embedder, None))
    return _INDEXES[embedder]


def match_purpose(activity: str, embedder: TextEmbedder, config: PurposeConfig | None = None,
                  along: Sequence[str] = ()) -> PurposeMatch:
    return PurposeMatch(activity, gloss_index(embedder).scores(activity, config, along))


def purpose_categories(match: PurposeMatch, config: PurposeConfig | None = None) -> tuple[str | None, dict[str, float]]:
    """(best category, alternatives with weights < 1): categories within ``margin`` of the best
    score, weighted by their score relative to the best."""
    cfg = config or PurposeConfig()
    items = list(match.scores.items())
    if is_placing(match.activity, scores=match.scores):
        # Any surface serves a thing put down: the scores only order them ("my laptop": a desk).
        keep = set(surfaces())
        items = [(c, v) for c, v in items if c in keep]
        if not items:
            return None, {}
        top = max(items[0][1], 1e-6)
        return items[0][0], {c: round(min(0.95, 0.95 * max(v, 0.0) / top), 3) or 0.05 for c, v in items[1:]}
    if not items or items[0][1] < cfg.min_score:
        return None, {}
    best_cat, best = items[0]
    alts: dict[str, float] = {}
    for cat, s in items[1:]:
        if s < best - cfg.margin or len(alts) >= cfg.max_alternatives:
            break
        alts[cat] = round(min(0.95, 0.95 * s / best), 3)
    return best_cat, alts


__all__ = ["CACHE_KEY", "HANDLED_MIN", "MADE_FOR", "GlossIndex", "PurposeConfig", "PurposeMatch", "RoomFitConfig",
           "activity_room", "explain_activity", "find_activity", "gloss_index", "is_placing", "match_purpose",
           "normalise_activity", "place_adjective", "purpose_categories", "room_scores", "room_text", "split_activity",
           "stated_purpose", "surfaces", "use_stored_glosses"]
