"""The benchmark track for change: map visit 1, update with visit 2, navigate in visit 2's home.

Per apartment: both visits are recorded (``capnav sim --visit``), visit 1 is mapped and captioned,
then three maps answer the same one-subgoal episodes in the visit-2 world:

* ``capnav``: visit 1's map updated with visit 2 (``capnav map --update``, then captioned);
* ``capnav-static``: visit 1's map as it was;
* ``capnav-remap``: visit 2 mapped from scratch;
* ``capnav-search``: visit 1's map with ``navigate --search``, on the objects the first map does not
  hold where they are (``moved`` and ``added``): success = reached within 1 m with a driven length
  of at most ``SEARCH_BUDGET`` times the direct path to the object (the walk from the start to its
  nearest viewpoint, a cell within 1 m with the object in sight, plus that metre; the harness judges
  the length, the search is not told it);
* ``capnav-update-search``: the updated map with ``navigate --search``, on the objects carried into
  a room visit 2 never entered (``hidden``, with ``--changes ...,hidden=N``): the update saw their
  old place empty and nothing of their new one, so only a search finds them (same success rule).

Goals are written from the truth the user holds, per change class (protocol ``description/<class>``):
``moved`` (described as at visit 2; success = reached at its new place), ``removed`` (described as at
visit 1; success = "not found"), ``added`` and ``unchanged`` (success = reached), ``hidden``
(described as at visit 2, where no frame of visit 2 shows it; success = reached). Each description
names its object alone in the home it describes (never a bare kind shared by several). Only the harness
reads the manifests; the maps see frames. The update's CPU time (detection included) is measured
beside mapping visit 2 from scratch on the same frames.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from capnav.core.atomic import write_json
from capnav.core.errors import InputError
from capnav.core.grid import FREE
from capnav.eval.episode_runner import run_episode
from capnav.eval.episodes import Episode, Subgoal
from capnav.eval.generate import SceneTruth
from capnav.eval.method import SceneContext, create_method
from capnav.eval.metrics import SubgoalRecord, summarize_all
from capnav.sim.changes import ChangeSpec
from capnav.sim.success import SUCCESS_RADIUS_M

CLASSES = ("moved", "removed", "added", "unchanged", "hidden")
METHODS = ("capnav", "capnav-static", "capnav-remap", "capnav-search", "capnav-update-search")
#: The change classes each method runs on (the others: every class). ``capnav-search``: objects not in
#: the first map where they are now; ``capnav-update-search``: objects out of everything visit 2 saw.
SEARCH_CLASSES = {"capnav-search": ("moved", "added"), "capnav-update-search": ("hidden",)}
#: Driven length allowed to a search, in direct paths from the start to the object.
SEARCH_BUDGET = 3.0


@dataclass(frozen=True)
class ChangeTrackConfig:
    """``per_class``: subgoals per change class and apartment (objects are described again, from
    other starts, when a class has fewer objects); camera ``width`` x ``height``."""

    scenes: int = 3
    seed: int = 0
    changes: ChangeSpec = field(default_factory=lambda: ChangeSpec(moved=3, removed=2, added=2))
    per_class: int = 8
    width: int = 160
    height: int = 120
    rooms: int | None = None
    noise: str = "default"
    reuse_maps: bool = False  # load the maps an earlier run saved in the same folder (no CPU figures then)
    methods: tuple[str, ...] = METHODS  # the methods to run (one alone, again on the saved maps: ``reuse_maps``)

    def __post_init__(self) -> None:
        unknown = [m for m in self.methods if m not in METHODS]
        if unknown or not self.methods:
            raise InputError(f"the change track runs {', '.join(METHODS)}; got {', '.join(unknown) or 'none'}")

    def scene_seeds(self) -> list[int]:
        return [1000 * self.seed + i for i in range(self.scenes)]


def _record(scene: int, cfg: ChangeTrackConfig, folder: Path) -> tuple[Path, Path]:
    from capnav.sim.record import record_dataset

    v1, v2 = folder / "visit1", folder / "visit2"
    for path, visit in ((v1, 1), (v2, 2)):
        if not (path / "meta.json").is_file():
            record_dataset(scene, path, width=cfg.width, height=cfg.height, rooms=cfg.rooms, progress=False,
                           visit=visit, changes=cfg.changes if visit > 1 else None, change_seed=cfg.seed,
                           overwrite=path.exists())
    return v1, v2


def _episodes(scene: int, cfg: ChangeTrackConfig, m1: Any, m2: Any, truth: SceneTruth,
              counts: dict[str, int] | None = None) -> dict[str, list[Episode]]:
    """Per change class, ``cfg.per_class`` one-subgoal episodes. A removed object is described as
    at visit 1, and the description must fit nothing present at visit 2 either (a newcomer of the
    same make in another room also fits "the purple lounge chair": "not found" would be ill-posed):
    it must single the object out in both visits' homes together (``_both_homes``). One that does
    not is described again from those (another rng, so the other episodes stay as they were) or
    dropped; ``counts`` (when given) receives ``removed_ill_posed``, ``removed_redescribed`` and
    ``removed_dropped``."""
    from capnav.sim.instructions import InstructionGenerator

    rng = np.random.default_rng([cfg.seed, scene, 0xC4A6])
    gen1, gen2 = InstructionGenerator(m1), InstructionGenerator(m2)
    both = _both_homes(m1, m2)
    gen_both = InstructionGenerator(both)
    tally = {"removed_ill_posed": 0, "removed_redescribed": 0, "removed_dropped": 0}
    changed = {c.id: c.kind for c in m2.changes}
    pools = {cls: [i for i, k in changed.items() if k == cls] for cls in CLASSES if cls != "unchanged"}
    pools["unchanged"] = sorted(o.id for o in m2.objects if o.id not in changed)
    out: dict[str, list[Episode]] = {}
    for cls, pool in pools.items():
        eps: list[Episode] = []
        if cls == "unchanged":
            pool = [pool[int(i)] for i in rng.permutation(len(pool))]
        man = m1 if cls == "removed" else m2
        gen = gen1 if cls == "removed" else gen2
        tried = 0
        while pool and len(eps) < cfg.per_class and tried < 4 * cfg.per_class:
            i = pool[tried % len(pool)]
            tried += 1
            start = truth.sample_start(rng)
            said = _single_out(gen, man, i, None if cls == "removed" else (start.x, start.y), rng)
            if said is not None and cls == "removed" and not gen_both.singles_out(said):
                tally["removed_ill_posed"] += 1
                again = np.random.default_rng([cfg.seed, scene, 0xC4A7, tried])
                said = _single_out(gen_both, both, i, None, again)
                tally["removed_redescribed" if said is not None else "removed_dropped"] += 1
            if said is None:
                continue
            text, kind = said.text, said.kind
            cat = next(o.category for o in man.objects if o.id == i)
            eps.append(Episode(id=f"s{scene}-{cls}-{len(eps)}", scene_seed=scene, start=start,
                               subgoals=[Subgoal(text=text, category=cat, kind=kind,
                                                 target_ids=[] if cls == "removed" else [i])]))
        out[cls] = eps
    if counts is not None:
        counts.update(tally)
    return out


def _both_homes(m1: Any, m2: Any) -> Any:
    """Visit 1's home with every object visit 2 holds elsewhere or anew beside it (a moved one at
    both places, its second place under a fresh id): a description that singles an object out here
    fits nothing either visit shows in its stead."""
    old = {o.id: o for o in m1.objects}
    extra = [o for o in m2.objects if o.id not in old or o.footprint != old[o.id].footprint]
    top = max([o.id for o in m1.objects] + [o.id for o in m2.objects], default=0)
    extra = [o if o.id not in old else o.model_copy(update={"id": top + 1 + k}) for k, o in enumerate(extra)]
    return m1.model_copy(update={"objects": [*m1.objects, *extra]})


def _single_out(gen: Any, man: Any, i: int, start_xy: tuple[float, float] | None, rng: np.random.Generator,
                tries: int = 8) -> Any:
    """A description of object ``i`` that names it alone in ``man``'s home: the generator falls back
    to the bare kind ("the chair") when nothing else singles an object out, and with other chairs
    about that names any of them, which scores nothing about the change (a removed chair's "the
    chair" is rightly answered by a remaining one). None when no draw singles it out."""
    cat = next(o.category for o in man.objects if o.id == i)
    unique = sum(o.category == cat for o in man.objects) == 1
    for _ in range(tries):
        ins = gen.describe_instruction(i, start_xy, rng)
        if ins.kind != "category" or unique:
            return ins
    return None


def _make_maps(cfg: ChangeTrackConfig, folder: Path, r1: Any, r2: Any, detector: Any, enc: Any, emb: Any, cap: Any,
               timings: dict[str, float], progress: bool) -> tuple[Any, Any, Any, dict[str, Any]]:
    """Visit 1 mapped and captioned, updated with visit 2, and visit 2 mapped alone; each saved, its
    CPU seconds in ``timings``."""
    from capnav.io.mapfile import save_map
    from capnav.language import describe_map
    from capnav.mapping import map_dataset
    from capnav.mapping.update import register_recording, update_map

    t = time.process_time()
    m1 = map_dataset(r1, detector(), enc, progress=progress)
    timings["map_visit1_cpu_s"] = time.process_time() - t
    describe_map(m1, r1, cap, emb, progress=progress)
    save_map(m1, folder / "visit1.capnav")
    t = time.process_time()
    reg = register_recording(m1, r2, f"{r2.path} to visit 1's map", icp=False)  # same world frame in the simulator
    mu, rep = update_map(m1, r2, detector(), enc, transform=reg.T, progress=progress, registration=reg)
    timings["update_cpu_s"] = time.process_time() - t
    t = time.process_time()
    describe_map(mu, r2, cap, emb, progress=progress)
    timings["update_caption_cpu_s"] = time.process_time() - t
    save_map(mu, folder / "updated.capnav")
    t = time.process_time()
    mr = map_dataset(r2, detector(), enc, progress=progress)
    timings["remap_visit2_cpu_s"] = time.process_time() - t
    t = time.process_time()
    describe_map(mr, r2, cap, emb, progress=progress)
    timings["remap_caption_cpu_s"] = time.process_time() - t
    save_map(mr, folder / "remapped.capnav")
    return m1, mu, mr, rep.to_dict()


def run_change_scene(scene: int, cfg: ChangeTrackConfig, out: Path, progress: bool = False) -> dict[str, Any]:
    """One apartment of the track: records (per subgoal) and the update's cost figures."""
    from capnav.io.dataset import DatasetReader
    from capnav.language import create_captioner, create_embedder
    from capnav.perception import create_detector, create_encoder
    from capnav.sim import Simulator
    from capnav.sim.config import CameraConfig, LayoutConfig, SimConfig
    from capnav.sim.manifest import SceneManifest
    from capnav.sim.sightline import sight_grid

    folder = out / "scenes" / str(scene)
    v1, v2 = _record(scene, cfg, folder)
    emb = create_embedder("minilm")
    cap = create_captioner("offline")

    def detector() -> Any:  # a fresh one per map: the same noise stream for each
        return create_detector("sim", noise=cfg.noise, seed=cfg.seed)

    enc = create_encoder("label-embedding", embedder=emb)
    r1, r2 = DatasetReader(v1), DatasetReader(v2)
    timings: dict[str, float] = {}
    saved = [folder / n for n in ("visit1.capnav", "updated.capnav", "remapped.capnav")]
    if cfg.reuse_maps and all(p.is_file() for p in saved):
        from capnav.io.mapfile import load_map

        m1, mu, mr = (load_map(p) for p in saved)
        update_report: dict[str, Any] = {"reused": [str(p) for p in saved]}
    else:
        m1, mu, mr, update_report = _make_maps(cfg, folder, r1, r2, detector, enc, emb, cap, timings, progress)

    man1 = SceneManifest.load(v1 / "manifest.json")
    man2 = SceneManifest.load(v2 / "manifest.json")
    simcfg = SimConfig(camera=CameraConfig(width=cfg.width, height=cfg.height),
                       layout=LayoutConfig(rooms=cfg.rooms) if cfg.rooms is not None else LayoutConfig())
    records: list[SubgoalRecord] = []
    with Simulator.from_seed(scene, simcfg, visit=2, changes=cfg.changes, change_seed=cfg.seed) as sim:
        nav = sim.navigable()
        truth = SceneTruth.from_manifest(sim.manifest, nav.spec, nav.cells == FREE,
                                         sight=sight_grid(sim.apartment, nav.spec))
        counts: dict[str, int] = {}
        episodes = _episodes(scene, cfg, man1, man2, truth, counts)
        for name, cmap, frames in (("capnav", mu, r2), ("capnav-static", m1, r1), ("capnav-remap", mr, r2),
                                   ("capnav-search", m1, r1), ("capnav-update-search", mu, r2)):
            classes = SEARCH_CLASSES.get(name, CLASSES)
            if name not in cfg.methods or not any(episodes.get(c) for c in classes):
                continue
            method = create_method("capnav-search" if name in SEARCH_CLASSES else "capnav")
            ctx = SceneContext(scene_seed=scene, seed=cfg.seed, sim=sim, embedder=emb, detector=detector(),
                               prior_map=cmap, occupancy=cmap.occupancy, frames=frames, workdir=folder / name)
            for cls, eps in episodes.items():
                if cls not in classes:
                    continue
                for ep in eps:
                    for r in run_episode(method, ctx, ep, truth, f"description/{cls}"):
                        r.method = name
                        if name in SEARCH_CLASSES:
                            _within_budget(r, truth)
                        records.append(r)
                        write_json(out / "logs" / name / cls / f"{ep.id}.json",
                                   {"episode": ep.model_dump(), "subgoal": r.to_dict()})
    return {"scene_seed": scene, "records": [r.to_dict() for r in records], "timings": timings, "episodes": counts,
            "update": update_report, "objects": {"visit1": len(m1.objects), "updated": len(mu.objects),
                                                 "retired": len(mu.retired), "remapped": len(mr.objects)}}


def _within_budget(r: SubgoalRecord, truth: SceneTruth) -> None:
    """A search succeeds only when it reached the object within ``SEARCH_BUDGET`` direct paths: the
    walk to the object's nearest viewpoint (a cell within the success radius from which it is in
    sight: Habitat ObjectNav's shortest path, Batra et al. 2020; a cell within 1 m behind a wall is
    no way to see it) plus ``radius`` (a start already within reach still has a metre to go)."""
    view = truth.view_field(r.target_ids)
    to_view = view.at(r.start_xy) if view is not None else math.inf
    r.view_path = to_view if math.isfinite(to_view) else r.shortest_path
    direct = r.view_path + truth.radius
    limit = SEARCH_BUDGET * direct
    if r.success and not r.path_length <= limit:
        r.success = False
        r.success_strict = False if r.success_strict is not None else None
        r.success_room = False if r.success_room is not None else None
        r.reason = f"reached, but drove {r.path_length:.1f} m, over {SEARCH_BUDGET:g}x the {direct:.1f} m " \
                   f"direct path ({limit:.1f} m); {r.reason}"


def run_change_track(cfg: ChangeTrackConfig, out: Path, progress: bool = True) -> dict[str, Any]:
    """Every apartment of the track; writes ``out/results.json`` and returns it."""
    from capnav.core.progress import track

    scenes = [run_change_scene(s, cfg, out) for s in track(cfg.scene_seeds(), "change track", enabled=progress)]
    recs = [SubgoalRecord.from_dict(r) for s in scenes for r in s["records"]]
    summaries = [s.to_dict() for s in summarize_all(recs)]
    cpu = {k: round(sum(s["timings"][k] for s in scenes), 3) for k in scenes[0]["timings"]} if scenes else {}
    if cfg.reuse_maps:
        cpu = {}  # maps loaded, not made: the CPU figures are the earlier run's
    search = _search_figures([r for r in recs if r.method == "capnav-search"])
    hidden = [r for r in recs if r.method == "capnav-update-search"]
    results = {"track": "change", "changes": str(cfg.changes), "seed": cfg.seed, "scenes": cfg.scene_seeds(),
               "camera": [cfg.width, cfg.height], "detector": f"sim:{cfg.noise}", "summaries": summaries,
               "search": search, **({"update_search": _search_figures(hidden)} if hidden else {}),
               "cpu_seconds": cpu,
               # removed-class descriptions that a visit-2 object also fits: described again or dropped
               "episodes": {k: sum(s.get("episodes", {}).get(k, 0) for s in scenes)
                            for k in ("removed_ill_posed", "removed_redescribed", "removed_dropped")},
               "per_scene": [{k: v for k, v in s.items() if k != "records"} for s in scenes]}
    write_json(out / "results.json", results)
    return results


def _search_figures(searched: list[SubgoalRecord]) -> dict[str, Any]:
    """How many searches reached their object within the budget, and at any length."""
    reached = [r for r in searched if r.success or r.reason.startswith("reached, but drove")]
    return {"subgoals": len(searched), "budget": f"{SEARCH_BUDGET:g}x the walk to the nearest viewpoint",
            "within_budget": sum(r.success for r in searched),
            # the older, stricter budget: 3x the walk to the 1 m region, which may reach through a wall
            "within_budget_of_region": sum(r.path_length <= SEARCH_BUDGET * (r.shortest_path + SUCCESS_RADIUS_M)
                                           for r in reached),
            "reached_any_length": len(reached),
            "driven_over_direct": [round(r.path_length / ((r.view_path if r.view_path is not None
                                                           else r.shortest_path) + SUCCESS_RADIUS_M), 3)
                                   for r in searched if r.success]}


def table(results: dict[str, Any]) -> str:
    """Success per method and change class, as a markdown table, with the CPU figures."""
    by = {(s["method"], s["protocol"].split("/")[-1]): s for s in results["summaries"]}
    lines = ["| method | " + " | ".join(CLASSES) + " |", "|---|" + "---|" * len(CLASSES)]
    for m in METHODS:
        cells = []
        for c in CLASSES:
            s = by.get((m, c))
            cells.append("-" if s is None else f"{100 * s['independent']:.1f} ({s['subgoals']})")
        lines.append(f"| {m} | " + " | ".join(cells) + " |")
    for key, name in (("search", "capnav-search"), ("update_search", "capnav-update-search")):
        srch = results.get(key) or {}
        if srch.get("subgoals"):
            lines.append("")
            lines.append(f"{name} ({', '.join(SEARCH_CLASSES[name])}): reached within {srch['budget']}: "
                         f"{srch['within_budget']} of {srch['subgoals']}, reached at any length "
                         f"{srch['reached_any_length']} (within 3x the walk to the 1 m region, through walls: "
                         f"{srch.get('within_budget_of_region', '-')})")
    cpu = results.get("cpu_seconds", {})
    if cpu:
        lines.append("")
        lines.append(f"CPU: update {cpu.get('update_cpu_s', math.nan):.1f} s (detection included) vs mapping visit 2 "
                     f"from scratch {cpu.get('remap_visit2_cpu_s', math.nan):.1f} s; captions after the update "
                     f"{cpu.get('update_caption_cpu_s', math.nan):.1f} s vs "
                     f"{cpu.get('remap_caption_cpu_s', math.nan):.1f} s")
    return "\n".join(lines)
