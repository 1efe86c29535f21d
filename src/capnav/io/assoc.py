"""Timestamp association shared by the recording importers (TUM, ROS bags).

Recordings log colour, depth and poses as separate streams with their own clocks and rates; a
CapNav frame needs all three at one instant. Colour is the reference stream: each colour image
takes the depth image nearest in time (mutual nearest, so no depth image is used twice) and the
pose interpolated at its timestamp. Every dropped colour image gets a reason, never silence.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, PoseError


@dataclass(frozen=True)
class Skip:
    """One recording frame that did not make it into the dataset, and why."""

    name: str  # what the user can find in the recording (file name, topic + stamp)
    timestamp: float
    reason: str  # short category: "no depth within max-dt", "no pose", ...
    detail: str = ""


@dataclass
class SkipLog:
    """Skipped frames by reason; the CLI prints the counts and a few examples of each."""

    skips: list[Skip] = field(default_factory=list)

    def add(self, name: str, timestamp: float, reason: str, detail: str = "") -> None:
        self.skips.append(Skip(name, float(timestamp), reason, detail))

    def counts(self) -> dict[str, int]:
        return dict(Counter(s.reason for s in self.skips).most_common())

    def __len__(self) -> int:
        return len(self.skips)

    def examples(self, reason: str, n: int = 3) -> list[Skip]:
        return [s for s in self.skips if s.reason == reason][:n]


def match_nearest(ref: NDArray[np.floating], other: NDArray[np.floating],
                  max_dt: float) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """For each ``ref`` stamp, the index of the mutually nearest ``other`` stamp within ``max_dt``, else -1.

    Mutual nearest keeps the pairing one-to-one when the streams run at different rates. Also
    returns the time difference to the nearest ``other`` stamp (inf when ``other`` is empty).
    """
    ref = np.asarray(ref, dtype=np.float64)
    other = np.asarray(other, dtype=np.float64)
    if other.size == 0 or ref.size == 0:
        return np.full(ref.shape, -1, dtype=np.intp), np.full(ref.shape, np.inf)
    order = np.argsort(other, kind="stable")
    srt = other[order]
    j = _nearest_sorted(srt, ref)
    dt = np.abs(srt[j] - ref)
    # which ref stamp is nearest to each other stamp: mutual nearest only
    rorder = np.argsort(ref, kind="stable")
    back = rorder[_nearest_sorted(ref[rorder], srt)]
    mutual = back[j] == np.arange(ref.size)
    idx = np.where((dt <= max_dt) & mutual, order[j], -1)
    return idx.astype(np.intp), dt


def _nearest_sorted(srt: NDArray[np.floating], q: NDArray[np.floating]) -> NDArray[np.intp]:
    hi = np.clip(np.searchsorted(srt, q), 1, len(srt) - 1) if len(srt) > 1 else np.zeros(q.shape, dtype=np.intp)
    lo = np.maximum(hi - 1, 0)
    return np.where(np.abs(srt[lo] - q) <= np.abs(srt[hi] - q), lo, hi).astype(np.intp)


def poses_from_quat(t: NDArray[np.floating], xyz: NDArray[np.floating], quat_xyzw: NDArray[np.floating],
                    names: list[str], tol: float = 1e-2) -> NDArray[np.float64]:
    """4x4 poses from translations and (x, y, z, w) quaternions; a quaternion whose norm is not ~1 or a
    non-finite value is not a rigid pose and raises ``PoseError`` naming ``names[i]`` (file line, topic)."""
    from scipy.spatial.transform import Rotation

    xyz = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
    q = np.asarray(quat_xyzw, dtype=np.float64).reshape(-1, 4)
    finite = np.isfinite(xyz).all(axis=1) & np.isfinite(q).all(axis=1) & np.isfinite(np.asarray(t, dtype=float))
    norm = np.linalg.norm(q, axis=1)
    bad = np.flatnonzero(~finite | (np.abs(norm - 1.0) > tol))
    if bad.size:
        i = int(bad[0])
        why = "non-finite values" if not finite[i] else f"quaternion norm {norm[i]:.4g} (a rigid pose needs 1)"
        raise PoseError(names[i], f"not a rigid pose: {why}" + (f" ({bad.size} such poses)" if bad.size > 1 else ""))
    T = np.tile(np.eye(4), (len(q), 1, 1))
    if len(q):
        T[:, :3, :3] = Rotation.from_quat(q / norm[:, None]).as_matrix()
    T[:, :3, 3] = xyz
    return T


def check_gap(max_gap: float) -> None:
    """``--max-pose-gap`` is a duration: a negative one would silently drop every frame."""
    if not (max_gap >= 0 and np.isfinite(max_gap)):
        raise InputError(f"--max-pose-gap must be a number of seconds >= 0, got {max_gap}")


class PoseTrack:
    """Poses at irregular stamps, interpolated in between (linear translation, slerp rotation).

    A query more than ``max_dt`` before the first / after the last stamp has no pose; closer ones take
    the end pose. Queries between two stamps more than ``max_gap`` apart have no pose either (the
    tracker lost the camera there, and a straight line through the gap would be made up).
    """

    def __init__(self, stamps: NDArray[np.floating], poses: NDArray[np.floating], source: str) -> None:
        stamps = np.asarray(stamps, dtype=np.float64)
        poses = np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)
        if stamps.size == 0:
            raise InputError(f"{source}: no poses")
        order = np.argsort(stamps, kind="stable")
        stamps, poses = stamps[order], poses[order]
        keep = np.concatenate([[True], np.diff(stamps) > 0])  # duplicate stamps: keep the first
        self.stamps, self.poses, self.source = stamps[keep], poses[keep], source

    def __len__(self) -> int:
        return int(self.stamps.size)

    def at(self, t: NDArray[np.floating], max_dt: float,
           max_gap: float) -> tuple[NDArray[np.float64], NDArray[np.bool_], list[str]]:
        """Poses at ``t`` (N, 4, 4), a mask of which exist, and the reason for each missing one ('' if ok)."""
        from scipy.spatial.transform import Rotation, Slerp

        check_gap(max_gap)
        t = np.asarray(t, dtype=np.float64)
        s = self.stamps
        out = np.tile(np.eye(4), (t.size, 1, 1))
        tc = np.clip(t, s[0], s[-1])
        outside = np.abs(tc - t) > max_dt
        hi = np.clip(np.searchsorted(s, tc, side="left"), 0, len(s) - 1)
        lo = np.where(s[hi] > tc, np.maximum(hi - 1, 0), hi)
        gap = s[hi] - s[lo]
        gapped = ~outside & (gap > max_gap)
        ok = ~outside & ~gapped
        if len(s) == 1:
            out[:] = self.poses[0]
        else:
            rot = Slerp(s, Rotation.from_matrix(self.poses[:, :3, :3]))(tc)
            out[:, :3, :3] = rot.as_matrix()
            for k in range(3):
                out[:, k, 3] = np.interp(tc, s, self.poses[:, k, 3])
        reasons = ["" if o else (f"outside the pose stamps [{s[0]:.3f}, {s[-1]:.3f}] by more than {max_dt} s"
                                 if out_ else f"pose stamps around it are {g:.2f} s apart (> {max_gap} s)")
                   for o, out_, g in zip(ok.tolist(), outside.tolist(), gap.tolist(), strict=True)]
        return out, ok, reasons
