"""Seeded natural-language instructions with ground-truth targets, from a scene manifest.

From the simulator's truth (it reads the manifest): the benchmark's description goals and the demo's
instructions. Kinds:
  ``attribute``   category + colour that singles one instance out among lookalikes
  ``superlative`` the biggest / smallest instance of a category
  ``relation``    the X next to the Y (unique: no other X is near a Y)
  ``room``        the X in the kitchen (unique: no other X in a room of that type)
  ``category``    the category only (any instance counts)
  ``closest``     the closest X to a given robot position (clear margin to the runner-up)
  ``absent``      a category that is not in the scene (the right answer is "not found")
Phrasing varies: category synonyms (couch for sofa), word order, polite / terse / imperative
forms and, with a small probability, a typo in a longer word. Colour is used to single an
instance out only when its colour differs visibly from every lookalike's (CIEDE2000 >= 15 with
lightness half-weighted): people describe differences they can see, and a "walnut" versus
"brown" desk is not one. A plant's colour is its pot's ("the plant in the red pot"), and green
pots are not used (they hide among the leaves). Materials are added as extra words, never as the
only cue.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from capnav.core.categories import BY_NAME, NAMES
from capnav.core.colour import ciede2000, srgb_to_lab
from capnav.core.errors import InputError
from capnav.core.footprint import footprint_distance
from capnav.sim.manifest import ObjectInstance, SceneManifest

KINDS: tuple[str, ...] = ("attribute", "superlative", "relation", "room", "category", "closest", "absent")
ROOM_WORDS = {"kitchen": ["kitchen"], "bedroom": ["bedroom"], "bathroom": ["bathroom"],
              "living room": ["living room", "lounge"], "office": ["office", "study"]}
OUT_OF_VOCABULARY = ["piano", "fireplace", "aquarium", "treadmill", "grandfather clock", "pool table",
                     "rocking horse", "harp"]
#: Synonyms that people use for a whole category (not sub-types like "dining chair" or "bar stool").
_SAFE_SYNONYMS = {"sofa": ["couch", "settee"], "armchair": ["easy chair", "lounge chair"], "tv": ["television"],
                  "refrigerator": ["fridge"], "bookshelf": ["bookcase"], "plant": ["potted plant", "houseplant"],
                  "wardrobe": ["closet", "armoire"], "dresser": ["chest of drawers"], "cabinet": ["cupboard"],
                  "nightstand": ["bedside table", "night table"], "sink": ["washbasin", "basin"],
                  "bathtub": ["tub", "bath"], "stove": ["cooker", "oven"], "counter": ["countertop", "worktop"],
                  "washing machine": ["washer"], "ottoman": ["footstool", "pouf"], "desk": ["writing desk"],
                  "coffee table": ["low table"], "lamp": ["floor lamp"], "toilet": ["wc"]}

_WRAP = {
    "polite": ["Could you please take me to {d}?", "Please go to {d}.", "Can you find {d}, please?",
               "Would you navigate to {d}?", "I'd like to go to {d}, please."],
    "terse": ["{d}", "{d}.", "to {d}"],
    "imperative": ["Go to {d}.", "Find {d}.", "Navigate to {d}.", "Take me to {d}.", "Head to {d}."],
}


@dataclass(frozen=True)
class InstructionConfig:
    color_delta_e: float = 15.0  # min CIEDE2000 (kL=2) to every lookalike's colour
    size_ratio: float = 1.3  # volume ratio to the runner-up for biggest / smallest
    relation_gap: float = 0.6  # m, target footprint to anchor footprint
    relation_margin: float = 1.0  # m, every lookalike at least this much farther from any anchor
    closest_margin: float = 1.0  # m, runner-up at least this much farther from the robot
    synonym_prob: float = 0.4
    typo_prob: float = 0.1
    material_prob: float = 0.25
    oov_absent_prob: float = 0.3


#: ``walk(robot_xy, instance) -> metres`` along the true floor from the robot to within reach of it.
Walk = Callable[[tuple[float, float], ObjectInstance], float]


@dataclass
class Instruction:
    text: str
    kind: str
    targets: list[int]  # instance ids that count as success (empty for "absent")
    category: str
    robot_xy: tuple[float, float] | None = None
    details: dict[str, Any] = field(default_factory=dict)

    @property
    def target_ids(self) -> list[int]:
        return self.targets

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def _volume(o: ObjectInstance) -> float:
    return float(np.prod(o.size))


def footprint_gap(a: ObjectInstance, b: ObjectInstance) -> float:
    """Distance between two convex footprints (0 when they touch or overlap): the nearest vertex of
    either to the other polygon."""
    pa, pb = np.asarray(a.footprint, dtype=np.float64), np.asarray(b.footprint, dtype=np.float64)
    return float(min(footprint_distance(pa, pb).min(), footprint_distance(pb, pa).min()))


class InstructionGenerator:
    """Describe instances of one scene; every public method takes the caller's ``rng``."""

    def __init__(self, manifest: SceneManifest, config: InstructionConfig | None = None,
                 walk: Walk | None = None) -> None:
        self.m = manifest
        self.cfg = config or InstructionConfig()
        self.walk = walk
        self.rooms = {r.id: r.name for r in manifest.rooms}
        self.by_id = {o.id: o for o in manifest.objects}
        self.lab = {o.id: srgb_to_lab(np.array(o.color_rgb, dtype=np.float64)) for o in manifest.objects}

    # -- wording -------------------------------------------------------------------------------
    def noun(self, cat: str, rng: np.random.Generator) -> str:
        syn = _SAFE_SYNONYMS.get(cat, [])
        if syn and rng.random() < self.cfg.synonym_prob:
            return str(syn[int(rng.integers(len(syn)))])
        return cat

    def typo(self, text: str, rng: np.random.Generator) -> str:
        words = text.split(" ")
        idx = [k for k, w in enumerate(words) if len(w) >= 6 and w.isalpha()]
        if not idx or rng.random() >= self.cfg.typo_prob:
            return text
        k = idx[int(rng.integers(len(idx)))]
        w = words[k]
        j = int(rng.integers(1, len(w) - 2))
        words[k] = w[:j] + w[j + 1] + w[j] + w[j + 2:] if rng.random() < 0.5 else w[:j] + w[j + 1:]
        return " ".join(words)

    def wrap(self, desc: str, rng: np.random.Generator) -> str:
        style = ("polite", "terse", "imperative")[int(rng.integers(3))]
        forms = _WRAP[style]
        return self.typo(forms[int(rng.integers(len(forms)))].format(d=desc), rng)

    # -- uniqueness tests ----------------------------------------------------------------------
    def peers(self, o: ObjectInstance) -> list[ObjectInstance]:
        return [p for p in self.m.objects if p.category == o.category and p.id != o.id]

    def distinct_color(self, o: ObjectInstance) -> bool:
        peers = self.peers(o)
        if not peers:
            return True
        d = ciede2000(self.lab[o.id][None], np.stack([self.lab[p.id] for p in peers]), kL=2.0)
        return bool(np.all(d >= self.cfg.color_delta_e))

    def superlative(self, o: ObjectInstance) -> str | None:
        peers = self.peers(o)
        if not peers:
            return None
        v, others = _volume(o), [_volume(p) for p in peers]
        if v >= self.cfg.size_ratio * max(others):
            return "largest"
        if v * self.cfg.size_ratio <= min(others):
            return "smallest"
        return None

    def relation_anchor(self, o: ObjectInstance) -> str | None:
        peers = self.peers(o)
        best: tuple[float, str] | None = None
        for a in self.m.objects:
            if a.category == o.category:
                continue
            g = footprint_gap(o, a)
            if g <= self.cfg.relation_gap and (best is None or g < best[0]):
                best = (g, a.category)
        if best is None:
            return None
        anchors = [a for a in self.m.objects if a.category == best[1]]
        for p in peers:
            if min(footprint_gap(p, a) for a in anchors) < best[0] + self.cfg.relation_margin:
                return None
        return best[1]

    def room_of(self, o: ObjectInstance) -> str | None:
        name = self.rooms.get(o.room)
        return name if name in ROOM_WORDS else None

    def unique_room(self, o: ObjectInstance) -> str | None:
        room = self.room_of(o)
        if room is None or any(self.room_of(p) == room for p in self.peers(o)):
            return None
        return room

    def closest_ok(self, o: ObjectInstance, robot_xy: tuple[float, float]) -> bool:
        """``o`` is the closest of its kind by a clear margin: in a straight line and, when the
        generator knows the floor (``walk``), along it too, so the instruction means one object
        whichever distance the reader has in mind (through a wall, the nearer plant may be the
        farther walk)."""
        peers = self.peers(o)
        if not peers:
            return False
        r = np.asarray(robot_xy)
        d = float(np.linalg.norm(np.asarray(o.center[:2]) - r))
        if not all(float(np.linalg.norm(np.asarray(p.center[:2]) - r)) >= d + self.cfg.closest_margin for p in peers):
            return False
        if self.walk is None:
            return True
        w = self.walk(robot_xy, o)
        return bool(np.isfinite(w)) and all(self.walk(robot_xy, p) >= w + self.cfg.closest_margin for p in peers)

    # -- one description per kind --------------------------------------------------------------
    def describe_as(self, o: ObjectInstance, kind: str, rng: np.random.Generator,
                    robot_xy: tuple[float, float] | None = None) -> Instruction | None:
        """A description of ``o`` of the given kind, or None when that kind cannot single it out."""
        noun = self.noun(o.category, rng)
        mat = f"{o.material} " if rng.random() < self.cfg.material_prob and o.material not in o.color_name else ""
        details: dict[str, Any] = {"instance": o.id}
        if kind == "attribute":
            if not self.peers(o) or not self.distinct_color(o):
                return None
            c = o.color_name
            if o.category == "plant":  # a plant's colour is its pot's; green pots hide among the leaves
                if c in ("green", "olive"):
                    return None
                desc = f"the {noun} in the {c} pot" if rng.random() < 0.5 else f"the {noun} with the {c} pot"
            else:
                desc = (f"the {c} {mat}{noun}" if rng.random() < 0.7 else f"the {mat}{noun} that is {c}")
            details["color"] = c
        elif kind == "superlative":
            sup = self.superlative(o)
            if sup is None:
                return None
            word = {"largest": ["biggest", "largest"], "smallest": ["smallest"]}[sup]
            desc = f"the {word[int(rng.integers(len(word)))]} {noun}"
            details["superlative"] = sup
        elif kind == "relation":
            if not self.peers(o):
                return None
            anchor = self.relation_anchor(o)
            if anchor is None:
                return None
            rel = ["next to", "near", "beside"][int(rng.integers(3))]
            desc = f"the {noun} {rel} the {self.noun(anchor, rng)}"
            details["anchor"] = anchor
        elif kind == "room":
            if not self.peers(o):
                return None
            room = self.unique_room(o)
            if room is None:
                return None
            rw = ROOM_WORDS[room][int(rng.integers(len(ROOM_WORDS[room])))]
            details["room"] = room
            if rng.random() < 0.3:  # room first: "In the kitchen, find the chair."
                verb = ["find", "go to", "please go to", "take me to"][int(rng.integers(4))]
                text = self.typo(f"In the {rw}, {verb} the {noun}.", rng)
                return Instruction(text, kind, [o.id], o.category, robot_xy, details)
            desc = f"the {noun} in the {rw}"
        elif kind == "closest":
            if robot_xy is None or not self.closest_ok(o, robot_xy):
                return None
            form = ["the closest {n}", "the nearest {n}", "the {n} closest to me", "the nearest {n} to me"]
            desc = form[int(rng.integers(len(form)))].format(n=noun)
        elif kind == "category":
            desc = f"the {noun}"
            ids = [p.id for p in self.m.by_category(o.category)]
            return Instruction(self.wrap(desc, rng), kind, ids, o.category, robot_xy, details)
        else:
            raise InputError(f"unknown instruction kind {kind!r}; kinds: {', '.join(KINDS)}")
        return Instruction(self.wrap(desc, rng), kind, [o.id], o.category, robot_xy, details)

    def describe(self, instance_id: int, robot_xy: tuple[float, float] | None,
                 rng: np.random.Generator) -> tuple[str, str]:
        """The ``Describe`` callable of ``capnav.eval.generate``: a text that singles out
        ``instance_id`` and its kind; category only when nothing else does (or it is unique)."""
        ins = self.describe_instruction(instance_id, robot_xy, rng)
        return ins.text, ins.kind

    def describe_instruction(self, instance_id: int, robot_xy: tuple[float, float] | None,
                             rng: np.random.Generator) -> Instruction:
        """``describe`` with what the text rests on (``Instruction.details``), for ``singles_out``."""
        o = self.by_id[instance_id]
        kinds = ["attribute", "superlative", "relation", "room"]
        if robot_xy is not None:
            kinds.append("closest")
        for k in rng.permutation(len(kinds)):
            ins = self.describe_as(o, kinds[int(k)], rng, robot_xy)
            if ins is not None:
                return ins
        ins = self.describe_as(o, "category", rng)
        assert ins is not None
        return ins

    def singles_out(self, ins: Instruction) -> bool:
        """Whether ``ins`` (made by this generator or by one of another home: another visit of
        the apartment) names its instance alone in this home, by the rule of its kind: its colour
        still differs from every lookalike's, it is still the biggest, its landmark still the only
        one near, its room still the only one of that type with such an object, its kind unique."""
        o = self.by_id.get(int(ins.details.get("instance", -1)))
        if o is None:
            return False
        if ins.kind == "attribute":
            return bool(self.peers(o)) and self.distinct_color(o)
        if ins.kind == "superlative":
            return self.superlative(o) == ins.details.get("superlative")
        if ins.kind == "relation":
            return bool(self.peers(o)) and self.relation_anchor(o) == ins.details.get("anchor")
        if ins.kind == "room":
            return bool(self.peers(o)) and self.unique_room(o) == ins.details.get("room")
        if ins.kind == "closest":
            return ins.robot_xy is not None and self.closest_ok(o, ins.robot_xy)
        return not self.peers(o)  # a bare kind

    __call__ = describe

    def absent(self, rng: np.random.Generator) -> Instruction:
        present = {o.category for o in self.m.objects}
        missing = [n for n in NAMES if n not in present]
        if not missing or rng.random() < self.cfg.oov_absent_prob:
            cat = OUT_OF_VOCABULARY[int(rng.integers(len(OUT_OF_VOCABULARY)))]
            noun = cat
        else:
            cat = missing[int(rng.integers(len(missing)))]
            noun = self.noun(cat, rng)
        return Instruction(self.wrap(f"the {noun}", rng), "absent", [], cat, None,
                           {"in_vocabulary": cat in BY_NAME})

    def robot_position(self, rng: np.random.Generator, clearance: float = 0.5) -> tuple[float, float]:
        """A random point inside a room, at least ``clearance`` from every footprint."""
        objs = self.m.objects
        for _ in range(1000):
            room = self.m.rooms[int(rng.integers(len(self.m.rooms)))]
            poly = np.asarray(room.polygon, dtype=np.float64)
            lo, hi = poly.min(0) + 0.4, poly.max(0) - 0.4
            if np.any(hi <= lo):
                continue
            p = rng.uniform(lo, hi)
            if all(footprint_distance(p, np.asarray(o.footprint))[0] >= clearance for o in objs):
                return float(p[0]), float(p[1])
        raise InputError(f"scene {self.m.seed}: no free robot position found")


def generate_instructions(manifest: SceneManifest, per_kind: int = 10, seed: int = 0,
                          kinds: Sequence[str] = KINDS, config: InstructionConfig | None = None,
                          robot_xy: tuple[float, float] | None = None, walk: Walk | None = None
                          ) -> list[Instruction]:
    """Up to ``per_kind`` instructions of each kind (fewer when the scene allows fewer), seeded.
    "closest" instructions use ``robot_xy`` when given, else random free positions in rooms, and
    hold by walking distance too when ``walk`` is given."""
    for k in kinds:
        if k not in KINDS:
            raise InputError(f"unknown instruction kind {k!r}; kinds: {', '.join(KINDS)}")
    gen = InstructionGenerator(manifest, config, walk)
    rng = np.random.default_rng(seed)
    out: list[Instruction] = []
    objs = list(manifest.objects)
    for kind in kinds:
        made: list[Instruction] = []
        if kind == "absent":
            made = [gen.absent(rng) for _ in range(per_kind)]
        elif kind == "category":
            for k in rng.permutation(len(objs))[:per_kind]:
                ins = gen.describe_as(objs[int(k)], "category", rng)
                if ins is not None:
                    made.append(ins)
        elif kind == "closest":
            tries = 0
            while len(made) < per_kind and tries < 50 * per_kind:
                tries += 1
                xy = robot_xy if robot_xy is not None else gen.robot_position(rng)
                cands = [o for o in objs if gen.closest_ok(o, xy)]
                if cands:
                    ins = gen.describe_as(cands[int(rng.integers(len(cands)))], "closest", rng, xy)
                    if ins is not None:
                        made.append(ins)
        else:
            seen: set[str] = set()
            for k in rng.permutation(len(objs)):
                if len(made) >= per_kind:
                    break
                ins = gen.describe_as(objs[int(k)], kind, rng)
                if ins is not None and ins.text not in seen:
                    seen.add(ins.text)
                    made.append(ins)
        out.extend(made)
    return out
