"""Benchmark generation: episodes of 4 subgoals from an apartment's ground truth.

Start poses are random navigable cells; subgoals are drawn from the categories present (label-only
protocol) or from instances that have lookalikes of their category (description protocol), and
must be reachable. The first goal must not already be reached at the start, so no subgoal is won
by standing still. Only the episode *content* is seeded here; the texts of description goals come
from the instruction generator (``capnav.sim.instructions``) through a ``Describe`` callable.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import DatasetError, InputError
from capnav.core.footprint import footprint_distance
from capnav.core.grid import GridSpec
from capnav.eval.episodes import Episode, StartPose, Subgoal
from capnav.sim.geodesic import DistanceField, distance_field, field_to, region_mask
from capnav.sim.sightline import SightGrid
from capnav.sim.success import SUCCESS_RADIUS_M, room_index


@dataclass(frozen=True)
class EpisodeConfig:
    """Episode generation settings; the defaults follow the paper (4 subgoals in sequence)."""

    episodes_per_scene: int = 9
    subgoals: int = 4
    success_radius: float = SUCCESS_RADIUS_M
    min_start_distance: float = 1.0  # geodesic metres from the start to the first goal's success region
    max_tries: int = 500

    def __post_init__(self) -> None:
        if self.episodes_per_scene < 1 or self.subgoals < 1:
            raise InputError(f"need >= 1 episode and subgoal, got {self.episodes_per_scene}, {self.subgoals}")


@dataclass
class SceneTruth:
    """Ground truth the harness scores against: instances (id -> category, footprint) and the
    navigable grid, with distance fields to success regions cached per goal."""

    scene_seed: int
    categories: dict[int, str]  # instance id -> category
    footprints: dict[int, NDArray[np.float64]]  # instance id -> (K, 2)
    spec: GridSpec
    navigable: NDArray[np.bool_]
    radius: float = SUCCESS_RADIUS_M
    sight: SightGrid | None = None  # walls and tall objects, for the strict (line-of-sight) success rule
    starts: NDArray[np.bool_] | None = None  # where a start may be drawn (default: every navigable cell)
    rooms: list[NDArray[np.float64]] | None = None  # room polygons, for the "in the object's room" rule
    _fields: dict[tuple[int | str, ...], DistanceField] = field(default_factory=dict, repr=False)

    @classmethod
    def from_manifest(cls, manifest: object, spec: GridSpec, navigable: NDArray[np.bool_],
                      radius: float = SUCCESS_RADIUS_M, sight: SightGrid | None = None,
                      starts: NDArray[np.bool_] | None = None) -> SceneTruth:
        objs = manifest.objects  # type: ignore[attr-defined]
        return cls(int(manifest.seed), {o.id: o.category for o in objs},  # type: ignore[attr-defined]
                   {o.id: np.asarray(o.footprint, dtype=np.float64) for o in objs}, spec,
                   np.asarray(navigable, dtype=bool), radius, sight,
                   None if starts is None else np.asarray(starts, dtype=bool),
                   rooms=[np.asarray(r.polygon, dtype=np.float64) for r in getattr(manifest, "rooms", [])] or None)

    def sees_goal(self, xy: tuple[float, float], target_ids: Sequence[int]) -> bool | None:
        """Strict success's second half: is one of the goal instances within ``radius`` AND in sight
        of ``xy``? None when this truth has no sight grid."""
        if self.sight is None:
            return None
        for t in target_ids:
            fp = self.footprints[t]
            if footprint_distance(np.asarray(xy, dtype=np.float64).reshape(1, 2), fp)[0] <= self.radius \
                    and self.sight.sees(xy, fp, own_ids=(t,)):
                return True
        return False

    def room_of(self, xy: Sequence[float] | NDArray[np.floating]) -> int:
        """Index of the room polygon holding ``xy`` (-1 outside every room or without rooms)."""
        return room_index(xy, self.rooms or [])

    def in_goal_room(self, xy: tuple[float, float], target_ids: Sequence[int]) -> bool | None:
        """The strict rule with the room: a goal instance within ``radius``, in sight, and in the
        room the stop point is in (None without sight grid or rooms)."""
        if self.sight is None or not self.rooms:
            return None
        here = self.room_of(xy)
        for t in target_ids:
            fp = self.footprints[t]
            if here >= 0 and self.room_of(fp.mean(axis=0)) == here \
                    and footprint_distance(np.asarray(xy, dtype=np.float64).reshape(1, 2), fp)[0] <= self.radius \
                    and self.sight.sees(xy, fp, own_ids=(t,)):
                return True
        return False

    def instances_of(self, category: str) -> list[int]:
        return sorted(i for i, c in self.categories.items() if c == category)

    def field(self, target_ids: Sequence[int]) -> DistanceField:
        key = tuple(sorted(target_ids))
        if key not in self._fields:
            missing = [t for t in key if t not in self.footprints]
            if missing:
                raise DatasetError(f"instances {missing} are not in scene {self.scene_seed}")
            self._fields[key] = distance_field(self.spec, self.navigable, [self.footprints[t] for t in key],
                                               self.radius)
        return self._fields[key]

    def view_field(self, target_ids: Sequence[int]) -> DistanceField | None:
        """Geodesic distance to the goal's viewpoints: navigable cells within ``radius`` of a goal
        instance from which it is in sight (Habitat ObjectNav's success region, whose nearest
        viewpoint also gives that benchmark's shortest path; Batra et al. 2020). None without a
        sight grid. A cell within the radius but behind a wall is no viewpoint."""
        if self.sight is None:
            return None
        key: tuple[int | str, ...] = ("view", *sorted(target_ids))
        if key not in self._fields:
            region = np.zeros_like(self.navigable)
            for t in sorted(set(target_ids)):
                near = region_mask(self.spec, self.navigable, [self.footprints[t]], self.radius)
                for r, c in np.argwhere(near):
                    if self.sight.sees(tuple(self.spec.to_world(np.array([r, c]))), self.footprints[t], own_ids=(t,)):
                        region[r, c] = True
            self._fields[key] = field_to(self.spec, self.navigable, region)
        return self._fields[key]

    def sample_start(self, rng: np.random.Generator) -> StartPose:
        cells = np.argwhere(self.navigable if self.starts is None or not self.starts.any() else self.starts)
        if len(cells) == 0:
            raise DatasetError(f"scene {self.scene_seed} has no navigable cell")
        rc = cells[int(rng.integers(len(cells)))]
        x, y = self.spec.to_world(rc)
        return StartPose(x=float(x), y=float(y), yaw=float(rng.uniform(-np.pi, np.pi)))


#: ``describe(instance_id, robot_xy or None, rng) -> (text, kind)`` for one description goal;
#: ``robot_xy`` is given only for the first subgoal (where "closest" is well defined).
Describe = Callable[[int, tuple[float, float] | None, np.random.Generator], tuple[str, str]]


def _draw_sequence(pool: list[str], n: int, rng: np.random.Generator) -> list[str]:
    """n items from ``pool`` without repetition when possible, never the same twice in a row."""
    if len(pool) >= n:
        return [pool[i] for i in rng.permutation(len(pool))[:n]]
    out: list[str] = []
    for _ in range(n):
        choices = [p for p in pool if not out or p != out[-1]] or pool
        out.append(choices[int(rng.integers(len(choices)))])
    return out


def _valid_chain(truth: SceneTruth, start: StartPose, goals: list[list[int]], cfg: EpisodeConfig) -> bool:
    """Every goal reachable from the start; the first one not already reached there."""
    first = truth.field(goals[0]).at((start.x, start.y))
    if not np.isfinite(first) or first < cfg.min_start_distance:
        return False
    return all(np.isfinite(truth.field(g).at((start.x, start.y))) for g in goals[1:])


def label_episodes(truth: SceneTruth, rng: np.random.Generator, cfg: EpisodeConfig | None = None,
                   id_prefix: str = "") -> list[Episode]:
    """Label-only episodes: the goal text is the category name; any instance of it succeeds."""
    cfg = cfg or EpisodeConfig()
    present = sorted(set(truth.categories.values()))
    if not present:
        raise DatasetError(f"scene {truth.scene_seed} has no objects to navigate to")
    episodes: list[Episode] = []
    for k in range(cfg.episodes_per_scene):
        for _ in range(cfg.max_tries):
            cats = _draw_sequence(present, cfg.subgoals, rng)
            goals = [truth.instances_of(c) for c in cats]
            start = truth.sample_start(rng)
            if _valid_chain(truth, start, goals, cfg):
                break
        else:
            raise DatasetError(f"scene {truth.scene_seed}: no valid label episode in {cfg.max_tries} tries")
        episodes.append(Episode(
            id=f"{id_prefix}s{truth.scene_seed}-label-{k}", scene_seed=truth.scene_seed, start=start,
            subgoals=[Subgoal(text=c, category=c, target_ids=g, kind="category") for c, g in zip(cats, goals,
                                                                                               strict=True)]))
    return episodes


def description_targets(truth: SceneTruth) -> list[int]:
    """Instances worth describing: those of a category with at least two instances (lookalikes);
    every instance if the apartment has no such category."""
    counts: dict[str, int] = {}
    for c in truth.categories.values():
        counts[c] = counts.get(c, 0) + 1
    multi = sorted(i for i, c in truth.categories.items() if counts[c] >= 2)
    return multi or sorted(truth.categories)


def description_episodes(truth: SceneTruth, describe: Describe, rng: np.random.Generator,
                         cfg: EpisodeConfig | None = None, id_prefix: str = "") -> list[Episode]:
    """Description episodes: one described instance per subgoal, preferring instances with lookalikes;
    no instance twice in an episode and no category twice in a row. An instance that the describer
    can only name by its bare category (nothing singles it out) is skipped: under this protocol
    only the described instance counts, so its text must identify it."""
    cfg = cfg or EpisodeConfig()
    pool = description_targets(truth)
    if not pool:
        raise DatasetError(f"scene {truth.scene_seed} has no objects to describe")
    lookalikes = {c for c in truth.categories.values() if len(truth.instances_of(c)) >= 2}
    episodes: list[Episode] = []
    for k in range(cfg.episodes_per_scene):
        for _ in range(cfg.max_tries):
            start = truth.sample_start(rng)
            goals: list[tuple[int, str, str]] = []  # (instance, text, kind)
            for j in range(cfg.subgoals):
                ids = [g[0] for g in goals]
                choices = [i for i in pool if i not in ids
                           and (not ids or truth.categories[i] != truth.categories[ids[-1]])] or pool
                for i in (choices[int(c)] for c in rng.permutation(len(choices))):
                    text, kind = describe(i, (start.x, start.y) if j == 0 else None, rng)
                    if kind != "category" or truth.categories[i] not in lookalikes:
                        goals.append((i, text, kind))
                        break
                else:
                    break  # nothing describable left for this slot: draw another episode
            if len(goals) == cfg.subgoals and _valid_chain(truth, start, [[g[0]] for g in goals], cfg):
                break
        else:
            raise DatasetError(f"scene {truth.scene_seed}: no valid description episode in {cfg.max_tries} tries")
        episodes.append(Episode(
            id=f"{id_prefix}s{truth.scene_seed}-desc-{k}", scene_seed=truth.scene_seed, start=start,
            subgoals=[Subgoal(text=t, category=truth.categories[i], target_ids=[i], kind=kd) for i, t, kd in goals]))
    return episodes
