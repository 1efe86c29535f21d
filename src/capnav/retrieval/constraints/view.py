"""What a constraint may read of the retriever and of the verifier's judge, as typed interfaces.

Why: the retriever and the verifier both build on the constraints, so the constraints cannot
import them (not even for types) without a circle. They see them through these two protocols,
which name exactly what a constraint reads: the map's objects, their categories and scene
context, distances, and the judge's attribute agreements.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

import numpy as np
from numpy.typing import NDArray

if TYPE_CHECKING:
    from capnav.language.colors import ColorCluster
    from capnav.language.context import SceneContext
    from capnav.mapping.objects import MapObject
    from capnav.retrieval.config import RetrievalConfig
    from capnav.retrieval.query import ParsedQuery
    from capnav.retrieval.spatial import FloorDistances


class JudgeConfig(Protocol):
    """The judge's thresholds a constraint reads."""

    @property
    def color_reject(self) -> float: ...


class Judge(Protocol):
    """The offline verifier's measurements of one object against the query's attributes."""

    @property
    def config(self) -> JudgeConfig: ...

    def shape(self, q: ParsedQuery, obj: MapObject) -> tuple[float | None, str]: ...

    def material(self, q: ParsedQuery, obj: MapObject) -> tuple[float | None, str]: ...

    def name_agreement(self, q: ParsedQuery, obj: MapObject) -> tuple[bool, float, str]: ...

    def observed_colors(self, q: ParsedQuery, obj: MapObject, base: bool | None = None) -> list[ColorCluster]: ...

    def base_colors(self, obj: MapObject) -> list[ColorCluster]: ...

    def color_fit(self, q: ParsedQuery, obj: MapObject, words: list[str] | None = None,
                  base: bool | None = None) -> tuple[float, float, str]: ...

    def color(self, q: ParsedQuery, obj: MapObject, words: list[str] | None = None,
              base: bool | None = None) -> tuple[float, str]: ...

    def size(self, q: ParsedQuery, obj: MapObject) -> float: ...


class Candidates(Protocol):
    """The retriever as the ranking constraints see it: the map's objects and what is known of them."""

    cmap: Any
    config: RetrievalConfig
    objects: list[MapObject]
    E: NDArray[np.float32]
    scene: SceneContext
    cats: list[str]
    cats_arr: NDArray[Any]
    volume: NDArray[np.float64]

    @property
    def judge(self) -> Judge: ...

    def of_category(self, cat: str) -> NDArray[np.intp]: ...

    def robot_distance(self, robot_xy: tuple[float, float], among: NDArray[np.intp] | None = None
                       ) -> tuple[NDArray[np.float64], str]: ...

    def floor_distances(self) -> FloorDistances | None: ...
