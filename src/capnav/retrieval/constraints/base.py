"""What every constraint of an instruction shares: the evidence it reports per candidate, the
ranking state it narrows and orders, and the two interfaces (ranking and verification).

Why: an instruction is a conjunction of constraints (a category, a room, a landmark relation, a
colour, ...). Each one is judged against what the map observed and reports one of three kinds of
evidence per candidate: ``supported`` (the map shows it), ``contradicted`` (the map shows the
opposite) or ``unobserved`` (the map cannot tell). The refusal, the order and the explanation are
built from these reports, so a runner-up's "why" and the chosen object's reason are the same
clauses. A kind of constraint is one module of this package that registers itself.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import NDArray

from capnav.retrieval.query import ParsedQuery

if TYPE_CHECKING:
    from capnav.mapping.objects import MapObject
    from capnav.retrieval.constraints.view import Candidates, Judge

Status = Literal["supported", "contradicted", "unobserved"]
SUPPORTED: Status = "supported"
CONTRADICTED: Status = "contradicted"
UNOBSERVED: Status = "unobserved"


@dataclass(frozen=True)
class Evidence:
    """One constraint's judgement of one candidate."""

    kind: str  # the constraint's kind ("colour", "material", ...)
    status: Status
    value: float = 0.0  # agreement in [0, 1] that the verifier's score adds (with the kind's weight)
    clause: str = ""  # the clause it contributes to the reason ("colour blue vs observed navy ...")
    terms: dict[str, float] = field(default_factory=dict)  # numbers shown with the candidate

    @property
    def refuses(self) -> bool:
        return self.status == CONTRADICTED


@dataclass
class RankState:
    """The candidates of one query while the ranking constraints narrow and order them.

    ``group_keys`` are compared first (lexicographically, the first most significant): candidates
    equal on every group key form a group, within which the verifier may reorder by attributes.
    ``order_keys`` order within a group before similarity. ``values`` are the numbers each
    constraint measured per pool member (shown as terms)."""

    r: Candidates
    q: ParsedQuery
    s: NDArray[np.float32]
    robot_xy: tuple[float, float] | None
    notes: list[str]
    pool: NDArray[np.intp] = field(default_factory=lambda: np.zeros(0, np.intp))
    weights: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    named: bool = False
    group_keys: list[NDArray[np.float64]] = field(default_factory=list)
    order_keys: list[NDArray[np.float64]] = field(default_factory=list)
    values: dict[str, NDArray[np.float64]] = field(default_factory=dict)
    predicate: str | None = None
    mode: str = "semantic"
    refusal: str | None = None
    refused_by: str | None = None
    #: Per object index: why it does not stand where the request's relation puts it ("next to" a
    #: landmark farther than the captions' next-to distance); the order is not changed by it.
    unmet: dict[int, str] = field(default_factory=dict)
    #: Per object index: its gap to the landmark when farther than the relation's reach (a loose
    #: "near" reaches farther than "next to"); when every candidate is, the query refuses.
    out_of_reach: dict[int, float] = field(default_factory=dict)
    #: That reach (m), None without a relation of nearness.
    reach: float | None = None
    order: NDArray[np.intp] = field(default_factory=lambda: np.zeros(0, np.intp))  # set by the sort
    groups: NDArray[np.int64] = field(default_factory=lambda: np.zeros(0, np.int64))
    #: Per constraint kind: per object index, the evidence it reported (for the explanation).
    evidence: dict[str, dict[int, Evidence]] = field(default_factory=dict)

    def refuse(self, kind: str, reason: str, override: bool = True) -> None:
        """Answer "not found" for ``reason`` (a later constraint's refusal replaces an earlier one
        unless ``override`` is False)."""
        if override or self.refusal is None:
            self.refusal, self.refused_by = reason, kind

    def keep(self, mask: NDArray[np.bool_]) -> None:
        """Narrow the pool (and every per-pool array measured so far) to ``mask``."""
        self.pool = self.pool[mask]
        self.group_keys = [k[mask] for k in self.group_keys]
        self.order_keys = [k[mask] for k in self.order_keys]
        self.values = {n: v[mask] for n, v in self.values.items()}

    def report(self, kind: str, i: int, ev: Evidence) -> None:
        self.evidence.setdefault(kind, {})[int(i)] = ev


class RankingConstraint(ABC):
    """A constraint that narrows the candidates or orders them before verification."""

    kind: str
    #: Place in the ranking (lower first): the pool is narrowed before it is ordered, and a
    #: constraint that reads the order (an ordinal) comes after the sort (``order >= SORT_AT``).
    order: int

    @staticmethod
    @abstractmethod
    def applies(q: ParsedQuery) -> bool: ...

    @abstractmethod
    def rank(self, st: RankState) -> None: ...


class AttributeConstraint(ABC):
    """A constraint the verifier judges per candidate from the candidate's observations."""

    kind: str
    order: int
    weight_field: str  # the ``OfflineVerifierConfig`` weight of its agreement
    #: Whether its ``supported`` evidence is the map showing the attribute outright (the grain of a
    #: spoken material), not a graded fit: such evidence puts a candidate before those of its
    #: predicate group on which the map cannot tell, ahead of the retrieval order (colour and size
    #: are graded and weigh in through their agreement; shape, see ``Shape``).
    shown: bool = False

    @staticmethod
    @abstractmethod
    def applies(q: ParsedQuery) -> bool: ...

    @abstractmethod
    def judge(self, v: Judge, q: ParsedQuery, obj: MapObject, weight: float) -> Evidence:
        """The evidence for ``obj`` (``weight``: 1 for the named category, < 1 for a stand-in)."""


#: Ranking constraints of ``order`` below this narrow and key the pool; the sort comes next.
SORT_AT = 90
RANKING: list[type[RankingConstraint]] = []
ATTRIBUTES: list[type[AttributeConstraint]] = []


def ranking(cls: type[RankingConstraint]) -> type[RankingConstraint]:
    """Register a ranking constraint (class decorator)."""
    RANKING.append(cls)
    RANKING.sort(key=lambda c: c.order)
    return cls


def attribute(cls: type[AttributeConstraint]) -> type[AttributeConstraint]:
    """Register an attribute constraint (class decorator)."""
    ATTRIBUTES.append(cls)
    ATTRIBUTES.sort(key=lambda c: c.order)
    return cls


