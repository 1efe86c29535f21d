"""What retrieval reads of one goal of an instruction: the target's category and attributes,
its landmarks with their relations, its room, what it must not be, and how it was read."""

from __future__ import annotations

from dataclasses import dataclass, field

#: Relations whose geometry the retriever measures beyond the gap: "between" two landmarks
#: (``anchor2_category``), "at the end of" a long object (the ends of its long axis), and
#: "in the room with" a landmark (its room region), and "across" a second landmark from the first
#: ("the armchair across the coffee table from the grey one": the coffee table between them).
BETWEEN = "between"
ACROSS = "across"
END_OF = "at the end of"
ROOM_WITH = "in the room with"


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
    size_axis: str | None = None  # what the size word or superlative measures: "height" ("tall"), "width", None: volume
    #: Size words of the other dimensions said with the first ("the tall narrow bookcase": small by
    #: width), as (size, axis): judged with it, each on its own measure.
    more_sizes: list[tuple[str, str | None]] = field(default_factory=list)
    proximity: str | None = None  # "closest" / "farthest"
    relation: str | None = None  # "next to", ...
    anchor_category: str | None = None
    anchor_phrase: str | None = None
    room: str | None = None
    #: Colours said of the room ("the yellow bedroom"): of the rooms of that type, the one holding
    #: an object of that colour; never the target's colours.
    room_colors: list[str] = field(default_factory=list)
    unknown_words: list[str] = field(default_factory=list)
    #: Other categories the target words may denote, with a weight below 1 (a chair request may
    #: be served by an armchair or a stool, ranked below chairs; a purpose maps to several).
    category_alternatives: dict[str, float] = field(default_factory=dict)
    purpose: str | None = None  # the request named a use ("somewhere to sit"), not an object
    #: The room the purpose implies ("rinse a cup before making tea": the kitchen): a preference
    #: among the instances of the category that serves it, never a refusal (``purpose.activity_room``).
    purpose_room: str | None = None
    #: The purpose puts a thing down ("somewhere to charge my phone"): every surface serves it, and a
    #: landmark chooses among them (``purpose.is_placing``).
    placing: bool = False
    negations: list[str] = field(default_factory=list)  # phrases the target must NOT match ("white")
    ordinal: int | None = None  # 2 for "the second closest"
    proximity_to_anchor: bool = False  # "the stool nearest the stove": distance to the anchor
    anchor2_category: str | None = None  # the second landmark of "between the bed and the wardrobe"
    anchor2_phrase: str | None = None
    #: How the goal was read: "patterns" or the parser's name; notes say what could not be read.
    parser: str = ""
    notes: list[str] = field(default_factory=list)
    #: Words of the instruction the parse did not attach to this goal's target (never attributes).
    dropped_words: list[str] = field(default_factory=list)
    origin_room: str | None = None  # the room a route comes from ("coming out of the bathroom")
    side: str | None = None  # "left" / "right" as seen walking the route into ``room``
    #: What an ordinal counts from or along ("the third lamp from the door"): a phrase.
    ordinal_from: str | None = None
    structure: dict[str, object] = field(default_factory=dict)  # the parse of the goal (head, modifiers, ...)
    #: The target was named by a word for any object ("the third thing you reach", "the one by the
    #: door") with a predicate that picks it: every category may answer.
    generic: bool = False
    #: Materials said of a part of the target ("the dresser with the glass top": top -> glass):
    #: the map observes no part apart, so they neither confirm nor refuse (a note says so).
    part_materials: dict[str, list[str]] = field(default_factory=dict)
    #: Shapes said of a part ("the armchair with rounded arms": arms -> round): the map measures the
    #: whole footprint, so they neither confirm nor refuse either.
    part_shapes: dict[str, list[str]] = field(default_factory=dict)

    @property
    def has_attributes(self) -> bool:
        return bool(self.colors or self.materials or self.shapes or self.size_word or self.superlative
                    or self.relation or self.room)

    @property
    def category_only(self) -> bool:
        return self.category is not None and not self.has_attributes and not self.unknown_words

    def to_dict(self) -> dict[str, object]:
        return {k: v for k, v in self.__dict__.items() if v not in (None, [], "", {}, False)}

