"""SG3DTracker: paper section 3.2, Algorithm 1, one ``update`` per frame.

The paper fixes the eq. 12 weights (0.6, 0.2, 0.2, 0.3) and names but does not give the other
parameters; ours, for indoor mapping at 0.1-0.3 m between frames:

* ``d_max = 0.6`` m: same-class neighbours (dining chairs, twin nightstands) stand 0.5-0.8 m
  apart; with 1.0 m a track whose object is missed in a frame takes its neighbour's detection
  (cost 0.68 at 0.8 m). The lifted mask centroid lies on the visible surface and can move more
  than that for a bed or sofa seen from a new side: the track is then re-born and the persistent
  memory re-links it to the same object (measured on 3 apartments: no duplicate either way);
* ``tau_assoc = 0.75``: a true match (0.2 m, IoU 0.3, same label) costs ~0.34; the same object
  with a confused label (chair/armchair, cos ~0.7) 0.2 m away ~0.66 (still matched); two
  different objects of different classes 0.4 m apart ~0.96 (gated);
* ``alpha_pos = 0.3``, ``alpha_bbox = 0.5``, ``alpha_sem = 0.2``: positions of static objects
  should be smooth, boxes follow the moving camera faster;
* ``m_max = 10`` frames: a few seconds out of view; persistence (``ObjectMemory``) keeps the
  object after the track dies, so a short ``m_max`` costs nothing;
* ``h_min = 3`` hits: one or two false positives never become objects. ``ObjectMemory`` counts
  them per 3D place, not per track: a track that dies unconfirmed leaves its detections to a later
  track of the same place (a small object seen in frames scattered more than ``m_max`` apart);
* weak candidates (``Detection.weak``: a real detector's boxes below its score threshold, down to
  its candidate floor) are tracked like any detection but can only match a track of the same or a
  lookalike label, and confirm an object only by ``weak_h_min`` sightings, ``weak_confident`` of
  them confident, whose leading label sums at least ``weak_score`` and holds ``weak_agreement``
  of their summed label scores, the model's rival readings of the same boxes included
  (``ObjectMemory.observe``); without a confident one, ``weak_shape`` confirms them when their
  points have the leading label's shape from several camera places (``mapping.corroborate``);
  ``weak_h_min`` is never lowered for a short recording, so a one-frame map keeps no weak
  candidate. Their label votes count only while a track or an object has no confident one;
* ``max_speed = 0.05`` m/frame clips the velocity of eq. 11 (not in the paper): objects are
  static, and the centroid jitter of a moving camera would otherwise be extrapolated during a miss.

Time steps are frames (``v = p - p_prev`` in Algorithm 1 is per update), so eq. 11's
``Delta t`` is the number of frames since the track's last update.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import linear_sum_assignment

from capnav.core.categories import BY_NAME, confusable
from capnav.core.errors import InputError
from capnav.mapping.cost import association_cost
from capnav.mapping.lifting import LiftedDetection

_BIG = 1e9


@dataclass(frozen=True)
class TrackerConfig:
    """All SG3DTracker parameters; eq. 12 weights are the paper's."""

    alpha_3d: float = 0.6
    beta_2d: float = 0.2
    gamma_sem: float = 0.2
    lambda_cls: float = 0.3
    d_max: float = 0.6
    tau_assoc: float = 0.75
    alpha_pos: float = 0.3
    alpha_bbox: float = 0.5
    alpha_sem: float = 0.2
    m_max: int = 10
    h_min: int = 3
    max_speed: float = 0.05
    weak_h_min: int = 5  # 0: weak candidates are not asked of the detector
    weak_score: float = 1.0
    weak_agreement: float = 2.0 / 3.0
    weak_confident: int = 1
    # Without the confident sighting, weak ones confirm a place whose points have the label's shape
    # (``mapping.corroborate``: a table's top at table height, open below, seen from 3 places): a
    # real table a COCO detector never scores at its threshold (issue 21), not a glass door.
    weak_shape: bool = True

    def __post_init__(self) -> None:
        if self.d_max <= 0 or self.tau_assoc <= 0:
            raise InputError("d_max and tau_assoc must be positive")
        for name in ("alpha_pos", "alpha_bbox", "alpha_sem"):
            if not 0.0 < getattr(self, name) <= 1.0:
                raise InputError(f"{name} must be in (0, 1]")
        if self.m_max < 0 or self.h_min < 1:
            raise InputError("m_max must be >= 0 and h_min >= 1")
        if self.weak_h_min and self.weak_h_min < self.h_min:
            raise InputError(f"weak_h_min must be 0 (off) or at least h_min ({self.h_min}), got {self.weak_h_min}")
        if self.weak_score < 0 or not 0.0 <= self.weak_agreement <= 1.0 or self.weak_confident < 0:
            raise InputError("weak_score and weak_confident must be >= 0 and weak_agreement in [0, 1]")

    @property
    def weights(self) -> tuple[float, float, float, float]:
        return (self.alpha_3d, self.beta_2d, self.gamma_sem, self.lambda_cls)


@dataclass
class Track:
    """Track state of section 3.2: p, v, B, s-bar, c and lifecycle counters."""

    id: int
    position: NDArray[np.float64]
    velocity: NDArray[np.float64]
    box: NDArray[np.float64]
    feature: NDArray[np.float32]
    class_id: int
    label: str
    age: int = 1
    hits: int = 1
    misses: int = 0
    last_update: int = 0  # tracker step of the last match
    class_votes: dict[int, float] = field(default_factory=dict)
    weak_votes: dict[int, float] = field(default_factory=dict)  # of weak candidates: count only without class_votes
    labels: dict[int, str] = field(default_factory=dict)
    object_id: int | None = None  # persistent object this track feeds (set by ObjectMemory)

    @property
    def confirmed(self) -> bool:
        return self.object_id is not None

    def vote(self, class_id: int, label: str, score: float, weak: bool = False) -> None:
        """Class ``c_j`` is the weighted majority of the track's detections (``vote_all``); the
        votes of weak candidates decide it only while no confident detection has voted."""
        votes = self.weak_votes if weak else self.class_votes
        votes[class_id] = votes.get(class_id, 0.0) + float(score)
        self.labels[class_id] = label
        votes = self.class_votes or self.weak_votes
        self.class_id = max(votes, key=lambda c: (votes[c], -c))
        self.label = self.labels[self.class_id]


def vote_weight(d: LiftedDetection) -> float:
    """What a detection's label vote weighs besides its confidence: its 3D support (m² of surface,
    ``LiftedDetection.support``), so that the cups standing on a table, each detected as often as
    the table, do not outvote it. At least 1 cm², so a detection without depth still counts."""
    return max(float(d.support), 1e-4)


def vote_all(t: Track, d: LiftedDetection) -> None:
    """Vote for every label the detection stands for (``Detection.label_votes``: several when
    overlapping detections of one thing were merged), each weighted by ``vote_weight``."""
    w = vote_weight(d)
    for label, score in d.detection.label_votes().items():
        cat = BY_NAME.get(label)
        t.vote(d.class_id if label == d.detection.label else (cat.id if cat else 0), label, score * w,
               d.detection.weak)


@dataclass
class TrackerStep:
    """What one update did: matches (track, detection index), births, deaths, exported tracks."""

    matches: list[tuple[Track, int]]
    births: list[tuple[Track, int]]
    deaths: list[Track]
    confirmed: list[Track]
    cost: NDArray[np.float64]


class SG3DTracker:
    """Algorithm 1 over lifted detections."""

    def __init__(self, config: TrackerConfig | None = None) -> None:
        self.config = config or TrackerConfig()
        self.tracks: list[Track] = []
        self.step = 0
        self._next_id = 1

    def predict(self, step: int | None = None) -> NDArray[np.float64]:
        """Step 1, eq. 11: p_pred = p + v * dt at ``step`` (default: the next frame), dt in frames
        since each track's last match."""
        if not self.tracks:
            return np.zeros((0, 3))
        at = self.step + 1 if step is None else step
        p = np.stack([t.position for t in self.tracks])
        v = np.stack([t.velocity for t in self.tracks])
        dt = np.array([at - t.last_update for t in self.tracks], dtype=np.float64)[:, None]
        return p + v * dt

    def update(self, dets: Sequence[LiftedDetection]) -> TrackerStep:
        cfg = self.config
        self.step += 1
        pred = self.predict(self.step)
        n_t, n_d = len(self.tracks), len(dets)
        cost = np.full((n_t, n_d), np.inf)
        matches: list[tuple[Track, int]] = []
        if n_t and n_d:
            cost, _ = association_cost(
                pred, np.stack([t.box for t in self.tracks]), np.stack([t.feature for t in self.tracks]),
                np.array([t.class_id for t in self.tracks]),
                np.stack([d.position for d in dets]), np.array([d.box for d in dets], dtype=np.float64),
                np.stack([d.descriptor for d in dets]), np.array([d.class_id for d in dets]),
                cfg.weights, cfg.d_max, cfg.tau_assoc)
            for j, d in enumerate(dets):  # a weak candidate is another sighting of the same kind only
                if d.detection.weak:
                    for r, t in enumerate(self.tracks):
                        if t.label != d.detection.label and d.detection.label not in confusable(t.label):
                            cost[r, j] = np.inf
            finite = np.isfinite(cost)
            if finite.any():
                rows, cols = linear_sum_assignment(np.where(finite, cost, _BIG))
                matches = [(self.tracks[r], int(c)) for r, c in zip(rows, cols, strict=True) if finite[r, c]]
        matched_t = {id(t) for t, _ in matches}
        matched_d = {i for _, i in matches}
        # Step 3: matched track update (EMAs).
        for t, i in matches:
            d = dets[i]
            prev = t.position
            t.position = cfg.alpha_pos * np.asarray(d.position, dtype=np.float64) + (1 - cfg.alpha_pos) * prev
            dt = max(self.step - t.last_update, 1)
            v = (t.position - prev) / dt
            speed = float(np.linalg.norm(v))
            t.velocity = v * (cfg.max_speed / speed) if speed > cfg.max_speed else v
            t.box = (1 - cfg.alpha_bbox) * t.box + cfg.alpha_bbox * np.asarray(d.box, dtype=np.float64)
            t.feature = ((1 - cfg.alpha_sem) * t.feature + cfg.alpha_sem * d.descriptor).astype(np.float32)
            vote_all(t, d)
            t.hits += 1
            t.misses = 0
            t.age += 1
            t.last_update = self.step
        # Step 5: track death (before birth so newborns are not aged).
        deaths: list[Track] = []
        survivors: list[Track] = []
        for t in self.tracks:
            if id(t) not in matched_t:
                t.age += 1
                t.misses += 1
                if t.misses > cfg.m_max:
                    deaths.append(t)
                    continue
            survivors.append(t)
        # Step 4: track birth.
        births: list[tuple[Track, int]] = []
        for i, d in enumerate(dets):
            if i in matched_d:
                continue
            t = Track(id=self._next_id, position=np.asarray(d.position, dtype=np.float64).copy(),
                      velocity=np.zeros(3), box=np.asarray(d.box, dtype=np.float64).copy(),
                      feature=np.asarray(d.descriptor, dtype=np.float32).copy(), class_id=d.class_id,
                      label=d.detection.label, last_update=self.step)
            vote_all(t, d)
            self._next_id += 1
            survivors.append(t)
            births.append((t, i))
        self.tracks = survivors
        # Step 6: export.
        confirmed = [t for t in self.tracks if t.hits >= cfg.h_min and t.misses == 0]
        return TrackerStep(matches, births, deaths, confirmed, cost)
