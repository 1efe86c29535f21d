"""The library face: a thin facade over the stages for code that drives CapNav (a robot's task
code, a notebook, a server).

``CapNav`` wraps one map. Constructing it does no work: the text embedder, the retriever and the
planner's costmap are made on first use and then kept, so asking many questions of one map costs
milliseconds each. Records handed out are plain, typed copies (``ObjectRecord``, ``Answer``,
``Plan``); the stage objects stay reachable (``CapNav.map``, ``Answer.result``) for anything the
facade does not cover.

    nav = CapNav.open("apt0.capnav")
    answer = nav.ask("the pink armchair", robot=(1.0, 2.0))
    plan = nav.plan((1.0, 2.0, 0.0), answer)

Planning goes as in ``capnav navigate`` (``capnav.planning.on_map``): on the mapped occupancy with
the unknown cells near the camera path counted as free, and from the map's last camera pose when
no start is given.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, NotFoundError
from capnav.core.frame import Frame
from capnav.core.grid import OccupancyGrid
from capnav.language.embedder import TextEmbedder
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.objects import MapObject
from capnav.planning.config import PlannerConfig
from capnav.retrieval.config import RetrievalConfig
from capnav.retrieval.result import QueryResult
from capnav.retrieval.retriever import Retriever

if TYPE_CHECKING:  # the mapping and captioning stages (detectors, scipy) load only when a map is built
    from capnav.language.describe import DescribeReport
    from capnav.mapping.mapper import MapperConfig
    from capnav.planning.costmap import Costmap
    from capnav.planning.goal import GoalPose

__all__ = ["Answer", "CapNav", "ObjectRecord", "Plan"]


def _floats(v: Any) -> list[float]:
    return [round(float(x), 4) for x in np.asarray(v).ravel()]


@dataclass(frozen=True)
class ObjectRecord:
    """One object of the map as a reader of the map sees it. ``views`` are the frame indices of
    the views chosen for captioning; ``embedding`` is the caption's unit vector (None before
    ``caption``)."""

    id: int
    category: str
    caption: str | None
    min: tuple[float, float, float]
    max: tuple[float, float, float]
    centroid: tuple[float, float, float]
    views: tuple[int, ...]
    embedding: NDArray[np.float32] | None = field(default=None, repr=False, compare=False)

    @classmethod
    def of(cls, o: MapObject) -> ObjectRecord:
        def t3(v: NDArray[np.float64]) -> tuple[float, float, float]:
            a = np.asarray(v, dtype=np.float64)
            return (float(a[0]), float(a[1]), float(a[2]))

        emb = None if o.embedding is None else np.array(o.embedding, dtype=np.float32)
        return cls(int(o.id), o.label, o.caption, t3(o.extent_min), t3(o.extent_max), t3(o.position),
                   tuple(int(v.frame_index) for v in o.views), emb)

    def to_dict(self) -> dict[str, Any]:
        return {"id": self.id, "category": self.category, "caption": self.caption, "min": _floats(self.min),
                "max": _floats(self.max), "centroid": _floats(self.centroid), "views": list(self.views)}


@dataclass(frozen=True)
class Answer:
    """What ``ask`` returns: the chosen object (None when nothing fits); ``score``, its caption's
    cosine similarity to the instruction (eq. 16; 0 when nothing fits); the reason in words; the
    runners-up in decision order with their final scores (the verification value where the
    candidate was judged, 0 when it was rejected, else the caption similarity: not one scale);
    and, when the robot's position was given, the goal pose to stop at (``goal``; its own
    ``reason`` says how it was chosen). ``to_dict`` keeps these names: ``score`` and
    ``runners_up[i].score``."""

    instruction: str
    object: ObjectRecord | None
    score: float
    reason: str
    runners_up: tuple[tuple[ObjectRecord, float], ...]
    goal: GoalPose | None
    robot: tuple[float, float] | None
    result: QueryResult = field(repr=False, compare=False)
    goal_note: str = ""
    #: Every goal of a request of several ("the fridge, then the sofa"), this one first; empty for
    #: one goal. ``stopped`` says why the sequence ended early (a goal not found).
    goals: tuple[Answer, ...] = field(default=(), repr=False, compare=False)
    stopped: str = ""

    @property
    def found(self) -> bool:
        return self.object is not None

    def to_dict(self) -> dict[str, Any]:
        return {"instruction": self.instruction, "found": self.found,
                "object": None if self.object is None else self.object.to_dict(),
                "score": round(self.score, 6), "reason": self.reason,
                "runners_up": [{**o.to_dict(), "score": round(s, 6)} for o, s in self.runners_up],
                "goal": None if self.goal is None else self.goal.to_dict(), "goal_note": self.goal_note,
                "robot": None if self.robot is None else _floats(self.robot),
                "mode": self.result.mode, "predicate": self.result.predicate,
                "timings_ms": {k: round(v * 1e3, 3) for k, v in self.result.timings.items()},
                **({"goals": [g.to_dict() for g in self.goals], "stopped": self.stopped}
                   if self.goals else {})}


@dataclass(frozen=True)
class Plan:
    """A planned path to an object: ``poses`` (N, 3) world x, y, θ from the start to the goal pose
    (θ is the heading of the segment driven, the last one faces the object), its length in metres,
    and why it succeeded or failed. ``success`` means the goal pose is within reach of the object;
    when no cell within reach can be reached the path goes as close as it can, with ``success=False``
    and the reason (not an exception); bad input (a start off the map or in a wall) raises ``InputError``."""

    success: bool
    poses: NDArray[np.float64]
    length_m: float
    reason: str
    goal: GoalPose | None = None
    target: int | None = None

    def to_dict(self) -> dict[str, Any]:
        return {"success": self.success, "poses": np.round(self.poses, 4).tolist(),
                "length_m": round(self.length_m, 4), "reason": self.reason, "target": self.target,
                "goal": None if self.goal is None else self.goal.to_dict()}


def _xy(robot: Sequence[float] | NDArray[np.floating] | None, what: str) -> tuple[float, float] | None:
    if robot is None:
        return None
    try:
        a = np.asarray(robot, dtype=np.float64).ravel()
    except (TypeError, ValueError):
        raise InputError(f"{what} must be numbers x, y (m), got {robot!r}") from None
    if len(a) < 2 or not np.isfinite(a[:2]).all():
        raise InputError(f"{what} must be finite numbers x, y (m), got {robot!r}")
    return (float(a[0]), float(a[1]))


def _headings(xy: NDArray[np.float64], start_yaw: float, end_yaw: float) -> NDArray[np.float64]:
    """θ per waypoint: the start's own yaw, then the heading of the segment that reached it; the
    goal faces the object."""
    yaw = np.full(len(xy), start_yaw, dtype=np.float64)
    if len(xy) > 1:
        d = np.diff(xy, axis=0)
        yaw[1:] = np.arctan2(d[:, 1], d[:, 0])
    yaw[-1] = end_yaw
    return np.column_stack([xy, yaw])


class CapNav:
    """One map, ready to be asked. ``embedder``: ``"auto"`` (the model the map's captions were
    embedded with, when it is the offline default) or a backend name, with ``embedder_path`` for
    folder-based models, or a ready ``TextEmbedder``. ``verifier``: a backend name (``offline``,
    ``none``, ``gemini``, ...)."""

    def __init__(self, cmap: CapNavMap, *, embedder: str | TextEmbedder = "auto", embedder_path: str | Path | None
                 = None, verifier: str = "offline", retrieval: RetrievalConfig | None = None,
                 planner: PlannerConfig | None = None, source: str | Path | None = None, fields: bool = True) -> None:
        if not isinstance(cmap, CapNavMap):
            raise InputError(f"CapNav wraps a CapNavMap, got {type(cmap).__name__} (use CapNav.open(path))")
        self.map = cmap
        self.source = None if source is None else Path(source)
        self.retrieval_config = retrieval or RetrievalConfig()
        self.planner_config = planner or PlannerConfig()
        self._embedder_spec = embedder
        self._embedder_path = embedder_path
        self._verifier_name = verifier
        self._embedder: TextEmbedder | None = embedder if isinstance(embedder, TextEmbedder) else None
        self._retriever: Retriever | None = None
        self._costmap: Costmap | None = None
        self._grid: tuple[OccupancyGrid, list[str]] | None = None
        self._frames: Any = None  # the frames a map was built from (for captioning views)
        self._without_voxels = False  # opened with voxels=False: save would lose them
        #: Per-object fields (goal fields, walk fields) that make asks from new robot positions
        #: lookups; False: every ask searches from the robot (the answers are the same).
        self.fields = fields

    # -- opening, building, saving ----------------------------------------------------------------
    @classmethod
    def open(cls, path: str | Path, *, voxels: bool = True, **kwargs: Any) -> CapNav:
        """Load a map file (``capnav map`` / ``save``); checks its format and checksums.

        ``voxels=False`` skips the dense voxel map, most of the file and of the load time (asking
        and planning never read it; 3D views and map pictures do): a robot process that opens a
        map to ask once starts in about half the time. Such a map cannot be saved over a full one."""
        from capnav.io.mapfile import load_map

        nav = cls(load_map(path, voxels=voxels), source=path, **kwargs)
        nav._without_voxels = not voxels
        return nav

    @classmethod
    def build(cls, frames: Iterable[Frame], detector: str = "sim", *, detector_options: dict[str, Any] | None = None,
              encoder: str = "label-embedding", embedder: str = "minilm", config: MapperConfig | None = None,
              progress: bool = False, meta: dict[str, Any] | None = None, **kwargs: Any) -> CapNav:
        """Map any iterable of posed RGB-D ``Frame``s with the named detector (``sim`` needs the
        simulator's instance images; ``owl`` runs on real images, see docs/perception.md).

        Captioning later needs the frames again to pick views: a reader (``len`` + ``frame(i)``, e.g.
        ``DatasetReader``) is kept as is; a one-pass iterable is kept in memory as it streams by."""
        from capnav.language import create_embedder
        from capnav.mapping.mapper import build_map
        from capnav.perception import create_detector, create_encoder

        opts = dict(detector_options or {})
        if detector == "sim":
            opts = {"noise": "default", "seed": 0, **opts}
        try:
            det = create_detector(detector, **opts)
        except TypeError as e:
            raise InputError(f"detector {detector!r} rejected its options {sorted(opts)}: {e}") from None
        emb = create_embedder(embedder)
        enc = create_encoder(encoder, embedder=emb)
        reader = frames if hasattr(frames, "frame") and hasattr(frames, "__len__") else None
        kept: list[Frame] = []

        def stream() -> Iterable[Frame]:
            for f in frames:
                if reader is None:
                    kept.append(f)
                yield f

        total = len(reader) if reader is not None else None  # type: ignore[arg-type]
        cmap = build_map(stream(), config, det, enc, progress=progress, total=total, meta=meta)
        nav = cls(cmap, **kwargs)
        nav._frames = reader if reader is not None else _FrameStore(kept)
        return nav

    @classmethod
    def simulate(cls, scene_seed: int, folder: str | Path, *, seed: int = 0, config: Any = None,
                 **kwargs: Any) -> CapNav:
        """The map of generated apartment ``scene_seed`` made by the product pipeline (explore, map,
        caption, embed; ``capnav.pipeline``), cached as ``folder/map.capnav``. ``config``: a
        ``PipelineConfig`` (image size, frames, detector noise, ...)."""
        from capnav.pipeline import PipelineConfig, open_sim_scene

        scene = open_sim_scene(scene_seed, seed, config or PipelineConfig(), Path(folder))
        try:
            cmap = scene.prior_map()
        finally:
            scene.sim.close()
        nav = cls(cmap, embedder=scene.embedder, source=Path(folder) / "map.capnav", **kwargs)
        nav._frames = scene.frames
        return nav

    def caption(self, frames: Any = None, captioner: str = "offline", embedder: str | TextEmbedder | None = None,
                *, progress: bool = False, **captioner_options: Any) -> DescribeReport:
        """Choose views, caption and embed every object (paper 3.3), in place. ``frames``: a reader
        with ``len`` and ``frame(i)`` (default: the frames the map was built from; None keeps the
        views the map already has). Captions are cached in the map, so a rerun is free."""
        from capnav.language import create_captioner, create_embedder, describe_map

        if embedder is None:
            emb = self._embedder or create_embedder("minilm")
        elif isinstance(embedder, TextEmbedder):
            emb = embedder
        else:
            emb = create_embedder(embedder)
        reader = frames if frames is not None else self._frames
        rep = describe_map(self.map, reader, create_captioner(captioner, **captioner_options), emb, progress=progress)
        self._embedder, self._retriever = emb, None
        return rep

    def save(self, path: str | Path) -> Path:
        """Write the map file atomically (captions and caches included)."""
        from capnav.io.mapfile import save_map

        if self._without_voxels:
            raise InputError(f"this map was opened with voxels=False ({self.source}); saving it would drop its "
                             "voxel map: open it with CapNav.open(path) to save")
        return save_map(self.map, path)

    # -- reading ------------------------------------------------------------------------------
    def objects(self) -> list[ObjectRecord]:
        return [ObjectRecord.of(o) for o in self.map.objects]

    def object(self, object_id: int) -> ObjectRecord:
        return ObjectRecord.of(self.map.object(object_id))

    def view_png(self, object_id: int) -> bytes | None:
        """The chosen captioning view of an object (full frame with its box), or None."""
        for v in self.map.object(object_id).views:
            if v.frame_png:
                return v.frame_png
        return None

    # -- asking and planning ------------------------------------------------------------------
    @property
    def embedder(self) -> TextEmbedder:
        if self._embedder is None:
            self._embedder = _embedder_for(self.map, self._embedder_spec, self._embedder_path)
        return self._embedder

    @property
    def retriever(self) -> Retriever:
        if self._retriever is None:
            from capnav.retrieval import create_verifier

            r = Retriever(self.map, self.embedder, create_verifier(self._verifier_name), self.retrieval_config)
            if not self.fields:
                r.field_bytes = 0
            self._retriever = r
        return self._retriever

    @property
    def occupancy(self) -> OccupancyGrid:
        """The grid goals and paths are planned on: the map's occupancy with the unknown cells
        within ``PATH_FREE_RADIUS`` of the camera path counted as free (``planning_grid``)."""
        if self._grid is None:
            from capnav.planning.on_map import planning_grid

            self._grid = planning_grid(self.map)
        return self._grid[0]

    @property
    def costmap(self) -> Costmap:
        if self._costmap is None:
            from capnav.planning.costmap import build_costmap
            from capnav.planning.sight import map_columns

            self._costmap = build_costmap(self.occupancy, self.planner_config, map_columns(self.map))
            if not self.fields:
                self._costmap.cache["no_fields"] = True
        return self._costmap

    def prepare(self, stop: Any = None) -> str:
        """Make every object's goal field and walk field ahead of the asks (a server does it on a
        thread of its own once a map is loaded; the kernels release the GIL): afterwards an ask
        from a robot position no ask used before costs a short search and lookups instead of
        searches from the robot. Without it fields are made as objects are asked (on the second
        ask). ``stop`` (a ``threading.Event``): stop early when set. Says what was made."""
        from capnav.planning.goal import prepare_goal
        from capnav.planning.sight import object_heights

        if not self.fields or not self.map.objects:
            return "no fields"
        goals = walks = 0
        floor = self.retriever.floor_distances()
        for i, obj in enumerate(self.map.objects):
            if stop is not None and stop.is_set():
                break
            try:
                goals += prepare_goal(self.occupancy, obj.footprint, self.costmap, self.planner_config,
                                      z_range=object_heights(obj))
            except (NotFoundError, InputError):
                pass
            if floor is not None:
                walks += floor.field(i) is not None
        held = sum(0 if f is None else f.nbytes for f in list(self.costmap.cache.get("goal_field", {}).values()))
        held += 0 if floor is None else floor.held
        return (f"goal fields for {goals}, walk fields for {walks} of {len(self.map.objects)} objects, "
                f"{held / 2**20:.0f} MB")

    def start_pose(self) -> tuple[tuple[float, float, float], str]:
        """The default start, as ``capnav navigate`` takes it: the map's last camera pose (x, y, yaw)
        and where it came from; ``InputError`` for a map that records no camera path."""
        from capnav.planning.on_map import camera_start

        if self.map.trajectory is None or not len(self.map.trajectory):
            raise InputError("this map records no camera path (built before CapNav stored it, or from no frame): "
                             "give a start x, y[, yaw]")
        return camera_start(self.map.trajectory)

    def ask(self, instruction: str, robot: Sequence[float] | None = None, k: int | None = None) -> Answer:
        """Retrieve the object ``instruction`` describes. ``robot`` (x, y[, yaw]) in metres gives
        "closest" its meaning and a goal pose to stop at; ``k`` caps the runners-up. A request of
        several goals ("the fridge, then the sofa") returns the first goal's answer with every
        goal's in ``goals`` (each asked from where the one before leaves the robot); the first
        goal not found ends them, with the reason in ``stopped``."""
        xy = _xy(robot, "robot")
        if k is not None and not 0 <= int(k) <= 50:
            raise InputError(f"k must be between 0 and 50, got {k}")
        from capnav.retrieval.query import prefetch_parser, validate_instruction
        from capnav.retrieval.sequence import query_goals

        prefetch_parser(validate_instruction(instruction))  # while the embedder's session is built
        seq = query_goals(self.retriever, instruction, robot_xy=xy)
        answers: list[Answer] = []
        for res in seq.results:
            answers.append(self._answer(res, xy, k))
            # The next goal is asked from where this one leaves the robot: its goal pose, else the object.
            last = answers[-1]
            if last.goal is not None:
                xy = (float(last.goal.xy[0]), float(last.goal.xy[1]))
            elif res.chosen is not None:
                xy = (float(res.chosen.position[0]), float(res.chosen.position[1]))
        if len(seq.goals) == 1:
            return answers[0]
        return replace(answers[0], goals=tuple(answers), stopped=seq.stopped)

    def _answer(self, res: QueryResult, xy: tuple[float, float] | None, k: int | None) -> Answer:
        goal, note = None, ""
        if res.chosen is None:
            note = "no object chosen"
        elif xy is None:
            note = "no robot position given"
        else:
            goal, note = self._goal(res.chosen, xy)
        runners = res.ranked if k is None else res.ranked[: int(k)]
        return Answer(res.instruction, ObjectRecord.of(res.chosen) if res.chosen is not None else None, res.score,
                      res.reason, tuple((ObjectRecord.of(o), float(s)) for o, s in runners), goal, xy, res, note)

    def _goal(self, obj: MapObject, xy: tuple[float, float]) -> tuple[GoalPose | None, str]:
        """The goal pose, or None and why (the answer stands even when the robot cannot plan)."""
        from capnav.planning.goal import select_goal
        from capnav.planning.sight import object_heights

        try:
            return select_goal(self.occupancy, obj.footprint, xy, self.planner_config, self.costmap,
                               z_range=object_heights(obj)), ""
        except (NotFoundError, InputError) as e:
            return None, f"no goal pose: {e}"

    def plan(self, start: Sequence[float] | None, target: Answer | ObjectRecord | int) -> Plan:
        """A* from ``start`` (x, y[, yaw]; None: the map's last camera pose, see ``start_pose``) to a
        goal pose within reach of the target object (an ``Answer``, an ``ObjectRecord`` or an
        object id)."""
        from capnav.planning.goal import select_goal
        from capnav.planning.path import plan_path

        if start is None:
            start = self.start_pose()[0]
        xy = _xy(start, "start")
        assert xy is not None
        s = np.asarray(start, dtype=np.float64).ravel()
        yaw0 = float(s[2]) if len(s) > 2 and math.isfinite(float(s[2])) else 0.0
        if isinstance(target, Answer):
            if target.object is None:
                return Plan(False, np.array([[*xy, yaw0]]), 0.0, f"nothing to plan to: {target.reason}")
            oid = target.object.id
        else:
            oid = target.id if isinstance(target, ObjectRecord) else int(target)
        obj = self.map.object(oid)
        try:
            goal = target.goal if isinstance(target, Answer) and target.robot == xy else None
            if goal is None:  # an answer asked from this start already holds its goal: one search less
                from capnav.planning.sight import object_heights

                goal = select_goal(self.occupancy, obj.footprint, xy, self.planner_config, self.costmap,
                                   z_range=object_heights(obj))
            path = plan_path(self.occupancy, xy, goal.xy, self.planner_config, self.costmap)
        except NotFoundError as e:
            return Plan(False, np.array([[*xy, yaw0]]), 0.0, str(e), None, oid)
        poses = _headings(path.waypoints, yaw0, goal.yaw)
        why = f"A* path of {path.length_m:.2f} m to {goal.reason}"
        if path.notes:
            why += f" ({'; '.join(path.notes)})"
        return Plan(goal.reached_within_reach, poses, path.length_m, why, goal, oid)

    def __repr__(self) -> str:
        where = f" from {self.source}" if self.source else ""
        return f"CapNav({self.map!r}{where})"


class _FrameStore:
    """Frames kept from a one-pass stream, looked up by their own index (views need them)."""

    def __init__(self, frames: list[Frame]) -> None:
        self._by_index = {f.index: f for f in frames}
        self._n = max(self._by_index, default=-1) + 1

    def __len__(self) -> int:
        return self._n

    def frame(self, index: int) -> Frame:
        try:
            return self._by_index[index]
        except KeyError:
            raise InputError(f"frame {index} was not in the stream the map was built from") from None


def _embedder_for(cmap: CapNavMap, spec: str | TextEmbedder, path: str | Path | None) -> TextEmbedder:
    """The embedder a map must be queried with: its own model for ``auto``."""
    from capnav.language import create_embedder
    from capnav.language.onnx_embedder import MINILM_MODEL_ID

    if isinstance(spec, TextEmbedder):
        return spec
    if spec != "auto":
        return create_embedder(spec, **({"path": path} if path is not None else {}))
    models = {o.embedding_model for o in cmap.objects if o.embedding_model}
    if not models:
        raise InputError("the map has no captions/embeddings: caption it first (`CapNav.caption` or "
                         "`capnav caption MAP --dataset DIR`)")
    if models != {MINILM_MODEL_ID}:
        raise InputError(f"the map was embedded with {sorted(models)}; pass embedder= and embedder_path= for it")
    return create_embedder("minilm")
