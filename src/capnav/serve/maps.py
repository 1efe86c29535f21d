"""The maps a server holds: each under its name, checked at load, replaced whole on reload.

A ``ServedMap`` is immutable once made: a reload (``POST /api/reload``, SIGHUP) opens the file
again, checks it, and swaps the new ``ServedMap`` in; requests already running finish on the old
one, so none is dropped. Worker threads notice the new ``version`` and make their own ``CapNav``
over it on their next job.
"""

from __future__ import annotations

import re
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from scipy import ndimage

from capnav.api import CapNav
from capnav.core.errors import CapNavError, InputError
from capnav.core.grid import FREE
from capnav.language.embedder import TextEmbedder
from capnav.mapping.cmap import CapNavMap
from capnav.mapping.embeddings import check_embeddings
from capnav.viz.mapimage import MapPicture, map_picture

_NAME = re.compile(r"[^A-Za-z0-9_.-]+")


@dataclass(frozen=True)
class AskOptions:
    """How a map is asked: the embedder (a backend name, ``auto``, or a ready instance), its model
    folder, and the verifier backend."""

    embedder: str | TextEmbedder = "auto"
    embedder_path: str | Path | None = None
    verifier: str = "offline"
    #: Per-object goal and walk fields (``CapNav.prepare``), made by each worker on a thread of its
    #: own once it has warmed up: asks from robot positions no ask used before are then lookups.
    fields: bool = True

    @property
    def shared_instance(self) -> bool:
        """A ready embedder object: every worker would share it, so the pool runs one worker."""
        return isinstance(self.embedder, TextEmbedder)


def default_robot(nav: CapNav) -> tuple[float, float] | None:
    """A start for the page until the user clicks one: the map's last camera pose, as ``capnav
    navigate`` starts (``CapNav.start_pose``); for a map with no camera path, the free cell farthest
    from any non-free cell (an open spot in the middle of a room)."""
    if nav.map.trajectory is not None and len(nav.map.trajectory):
        (x, y, _), _ = nav.start_pose()
        return (round(x, 3), round(y, 3))
    occ = nav.occupancy
    free = occ.cells == FREE
    if not free.any():
        return None
    dist = ndimage.distance_transform_edt(free)
    r, c = np.unravel_index(int(np.argmax(dist)), dist.shape)
    x, y = occ.spec.to_world(np.array([r, c]))
    return (round(float(x), 3), round(float(y), 3))


@dataclass(frozen=True)
class MapRef:
    """A served map as a worker process knows it: its name, file and version (it pickles)."""

    name: str
    path: Path
    version: int
    options: AskOptions


def _stamp(path: Path | None) -> tuple[int, int] | None:
    if path is None:
        return None
    st = path.stat()
    return (st.st_mtime_ns, st.st_size)


@dataclass
class ServedMap:
    """One map as served: its ``CapNav`` for the read-only endpoints (objects, views, picture),
    the file it came from (None for a map handed over in memory) and its ``version``."""

    name: str
    nav: CapNav
    options: AskOptions
    path: Path | None = None
    version: int = 1
    stamp: tuple[int, int] | None = None
    robot0: tuple[float, float] | None = None
    _picture: MapPicture | None = field(default=None, repr=False)
    _lock: threading.Lock = field(default_factory=threading.Lock, repr=False)

    @classmethod
    def make(cls, name: str, nav: CapNav, options: AskOptions, path: Path | None = None, version: int = 1
             ) -> ServedMap:
        check_embeddings(nav.map, str(path) if path is not None else f"map {name!r}")
        robot0 = default_robot(nav) if (nav.map.occupancy.cells == FREE).any() else None
        return cls(name, nav, options, path, version, _stamp(path), robot0)

    @classmethod
    def open(cls, path: Path, options: AskOptions, name: str | None = None, version: int = 1) -> ServedMap:
        nav = CapNav.open(path, embedder=options.embedder, embedder_path=options.embedder_path,
                          verifier=options.verifier)
        return cls.make(name or map_name(path), nav, options, path, version)

    def picture(self) -> MapPicture:
        """The top-down picture, drawn once (off the event loop: the first call takes ~0.1-1 s)."""
        with self._lock:
            if self._picture is None:
                self._picture = map_picture(self.nav.map)
            return self._picture

    def worker_nav(self, embedder: TextEmbedder) -> CapNav:
        """A worker thread's own ``CapNav`` over this map: its own retriever and costmap, the
        thread's embedder; the map itself is read-only and shared."""
        n = self.nav
        return CapNav(n.map, embedder=embedder, verifier=self.options.verifier, retrieval=n.retrieval_config,
                      planner=n.planner_config, source=self.path, fields=self.options.fields)

    def ref(self) -> MapRef:
        """How a worker process names this map (only a map opened from a file has one)."""
        if self.path is None or self.options.shared_instance:
            raise InputError(f"map {self.name!r} was given in memory (or with a ready embedder object): worker "
                             "processes open maps from their files; serve it with worker threads")
        return MapRef(self.name, self.path, self.version, self.options)

    def changed_on_disk(self) -> bool:
        return self.path is not None and _stamp(self.path) != self.stamp

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, "objects": len(self.nav.map.objects), "version": self.version,
                "source": None if self.path is None else self.path.name}


def map_name(path: Path) -> str:
    """A map's name in URLs: the file name without its suffix, in URL-safe characters."""
    return _NAME.sub("-", path.stem).strip("-") or "map"


def unique_names(paths: list[Path]) -> list[str]:
    """One name per map file; an error naming both files when two would share a name."""
    names: dict[str, Path] = {}
    for p in paths:
        n = map_name(p)
        if n in names:
            raise InputError(f"{names[n]} and {p} would both be served as {n!r}: rename one of the files")
        names[n] = p
    return list(names)


def embedder_key(cmap: CapNavMap, options: AskOptions) -> tuple[Any, ...]:
    """Maps that can share one embedder (per worker thread) have the same key."""
    models = tuple(sorted({str(o.embedding_model) for o in cmap.objects if o.embedding_model}))
    spec = options.embedder if isinstance(options.embedder, str) else id(options.embedder)
    return (spec, None if options.embedder_path is None else str(options.embedder_path), models)


def make_embedder(m: ServedMap) -> TextEmbedder:
    """The embedder ``m`` is asked with (its own model for ``auto``), made in the calling thread."""
    if isinstance(m.options.embedder, TextEmbedder):
        return m.options.embedder
    probe = CapNav(m.nav.map, embedder=m.options.embedder, embedder_path=m.options.embedder_path)
    return probe.embedder


class WorkerState:
    """What one worker thread owns: an embedder per model and a ``CapNav`` per served map."""

    def __init__(self) -> None:
        self.embedders: dict[tuple[Any, ...], TextEmbedder] = {}
        self.navs: dict[str, tuple[int, CapNav]] = {}
        self.opened: dict[str, ServedMap] = {}
        self.preparing: dict[str, tuple[threading.Thread, threading.Event]] = {}

    def served(self, m: ServedMap | MapRef) -> ServedMap:
        """The map a job names: the server's own object (worker threads), or in a worker process
        the file opened here, again when the server has reloaded it (a newer version)."""
        if isinstance(m, ServedMap):
            return m
        have = self.opened.get(m.name)
        if have is None or have.version < m.version:
            have = self.opened[m.name] = ServedMap.open(m.path, m.options, m.name, m.version)
        return have

    def nav(self, m: ServedMap) -> CapNav:
        have = self.navs.get(m.name)
        if have is not None and have[0] == m.version:
            return have[1]
        key = embedder_key(m.nav.map, m.options)
        emb = self.embedders.get(key)
        if emb is None:
            emb = self.embedders[key] = make_embedder(m)
        nav = m.worker_nav(emb)
        if have is None or have[0] < m.version:  # a request begun before a reload gets a nav of its own
            self.navs[m.name] = (m.version, nav)
            if have is not None:  # a reloaded map: its fields are made again
                self.prepare(m.name, nav)
        return nav

    def prepare(self, name: str, nav: CapNav) -> None:
        """Make ``nav``'s per-object fields on a daemon thread of their own (the kernels release
        the GIL; the asks meanwhile search as without fields), stopping the one of the map's
        previous version."""
        if not nav.fields:
            return
        old = self.preparing.pop(name, None)
        if old is not None:
            old[1].set()
        stop = threading.Event()
        t = threading.Thread(target=_prepare, args=(nav, stop), name=f"capnav-fields-{name}", daemon=True)
        self.preparing[name] = (t, stop)
        t.start()

    def warm(self, m: ServedMap) -> None:
        """Load the embedder, build the costmap and run the planner once, so the first real ask
        is as fast as the rest."""
        if not m.nav.map.objects:
            return
        try:
            nav = self.nav(m)
            o = nav.map.objects[0]
            nav.ask(o.label, robot=m.robot0)
            if m.robot0 is not None:
                nav.plan(m.robot0, o.id)
        except CapNavError:
            return  # an uncaptioned map still serves its picture; its asks say why they cannot be answered
        self.prepare(m.name, nav)


def _prepare(nav: CapNav, stop: threading.Event) -> None:
    try:
        nav.prepare(stop)
    except CapNavError:
        pass  # the asks make what they need as they go
