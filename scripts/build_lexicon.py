"""Build CapNav's word lexicon (``src/capnav/language/data/lexicon.json``) from WordNet 3.0, once.

Run it after changing the category vocabulary or the choices below; the test
``tests/language/test_lexicon.py`` rebuilds it from /usr/share/wordnet and checks that the shipped
file is identical. Runtime never imports nltk: it reads the JSON.

    python scripts/build_lexicon.py [--wordnet /usr/share/wordnet] [-o src/capnav/language/data/lexicon.json]

Needs ``nltk``, ``stop-words`` and ``scikit-learn`` (the ``dev`` extra) and Debian's ``wordnet-base`` +
``wordnet-sense-index``. nltk's reader takes those files once they are copied (not linked) into
``DIR/corpora/wordnet/`` with a ``lexnames`` file added (Debian ships that table only in the
lexnames(5WN) man page; it is the fixed table below).

What the lexicon holds, and the choices made (WordNet's senses do not always match how a home robot
is spoken to):

- ``forms``: surface form -> category, for every lemma of the category's synsets and of their
  hyponyms. A lemma counts only when its most frequent *physical* sense (noun.artifact or
  noun.plant; abstract senses such as chair = "professorship" are ignored) lies under the
  category: "press" (a printing press first), "can" or "pot" (containers first) do not become a
  wardrobe or a toilet, while "commode" (toilet first, chest of drawers second) is a toilet with
  the dresser as an alternative. Lemmas that are colour or room words are left out ("lounge" is a
  room in CapNav's room words). The category's own names and synonyms from
  ``capnav.core.categories`` are always forms.
- Synsets chosen per category (``ROOTS``): settee's first WordNet sense is ``settle.n.01`` (a
  bench with a back), but people say settee for a small sofa and CapNav has no bench, so
  ``settle.n.01`` is put with the sofa. Easy chairs (lounge chair, wing chair, recliner) are
  armchairs, which WordNet puts under armchair already except ``easy_chair.n.01`` itself. The
  plant category is a potted indoor plant: WordNet's ``plant.n.02`` covers every organism of the
  plant kingdom (and its lemmas include olive, orange, rose), so only houseplants, pot plants,
  succulents (cactus, aloe), ferns, palms and bonsai are taken. WordNet 3.0 has no nightstand
  (bedside table): its nearest synset, ``stand.n.04`` (a small table for holding articles), gives
  the nightstand's gloss. A category's first synset is what it is (its kinds and its Wu-Palmer
  similarities come from it): the bookshelf is ``bookcase.n.01`` first, the piece of furniture that
  CapNav's bookshelf is, and ``bookshelf.n.01`` (a single shelf, a support) gives its name. The
  counter is ``counter.n.01`` without its hyponyms (shop counters, bars, checkouts) plus the
  countertop. The toilet includes the British
  ``water_closet.n.01`` (loo) although WordNet files it as a room, and so is every room WordNet
  defines only by the fixture it is equipped with (``toilet.n.01``, "a room or building equipped
  with one or more toilets": lavatory, lav, privy). Lamps are ``lamp.n.02`` (the
  furniture), not ``lamp.n.01`` (any source of light: torches, searchlights).
- ``other``: compounds whose last word is a category word but which name something else (a pool
  table, a toilet seat, a power plant), and two-word compounds whose first word is one ("bath
  towel", "bed linen": the category says what the thing is for): game, operating, altar and work tables, wheelchairs,
  hospital beds (``EXCLUDE``), and every WordNet noun ending in a category word whose first physical sense
  is outside that category. "the pool table" is then an object CapNav does not know, not a table.
- ``relations``: for each ordered pair of categories, ``kind_of`` when one's synsets lie under the
  other's (an armchair is a chair; a coffee table, a desk, a nightstand and a counter are tables)
  and the Wu-Palmer similarity of their first synsets (chair-stool 0.9, chair-sofa 0.87): the
  parser turns these into weighted alternative categories.
- ``glosses``: WordNet's definitions of each category's synsets and their direct hyponyms, for
  requests by purpose ("somewhere to sit" is matched to them with the text embedder). Not its
  example sentences: "he sat on the edge of the bed" says how the word is used, not what a bed is
  for, and it drew "somewhere to lie down" to whatever else mentions sitting.
- ``sizes``: size adjectives -> "large" / "small" ("king-size", "oversized", "tiny", "bigger",
  "tinier"): the lemmas of WordNet's adjective clusters around ``large.a.01`` and ``small.a.01``
  whose most frequent adjective sense lies in the cluster ("deep", "wide", "slim" and "super" are
  another sense first) and which are not used more often as a noun or verb in WordNet's
  sense-tagged corpus ("minute", "giant"), with their comparatives from WordNet's exception list
  (``adj.exc``: bigger, tinier); a hyphenated one also with a space ("king size").
- ``heights`` / ``height_superlatives``: words of height -> "large" / "small" ("tall", "short",
  "lanky", "stumpy", "lower") and "tallest", "shortest", "highest", "lowest" -> "largest" /
  "smallest": the head of WordNet's adjective of stature (``tall.a.01``) and of elevation
  (``high.a.02``), each with its antonym (short, low) and their regular -er / -est forms, plus the
  stature clusters' lemmas chosen as the size words are (not the elevation cluster's: it holds
  "under" and "upper"); a word the size table has ("little") stays a size. The retriever compares
  these against the mapped heights, not the volumes.
- ``widths`` / ``width_superlatives``: words of width -> "large" / "small" and their superlatives:
  the lemmas of WordNet's adjective of width (``wide.a.01``: wide, broad) and of its antonym
  (narrow) with their regular -er / -est forms, not their clusters (those hold "panoramic",
  "tapering"). The retriever compares these against the mapped footprint's longer side.
- ``growth``: words that name a plant's growth form -> the growth word the captioner measures
  from the points (``capnav.language.form.growth``). A cactus grows as a column narrower than its
  pot, so every lemma of ``cactus.n.01`` and its hyponyms, and of ``succulent.n.01`` itself (the
  class WordNet files cacti under), implies "slender"; the succulent's other hyponyms (aloe,
  living stones) are rosettes and imply nothing. So do the adjectives WordNet derives from the
  plant parts that the cactus's definition names ("usually having spines": spine -> spiny,
  prickly, thorny, spinous, with their synsets' other lemmas), except parts that are the cactus's
  own hypernyms or taxonomic groups ("succulent", "Cactaceae").
- ``foreign``: function words of French, Spanish, German, Italian, Portuguese and Dutch (from the
  ``stop-words`` package) that are not English: not an English stop word (scikit-learn's list) and
  not a WordNet lemma
  that occurs in lower case in its sense-tagged corpus (``cntlist``; "LA" the state does not make
  "la" English); they mark an instruction as not English (``capnav.retrieval.query`` says when).

- ``persons``: nouns whose most frequent sense is a person (noun.person), with their plurals, so
  that "where can the kids sit" is read as an activity of people, not as where things are kept.

- ``labels``: surface form -> detector class, for the classes a closed-set detector gives that are
  not CapNav categories (``LABEL_ROOTS``: COCO's cup, bottle, book, laptop, cell phone, ...), so
  that every indoor class is reachable by its everyday names ("mug", "rucksack", "mobile phone",
  "paperback"), chosen like the categories' forms.

- ``kinds``: words for a kind of several categories -> those categories ("appliance": the
  refrigerator, the stove and the washing machine; "plumbing fixture": the sink and the toilet;
  "furniture"), WordNet's artifact synsets above two
  categories or more (``_kinds`` says which are left out), so that "the appliance on your left"
  is asked of every category it covers, each as the named one; and the head noun of a category's
  own two-word name when it is an artifact and no category word ("machine": the washing machine,
  and the refrigerator by WordNet's "ice machine").

- ``placing``: verbs of putting a thing down on a support ("put", "set down", "rest", "plonk":
  ``PLACING_SENSES`` and ``PLACING_TREES``), so that "somewhere to rest my cup" asks for a surface
  rather than for what the cup is kept in; ``body``: nouns for parts of the body (noun.body) with
  their plurals, so that "somewhere to rest my feet" rests the person.

- ``attributes``: adjectives (and a few nouns) the tables above lack, mapped onto an attribute
  the map reads through WordNet's relations, each with its kind, value and relation ("boxy":
  shape rectangular by its gloss; "oblong": long by similar_to; "see-through": glass by the
  material's definition; "timber": wood by its genus; "vermilion": scarlet by hypernym;
  "squishy": soft, a property no map observes, read and never judged): ``_attributes`` says how.

WordNet's licence notice is copied beside the data (``WORDNET_LICENSE``).
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from capnav.core.categories import CATEGORIES  # noqa: E402
from capnav.language.colors import ALIASES, LEXICON  # noqa: E402

#: lexnames(5WN): file number -> lexicographer file name (a fixed table of WordNet 3.0).
LEXNAMES = ("adj.all adj.pert adv.all noun.Tops noun.act noun.animal noun.artifact noun.attribute noun.body "
            "noun.cognition noun.communication noun.event noun.feeling noun.food noun.group noun.location "
            "noun.motive noun.object noun.person noun.phenomenon noun.plant noun.possession noun.process "
            "noun.quantity noun.relation noun.shape noun.state noun.substance noun.time verb.body verb.change "
            "verb.cognition verb.communication verb.competition verb.consumption verb.contact verb.creation "
            "verb.emotion verb.motion verb.perception verb.possession verb.social verb.stative verb.weather "
            "adj.ppl").split()

#: Category -> WordNet synsets whose lemmas and hyponyms' lemmas name it (see the module docstring).
ROOTS: dict[str, list[str]] = {
    "sofa": ["sofa.n.01", "settle.n.01", "sectional.n.01"],
    "armchair": ["armchair.n.01"],
    "chair": ["chair.n.01"],
    "stool": ["stool.n.01"],
    "table": ["table.n.02", "table.n.03"],
    "coffee table": ["coffee_table.n.01"],
    "desk": ["desk.n.01", "writing_desk.n.01", "secretary.n.02"],
    "bed": ["bed.n.01"],
    "nightstand": ["stand.n.04"],
    "wardrobe": ["wardrobe.n.01"],
    "dresser": ["chest_of_drawers.n.01"],
    "cabinet": ["cabinet.n.01", "buffet.n.01", "cupboard.n.01"],
    "bookshelf": ["bookcase.n.01", "bookshelf.n.01"],
    "tv": ["television_receiver.n.01"],
    "lamp": ["lamp.n.02"],
    "plant": ["houseplant.n.01", "pot_plant.n.01", "succulent.n.01", "fern.n.01", "palm.n.03", "bonsai.n.01"],
    "toilet": ["toilet.n.02", "water_closet.n.01"],
    "sink": ["sink.n.01", "washbasin.n.02"],
    "bathtub": ["bathtub.n.01"],
    "refrigerator": ["refrigerator.n.01"],
    "counter": ["counter.n.01!", "countertop.n.01"],
    "stove": ["stove.n.01", "oven.n.01"],
    "washing machine": ["washer.n.03"],
    "ottoman": ["ottoman.n.03", "footstool.n.01"],
}

#: Synsets that only name a category (their lemmas and hyponyms' lemmas), their definitions not
#: among its glosses (what it is for): the COCO class tv is PASCAL VOC's "tvmonitor", so monitors
#: and screens are the class, but "watch the news" is still what a television is for.
NAME_ROOTS: dict[str, list[str]] = {"tv": ["monitor.n.04", "screen.n.03"]}

#: Branches under the roots that are not the household object (their lemmas become ``other``).
EXCLUDE = ["pool_table.n.01", "card_table.n.01", "gaming_table.n.01", "table-tennis_table.n.01",
           "operating_table.n.01", "altar.n.01", "worktable.n.01", "platen.n.01", "booth.n.01", "lectern.n.01",
           "wheelchair.n.01", "barber_chair.n.01", "throne.n.01", "electric_chair.n.01", "highchair.n.01",
           "deathbed.n.02", "sickbed.n.01", "hospital_bed.n.01", "hammock.n.02", "chamberpot.n.01",
           "toilet_seat.n.01", "medicine_chest.n.01", "background.n.07"]
#: Synsets whose hyponyms (not themselves) are excluded: shop counters, bars and checkouts.
EXCLUDE_HYPONYMS_OF = ["counter.n.01"]

PHYSICAL = {"noun.artifact", "noun.plant"}
#: Senses of other concrete things that outrank a furniture sense ("squab" is a pigeon first).
CONCRETE = PHYSICAL | {"noun.animal", "noun.food", "noun.person", "noun.object", "noun.body", "noun.substance"}
MAX_GLOSSES = 12
ROOM_WORDS = {"kitchen", "bedroom", "bathroom", "lounge", "study", "office", "hall", "hallway", "room"}
FOREIGN_LANGUAGES = ("french", "spanish", "german", "italian", "portuguese", "dutch")


def open_wordnet(source: Path, workdir: Path) -> Any:
    """nltk's WordNet reader over Debian's files, without any download."""
    import nltk  # build-time only (the dev extra)

    target = workdir / "corpora" / "wordnet"
    target.mkdir(parents=True)
    for f in source.iterdir():
        if f.is_file():
            shutil.copyfile(f, target / f.name)
    with open(target / "lexnames", "w") as fh:
        pos = {"noun": 1, "verb": 2, "adj": 3, "adv": 4}
        for i, name in enumerate(LEXNAMES):
            fh.write(f"{i:02d}\t{name}\t{pos[name.split('.')[0]]}\n")
    nltk.data.path.insert(0, str(workdir))
    from nltk.corpus.reader.wordnet import WordNetCorpusReader

    return WordNetCorpusReader(str(target), None)


def _form(lemma: str) -> str:
    return lemma.replace("_", " ").lower()


def build(wordnet: Path) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        wn = open_wordnet(wordnet, Path(tmp))
        out = _build(wn)
        noun_exc = (wordnet / "noun.exc").read_text().splitlines()
        out["sizes"] = _sizes(wn, (wordnet / "adj.exc").read_text().splitlines())
        out["heights"], out["height_superlatives"] = _heights(wn, out["sizes"])
        out["widths"], out["width_superlatives"] = _widths(wn, set(out["sizes"]) | set(out["heights"]))
        out["growth"] = _growth(wn, out["forms"])
        out["labels"] = _labels(wn, out["forms"])
        out["persons"] = _persons(wn, noun_exc)
        out["kinds"] = _kinds(wn, out["forms"])
        out["placing"] = _placing(wn)
        out["verb_phrases"] = _verb_phrases(wn)
        out["placing_past"] = _placing_past(out["placing"], (wordnet / "verb.exc").read_text().splitlines())
        out["body"] = _body(wn, noun_exc)
        out["materials"], out["material_nouns"] = _materials(wn, out["forms"], out["labels"])
        out["surface_nouns"] = _surface_nouns(wn)
        out["part_nouns"] = _part_nouns(wn, out["forms"])
        out["rooms"] = _rooms(wn, out["forms"], noun_exc)
        out["attributes"] = _attributes(wn, out)
        out["room_glosses"] = _room_glosses(wn)
        out["gloss_adjectives"] = _gloss_adjectives(wn, out)
        out["furniture_senses"] = _furniture_senses(wn, out["forms"])
        _irregular_plurals(out["forms"], out["growth"], noun_exc)
        out["plant_names"] = _plant_names(wn, out)
        names = set(out["plant_names"])
        out["other"] = [f for f in out["other"] if f not in names]  # "rubber plant" is one
        out["forms"] = dict(sorted(out["forms"].items()))
        out["growth"] = dict(sorted(out["growth"].items()))
        return out


#: The detector classes that are not CapNav categories (COCO's indoor things kept under their own
#: name, ``capnav.perception.coco.KEPT_AS_IS``) and the WordNet synsets each one is: their lemmas
#: and their hyponyms' lemmas are the everyday names that reach the class ("rucksack", "mobile
#: phone", "microwave oven", "paperback"). A mug (``mug.n.04``) is not under ``cup.n.01`` in
#: WordNet, but COCO's "cup" is the class a detector gives a mug, so it is a root of the cup too.
LABEL_ROOTS: dict[str, list[str]] = {
    "bench": ["bench.n.01"], "backpack": ["backpack.n.01"], "umbrella": ["umbrella.n.01"], "handbag": ["bag.n.04"],
    "suitcase": ["bag.n.06"], "bottle": ["bottle.n.01"], "wine glass": ["wineglass.n.01"],
    "cup": ["cup.n.01", "mug.n.04"], "bowl": ["bowl.n.03", "bowl.n.01"], "laptop": ["laptop.n.01"],
    "mouse": ["mouse.n.04"], "remote": ["remote_control.n.01"], "keyboard": ["keyboard.n.01"],
    "cell phone": ["cellular_telephone.n.01"], "microwave": ["microwave.n.02"], "toaster": ["toaster.n.02"],
    "book": ["book.n.02"], "clock": ["clock.n.01"], "vase": ["vase.n.01"], "scissors": ["scissors.n.01"],
    "teddy bear": ["teddy.n.01"], "hair drier": ["hand_blower.n.01"], "toothbrush": ["toothbrush.n.01"],
}


def _labels(wn: Any, forms: dict[str, str]) -> dict[str, str]:
    """Surface form -> detector class for the classes of ``LABEL_ROOTS``, chosen like the
    categories' forms: a lemma counts when its most frequent physical sense lies under the class
    and it is not a category's form, a colour or a room word (the category table wins: "settee"
    stays a sofa although WordNet files it under bench; "toilet bowl", with a category's own word
    in it, is left to that category)."""
    colour_words = set(LEXICON) | set(ALIASES)
    owner: dict[str, str] = {}
    for label, roots in LABEL_ROOTS.items():
        for n in roots:
            s = wn.synset(n)
            for x in [s, *s.closure(lambda y: y.hyponyms())]:
                owner.setdefault(x.name(), label)
    out: dict[str, str] = {label: label for label in LABEL_ROOTS}
    category_words = {f for f in forms if " " not in f}
    # The roots' own lemmas are the class's synonyms ("mug", "rucksack", "microwave oven"), unless
    # two classes share one ("bag": a handbag and a suitcase).
    root_lemmas: dict[str, set[str]] = {}
    for label, roots in LABEL_ROOTS.items():
        for n in roots:
            for lem in wn.synset(n).lemmas():
                root_lemmas.setdefault(_form(lem.name()), set()).add(label)
    for form, labels in sorted(root_lemmas.items()):
        if len(labels) == 1 and form not in forms and form not in colour_words and form not in ROOM_WORDS \
                and form == form.lower():
            out.setdefault(form, next(iter(labels)))
    for name in sorted(owner):
        for lem in wn.synset(name).lemmas():
            lemma, form = lem.name(), _form(lem.name())
            if lemma != lemma.lower() or form in forms or form in colour_words or form in ROOM_WORDS or form in out:
                continue
            if len(form.split()) > 3 or not all(ch.isalpha() or ch in " -'" for ch in form):
                continue
            if " " not in form and any(wn.synsets(lemma, pos) for pos in ("v", "a", "s", "r")):
                continue
            if category_words.intersection(form.split()):
                continue  # "toilet bowl": a part of a category's object, said with its name
            senses = [x for x in wn.synsets(lemma, "n") if x.lexname() in CONCRETE
                      and any(lm.name() == lemma for lm in x.lemmas())]
            if senses and owner.get(senses[0].name()) == owner[name]:
                out[form] = owner[name]
    return dict(sorted(out.items()))


#: The heads of WordNet's size clusters and the size word each stands for.
SIZE_HEADS = {"large": "large.a.01", "small": "small.a.01"}


def _cluster_adjectives(wn: Any, head: Any) -> list[str]:
    """The lemmas of the adjective cluster around the synset ``head`` (it and its similar-tos)
    whose most frequent adjective sense lies in the cluster and which WordNet's sense-tagged corpus
    does not use more often as a noun or verb; lower-case single words (hyphens allowed)."""

    def count(lemma: str, pos: str) -> int:
        return sum(lem.count() for s in wn.synsets(lemma, pos) for lem in s.lemmas() if lem.name() == lemma)

    cluster = {head, *head.similar_tos()}
    out = []
    for lemma in sorted({lem.name() for s in cluster for lem in s.lemmas()}):
        if lemma != lemma.lower() or "_" in lemma:
            continue
        senses = [s for s in wn.synsets(lemma) if s.pos() in "as" and any(lem.name() == lemma for lem in s.lemmas())]
        if not senses or senses[0] not in cluster:
            continue
        if max(count(lemma, "n"), count(lemma, "v")) > count(lemma, "a"):
            continue
        out.append(lemma)
    return out


def _sizes(wn: Any, exceptions: list[str]) -> dict[str, str]:
    """Size adjectives -> "large" / "small" (see the module docstring)."""
    out: dict[str, str] = {}
    for size, head in SIZE_HEADS.items():
        for lemma in _cluster_adjectives(wn, wn.synset(head)):
            out[lemma] = size
            if "-" in lemma:
                out[lemma.replace("-", " ")] = size
    for line in exceptions:
        infl, *bases = line.split()
        if not infl.endswith("est") and any(b in out for b in bases):
            out.setdefault(infl, out[next(b for b in bases if b in out)])
    return dict(sorted(out.items()))


#: Height: WordNet's adjective of stature, whose antonym gives the other end, and the head of
#: elevation with its antonym (only the two head words: that cluster holds "under", "upper").
HEIGHT_HEADS = {"stature": "tall.a.01", "elevation": "high.a.02"}


def _heights(wn: Any, sizes: dict[str, str]) -> tuple[dict[str, str], dict[str, str]]:
    """Height adjectives -> "large" / "small" and superlatives -> "largest" / "smallest" (see the
    module docstring): the head words of stature and elevation and their antonyms (tall, short,
    high, low) with their regular comparatives and superlatives ("taller", "lowest"), and the
    lemmas of the stature clusters whose most frequent adjective sense lies in them ("lanky",
    "stumpy"), as the size words are chosen; a word of the size table ("little") stays a size."""
    words: dict[str, str] = {}
    superlative: dict[str, str] = {}
    for dim, head in HEIGHT_HEADS.items():
        up = wn.synset(head)
        down = next(a.synset() for lem in up.lemmas() for a in lem.antonyms())
        for size, syn in (("large", up), ("small", down)):
            word = syn.lemmas()[0].name()  # the head word: regular -er / -est
            words[word] = words[word + "er"] = size
            superlative[word + "est"] = {"large": "largest", "small": "smallest"}[size]
            if dim == "stature":
                for lemma in _cluster_adjectives(wn, syn):
                    if lemma not in words and lemma not in sizes:
                        words[lemma] = size
    return dict(sorted(words.items())), dict(sorted(superlative.items()))


#: Width: WordNet's adjective of width; its antonym gives the other end (only the two synsets' own
#: lemmas: the clusters hold "panoramic", "sweeping", "tapering").
WIDTH_HEAD = "wide.a.01"


def _widths(wn: Any, taken: set[str]) -> tuple[dict[str, str], dict[str, str]]:
    """Width adjectives -> "large" / "small" and superlatives -> "largest" / "smallest" (see the
    module docstring): wide, broad, narrow, with their regular -er / -est forms; a word another
    size table holds stays there."""
    words: dict[str, str] = {}
    superlative: dict[str, str] = {}
    up = wn.synset(WIDTH_HEAD)
    down = next(a.synset() for lem in up.lemmas() for a in lem.antonyms())
    for size, syn in (("large", up), ("small", down)):
        for lem in syn.lemmas():
            word = lem.name()
            if word in taken or not word.isalpha():
                continue
            stem = word[:-1] if word.endswith("e") else word
            words[word] = words[stem + "er"] = size
            superlative[stem + "est"] = {"large": "largest", "small": "smallest"}[size]
    return dict(sorted(words.items())), dict(sorted(superlative.items()))


#: Growth forms: the synset whose lemmas (with its hyponyms') imply the growth word, the synsets
#: whose own lemmas do too, and the word (``capnav.language.form.growth`` says it of the points).
GROWTH_FORMS = {"slender": ("cactus.n.01", ["succulent.n.01"])}


def _growth(wn: Any, forms: dict[str, str]) -> dict[str, str]:
    """Words that imply a plant's growth form (see the module docstring). The lemmas of the
    synsets named in ``GROWTH_FORMS`` become plant forms (in ``forms``) even when WordNet also has
    them as an adjective, which keeps other words out of ``forms``: "succulent" names the plant."""
    import re

    out: dict[str, str] = {}
    for word, (root, own) in GROWTH_FORMS.items():
        syn = wn.synset(root)
        for n in own:
            for lem in wn.synset(n).lemmas():
                if lem.name() == lem.name().lower():
                    forms.setdefault(_form(lem.name()), "plant")
        members = [syn, *syn.closure(lambda x: x.hyponyms()), *(wn.synset(n) for n in own)]
        for s in members:
            for lem in s.lemmas():
                form = _form(lem.name())
                if lem.name() == lem.name().lower() and forms.get(form) == "plant":
                    out[form] = word
        above = {h.name() for h in syn.closure(lambda x: x.hypernyms())}
        for tok in re.findall(r"[a-z]+", syn.definition().lower()):
            base = wn.morphy(tok, "n")
            for part in wn.synsets(base, "n") if base else []:
                if part.lexname() != "noun.plant" or part.name() in above or part.member_meronyms():
                    continue
                for lem in part.lemmas():
                    for d in lem.derivationally_related_forms():
                        if d.synset().pos() in "as":
                            for adj in d.synset().lemmas():
                                if adj.name().isalpha() and adj.name() == adj.name().lower():
                                    out.setdefault(adj.name(), word)
    return dict(sorted(out.items()))


def _kinds(wn: Any, forms: dict[str, str]) -> dict[str, list[str]]:
    """Words for a kind of several categories ("appliance", "plumbing fixture") -> those
    categories: the lemmas of every artifact synset above the roots of two categories or more,
    but of at most two thirds of them (above that: "artifact", "instrumentality"), whose word's
    first noun sense is an artifact ("area" is a region first, "vessel" a blood vessel), whose
    first artifact sense above categories is this one, and which is used as a noun at least as
    often as otherwise in WordNet's sense-tagged corpus ("good" is an adjective first). A word
    that already names a category ("seat": a chair) keeps it. Only the ancestors of a category's
    own sense (its first root) count: its other roots bring its other names, and what lies above
    those only is not what the category is (the loo is filed as a room, the cupboard as a storage
    space, the writing desk as a box, so "structure" and "container" would cover a toilet, a
    cabinet and a desk)."""
    cats_under: dict[str, set[str]] = {}
    for cat, roots in ROOTS.items():
        for path in wn.synset(roots[0].rstrip("!")).hypernym_paths():
            for a in path:
                cats_under.setdefault(a.name(), set()).add(cat)

    def used(lemma: str, pos: str) -> int:
        return sum(lem.count() for s in wn.synsets(lemma, pos) for lem in s.lemmas() if lem.name() == lemma)

    out: dict[str, list[str]] = {}
    for name, cats in sorted(cats_under.items()):
        s = wn.synset(name)
        if s.lexname() != "noun.artifact" or not 2 <= len(cats) <= 2 * len(ROOTS) // 3:
            continue
        for lem in s.lemmas():
            lemma, form = lem.name(), _form(lem.name())
            if lemma != lemma.lower() or form in forms or form in ROOM_WORDS:
                continue
            senses = [k for k in wn.synsets(lemma, "n") if any(x.name() == lemma for x in k.lemmas())]
            kinds = [k for k in senses if k.lexname() == "noun.artifact" and k.name() in cats_under]
            if not kinds or kinds[0].name() != name or senses[0].lexname() != "noun.artifact":
                continue  # "area": a region first; "vessel": a blood vessel first
            if used(lemma, "n") < max(used(lemma, pos) for pos in ("v", "a", "s", "r")):
                continue
            out[form] = sorted(cats)
    # The head noun of a category's own two-word name ("washing machine": a machine for washing;
    # an English compound is a kind of its head) that is no category word itself and whose first
    # noun sense is an artifact names a kind of every category with a form ending in it ("ice
    # machine": the refrigerator), although WordNet files the washer under white goods, not under
    # machine. "shelving unit" gives nothing (a unit is a quantity first), nor "chest of drawers".
    for cat in CATEGORIES:
        for name in (cat.name, *cat.synonyms):
            words = name.split()
            if len(words) != 2 or words[1] in forms or words[1] in out or words[1] in ROOM_WORDS:
                continue
            senses = wn.synsets(words[1], "n")
            if not senses or senses[0].lexname() != "noun.artifact":
                continue
            out[words[1]] = sorted({c for f, c in forms.items() if f.endswith(" " + words[1])})
    return dict(sorted(out.items()))


#: Verb senses of putting a thing down on a support (their own lemmas): "put into a certain
#: place", "put in a horizontal position", "put something in a resting position, as for
#: support", "place temporarily"; and, with their hyponyms (plonk, plunk, plump down), "put or
#: settle into a position" and "cause to ... be in a settled position or place". Not the
#: hyponyms of the first ones: they bury, sow, bottle and install.
#: ``leave.v.02`` ("go and leave behind, either intentionally or by neglect"): a thing left
#: somewhere stays where it was left ("she left her bag by the bed", "where can I leave my keys").
PLACING_SENSES = ["put.v.01", "lay.v.02", "rest.v.08", "park.v.01", "leave.v.02"]
PLACING_TREES = ["set_down.v.03", "set_down.v.04"]


def _placing(wn: Any) -> list[str]:
    """Verbs (and phrasal verbs) of putting something down (``PLACING_SENSES``, ``PLACING_TREES``)."""
    out = {_form(lem.name()) for n in PLACING_SENSES for lem in wn.synset(n).lemmas()}
    for n in PLACING_TREES:
        for s in [wn.synset(n), *wn.synset(n).closure(lambda x: x.hyponyms())]:
            out |= {_form(lem.name()) for lem in s.lemmas()}
    return sorted(f for f in out if f.replace(" ", "").isalpha() and f == f.lower())


#: Verbs that carry little meaning of their own in an idiom ("do the dishes", "get dressed").
LIGHT_VERBS = ("do", "have", "take", "get", "make", "go", "give")


def _verb_phrases(wn: Any) -> dict[str, str]:
    """Idioms of a light verb (``LIGHT_VERBS``) -> the definition of their first sense ("do the
    dishes": "wash dishes", "get dressed": "put on clothes"), so that an activity said as an idiom
    is compared with the furniture by what it means. Not other verbs of several words: their
    own verb carries the meaning, and their first sense is often not the household one ("hang
    up": a telephone receiver)."""
    out: dict[str, str] = {}
    for lemma in wn.all_lemma_names("v"):
        words = lemma.split("_")
        if len(words) < 2 or len(words) > 4 or lemma != lemma.lower() or not all(w.isalpha() for w in words) \
                or words[0] not in LIGHT_VERBS:
            continue
        out[" ".join(words)] = wn.synsets(lemma, "v")[0].definition()
    return dict(sorted(out.items()))


def _placing_past(placing: list[str], exceptions: list[str]) -> dict[str, str]:
    """Irregular inflections of the placing verbs from WordNet's exception list (``verb.exc``:
    "left" leave, "laid" lay): "she left her bag by the bed" puts the bag where it was left."""
    single = {p for p in placing if " " not in p}
    out: dict[str, str] = {}
    for line in exceptions:
        infl, *bases = line.split()
        base = next((b for b in bases if b in single), None)
        if base is not None and infl not in single:
            out[infl] = base
    return dict(sorted(out.items()))


#: The materials the surface test knows (``capnav.language.surface``), each with the WordNet
#: synsets it is: every word under one of them names that material. ``alloy.n.01`` and
#: ``metallic_element.n.01`` hold steel, brass, iron and chromium; ``ceramic_ware.n.01`` holds
#: porcelain and earthenware; stone has no surface test (``rock.n.02``: granite, slate) and is
#: named only so that it reads as a material, neither confirmed nor refused by the pixels. Paper
#: is left to its own word: WordNet files pads, tablets and cards as kinds of paper.
MATERIAL_ROOTS: dict[str, list[str]] = {
    "wood": ["wood.n.01"], "fabric": ["fabric.n.01"], "leather": ["leather.n.01"], "velvet": ["velvet.n.01"],
    "metal": ["metal.n.01", "alloy.n.01", "metallic_element.n.01"], "glass": ["glass.n.01"],
    "marble": ["marble.n.01"], "plastic": ["plastic.n.01"], "ceramic": ["ceramic.n.01", "ceramic_ware.n.01"],
    "wool": ["wool.n.01"], "cotton": ["cotton.n.01"], "stone": ["rock.n.02"],
}
#: Under a material, things made of it rather than kinds of it: a piece of cloth (a towel, a rag).
NOT_MATERIALS = {"piece_of_cloth.n.01"}
#: How many of a word's senses (WordNet's order: most frequent first) are read for a material:
#: "pine" is a tree first and its wood second.
MATERIAL_SENSES = 2


#: Nouns for how a whole object looks or feels, not a part of it: "the sofa with the velvety
#: feel", "a cabinet with a walnut finish" say the material of the whole (the surface the pixels
#: show), "the dresser with the glass top" that of a part. The synsets' lemmas (and the kinds of
#: tactile property: texture, touch).
SURFACE_NOUN_SENSES = ["appearance.n.01", "look.n.03", "tactile_property.n.01", "coating.n.02", "surface.n.01",
                       "upholstery.n.01", "covering.n.02"]


def _surface_nouns(wn: Any) -> list[str]:
    out: set[str] = set()
    for n in SURFACE_NOUN_SENSES:
        s = wn.synset(n)
        for x in [s, *(s.hyponyms() if n == "tactile_property.n.01" else [])]:
            out |= {lem.name() for lem in x.lemmas() if lem.name().isalpha() and lem.name() == lem.name().lower()}
    return sorted(out | _plurals(out))


def _part_nouns(wn: Any, forms: dict[str, str]) -> list[str]:
    """Nouns of a piece of an object: the lemmas WordNet lists as parts (part meronyms) of a
    category's synsets or of their hypernyms (arm, back, leg, base, drawer, frame, lampshade, pot),
    whose first noun sense is an artifact or a body part, with their plurals. Words for the whole's
    outline (edge, side, corner, top: locations first) are not among them, so "the sofa with
    curved edges" keeps its shape and "the armchair with rounded arms" gives it to the arms. A
    category word is no outline word, so one WordNet lists as a part is a piece whatever its first
    sense ("seat": seat.n.04, a part of seat.n.03 above chairs and sofas; a place first)."""
    out: set[str] = set()
    for roots in ROOTS.values():
        for n in roots:
            s = wn.synset(n.rstrip("!"))
            for h in [s, *s.closure(lambda x: x.hypernyms())]:
                for m in h.part_meronyms():
                    for lem in m.lemmas():
                        w = lem.name()
                        first = wn.synsets(w, "n")
                        if w.isalpha() and w == w.lower() and first and (
                                first[0].lexname() in ("noun.artifact", "noun.body") or w in forms):
                            out.add(w)
    return sorted(out | _plurals(out))


def _materials(wn: Any, forms: dict[str, str], labels: dict[str, str]) -> tuple[dict[str, str], dict[str, str]]:
    """Material words -> the material they are ("velvety" velvet, "oak" wood, "suede" leather,
    "chenille" fabric, "brass" metal), from WordNet: a word is a material when one of its first
    ``MATERIAL_SENSES`` senses lies under a material's synsets (the nearest one above it wins, so
    velvet stays velvet rather than fabric), for an adjective through the noun it is derived from
    or pertains to. Category and detector-class forms, colour words ("walnut", "gold", "ivory"
    stay colours) and room words are left out: the word must not change what else it says.

    Second table: words whose adjective names no material but whose noun does ("plush": lavish,
    and a fabric), and colour words that are a material's noun ("oak", "walnut"), read as a
    material only where said as a noun (in a phrase after the target's noun: "covered in soft
    plush", "made from solid oak"). A fabric defined by velvet (velour, velveteen, plush) is velvet: its pile
    shows no weave, which is what the surface test tells velvet from a woven fabric by."""
    by_synset = {n: m for m, names in MATERIAL_ROOTS.items() for n in names}
    colour_words = set(LEXICON) | set(ALIASES)

    def kind_of_material(s: Any, root: Any) -> bool:
        # A substance, a wood named by its tree (teak), or of the root's own kind (fabrics are
        # artifacts); not a thing made of it (paper's pads and cards are artifacts, paper is not).
        return bool(s.lexname() in ("noun.substance", "noun.plant") or s.lexname() == root.lexname())

    def nearest(s: Any) -> str | None:
        """The material of the nearest root above ``s`` (none through a thing made of it)."""
        frontier, seen = [s], {s}
        while frontier:
            hit = sorted({by_synset[x.name()] for x in frontier
                          if x.name() in by_synset and kind_of_material(s, wn.synset(x.name()))})
            if hit:
                return hit[0]
            nxt = []
            for x in frontier:
                nxt += [h for h in x.hypernyms() + x.instance_hypernyms()
                        if h not in seen and h.name() not in NOT_MATERIALS]
            seen |= set(nxt)
            frontier = nxt
        return None

    def count(word: str, pos: str) -> int:
        return sum(lem.count() for s in wn.synsets(word, pos) for lem in s.lemmas() if lem.name().lower() == word)

    def pile(n: Any, m: str) -> str:
        # A fabric defined by velvet ("heavy fabric that resembles velvet": velour; "a fabric with
        # a nap ... softer than velvet": plush) has velvet's pile, which shows no weave: its surface
        # is velvet's, the only fabric the surface test tells from a woven one.
        return "velvet" if m == "fabric" and re.search(r"\bvelvet\b", n.definition()) else m

    def material(word: str, as_noun: bool = False) -> str | None:
        # An adjective is read as one ("metallic", not the metallic fabric); a word used more often
        # as a verb in the sense-tagged corpus ("lead", "iron") says something else first. With
        # ``as_noun``, the word's noun senses ("plush": lavish as an adjective, a fabric as a noun).
        senses = wn.synsets(word, "n") if as_noun else wn.synsets(word, "a") + wn.synsets(word, "s") \
            or wn.synsets(word, "n")
        if not senses or count(word, "v") > sum(count(word, p) for p in ("n", "a", "s")):
            return None
        for s in senses[:MATERIAL_SENSES]:
            nouns = [s] if s.pos() == "n" else [
                r.synset() for lem in s.lemmas() if lem.name().lower() == word
                for r in lem.pertainyms() + lem.derivationally_related_forms() if r.synset().pos() == "n"]
            for n in nouns:
                m = nearest(n)
                if m is not None:
                    return pile(n, m)
        return None

    def words_of_roots() -> set[str]:
        # Colour words that are also a material's noun ("oak", "walnut", "gold"): a colour before
        # the target ("the oak table"), a material in "made of solid oak" (the noun table only).
        return {lem.name() for names in MATERIAL_ROOTS.values() for n in names
                for s in [wn.synset(n), *wn.synset(n).closure(lambda x: x.hyponyms())] for lem in s.lemmas()}

    words: set[str] = set()
    for names in MATERIAL_ROOTS.values():
        for n in names:
            root = wn.synset(n)
            for s in [root, *root.closure(lambda x: [h for h in x.hyponyms() if h.name() not in NOT_MATERIALS])]:
                if not kind_of_material(s, root):
                    continue
                for lem in s.lemmas():
                    words.add(lem.name())
                    words |= {r.name() for r in lem.derivationally_related_forms() if r.synset().pos() in "as"}
                    words |= {r.name() for r in lem.pertainyms()}
    for s in wn.all_synsets("a"):  # adjectives that pertain to a material ("woollen", "ceramic")
        for lem in s.lemmas():
            if any(p.synset().name() in by_synset for p in lem.pertainyms()):
                words.add(lem.name())
    # A lemma of a root itself names its material whatever the rank of that sense: the root is the
    # material ("stone" is rock.n.02's lemma, its third noun sense after a lump of rock and a hewn
    # building stone, both things of stone), when its noun is said more often than its adjective
    # and its verb in the sense-tagged corpus (stone's adjective is a dull grey colour, tagged 0 times),
    # and no sense of it lies above another root (fabric.n.01's "material" is also material.n.01: any material).
    roots = [wn.synset(n) for names in MATERIAL_ROOTS.values() for n in names]
    above = {h for r in roots for h in r.closure(lambda x: x.hypernyms())} - set(roots)
    own = {lem.name(): m for m, names in MATERIAL_ROOTS.items() for n in names for lem in wn.synset(n).lemmas()
           if not above & set(wn.synsets(lem.name(), "n"))}
    out: dict[str, str] = {}
    nouns: dict[str, str] = {}
    for w in sorted(words | (colour_words & words_of_roots())):
        if not w.isalpha() or w != w.lower() or w in forms or w in labels or w in ROOM_WORDS:
            continue
        m = material(w) if w not in colour_words else None
        if m is None and w in own and w not in colour_words \
                and count(w, "n") > max(count(w, "v"), count(w, "a") + count(w, "s")):
            m = own[w]
        if m is not None:
            out[w] = m
        elif (m := material(w, as_noun=True)) is not None:
            nouns[w] = m
    return out, nouns


#: The shape words the parse reads (``capnav.retrieval.query.tokens._SHAPES``, judged by
#: ``capnav.language.form``) and the WordNet adjective each one is.
SHAPE_HEADS = {"round": "round.a.01", "long": "long.a.02", "square": "square.a.01",
               "rectangular": "rectangular.s.01", "curved": "curved.a.01", "L-shaped": "l-shaped.s.01"}
#: Properties no map observes, each with its WordNet adjective: a word of them is read and
#: neither confirms nor refuses ("squishy", "padded", "cushioned": soft.a.01's cluster).
UNOBSERVED_HEADS = {"soft": "soft.a.01"}
#: The colour nouns: every hyponym of ``color.n.01`` (noun.attribute).
COLOUR_ROOT = "color.n.01"
#: Colour adjectives: the satellites of the adjectives of hue (chromatic, achromatic).
COLOUR_ADJECTIVE_HEADS = ["chromatic.a.03", "achromatic.a.01"]


def _attributes(wn: Any, lex: dict[str, Any]) -> dict[str, list[str]]:
    """Adjectives (and a few nouns) the plain tables lack, mapped onto the attributes the map
    reads through WordNet's relations: word -> [kind, value, relation]. Kinds: "shape" (a word of
    ``SHAPE_HEADS``), "material" (a material of ``MATERIAL_ROOTS``), "colour" (a colour phrase
    ``capnav.language.colors.color_lab`` knows) and "unobserved" (``UNOBSERVED_HEADS``: read,
    never judged). Relations, the first that gives a value wins:

    - ``similar_to``: the lemma lies in the head adjective's cluster (its similar-tos) and its most
      frequent adjective sense is there ("spherical", "disc-shaped": round; "oblong": long;
      "squishy", "padded": soft);
    - ``also_see``: the lemma of an adjective the head points to ("rounded": round);
    - ``antonym``: a shape head's opposite no other table holds and its cluster ("straight",
      "uncurved": straight, curved's antonym), of the unobserved kind (no curvature is measured);
    - ``gloss``: an adjective whose definition names the head's attribute noun ("boxy":
      "resembling a box in rectangularity", rectangularity being rectangular's noun);
    - ``definition``: a descriptive adjective (one with an attribute noun in WordNet, directly or
      through its cluster's head) said before the genus of one material's own definition and of no
      other's (glass.n.01: "a brittle transparent solid": transparent, and the lemmas of its first
      two senses whose first sense they are, "see-through"); soft, said of cotton, is taken by the
      unobserved kind first;
    - ``genus``: a noun whose definition's genus is a material ("timber": "the wood of trees cut
      and prepared for use as building material");
    - ``hypernym``: a colour noun's nearest colour up the tree ("vermilion": scarlet; "azure":
      blue; not the lightness its definition may give: azure's noun is "a light shade of blue",
      its adjective "a deep somewhat purplish blue", so the broader word refuses less);
    - ``derivation``: a colour adjective derived from a colour noun, or in a synset with a colour
      word ("ruby": red; "sapphire": blue);
    - ``gloss``: a colour adjective whose definition names a colour ("tangerine": "of a strong
      reddish orange color").

    A word must be a lower-case WordNet lemma whose most frequent sense of its part of speech is the
    one related (and not used more often as a verb or a noun, for adjectives), and no word any other
    table holds (categories, detector classes, colours, materials, rooms, sizes, heights, growth);
    a colour word also names no material ("cherry" is a wood)."""
    import re

    from capnav.language.colors import SHADES, canonical_color, color_lab

    taken = (set(lex["forms"]) | set(lex["labels"]) | set(lex["materials"]) | set(lex["rooms"]) | set(lex["sizes"])
             | set(lex["heights"]) | set(lex["height_superlatives"]) | set(lex["widths"]) | set(lex["growth"])
             | set(lex["kinds"])
             | set(LEXICON) | set(ALIASES) | set(SHADES) | ROOM_WORDS)
    material_synsets = {n: m for m, names in MATERIAL_ROOTS.items() for n in names}
    stop = _english_stop_words()

    def count(lemma: str, pos: str) -> int:
        return sum(lem.count() for s in wn.synsets(lemma, pos) for lem in s.lemmas() if lem.name() == lemma)

    def adjective_senses(lemma: str) -> list[Any]:
        return [s for s in wn.synsets(lemma) if s.pos() in "as" and any(x.name() == lemma for x in s.lemmas())]

    def usable(lemma: str) -> bool:
        return (lemma == lemma.lower() and "_" not in lemma and all(ch.isalpha() or ch == "-" for ch in lemma)
                and _form(lemma) not in taken)

    def adjective(lemma: str, among: set[Any], senses: int = 1, first: bool = True) -> bool:
        """One of the lemma's ``senses`` most frequent adjective senses is in ``among`` and (with
        ``first``) it is an adjective first in the sense-tagged corpus."""
        found = adjective_senses(lemma)
        return (any(x in among for x in found[:senses])
                and (not first or max(count(lemma, "n"), count(lemma, "v")) <= count(lemma, "a") + count(lemma, "s")))

    def shape_first(lemma: str) -> bool:
        """The lemma's first adjective sense is defined by a shape ("oblong": "(of a leaf shape)
        having a somewhat elongated form"), so its second may be read ("far" is a distance first)."""
        found = adjective_senses(lemma)
        return bool(found) and re.search(r"\b(?:shape|form)\b", found[0].definition()) is not None

    def names_material(word: str) -> bool:
        for s in wn.synsets(word, "n"):
            for path in s.hypernym_paths():
                if any(x.name() in material_synsets for x in path):
                    return True
        return False

    out: dict[str, list[str]] = {}

    def add(lemma: str, kind: str, value: str, via: str) -> None:
        if usable(lemma) and _form(lemma) not in out:
            out[_form(lemma)] = [kind, value, via]
            if "-" in lemma and _form(lemma).replace("-", " ") not in taken:
                out.setdefault(_form(lemma).replace("-", " "), [kind, value, via])

    heads = [("shape", v, wn.synset(n)) for v, n in SHAPE_HEADS.items()]
    heads += [("unobserved", v, wn.synset(n)) for v, n in UNOBSERVED_HEADS.items()]
    # similar_to: the head's cluster (a satellite head is a cluster of its own lemmas). A shape
    # word's first two senses are read ("oblong": a leaf's shape first, elongated second).
    for kind, value, head in heads:
        cluster = {head, *head.similar_tos()} if head.pos() == "a" else {head}
        for lemma in sorted({x.name() for s in cluster for x in s.lemmas()}):
            if adjective(lemma, cluster) or (kind == "shape" and shape_first(lemma) and adjective(lemma, cluster, 2)):
                add(lemma, kind, value, "similar_to")
    # also_see: the lemmas of the adjectives the head points to.
    for kind, value, head in heads:
        for other in head.also_sees():
            for lemma in sorted(x.name() for x in other.lemmas()):
                if adjective(lemma, {other}):
                    add(lemma, kind, value, "also_see")
    # antonym: a shape head's opposite that no table holds ("straight", curved's antonym), with its
    # cluster ("uncurved"), is read as its own word of the unobserved kind: the points measure no
    # curvature (``capnav.language.form``: a curved sofa's footprint measured rectangular on the
    # apartments), so neither straightness; it is read, noted and never judged. An opposite
    # another table holds ("short": a height) is not read here.
    head_names = {h.name() for kind, _, h in heads}
    for kind, _, head in heads:
        if kind != "shape":
            continue
        for other in sorted({a.synset() for lem in head.lemmas() for a in lem.antonyms()}, key=lambda x: x.name()):
            word = other.lemmas()[0].name()
            if other.name() in head_names or not usable(word):
                continue
            # The opposite's own word may be a shape in a later sense: "straight" is "successive"
            # first, but one of its senses has WordNet's attribute shape ("having no deviations").
            if adjective(word, {other}) or adjective(word, {x for x in adjective_senses(word)
                                                            if any(t.name() == "shape.n.01" for t in x.attributes())},
                                                     senses=len(adjective_senses(word))):
                add(word, "unobserved", _form(word), "antonym")
            for s in [other, *other.similar_tos()]:
                for lemma in sorted(x.name() for x in s.lemmas()):
                    if adjective(lemma, {s}):
                        add(lemma, "unobserved", _form(word), "antonym")
    # gloss: an adjective whose definition names the noun of a head's lemma ("rectangularity").
    nouns: dict[str, tuple[str, str]] = {}
    for kind, value, head in heads:
        for lem in head.lemmas():
            for d in lem.derivationally_related_forms():
                if d.synset().pos() == "n" and d.synset().lexname() == "noun.attribute":
                    nouns.setdefault(d.name().lower(), (kind, value))
    for s in sorted(wn.all_synsets("a"), key=lambda x: x.name()):
        hit = next((nouns[t] for t in re.findall(r"[a-z]+", s.definition().lower()) if t in nouns), None)
        if hit is not None:
            for lem in s.lemmas():
                if adjective(lem.name(), {s}):
                    add(lem.name(), hit[0], hit[1], "gloss")
    # definition: descriptive adjectives before the genus of one material's own definition.
    def descriptive(s: Any) -> bool:
        return bool(s.attributes() or any(h.attributes() for h in s.similar_tos()))

    def said_as_adjective(tok: str) -> bool:
        return bool(adjective_senses(tok)) and count(tok, "n") <= count(tok, "a") + count(tok, "s")

    said: dict[str, set[str]] = {}
    for material, names in MATERIAL_ROOTS.items():
        for n in names:
            run: list[str] = []
            for tok in re.findall(r"[a-z-]+", wn.synset(n).definition().lower()):
                if tok in ("a", "an", "the") and not run:
                    continue
                if tok in stop or not said_as_adjective(tok):
                    break  # the genus (or any noun or function word) ends the adjectives before it
                run.append(tok)
            if run and wn.synsets(run[-1], "n"):
                run.pop()  # "a brittle transparent solid": the last one is the genus
            for tok in run:
                said.setdefault(tok, set()).add(material)
    for word, materials in sorted(said.items()):
        if len(materials) != 1:
            continue
        senses = [s for s in adjective_senses(word)[:MATERIAL_SENSES] if descriptive(s)]
        for s in senses:
            for lem in s.lemmas():
                if adjective(lem.name(), set(senses)):
                    add(lem.name(), "material", next(iter(materials)), "definition")
    # genus: nouns defined as a kind of a material ("the wood of trees ...").
    # The material's own words: lemmas of a root whose first noun sense it is ("cloth", not
    # "material"); the genus is such a word followed by no other noun ("metal supports" are things).
    material_words = {_form(x.name()): m for m, names in MATERIAL_ROOTS.items() for n in names
                      for x in wn.synset(n).lemmas() if wn.synsets(x.name(), "n")[0] == wn.synset(n)}
    for s in sorted(wn.all_synsets("n"), key=lambda x: x.name()):
        if s.lexname() != "noun.substance":
            continue
        genus = None
        toks = re.findall(r"[a-z-]+", s.definition().lower())
        for k, tok in enumerate(toks):
            if tok in ("a", "an", "the") and k == 0:
                continue
            if tok in material_words:
                nxt = toks[k + 1] if k + 1 < len(toks) else None
                if nxt is None or nxt in stop or said_as_adjective(nxt):
                    genus = material_words[tok]
            elif said_as_adjective(tok) and tok not in stop:
                continue
            break
        if genus is None:
            continue
        for lem in s.lemmas():
            senses = wn.synsets(lem.name(), "n")
            if senses and senses[0] == s and count(lem.name(), "v") <= count(lem.name(), "n"):
                add(lem.name(), "material", genus, "genus")
    # hypernym: colour nouns.
    named = set(LEXICON) | set(ALIASES) | set(SHADES)

    def known_colour(s: Any) -> str | None:
        """A colour word of the synset: a palette, alias or shade word first, else a phrase
        ``color_lab`` reads ("reddish orange")."""
        forms = [_form(lem.name()) for lem in s.lemmas() if lem.name() == lem.name().lower()]
        for form in [*(f for f in forms if f in named), *(f for f in forms if f not in named)]:
            if color_lab(form) is not None:
                return canonical_color(form) or form
        return None

    colour_adjectives = {x for name in COLOUR_ADJECTIVE_HEADS for x in wn.synset(name).similar_tos()}

    def colour_of(s: Any) -> str | None:
        frontier: list[Any] = [s]
        while frontier:
            for x in frontier:
                c = known_colour(x)
                if c is not None:
                    return c
            frontier = [h for x in frontier for h in x.hypernyms()]
        return None

    colour_nouns = {s: c for s in wn.synset(COLOUR_ROOT).closure(lambda x: x.hyponyms())
                    if (c := colour_of(s)) is not None}
    for s, c in sorted(colour_nouns.items(), key=lambda kv: kv[0].name()):
        for lem in s.lemmas():
            senses = wn.synsets(lem.name(), "n")
            adj = adjective_senses(lem.name())
            if senses and senses[0] == s and not names_material(lem.name()) \
                    and count(lem.name(), "v") <= count(lem.name(), "n") and (not adj or adj[0] in colour_adjectives):
                add(lem.name(), "colour", c, "hypernym")
    # derivation: colour adjectives (satellites of chromatic / achromatic).
    for name in COLOUR_ADJECTIVE_HEADS:
        for s in sorted(wn.synset(name).similar_tos(), key=lambda x: x.name()):
            value = known_colour(s)
            if value is None:
                value = next((colour_nouns[d.synset()] for lem in s.lemmas()
                              for d in lem.derivationally_related_forms() if d.synset() in colour_nouns), None)
            via = "derivation"
            if value is None:  # "of a strong reddish orange color": the colour its definition names
                words = re.findall(r"[a-z-]+", s.definition().lower())
                grams = [" ".join(words[i:i + n]) for n in (2, 1) for i in range(len(words) - n + 1)]
                value = next((canonical_color(g) or g for g in grams
                              if g.split()[-1] in named and color_lab(g) is not None), None)
                via = "gloss"
            if value is None:
                continue
            for lem in s.lemmas():
                # Named after a thing ("tangerine", "chocolate"): a noun more often, a colour before
                # a noun; its first adjective sense says so.
                if adjective(lem.name(), {s}, first=False) and not names_material(lem.name()):
                    add(lem.name(), "colour", value, via)
    return dict(sorted(out.items()))


#: CapNav's room types (``capnav.language.context``) and the WordNet synsets each one is; a name
#: ending in "!" is taken without its hyponyms (the hyponyms of ``office.n.01`` are places of
#: business: box offices, newsrooms). The washroom and the powder room are under
#: ``toilet.n.01``, a room WordNet defines by its fixture: its own lemmas are the toilet's forms
#: (``_rooms_of_fixtures``), its other hyponyms name the bathroom.
ROOM_ROOTS: dict[str, list[str]] = {
    "kitchen": ["kitchen.n.01"], "bedroom": ["bedroom.n.01"],
    "bathroom": ["bathroom.n.01", "toilet.n.01"], "living room": ["living_room.n.01"],
    "office": ["office.n.01!", "home_office.n.01", "study.n.05", "workroom.n.01"],
    "hallway": ["corridor.n.01", "foyer.n.01"],
}


def _rooms(wn: Any, forms: dict[str, str], noun_exceptions: list[str]) -> dict[str, str]:
    """Room word -> CapNav room type: the lemmas of ``ROOM_ROOTS`` and their hyponyms whose most
    frequent noun sense lies there ("chamber" is any enclosed space first, "closet" a cupboard,
    "head" a body part: none is a room word), that are not a category's form ("lavatory" asks for
    the toilet). A closed compound on "room" is also said in two words ("guestroom", "guest
    room"), and a room named after a person ("child's room") by that person's synonyms and
    plural ("kid's room", "children's room", "kids room"), since that is how people write them. A
    lemma that is also a person's name ("john") is no room word."""
    plural = {}
    for line in noun_exceptions:
        parts = line.split()
        if len(parts) == 2:
            plural.setdefault(parts[1].replace("_", " "), parts[0].replace("_", " "))
    out: dict[str, str] = {}
    for room, roots in ROOM_ROOTS.items():
        members = _closure(wn, roots, set())
        for name in sorted(members):
            for lemma in wn.synset(name).lemmas():
                word = _form(lemma.name())
                senses = wn.synsets(lemma.name(), "n")
                if (not senses or senses[0].name() not in members or word in forms or word in out
                        or _is_name(wn, lemma.name())):
                    continue
                for variant in _room_variants(wn, word, plural):
                    out.setdefault(variant, room)
    return dict(sorted(out.items()))


def _room_variants(wn: Any, word: str, plural: dict[str, str]) -> list[str]:
    """``word`` and the ways it is written: "guestroom" -> "guest room"; "child's room" -> "kid's
    room", "children's room", "kids room" (the owner's lemmas of its first sense, each singular or
    plural, with or without the apostrophe)."""
    out = [word]
    if word.endswith("room") and len(word) > 4 and " " not in word and "-" not in word:
        out.append(word[:-4] + " room")
    head, sep, rest = word.partition("'s ")
    person = wn.synsets(head, "n")[0] if sep else None
    if person is not None and person.lexname() == "noun.person":
        owners = [_form(lem.name()) for lem in person.lemmas()
                  if "_" not in lem.name() and wn.synsets(lem.name(), "n")[0] == person]
        for owner in owners:
            many = plural.get(owner, owner + "s")
            out += [f"{owner}'s {rest}", f"{owner}s {rest}", f"{many}' {rest}" if many.endswith("s")
                    else f"{many}'s {rest}", f"{many} {rest}"]
    return list(dict.fromkeys(out))


def _is_name(wn: Any, lemma: str) -> bool:
    """Whether WordNet also has ``lemma`` capitalised as a person's name (noun.person)."""
    cap = lemma.capitalize()
    return any(s.lexname() == "noun.person" for s in wn.synsets(cap, "n")
               if any(lem.name() == cap for lem in s.lemmas()))


def _rooms_of_fixtures(wn: Any) -> dict[str, list[str]]:
    """Category -> synsets of a room that WordNet defines only by that fixture ("a room or
    building equipped with one or more toilets": lavatory, lav, privy): asking for such a room
    is asking for the fixture, as the British ``water_closet.n.01`` (loo) already is."""
    import re

    out: dict[str, list[str]] = {}
    for syn in wn.all_synsets("n"):
        m = re.fullmatch(r"a room(?: or building)? equipped with (?:one or more |an? )?(?P<what>[a-z ]+)",
                         syn.definition())
        if not m:
            continue
        what = m.group("what")
        for cat in ROOTS:
            if what in (cat, cat + "s", cat + "es"):
                out.setdefault(cat, []).append(syn.name() + "!")  # not its hyponyms (public toilets)
    return out


def _part(syn: Any, owner: dict[str, str]) -> bool:
    """Whether ``syn`` or a hypernym of it is a part of a category's object (WordNet's part
    holonyms: a lampshade of the lamp)."""
    return any(h.name() in owner for x in [syn, *syn.closure(lambda y: y.hypernyms())] for h in x.part_holonyms())


def _room_glosses(wn: Any) -> dict[str, list[str]]:
    """Room type -> WordNet's definitions of its ``ROOM_ROOTS`` ("a room equipped for preparing
    meals"), so that an activity can say which room it is done in ("making tea": the kitchen)."""
    return {room: list(dict.fromkeys(wn.synset(n.rstrip("!")).definition() for n in roots))
            for room, roots in ROOM_ROOTS.items()}


def _gloss_adjectives(wn: Any, lex: dict[str, Any]) -> dict[str, list[str]]:
    """Adjective -> the categories whose definitions say it, through its first sense: the lemmas
    of that synset and, for a satellite, of its head ("cosy" -> cozy.s.01, whose head
    comfortable.a.01 an easy chair's definition says: "a comfortable upholstered armchair"). A
    place described by one ("a cosy place to read") is that furniture among the ones serving the
    activity. Words of the size, height, colour, material and attribute tables are left to them."""
    import re

    def adjective(w: str) -> bool:  # a gloss word used as an adjective first ("comfortable")
        first = wn.synsets(w)
        return len(w) > 3 and bool(first) and first[0].pos() in "as"

    def count(w: str, pos: str) -> int:
        return sum(lem.count() for x in wn.synsets(w, pos) for lem in x.lemmas() if lem.name() == w)

    words = {c: {w for w in re.findall(r"[a-z]+", " ".join(g).lower()) if adjective(w)}
             for c, g in lex["glosses"].items()}
    taken = set(lex["sizes"]) | set(lex["heights"]) | set(lex["materials"]) | set(lex["attributes"]) \
        | set(LEXICON) | set(ALIASES) | set(lex["forms"])
    out: dict[str, list[str]] = {}
    for lemma in sorted(set(wn.all_lemma_names("a")) | set(wn.all_lemma_names("s"))):
        if lemma != lemma.lower() or not lemma.isalpha() or lemma in taken:
            continue
        senses = [s for s in wn.synsets(lemma) if s.pos() in "as"]
        if not senses or wn.synsets(lemma, "v") or count(lemma, "n") > count(lemma, "a"):
            continue  # "cosy" (a tea cosy too, rarely said) yes, "wash" (a verb too) no
        near = [senses[0], *(senses[0].similar_tos() if senses[0].pos() == "s" else [])]
        said = {lem.name().lower() for x in near for lem in x.lemmas()}
        cats = sorted(c for c, ws in words.items() if said & ws)
        if cats and len(cats) <= 2:  # a word many definitions say ("small") picks nothing out
            out[lemma] = cats
    return out


def _plant_names(wn: Any, out: dict[str, Any]) -> list[str]:
    """Words for a kind of plant ("ficus", "monstera", "rubber plant"), read as the plant category
    only where a request names no category otherwise (``tokens.plant_name``): lemmas whose first
    noun sense is a vascular plant, or a genus of them (WordNet has "Ficus" only as a genus), and
    that say nothing else a request may mean. Not in ``forms``, where their thousands of names
    would draw typo corrections and compound checks: only ``ROOTS``' houseplants are there. Left
    out: words that are also a colour ("olive", "lavender"), a material ("oak", "bamboo", "beech":
    woods named by their trees), a category, detector class or room word, or (one word) a verb or
    adjective too ("rose", "palm")."""
    vascular = wn.synset("vascular_plant.n.01")
    roots = {n for names in MATERIAL_ROOTS.values() for n in names}
    taken = (set(out["forms"]) | set(out["labels"]) | set(out["materials"]) | set(out["material_nouns"])
             | set(LEXICON) | set(ALIASES) | ROOM_WORDS)

    def a_plant(s: Any) -> bool:
        if s.lexname() != "noun.plant":
            return False
        up = s.closure(lambda x: x.hypernyms())
        return vascular in up or any(vascular in m.closure(lambda x: x.hypernyms()) for m in s.member_meronyms())

    def a_material(lemma: str) -> bool:
        return any(k.lexname() == "noun.substance" or any(h.name() in roots for h in k.closure(lambda x: x.hypernyms()))
                   for k in wn.synsets(lemma, "n"))

    found: set[str] = set()
    for syn in wn.all_synsets("n"):
        if syn.lexname() != "noun.plant":
            continue
        for lem in syn.lemmas():
            lemma = lem.name()
            word = _form(lemma)
            single = " " not in word
            if lemma != lemma.lower() and not (single and lemma.istitle() and syn.member_meronyms()):
                continue  # a capitalised name is taken only as a genus said in lower case ("ficus")
            if word in taken or len(word.split()) > 3 or not all(ch.isalpha() or ch in " -" for ch in word):
                continue
            senses = wn.synsets(word.replace(" ", "_"), "n")
            if not senses or senses[0] != syn or not a_plant(syn) or a_material(word.replace(" ", "_")):
                continue
            if single and any(wn.synsets(word, pos) for pos in ("v", "a", "s", "r")):
                continue
            found.add(word)
    return sorted(found)


def _furniture_senses(wn: Any, forms: dict[str, str]) -> dict[str, dict[str, Any]]:
    """Words whose first physical sense is something else but which WordNet also has as a piece
    of furniture of a category, and only as that one (Irish and British "press": a printing press
    first, the wardrobe's synonym "clothes press" too): word -> {"category", "synset",
    "alternatives"}. Read only as the head of a request that names no category otherwise. The
    alternatives are the categories of the first sense of the synset's other lemmas ("closet":
    a cupboard, the cabinet). Words with an adjective sense ("lower") or that name a person
    first ("secretary") are left out."""
    excluded = {s.name() for n in EXCLUDE for s in wn.synset(n).closure(lambda x: x.hyponyms())} | set(EXCLUDE)
    members = {cat: _closure(wn, roots, excluded) for cat, roots in ROOTS.items()}
    owner: dict[str, str] = {}
    for cat in sorted(members, key=lambda c: len(members[c]), reverse=True):
        for s in members[cat]:
            owner[s] = cat
    furniture = wn.synset("furniture.n.01")
    found: dict[str, set[str]] = {}
    for name, _cat in sorted(owner.items()):
        syn = wn.synset(name)
        if furniture not in syn.closure(lambda x: x.hypernyms()):
            continue
        for lem in syn.lemmas():
            word = lem.name()
            if word != word.lower() or not word.isalpha() or word in forms or word in ROOM_WORDS:
                continue
            nouns = wn.synsets(word, "n")
            if not nouns or nouns[0].lexname() == "noun.person" or wn.synsets(word, "a") or wn.synsets(word, "s"):
                continue
            found.setdefault(word, set()).add(name)
    out: dict[str, dict[str, Any]] = {}
    for word, names in sorted(found.items()):
        cats = {owner[n] for n in names}
        if len(cats) != 1:
            continue
        name = sorted(names)[0]
        alts: dict[str, float] = {}
        for lem in wn.synset(name).lemmas():
            other = lem.name()
            if other == word:
                continue
            first = [x for x in wn.synsets(other, "n") if x.lexname() in PHYSICAL]
            if first and first[0].name() in owner and owner[first[0].name()] not in cats:
                alts[owner[first[0].name()]] = 0.5
        out[word] = {"category": next(iter(cats)), "synset": name, "alternatives": dict(sorted(alts.items()))}
    return out


def _closure(wn: Any, names: list[str], excluded: set[str]) -> set[str]:
    """The synsets and their hyponyms (a name ending in "!" is taken without its hyponyms)."""
    out = {n[:-1] for n in names if n.endswith("!")}
    stack = [wn.synset(n) for n in names if not n.endswith("!")]
    while stack:
        s = stack.pop()
        if s.name() in out or s.name() in excluded:
            continue
        out.add(s.name())
        stack.extend(s.hyponyms())
    return out


def _build(wn: Any) -> dict[str, Any]:
    excluded = {s.name() for n in EXCLUDE for s in wn.synset(n).closure(lambda x: x.hyponyms())} | set(EXCLUDE)
    excluded |= {s.name() for n in EXCLUDE_HYPONYMS_OF for s in wn.synset(n).closure(lambda x: x.hyponyms())}
    members = {cat: _closure(wn, roots + NAME_ROOTS.get(cat, []), excluded) for cat, roots in ROOTS.items()}
    fixture_rooms: set[str] = set()
    for cat, extra in _rooms_of_fixtures(wn).items():
        members[cat] |= _closure(wn, extra, excluded)
        fixture_rooms |= {n.rstrip("!") for n in extra}
    # A synset under two categories' roots belongs to the more specific one (the smaller closure).
    owner: dict[str, str] = {}
    for cat in sorted(members, key=lambda c: len(members[c]), reverse=True):
        for s in members[cat]:
            owner[s] = cat
    colour_words = set(LEXICON) | set(ALIASES)
    fixed = {f: c.name for c in CATEGORIES for f in (c.name, *c.synonyms)}
    forms: dict[str, str] = dict(fixed)
    alternatives: dict[str, dict[str, float]] = {}

    def physical_senses(lemma: str) -> list[Any]:
        # Senses where the word is written in lower case: Chesterfield the statesman is no sofa.
        return [s for s in wn.synsets(lemma, "n") if s.lexname() in CONCRETE
                and any(lem.name() == lemma for lem in s.lemmas())]

    def other_parts_of_speech(lemma: str) -> bool:
        return any(wn.synsets(lemma, pos) for pos in ("v", "a", "s", "r"))

    candidates = sorted({lem.name() for s in owner for lem in wn.synset(s).lemmas()})
    for lemma in candidates:
        form = _form(lemma)
        if lemma != lemma.lower() or form in fixed or form in colour_words or form in ROOM_WORDS:
            continue
        if len(form.split()) > 3 or not all(ch.isalpha() or ch in " -'" for ch in form):
            continue
        if " " not in form and other_parts_of_speech(lemma):
            continue  # "settle", "lower", "console", "palm": a verb or adjective first in speech
        senses = physical_senses(lemma)
        if senses and senses[0].name() in fixture_rooms and _is_name(wn, lemma):
            continue  # "john": a person's name too (John), which a lower-cased instruction cannot tell
        if not senses or senses[0].name() not in owner:
            continue
        cat = owner[senses[0].name()]
        forms[form] = cat
        others = {owner[s.name()] for s in senses[1:] if s.name() in owner} - {cat}
        if others:
            alternatives[form] = {o: 0.5 for o in sorted(others)}
    # Compounds ending in a category word that are something else.
    heads = {f.split()[-1] for f in forms}
    # ... and compounds in which a category word names what the object is for ("bath towel",
    # "bed linen"): the category word modifies another noun.
    firsts = {f for f in forms if " " not in f}
    other: list[str] = []
    for lemma in wn.all_lemma_names("n"):
        form = _form(lemma)
        words = form.split()
        if len(words) < 2 or len(words) > 3 or form in forms or lemma != lemma.lower():
            continue
        first_word = words[-1] not in heads
        if first_word and not (len(words) == 2 and words[0] in firsts and words[1] not in firsts):
            continue
        if first_word:
            # Not a part of the object ("lamp shade", "toilet seat": the lamp, the toilet) nor a room.
            sense = next(iter(physical_senses(lemma)), None)
            if sense is None or sense.lexname() != "noun.artifact" or _part(sense, owner) or words[1] in ROOM_WORDS:
                continue
        senses = physical_senses(lemma)
        if senses and senses[0].name() not in owner:
            other.append(form)
    # Relations between categories.
    relations: dict[str, dict[str, dict[str, float | bool]]] = {}
    for a, ra in ROOTS.items():
        row: dict[str, dict[str, float | bool]] = {}
        for b, rb in ROOTS.items():
            if a == b:
                continue
            kind_of = any(n.rstrip("!") in members[a] for n in rb)
            wup = float(wn.synset(ra[0].rstrip("!")).wup_similarity(wn.synset(rb[0].rstrip("!"))) or 0.0)
            if kind_of or wup >= 0.7:
                row[b] = {"kind_of": kind_of, "wup": round(wup, 3)}
        relations[a] = row
    # Glosses for purposes.
    glosses: dict[str, list[str]] = {}
    for cat, roots in ROOTS.items():
        texts: list[str] = []
        for n in roots:
            s = wn.synset(n.rstrip("!"))
            texts.append(s.definition())
            for h in sorted(s.hyponyms(), key=lambda x: x.name()):
                if h.name() in owner and owner[h.name()] == cat:
                    texts.append(h.definition())
        glosses[cat] = list(dict.fromkeys(t.strip() for t in texts if t.strip()))[:MAX_GLOSSES]
    return {"forms": dict(sorted(forms.items())), "alternatives": dict(sorted(alternatives.items())),
            "other": sorted(set(other)), "relations": relations, "glosses": glosses,
            "foreign": _foreign(wn), "english": _english(), "not_typos": _not_typos(wn, forms),
            "source": "WordNet 3.0 (Princeton University), see WORDNET_LICENSE",
            "roots": ROOTS, "name_roots": NAME_ROOTS, "exclude": EXCLUDE}


#: Words the parser corrects typos towards besides category, colour and room words.
TYPO_KEYWORDS = ["beside", "near", "next", "behind", "opposite", "front", "closest", "nearest", "farthest",
                 "furthest", "biggest", "largest", "smallest"]


def typo_distance(word: str) -> int:
    """The edit distance (optimal string alignment: a swap of two letters is one edit) within
    which a word of this length is read as a typo of a known word: 1 up to five letters, else 2.
    The parser (``capnav.retrieval.query.tokens``) uses the same rule."""
    return 1 if len(word) <= 5 else 2


def _not_typos(wn: Any, forms: dict[str, str]) -> list[str]:
    """Common English words (lower-case WordNet lemmas seen in its sense-tagged corpus, of similar
    length and with the same first letter) that look like a word the parser corrects typos
    towards: "store" is no typo of "stove", nor "write" of "white", nor "cactu" ... Every word
    within ``typo_distance`` of a target (a category form of any length, a colour, a room or a
    keyword) is one, besides difflib's close matches."""
    import difflib

    from rapidfuzz.distance import OSA

    from capnav.language.colors import SHADES

    targets = {w for c in CATEGORIES for f in (c.name, *c.synonyms) for w in f.split()}
    targets |= {w for f in forms for w in f.split() if len(w) >= 4 and w.isalpha()}
    targets |= {w + "s" for w in targets} | {w for f in (*LEXICON, *ALIASES, *SHADES) for w in f.split()}
    targets |= ROOM_WORDS | set(TYPO_KEYWORDS)
    # Candidates of similar length that share the first letter (typos rarely change it).
    by_key: dict[tuple[str, int], list[str]] = {}
    for lemma in wn.all_lemma_names():
        if lemma == lemma.lower() and lemma.isalpha() and len(lemma) >= 3 and lemma not in targets:
            by_key.setdefault((lemma[0], len(lemma)), []).append(lemma)
    near: set[str] = set()
    for t in sorted(targets):
        pool = [w for n in range(len(t) - 2, len(t) + 3) for w in by_key.get((t[0], n), [])]
        near.update(difflib.get_close_matches(t, pool, n=100, cutoff=0.75))
        near.update(w for w in pool if OSA.distance(w, t) <= typo_distance(w))
    out = {w for w in near if _seen(wn, w)}
    # The regular inflections of common words ("sheets", "swears", "charging") are words too.
    by_len: dict[tuple[str, int], list[str]] = {}
    for t in targets:
        by_len.setdefault((t[0], len(t)), []).append(t)
    for lemma in sorted({lem for group in by_key.values() for lem in group}):
        for form in _inflections(lemma):
            if form in targets or form in out:
                continue
            close = [t for n in range(len(form) - 2, len(form) + 3) for t in by_len.get((form[0], n), [])]
            if any(OSA.distance(form, t) <= typo_distance(form) for t in close) and _seen(wn, lemma):
                out.add(form)
    return sorted(out)


def _regular_plural(word: str) -> str:
    """The plural the runtime makes of a form (``retrieval.query.tokens._plural``)."""
    if word.endswith("f"):
        return word[:-1] + "ves"
    if word.endswith(("s", "x", "ch", "sh")):
        return word + "es"
    if word.endswith("y") and word[-2:-1] not in "aeiou":
        return word[:-1] + "ies"
    return word + "s"


def _irregular_plurals(forms: dict[str, str], growth: dict[str, str], exceptions: list[str]) -> None:
    """Add to ``forms`` (and to ``growth``) the plurals WordNet's exception list (``noun.exc``)
    gives for the last word of a form where the runtime's regular plural differs: "cacti" is a
    plant, and slender like a cactus. A plural that is already a form of its own stays as it is."""
    plural_of: dict[str, list[str]] = {}
    for line in exceptions:
        parts = line.split()
        if len(parts) >= 2 and parts[0].isalpha() and parts[1].isalpha():
            plural_of.setdefault(parts[1], []).append(parts[0])
    for form, cat in sorted(forms.items()):
        *head, last = form.split()
        for plural in plural_of.get(last, []):
            if plural == _regular_plural(last):
                continue
            pform = " ".join([*head, plural])
            forms.setdefault(pform, cat)
            if form in growth and forms.get(pform) == cat:
                growth.setdefault(pform, growth[form])


def _persons(wn: Any, exceptions: list[str]) -> list[str]:
    """Nouns whose most frequent sense is a person (lexicographer file noun.person) and that occur
    in lower case in the sense-tagged corpus, with their plurals (regular ones and WordNet's
    exceptions, ``noun.exc``: children, men): "where can the kids sit" asks where people sit, not
    where things are kept."""
    return _nouns_of(wn, "noun.person", exceptions)


def _body(wn: Any, exceptions: list[str]) -> list[str]:
    """Nouns whose most frequent sense is a part of the body (noun.body), with their plurals
    (feet): "somewhere to rest my feet" rests the person, not a thing put down."""
    return _nouns_of(wn, "noun.body", exceptions)


def _nouns_of(wn: Any, lexname: str, exceptions: list[str]) -> list[str]:
    """Lower-case nouns seen in the sense-tagged corpus whose first sense is in ``lexname``, with
    their plurals."""
    out: set[str] = set()
    for lemma in wn.all_lemma_names("n"):
        if lemma != lemma.lower() or not lemma.isalpha():
            continue
        senses = [x for x in wn.synsets(lemma, "n") if any(lem.name() == lemma for lem in x.lemmas())]
        if senses and senses[0].lexname() == lexname and _seen(wn, lemma):
            out.add(lemma)
    plural = _plurals(out)
    for line in exceptions:
        infl, *bases = line.split()
        if infl.isalpha() and any(b in out for b in bases):
            plural.add(infl)
    return sorted(out | plural)


def _plurals(words: set[str]) -> set[str]:
    """The regular plurals of ``words`` (boxes, legs, potties, keys)."""
    out = {w + ("es" if w.endswith(("s", "x", "ch", "sh")) else "s") for w in words if not w.endswith("y")}
    out |= {w[:-1] + "ies" for w in words if w.endswith("y") and w[-2:-1] not in "aeiou"}
    return out | {w + "s" for w in words if w.endswith("y") and w[-2:-1] in "aeiou"}


def _seen(wn: Any, word: str) -> bool:
    """Whether ``word`` occurs in lower case in WordNet's sense-tagged corpus."""
    return any(lem.count() > 0 for lem in wn.lemmas(word) if lem.name() == word)


def _inflections(lemma: str) -> list[str]:
    """Regular plural / third person, past and -ing forms of ``lemma``."""
    out = [lemma + "s", lemma + "es", lemma + "ed", lemma + "ing"]
    if lemma.endswith("e"):
        out += [lemma + "d", lemma[:-1] + "ing"]
    if lemma.endswith("y"):
        out += [lemma[:-1] + "ies", lemma[:-1] + "ied"]
    return out


def _other_stop_words() -> set[str]:
    from stop_words import get_stop_words  # build-time only (the dev extra)

    return {w.lower().strip() for lang in FOREIGN_LANGUAGES for w in get_stop_words(lang)}


def _english_stop_words() -> set[str]:
    # scikit-learn's list (the Glasgow IR group's): stop-words' own English list also holds "la",
    # "il" and "et", so it cannot tell English from French.
    from sklearn.feature_extraction.text import ENGLISH_STOP_WORDS

    return {str(w) for w in ENGLISH_STOP_WORDS}


def _english() -> list[str]:
    """English function words that are no function word of the six other languages ("the", "to",
    "near"; not "a", "in", "de"): their presence marks a sentence as English."""
    others = _other_stop_words()
    return sorted(w for w in _english_stop_words() if w.isalpha() and w not in others)


def _foreign(wn: Any) -> list[str]:
    english = _english_stop_words()
    out: set[str] = set()
    for w in sorted(_other_stop_words()):
        if len(w) < 2 or not w.replace("'", "").isalpha() or w in english:
            continue
        if not any(lem.count() > 0 for lem in wn.lemmas(w) if lem.name() == w):  # lower case: not "LA"
            out.add(w)
    return sorted(out)


LICENSE = """WordNet Release 3.0 (the lexicon in lexicon.json is derived from it)

This software and database is being provided to you, the LICENSEE, by
Princeton University under the following license.  By obtaining, using
and/or copying this software and database, you agree that you have
read, understood, and will comply with these terms and conditions.:

Permission to use, copy, modify and distribute this software and
database and its documentation for any purpose and without fee or
royalty is hereby granted, provided that you agree to comply with
the following copyright notice and statements, including the disclaimer,
and that the same appear on ALL copies of the software, database and
documentation, including modifications that you make for internal
use or for distribution.

WordNet 3.0 Copyright 2006 by Princeton University.  All rights reserved.

THIS SOFTWARE AND DATABASE IS PROVIDED "AS IS" AND PRINCETON
UNIVERSITY MAKES NO REPRESENTATIONS OR WARRANTIES, EXPRESS OR
IMPLIED.  BY WAY OF EXAMPLE, BUT NOT LIMITATION, PRINCETON
UNIVERSITY MAKES NO REPRESENTATIONS OR WARRANTIES OF MERCHANT-
ABILITY OR FITNESS FOR ANY PARTICULAR PURPOSE OR THAT THE USE
OF THE LICENSED SOFTWARE, DATABASE OR DOCUMENTATION WILL NOT
INFRINGE ANY THIRD PARTY PATENTS, COPYRIGHTS, TRADEMARKS OR
OTHER RIGHTS.

The name of Princeton University or Princeton may not be used in
advertising or publicity pertaining to distribution of the software
and/or database.  Title to copyright in this software, database and
any associated documentation shall at all times remain with
Princeton University and LICENSEE agrees to preserve same.
"""


def dumps(lexicon: dict[str, Any]) -> str:
    return json.dumps(lexicon, indent=1, sort_keys=False, ensure_ascii=False) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--wordnet", default="/usr/share/wordnet", help="WordNet 3.0 database folder")
    ap.add_argument("-o", "--output", default=str(ROOT / "src/capnav/language/data/lexicon.json"))
    args = ap.parse_args()
    out = Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    lex = build(Path(args.wordnet))
    out.write_text(dumps(lex))
    (out.parent / "WORDNET_LICENSE").write_text(LICENSE)
    print(f"wrote {out}: {len(lex['forms'])} forms, {len(lex['other'])} other compounds, "
          f"{sum(len(g) for g in lex['glosses'].values())} glosses, {len(lex['foreign'])} foreign words")


if __name__ == "__main__":
    main()
