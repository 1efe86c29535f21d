"""Do the poses and the depth of a recording agree? A check between neighbouring frames.

A wrong pose convention (world-to-camera read as camera-to-world, OpenGL camera axes read as
OpenCV, a robot body's pose read as the camera's) or a wrong depth scale gives a dataset that
imports without complaint and maps into garbage. Neighbouring frames see the same surfaces, so
frame a's depth, lifted with its pose and projected into frame b with b's pose, must land on b's
depth. The share of points that do (within 3 cm or 3 %) is measured for the poses as read and for
each other reading; when another reading fits far better, the import is refused with the reason.
Pairs are taken a little apart in motion (a few centimetres or degrees), so the readings differ;
a recording whose cameras hardly move, or whose neighbours do not overlap, is not judged.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.geometry import Intrinsics

F64 = NDArray[np.float64]
GL = np.diag([1.0, -1.0, -1.0, 1.0])

#: A ROS body frame (x forward, y left, z up) -> the optical frame of a camera at its origin looking
#: along x (optical z = body x, x = -body y, y = -body z); quaternion (x, y, z, w) = (0.5, -0.5, 0.5, -0.5).
BODY_TO_OPTICAL = np.array([[0.0, 0.0, 1.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class Reading:
    """One way of reading a recording's poses and depth: what it means, and how it turns the recorded
    (pose, depth) into the ones that would then be true."""

    name: str
    meaning: str
    pose: Callable[[F64], F64]
    depth_factor: float = 1.0
    remedy: str = ""


READINGS: tuple[Reading, ...] = (
    Reading("as recorded", "", lambda T: T),
    Reading("world-to-camera", "the poses are world-to-camera (inverse) matrices, not camera-to-world",
            lambda T: np.asarray(np.linalg.inv(T), dtype=np.float64), remedy="invert them"),
    Reading("OpenGL camera", "the poses use OpenGL camera axes (y up, z backwards), not OpenCV's (y down, z forward)",
            lambda T: np.asarray(T @ GL, dtype=np.float64),
            remedy="turn them by diag(1, -1, -1) (capnav import stray: --camera-axes opengl)"),
    Reading("body frame", "the poses are of a body frame (x forward, z up, as ROS odometry), not the camera's "
            "optical frame", lambda T: np.asarray(T @ BODY_TO_OPTICAL, dtype=np.float64),
            remedy="pass --camera-in-body x,y,z,qx,qy,qz,qw, the optical frame in the body frame "
                   "(0,0,0,0.5,-0.5,0.5,-0.5 for a camera at the body's origin looking along its x)"),
    Reading("depth x5", "the depth is 5 times too small: is --depth-scale 5 times too big (5000 read for "
            "millimetre PNGs)?", lambda T: T, 5.0),
    Reading("depth /5", "the depth is 5 times too large: is --depth-scale 5 times too small (1000 read for "
            "TUM's 5000)?", lambda T: T, 0.2),
)


@dataclass
class Consistency:
    """Agreement per reading (share of reprojected points landing on the other frame's depth)."""

    pairs: int
    agreement: dict[str, float] = field(default_factory=dict)
    verdict: str = "not judged"  # "consistent", "refused", "weak", "not judged"
    reason: str = ""

    def to_meta(self) -> dict[str, Any]:
        return {"pairs": self.pairs, "agreement": {k: round(v, 4) for k, v in self.agreement.items()},
                "verdict": self.verdict, "reason": self.reason}


def agreement(da: NDArray[np.floating], Ta: F64, db: NDArray[np.floating], Tb: F64, K: Intrinsics,
              rng: np.random.Generator, n: int = 1500, tol: float = 0.03) -> tuple[float, int]:
    """Share of ``n`` random valid pixels of frame a that, lifted and projected into frame b, meet b's
    depth within ``tol`` m or ``tol`` of the depth, among those landing on valid depth in b; and how many landed."""
    za = np.asarray(da, dtype=np.float64)
    ok = np.flatnonzero(np.isfinite(za).reshape(-1) & (za.reshape(-1) > 0))
    if len(ok) == 0:
        return 0.0, 0
    pick = rng.choice(ok, min(n, len(ok)), replace=False)
    v, u = np.divmod(pick, K.width)
    z = za.reshape(-1)[pick]
    Pc = np.stack([(u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z], axis=1)
    M = np.linalg.inv(Tb) @ Ta
    Q = Pc @ M[:3, :3].T + M[:3, 3]
    front = Q[:, 2] > 0.05
    with np.errstate(divide="ignore", invalid="ignore"):
        ub = np.rint(K.fx * Q[:, 0] / Q[:, 2] + K.cx)
        vb = np.rint(K.fy * Q[:, 1] / Q[:, 2] + K.cy)
    inside = front & (ub >= 0) & (ub < K.width) & (vb >= 0) & (vb < K.height)
    zb = np.asarray(db, dtype=np.float64)[vb[inside].astype(int), ub[inside].astype(int)]
    seen = np.isfinite(zb) & (zb > 0)
    if seen.sum() == 0:
        return 0.0, 0
    err = np.abs(Q[inside, 2][seen] - zb[seen])
    return float(np.mean(err < np.maximum(tol, tol * zb[seen]))), int(seen.sum())


def motion(Ta: F64, Tb: F64) -> tuple[float, float]:
    """Translation (m) and rotation (deg) between two poses."""
    R = Ta[:3, :3].T @ Tb[:3, :3]
    ang = float(np.degrees(np.arccos(np.clip((np.trace(R) - 1) / 2, -1.0, 1.0))))
    return float(np.linalg.norm(Tb[:3, 3] - Ta[:3, 3])), ang


def pair_up(poses: list[F64], max_pairs: int = 8, lo: tuple[float, float] = (0.1, 5.0),
            hi: tuple[float, float] = (1.0, 40.0)) -> list[tuple[int, int]]:
    """Neighbouring frame pairs (i, j > i) moved at least ``lo`` (m or deg) and at most ``hi`` apart,
    spread over the recording."""
    n = len(poses)
    starts = np.unique(np.linspace(0, max(n - 2, 0), min(n, 4 * max_pairs)).astype(int))
    out: list[tuple[int, int]] = []
    for i in starts.tolist():
        for j in range(i + 1, min(n, i + 60)):
            t, r = motion(poses[i], poses[j])
            if t > hi[0] or r > hi[1]:
                break
            if t >= lo[0] or r >= lo[1]:
                out.append((i, j))
                break
        if len(out) >= max_pairs:
            break
    return out


def check(depths: list[NDArray[np.floating]], poses: list[F64], K: Intrinsics, seed: int = 0,
          min_agreement: float = 0.5, margin: float = 0.25) -> Consistency:
    """Judge the pose convention and depth scale on ``(depth, pose)`` neighbours (pairs ``2k, 2k+1``)."""
    rng = np.random.default_rng(seed)
    res = Consistency(pairs=len(depths) // 2)
    if res.pairs == 0:
        res.reason = "no neighbouring frames moved a few centimetres or degrees apart"
        return res
    for rd in READINGS:
        vals = []
        for k in range(res.pairs):
            da, db = depths[2 * k] * rd.depth_factor, depths[2 * k + 1] * rd.depth_factor
            a, m = agreement(da, rd.pose(poses[2 * k]), db, rd.pose(poses[2 * k + 1]), K, rng)
            if m >= 50:
                vals.append(a)
        res.agreement[rd.name] = float(np.median(vals)) if vals else 0.0
    given = res.agreement["as recorded"]
    alt = max(READINGS[1:], key=lambda rd: res.agreement[rd.name])
    best = res.agreement[alt.name]
    if best >= min_agreement and best > given + margin:
        res.verdict = "refused"
        res.reason = (f"{alt.meaning}: neighbouring frames' depth agrees on {100 * best:.0f}% of the points "
                      f"read that way, {100 * given:.0f}% as recorded ({res.pairs} frame pairs)"
                      + (f"; {alt.remedy}" if alt.remedy else ""))
    elif given >= min_agreement:
        res.verdict = "consistent"
        res.reason = f"neighbouring frames' depth agrees on {100 * given:.0f}% of the points ({res.pairs} pairs)"
    else:
        res.verdict = "weak"
        res.reason = (f"neighbouring frames' depth agrees on only {100 * given:.0f}% of the points ({res.pairs} "
                      "pairs) and no other pose or depth reading fits better: poses of another recording, "
                      "wrong intrinsics, or frames far apart?")
    return res
