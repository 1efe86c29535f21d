"""Gravity / floor alignment of an imported recording into CapNav's world (z up, floor at z = 0).

Recordings come in whatever world their tracker chose (TUM: the first camera's frame, y down;
odometry: the robot's start, z up but the floor at -0.3 m ...). The occupancy map and object
heights need the floor at z = 0, so the importer finds a rigid transform ``A`` and writes
``T_wc' = A @ T_wc`` for every frame. By default up is found from the recording itself
(``capnav.io.up_axis``: the floor, the cameras' height over it and how they are held); a user may
name the approximate axis instead, which is checked against the same evidence. The floor is the
lowest well-supported plane facing up with the cameras at a carried height above it, not
the plane with the most points (a table top under a camera looking down at it). Yaw and the horizontal origin stay as
recorded.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.geometry import Intrinsics
from capnav.io.up_axis import UpCandidate, UpConfig, UpResult, angle_deg, cue_words, find_up, nearest_axis

AXES = {"+x": (1.0, 0.0, 0.0), "-x": (-1.0, 0.0, 0.0), "+y": (0.0, 1.0, 0.0), "-y": (0.0, -1.0, 0.0),
        "+z": (0.0, 0.0, 1.0), "-z": (0.0, 0.0, -1.0)}
UP_CHOICES = ("auto", *AXES, "none")


def parse_up(up: str) -> NDArray[np.float64] | None:
    """The up direction named by ``--up``: an axis (``+z``, ``-y``, ``y`` = ``+y``, ...) or any direction
    ``x,y,z`` in the recording's frame (normalised); None for ``none`` / ``auto``."""
    key = up.strip().lower()
    if key in ("none", "auto"):
        return None
    if "," in key:
        try:
            v = np.array([float(t) for t in key.split(",")], dtype=np.float64)
        except ValueError:
            raise InputError(f"--up x,y,z needs three numbers, got {up!r}") from None
        if v.shape != (3,) or not np.isfinite(v).all() or np.linalg.norm(v) < 1e-9:
            raise InputError(f"--up x,y,z needs three finite numbers, not all 0, got {up!r}")
        return v / np.linalg.norm(v)
    if len(key) == 1:
        key = "+" + key
    if key not in AXES:
        raise InputError(f"--up must be one of {', '.join(UP_CHOICES)} or a direction x,y,z, got {up!r}")
    return np.array(AXES[key])


def rotation_between(a: NDArray[np.floating], b: NDArray[np.floating]) -> NDArray[np.float64]:
    """The smallest rotation taking unit direction ``a`` to ``b`` (Rodrigues; a half turn for opposites)."""
    a = np.asarray(a, dtype=np.float64) / np.linalg.norm(a)
    b = np.asarray(b, dtype=np.float64) / np.linalg.norm(b)
    v, c = np.cross(a, b), float(a @ b)
    if c < -1.0 + 1e-12:  # opposite: turn half a circle about any axis perpendicular to a
        p = np.eye(3)[int(np.argmin(np.abs(a)))]
        axis = np.cross(a, p)
        axis /= np.linalg.norm(axis)
        return 2.0 * np.outer(axis, axis) - np.eye(3)
    vx = np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])
    return np.eye(3) + vx + vx @ vx / (1.0 + c)


@dataclass
class Alignment:
    """The rigid transform applied to every pose, and how it was found (recorded in the dataset meta)."""

    A: NDArray[np.float64]
    up: str
    info: dict[str, Any] = field(default_factory=dict)

    def to_meta(self) -> dict[str, Any]:
        return {"up": self.up, "A": [float(v) for v in self.A.reshape(-1)], **self.info}


def identity(up: str = "none") -> Alignment:
    return Alignment(np.eye(4), up, {"method": "none"})


def floor_alignment(views: Iterable[tuple[NDArray[np.floating], NDArray[np.floating]]], K: Intrinsics,
                    up: str = "auto", cfg: UpConfig | None = None,
                    poses: NDArray[np.floating] | None = None) -> Alignment:
    """``A`` that turns the floor's normal into +z and puts the floor at z = 0.

    ``up='auto'`` finds up from the depth and the camera poses (``capnav.io.up_axis``) and refuses
    when the evidence is weak; a named axis takes the best floor within ``max_tilt_deg`` of it, and
    refuses when the evidence confidently points elsewhere or that floor leaves the world on its
    side (points below it, cameras under it); ``'none'`` keeps the recorded frame. ``poses`` are
    every frame's camera poses (the views' own when not given), for the camera cues.
    """
    auto = up.strip().lower() == "auto"
    u = parse_up(up)
    if u is None and not auto:
        return identity()
    cfg = cfg or UpConfig()
    views = list(views)
    cams = np.stack([np.asarray(T, dtype=np.float64) for _, T in views]) if poses is None and views else poses
    if cams is None or len(cams) == 0:
        raise InputError("floor alignment: no frame with depth to look for the floor in")
    res = find_up(views, K, np.asarray(cams, dtype=np.float64), cfg)
    if u is None:
        if not res.ok or res.chosen is None:
            raise InputError(f"cannot tell which way is up (confidence {res.confidence:.2f} < "
                             f"{cfg.min_confidence:.2f}): {res.reason}. Pass --up AXIS (+z, -y, ...) if you know it, "
                             "or --up none to keep the recorded frame")
        c = res.chosen
    else:
        c = named_floor(res, u, up, cfg)
    A = np.eye(4)
    A[:3, :3] = rotation_between(c.up, np.array([0.0, 0.0, 1.0]))
    A[2, 3] = -c.offset  # the plane n.p = offset becomes z = offset after the rotation
    axis, ang = nearest_axis(c.up)
    return Alignment(A, up, {"method": "floor-auto" if u is None else "floor-named",
                             "up_in_recording": [round(float(v), 6) for v in c.up], "nearest_axis": axis,
                             "axis_angle_deg": round(ang, 3), "tilt_from_up_deg": round(ang if u is None else
                                                                                          angle_deg(c.up, u), 3),
                             "confidence": round(res.confidence, 4), "floor_points": c.floor_points,
                             "floor_rms_m": c.floor_rms_m, "floor_confidence": round(c.facts["floor_confidence"], 4),
                             "floor_runner_up": None if c.runner_up_plane is None else
                             {k: round(v, 4) for k, v in c.runner_up_plane.items()},
                             "cues": {k: round(v, 4) for k, v in c.cues.items()},
                             "facts": {k: round(v, 4) for k, v in c.facts.items()}, "search": res.to_meta()})


def named_floor(res: UpResult, u: NDArray[np.float64], up: str, cfg: UpConfig) -> UpCandidate:
    """The floor for a user-named up axis, or a refusal that says what the depth shows instead."""
    found = f"the depth says up is {res.chosen.describe()} (confidence {res.confidence:.2f})" if res.chosen else ""
    if res.ok and res.chosen is not None and angle_deg(res.chosen.up, u) > cfg.max_tilt_deg:
        raise InputError(f"--up {up} contradicts the recording: {found}, {angle_deg(res.chosen.up, u):.0f} deg "
                         "from it. Drop --up to use the floor found, or --up none to keep the recorded frame")
    near = [c for c in res.candidates if angle_deg(c.up, u) <= cfg.max_tilt_deg]
    if not near:
        raise InputError(f"no floor within {cfg.max_tilt_deg:.0f} deg of --up {up} (is --up right?)"
                         + (f"; {found}" if found else f": {res.reason}"))
    c = max(near, key=lambda c: c.geometric_fit)
    if c.geometric_fit < cfg.min_confidence:
        cue = min(("support", "below", "cameras"), key=lambda k: c.cues[k])
        raise InputError(f"with --up {up} the world would be on its side: the floor found "
                         f"({c.describe()}) fails on {cue} ({cue_words(cue, c.facts)})"
                         + (f"; {found}" if found else ""))
    return c
