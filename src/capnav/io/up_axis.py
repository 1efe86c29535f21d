"""Where is up in a recording? Found from what its camera saw and how it moved, not from its axes.

A recording's world can point anywhere (TUM: a mocap frame; odometry: the start pose; a phone
app: its own). The floor gives it away, through four things that hold for any indoor recording
made by a person or a robot. For a candidate up direction ``n`` and the floor plane it implies
(the lowest well-supported surface facing along ``n``), each is a cue in [0, 1]:

- support: the floor holds a fair share of the depth points (the floor is large);
- below / cameras: almost no point lies under it, and the cameras are above it at a height a
  hand or a robot holds a camera (the floor is the lowest surface and lies below the cameras);
- upright: the cameras hold their image rows level (perpendicular to ``n``) and their image-down
  axis has a share along ``-n`` (a camera may look down at a table steeply, but not straight down,
  where image rows say nothing about gravity);
- level: the cameras move far less along ``n`` than across it (they travel at a constant height;
  no information when they hardly move).

Candidates are the dominant surface orientations of the depth itself (per-pixel normals oriented
towards the camera that saw them, clustered on the sphere), plus the cameras' mean image-up and
the normal of the plane they moved in: any direction, not only the six axes. A candidate's fit is
the geometric mean of its cues (one failed cue sinks it); the confidence is the best fit, capped
by its margin over the next distinct candidate, so two equally good explanations (a wall facing
a camera that looks straight down, a portrait-held phone) read as weak evidence, not as a guess.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.geometry import Intrinsics

F64 = NDArray[np.float64]
AXIS_NAMES = ("+x", "-x", "+y", "-y", "+z", "-z")
CUES = ("support", "below", "cameras", "upright", "level")


@dataclass(frozen=True)
class UpConfig:
    """Knobs of the search; the cue ranges say when a cue is fully met (1) and when it fails (0)."""

    points_per_frame: int = 3000
    max_range: float = 6.0  # m; far depth is noisy
    normal_step_frac: float = 0.01  # normals from neighbours this fraction of the image width apart (>= 2 px)
    cluster_deg: float = 10.0  # surface orientations within this angle are one candidate
    facing_deg: float = 15.0  # points whose normal is this close to a candidate belong to its planes
    max_candidates: int = 8
    inlier_dist: float = 0.03  # m from the floor plane
    min_points: int = 200  # a plane needs this many sampled points (or 2% of them, when fewer than 10000)
    min_plane_area: float = 0.5  # m^2 it must cover (0.2 m cells), so a small step or box top is not the floor
    support_full: float = 0.05  # floor share of all points at which the support cue is 1
    below_tol: float = 0.10  # m under the floor before a point counts as below it (depth noise)
    below_fail: float = 0.10  # share of points below the floor at which the below cue is 0
    camera_height: tuple[float, float] = (0.05, 3.0)  # m above the floor a camera is carried at
    usual_height: tuple[float, float] = (0.3, 2.5)  # m; outside it the import warns (a wrong depth scale?)
    cameras_full: float = 0.95  # share of cameras at such a height for a full cue (0 at 0.8)
    down_range: tuple[float, float] = (0.1, 0.3)  # cos(image-down, gravity): cue 0 .. 1 (pitch 84 .. 72.5 deg)
    roll_range_deg: tuple[float, float] = (30.0, 12.0)  # image rows' angle to level: cue 0 .. 1
    level_ratio: tuple[float, float] = (0.2, 0.6)  # height spread / horizontal spread: cue 1 .. 0
    level_min_travel: float = 0.3  # m of horizontal spread below which the level cue says nothing
    distinct_deg: float = 20.0  # the runner-up must differ by more than this from the choice
    margin_full: float = 0.5  # fit margin over the runner-up for full confidence
    min_confidence: float = 0.5  # below this the import refuses to choose
    max_tilt_deg: float = 20.0  # a named --up axis may be this far from the floor's normal
    seed: int = 0


@dataclass
class UpCandidate:
    """One hypothesis: ``up`` (unit, the recording's frame), the floor ``n . p = offset`` and its cues."""

    up: F64
    offset: float
    source: str  # "surfaces" (a normal cluster), "image-up" or "camera-plane"
    floor_points: int
    floor_rms_m: float
    cues: dict[str, float]
    facts: dict[str, float]
    runner_up_plane: dict[str, float] | None = None  # the biggest other plane facing along ``up``

    @property
    def fit(self) -> float:
        v = np.array([self.cues[c] for c in CUES])
        return 0.0 if (v <= 0).any() else float(np.exp(np.log(v).mean()))

    @property
    def geometric_fit(self) -> float:
        """The cues that need no assumption about how the camera was held (support, below, cameras)."""
        v = np.array([self.cues[c] for c in ("support", "below", "cameras")])
        return 0.0 if (v <= 0).any() else float(np.exp(np.log(v).mean()))

    def weakest(self) -> tuple[str, float]:
        name = min(CUES, key=lambda c: self.cues[c])
        return name, self.cues[name]

    def describe(self) -> str:
        axis, ang = nearest_axis(self.up)
        return (f"({', '.join(f'{v:+.2f}' for v in self.up)}), {ang:.1f} deg from {axis}, fit {self.fit:.2f}: "
                + ", ".join(f"{c} {self.cues[c]:.2f}" for c in CUES))

    def to_dict(self) -> dict[str, Any]:
        axis, ang = nearest_axis(self.up)
        return {"up": [round(float(v), 5) for v in self.up], "offset": round(self.offset, 4), "source": self.source,
                "nearest_axis": axis, "axis_angle_deg": round(ang, 2), "fit": round(self.fit, 4),
                "cues": {k: round(v, 4) for k, v in self.cues.items()},
                "facts": {k: round(v, 4) for k, v in self.facts.items()},
                "floor_points": self.floor_points, "floor_rms_m": round(self.floor_rms_m, 5),
                "runner_up_plane": None if self.runner_up_plane is None else
                {k: round(v, 4) for k, v in self.runner_up_plane.items()}}


@dataclass
class UpResult:
    """The chosen candidate (None when nothing qualified), the runner-up, confidence and the verdict."""

    chosen: UpCandidate | None
    runner_up: UpCandidate | None
    confidence: float
    margin: float
    ok: bool
    reason: str
    candidates: list[UpCandidate] = field(default_factory=list)
    points: int = 0

    def to_meta(self) -> dict[str, Any]:
        return {"confidence": round(self.confidence, 4), "margin": round(self.margin, 4), "ok": self.ok,
                "reason": self.reason, "points": self.points,
                "chosen": None if self.chosen is None else self.chosen.to_dict(),
                "runner_up": None if self.runner_up is None else self.runner_up.to_dict()}


def nearest_axis(v: NDArray[np.floating]) -> tuple[str, float]:
    """The named axis closest to ``v`` and the angle to it (degrees)."""
    axes = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=np.float64)
    c = axes @ (np.asarray(v, dtype=np.float64) / np.linalg.norm(v))
    i = int(np.argmax(c))
    return AXIS_NAMES[i], float(np.degrees(np.arccos(np.clip(c[i], -1.0, 1.0))))


def angle_deg(a: NDArray[np.floating], b: NDArray[np.floating]) -> float:
    c = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return float(np.degrees(np.arccos(np.clip(c, -1.0, 1.0))))


def surface_samples(views: Iterable[tuple[NDArray[np.floating], NDArray[np.floating]]], K: Intrinsics,
                    cfg: UpConfig) -> tuple[F64, F64]:
    """World points and unit normals (oriented towards the camera; NaN where the neighbourhood is
    broken by a depth edge or a hole), ``points_per_frame`` random pixels per ``(depth, T_wc)`` view."""
    rng = np.random.default_rng(cfg.seed)
    s = max(2, round(cfg.normal_step_frac * K.width))
    u = (np.arange(K.width, dtype=np.float64) - K.cx) / K.fx
    v = (np.arange(K.height, dtype=np.float64) - K.cy) / K.fy
    pts, nrm = [], []
    for depth, T in views:
        z = np.asarray(depth, dtype=np.float64)
        z = np.where(np.isfinite(z) & (z > 0) & (z < cfg.max_range), z, np.nan)
        X = np.stack([u[None, :] * z, v[:, None] * z, z], axis=-1)  # camera frame (H, W, 3)
        dx = X[s:-s, 2 * s:] - X[s:-s, :-2 * s]
        dy = X[2 * s:, s:-s] - X[:-2 * s, s:-s]
        n = np.cross(dx, dy)
        zc = z[s:-s, s:-s]
        edge = (np.abs(dx[..., 2]) > 0.1 * zc) | (np.abs(dy[..., 2]) > 0.1 * zc)
        n[edge] = np.nan
        norm = np.linalg.norm(n, axis=-1, keepdims=True)
        n = n / np.where(norm > 0, norm, np.nan)
        Xc = X[s:-s, s:-s]
        n *= -np.sign(np.sum(n * Xc, axis=-1, keepdims=True))  # towards the camera: n . (0 - X) > 0
        keep = np.flatnonzero(np.isfinite(zc).reshape(-1))
        if len(keep) > cfg.points_per_frame:
            keep = rng.choice(keep, cfg.points_per_frame, replace=False)
        Tm = np.asarray(T, dtype=np.float64)
        pts.append(Xc.reshape(-1, 3)[keep] @ Tm[:3, :3].T + Tm[:3, 3])
        nrm.append(n.reshape(-1, 3)[keep] @ Tm[:3, :3].T)
    if not pts:
        return np.zeros((0, 3)), np.zeros((0, 3))
    return np.concatenate(pts), np.concatenate(nrm)


def normal_clusters(normals: F64, cfg: UpConfig) -> list[F64]:
    """Dominant surface orientations, biggest first (greedy: densest direction, its mean, remove, repeat)."""
    N = normals[np.isfinite(normals).all(axis=1)]
    rng = np.random.default_rng(cfg.seed)
    if len(N) > 8000:  # plenty to find orientations holding a few percent of the points
        N = N[rng.choice(len(N), 8000, replace=False)]
    cos_c = np.cos(np.radians(cfg.cluster_deg))
    out: list[F64] = []
    min_n = need_points(len(N), cfg)
    while len(N) >= min_n and len(out) < cfg.max_candidates:
        seeds = N[rng.choice(len(N), min(len(N), 300), replace=False)]
        counts = (seeds @ N.T >= cos_c).sum(axis=1)
        d = seeds[int(np.argmax(counts))]
        for _ in range(3):  # mean shift of the densest seed
            m = N[N @ d >= cos_c].mean(axis=0)
            d = m / np.linalg.norm(m)
        if int((N @ d >= cos_c).sum()) < min_n:
            break
        out.append(d)
        N = N[N @ d < np.cos(np.radians(2 * cfg.cluster_deg))]
    return out


def need_points(n: int, cfg: UpConfig) -> int:
    """Points a plane needs: ``min_points``, fewer for a small sample (one low-resolution frame)."""
    return min(cfg.min_points, max(30, n // 50))


@dataclass
class FloorFit:
    """The floor found along an up direction, and the biggest other horizontal plane (the runner-up)."""

    normal: F64
    offset: float
    points: int
    rms: float
    area_m2: float
    confidence: float  # how well the chosen plane is supported: the area it covers, the cameras above it
    runner_up: dict[str, float] | None  # height above the floor, points, area of the next plane


def plane_peaks(h: F64, cfg: UpConfig) -> list[tuple[float, int]]:
    """Heights of the horizontal planes in sorted point heights ``h``: local maxima of the number of
    points within ``inlier_dist``, at least ``2 inlier_dist`` apart, with their support, lowest first."""
    from scipy.ndimage import maximum_filter1d

    tol, step = cfg.inlier_dist, cfg.inlier_dist / 2
    grid = np.arange(h[0], h[-1] + step, step)
    support = np.searchsorted(h, grid + tol) - np.searchsorted(h, grid - tol)
    w = 2 * round(2 * tol / step) + 1
    top = np.flatnonzero((support == maximum_filter1d(support, size=w, mode="constant")) & (support > 0))
    peaks: list[tuple[float, int]] = []
    for i in top[np.argsort(-support[top], kind="stable")]:
        if all(abs(grid[i] - g) > 2 * tol for g, _ in peaks):
            peaks.append((float(grid[i]), int(support[i])))
    return sorted(peaks)


def plane_area(P: F64, n: F64, cell: float = 0.2) -> float:
    """Area (m^2) of the ``cell``-sized squares the points ``P`` of a plane with normal ``n`` cover."""
    if len(P) == 0:
        return 0.0
    e1 = np.cross(n, [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    ij = np.floor(np.stack([P @ e1, P @ e2], axis=1) / cell).astype(np.int64)
    return float(len(np.unique(ij, axis=0))) * cell * cell


def floor_along(points: F64, normals: F64, n: F64, poses: NDArray[np.floating] | None,
                cfg: UpConfig) -> FloorFit | None:
    """The floor for up ``n``: the lowest well-supported plane facing along ``n`` (``need_points``
    points covering ``min_plane_area``) with most cameras at a carried height above it, not the
    plane with the most points (a table top, counter or bed under a camera looking down at it holds
    far more: the floor may show only at the image edges). Refitted by least squares; None when no
    plane faces that way."""
    n = np.asarray(n, dtype=np.float64) / np.linalg.norm(n)
    cos_f = np.cos(np.radians(cfg.facing_deg))
    tol = cfg.inlier_dist
    need = need_points(len(points), cfg)
    C = None if poses is None else np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)[:, :3, 3]
    lo, hi = cfg.camera_height
    off, area, runner, carried = 0.0, 0.0, None, 1.0
    for _ in range(3):
        with np.errstate(invalid="ignore"):
            facing = np.nan_to_num(normals @ n, nan=-1.0) >= cos_f
        if facing.sum() < need:
            return None
        Pf = points[facing]
        hf = Pf @ n
        peaks = plane_peaks(np.sort(hf), cfg)
        sized = [(g, c, plane_area(Pf[np.abs(hf - g) < tol], n)) for g, c in peaks if c >= need]
        if not sized:
            return None
        good = [p for p in sized if p[2] >= cfg.min_plane_area] or [max(sized, key=lambda p: p[1])]
        share = [1.0 if C is None else float(np.mean((C @ n - g > lo) & (C @ n - g < hi))) for g, _, _ in good]
        pick = next((i for i, sh in enumerate(share) if sh >= 0.5), 0)
        off, _, area = good[pick]
        carried = share[pick]
        others = [p for p in sized if abs(p[0] - off) > 2 * tol]
        big = max(others, key=lambda p: p[1]) if others else None
        runner = None
        if big is not None:  # heights from the planes' points, not the peak search's grid
            dh = float(np.median(hf[np.abs(hf - big[0]) < tol]) - np.median(hf[np.abs(hf - off) < tol]))
            runner = {"height_m": dh, "points": float(big[1]), "area_m2": big[2]}
        inl = facing & (np.abs(points @ n - off) < tol)
        P = points[inl]
        c = P.mean(axis=0)
        _, _, vt = np.linalg.svd(P - c, full_matrices=False)
        n = vt[2] * np.sign(vt[2] @ n)
        off = float(n @ c)
    inl = np.abs(points @ n - off) < tol
    rms = float(np.sqrt(np.mean((points[inl] @ n - off) ** 2))) if inl.any() else float("nan")
    conf = min(_ramp(area, cfg.min_plane_area, 4 * cfg.min_plane_area), _ramp(carried, 0.5, cfg.cameras_full))
    return FloorFit(n, off, int(inl.sum()), rms, area, conf, runner)


def _ramp(x: float, zero: float, one: float) -> float:
    """0 at ``zero``, 1 at ``one``, linear between (either order), clipped."""
    return float(np.clip((x - zero) / (one - zero), 0.0, 1.0))


def score(points: F64, n: F64, offset: float, poses: NDArray[np.floating], cfg: UpConfig) -> tuple[
        dict[str, float], dict[str, float]]:
    """The five cues of the floor ``n . p = offset`` given all camera poses (N, 4, 4), and the facts behind them."""
    h = points @ n - offset
    floor_share = float(np.mean(np.abs(h) < cfg.inlier_dist))
    below = float(np.mean(h < -cfg.below_tol))
    T = np.asarray(poses, dtype=np.float64)
    C = T[:, :3, 3]
    hc = C @ n - offset
    lo, hi = cfg.camera_height
    carried = float(np.mean((hc > lo) & (hc < hi)))
    upright = float(np.median(T[:, :3, 1] @ -n))  # image-down axis against gravity (-n)
    roll = float(np.degrees(np.arcsin(np.clip(np.median(np.abs(T[:, :3, 0] @ n)), 0.0, 1.0))))  # rows vs level
    across = C - np.outer(C @ n, n)
    travel = float(np.sqrt(np.sum(np.var(across, axis=0))))
    height_sd = float(np.std(hc))
    ratio = height_sd / travel if travel > 0 else float("inf")
    level = 1.0 if travel < cfg.level_min_travel else _ramp(ratio, cfg.level_ratio[1], cfg.level_ratio[0])
    cues = {"support": _ramp(floor_share, 0.0, cfg.support_full), "below": _ramp(below, cfg.below_fail, 0.0),
            "cameras": _ramp(carried, 0.8, cfg.cameras_full),
            "upright": min(_ramp(upright, *cfg.down_range), _ramp(roll, *cfg.roll_range_deg)), "level": level}
    facts = {"floor_share": floor_share, "below_share": below, "cameras_carried": carried,
             "camera_height_median_m": float(np.median(hc)), "camera_height_sd_m": height_sd,
             "camera_travel_m": travel, "upright_cos": upright,
             "upright_deg": float(np.degrees(np.arccos(np.clip(upright, -1.0, 1.0)))), "roll_deg": roll}
    return cues, facts


def evaluate(points: F64, normals: F64, n: F64, poses: NDArray[np.floating], source: str,
             cfg: UpConfig) -> UpCandidate | None:
    """The candidate for up near ``n`` (its floor refined), or None when no plane faces along ``n``."""
    fl = floor_along(points, normals, n, poses, cfg)
    if fl is None:
        return None
    cues, facts = score(points, fl.normal, fl.offset, poses, cfg)
    facts["floor_area_m2"] = fl.area_m2
    facts["floor_confidence"] = fl.confidence
    return UpCandidate(fl.normal, fl.offset, source, fl.points, fl.rms, cues, facts, fl.runner_up)


def camera_directions(poses: NDArray[np.floating], cfg: UpConfig) -> list[tuple[F64, str]]:
    """Up guesses from the cameras alone: their mean image-up, and the normal of the plane they moved
    in (both ways) when they spread over an area and hardly left that plane."""
    T = np.asarray(poses, dtype=np.float64)
    out: list[tuple[F64, str]] = []
    m = -T[:, :3, 1].mean(axis=0)
    if np.linalg.norm(m) > 0.3:
        out.append((m / np.linalg.norm(m), "image-up"))
    C = T[:, :3, 3]
    if len(C) >= 3:
        w, V = np.linalg.eigh(np.cov(C.T))
        sd = np.sqrt(np.clip(w, 0, None))
        if sd[1] >= cfg.level_min_travel and sd[0] < cfg.level_ratio[0] * sd[1]:
            out += [(V[:, 0], "camera-plane"), (-V[:, 0], "camera-plane")]
    return out


def find_up(views: Iterable[tuple[NDArray[np.floating], NDArray[np.floating]]], K: Intrinsics,
            poses: NDArray[np.floating], cfg: UpConfig | None = None) -> UpResult:
    """Look for up in ``(depth, T_wc)`` views, with every frame's pose ``poses`` (N, 4, 4) for the camera cues."""
    cfg = cfg or UpConfig()
    P, Nr = surface_samples(views, K, cfg)
    return choose_up(P, Nr, poses, cfg)


def choose_up(P: F64, Nr: F64, poses: NDArray[np.floating], cfg: UpConfig) -> UpResult:
    """Rank every candidate direction; the verdict says whether the best one is trustworthy and why."""
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)
    if len(P) < max(cfg.min_points, 1000) or len(poses) == 0:
        return UpResult(None, None, 0.0, 0.0, False,
                        f"only {len(P)} depth points within {cfg.max_range:g} m in the sampled frames "
                        f"(need {max(cfg.min_points, 1000)})", points=len(P))
    dirs = [(d, "surfaces") for d in normal_clusters(Nr, cfg)] + camera_directions(poses, cfg)
    cands: list[UpCandidate] = []
    for d, src in dirs:
        c = evaluate(P, Nr, d, poses, src, cfg)
        if c is None:
            continue
        same = [i for i, o in enumerate(cands) if angle_deg(o.up, c.up) < cfg.cluster_deg / 2]
        if not same:
            cands.append(c)
        elif c.fit > cands[same[0]].fit:
            cands[same[0]] = c
    cands.sort(key=lambda c: -c.fit)
    if not cands:
        return UpResult(None, None, 0.0, 0.0, False,
                        f"no surface in the depth is large enough to be a floor ({need_points(len(P), cfg)} points "
                        "facing one way)", points=len(P))
    best = cands[0]
    rival = next((c for c in cands[1:] if angle_deg(c.up, best.up) > cfg.distinct_deg), None)
    margin = _ramp(best.fit - (rival.fit if rival else 0.0), 0.0, cfg.margin_full)
    conf = min(best.fit, margin)
    ok = conf >= cfg.min_confidence
    if ok:
        reason = f"up {best.describe()}"
    elif best.fit < cfg.min_confidence:
        cue, val = best.weakest()
        reason = (f"no direction looks like up: the best, {best.describe()}, fails on {cue} ({val:.2f}: "
                  f"{cue_words(cue, best.facts)})")
    else:
        assert rival is not None
        reason = (f"two directions explain the recording about equally well: {best.describe()}; and "
                  f"{rival.describe()}")
    return UpResult(best, rival, conf, margin, ok, reason, cands, len(P))


def cue_words(cue: str, f: dict[str, float]) -> str:
    """What a failed cue means, with its number."""
    return {
        "support": f"only {100 * f['floor_share']:.1f}% of the depth points lie on that floor",
        "below": f"{100 * f['below_share']:.0f}% of the depth points lie below that floor",
        "cameras": f"only {100 * f['cameras_carried']:.0f}% of the cameras are 0.05-3 m above it "
                   f"(median {f['camera_height_median_m']:+.2f} m)" + (
                       "; cameras that far above every floor mean depth read too far: is the depth scale right "
                       "(--depth-scale: units per metre)?" if f["camera_height_median_m"] > 3.0 else ""),
        "upright": (f"the image rows would be {f['roll_deg']:.0f} deg from level" if f["roll_deg"] > 20 else
                    f"the image-down axis is {f['upright_deg']:.0f} deg from that gravity, so the image rows "
                    "would not tell which way is down"),
        "level": f"the cameras move {f['camera_height_sd_m']:.2f} m up and down over {f['camera_travel_m']:.2f} m "
                 "across",
    }[cue]
