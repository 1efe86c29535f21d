"""The embodied agent: a cylinder that turns, steps and follows waypoints without passing obstacles."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import look_at_pose

if TYPE_CHECKING:
    from capnav.core.geometry import Intrinsics
    from capnav.sim.config import SimConfig
    from capnav.sim.manifest import SceneManifest


class AgentWorld(Protocol):
    """What an agent needs of its world (``capnav.sim.Simulator``, which imports this module: typed
    structurally so the two do not import each other)."""

    config: SimConfig

    @property
    def manifest(self) -> SceneManifest: ...

    def collides(self, x: float, y: float) -> bool: ...

    def collides_many(self, xy: NDArray[np.floating]) -> NDArray[np.bool_]: ...

    def render(self, T_wc: NDArray[np.floating], K: Intrinsics | None = None, index: int = 0) -> Frame: ...

ACTIONS = ("move_forward", "turn_left", "turn_right", "stop")
_SWEEP = 0.02  # collision sampling step along a motion (m); refined by bisection to 1 mm


class Agent:
    """Position (x, y), heading ``yaw`` (radians from +x towards +y); radius/height from SimConfig.agent.

    Motion is checked against the true 2D geometry (agent disk vs. wall slabs and furniture
    footprints); a blocked motion stops at contact and reports False.
    """

    def __init__(self, sim: AgentWorld, x: float, y: float, yaw: float = 0.0) -> None:
        if not all(math.isfinite(v) for v in (x, y, yaw)):
            raise InputError(f"agent pose must be finite, got ({x}, {y}, {yaw})")
        if sim.collides(x, y):
            x0, y0, x1, y1 = sim.manifest.bounds
            where = ("it is outside the apartment, which spans "
                     f"x in [{x0:.2f}, {x1:.2f}], y in [{y0:.2f}, {y1:.2f}]"
                     if not (x0 < x < x1 and y0 < y < y1) else "it would overlap a wall or furniture")
            raise InputError(f"cannot spawn the agent at ({x:.2f}, {y:.2f}): {where}")
        self.sim = sim
        self.cfg = sim.config.agent
        self.x, self.y, self.yaw = float(x), float(y), _wrap(float(yaw))
        self.trajectory: list[tuple[float, float, float]] = [self.pose]
        self.path_length = 0.0
        self.steps = 0
        self.collisions = 0

    @property
    def pose(self) -> tuple[float, float, float]:
        return (self.x, self.y, self.yaw)

    def camera_pose(self, pitch: float = 0.0) -> NDArray[np.float64]:
        """T_wc of the head camera (OpenCV), tilted down by ``pitch`` radians."""
        return look_at_pose(np.array([self.x, self.y, self.cfg.camera_height]), self.yaw, pitch)

    def observe(self, index: int | None = None, pitch: float = 0.0) -> Frame:
        return self.sim.render(self.camera_pose(pitch), index=self.steps if index is None else index)

    def step(self, action: str) -> bool:
        """Apply a discrete action; returns False when a forward move was blocked."""
        if action not in ACTIONS:
            raise InputError(f"unknown action {action!r}; valid: {', '.join(ACTIONS)}")
        self.steps += 1
        turn = math.radians(self.cfg.turn_deg)
        if action == "turn_left":
            self.yaw = _wrap(self.yaw + turn)
        elif action == "turn_right":
            self.yaw = _wrap(self.yaw - turn)
        elif action == "move_forward":
            gx = self.x + self.cfg.forward_step * math.cos(self.yaw)
            gy = self.y + self.cfg.forward_step * math.sin(self.yaw)
            ok = self._translate(gx, gy)
            self.trajectory.append(self.pose)
            return ok
        self.trajectory.append(self.pose)
        return True

    def move_to(self, x: float, y: float) -> bool:
        """Turn towards (x, y) and move straight to it; stop at first contact (returns False)."""
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InputError(f"waypoint must be finite, got ({x}, {y})")
        if math.hypot(x - self.x, y - self.y) > 1e-9:
            self.yaw = math.atan2(y - self.y, x - self.x)
        ok = self._translate(x, y)
        self.steps += 1
        self.trajectory.append(self.pose)
        return ok

    def _translate(self, gx: float, gy: float) -> bool:
        sx, sy = self.x, self.y
        dist = math.hypot(gx - sx, gy - sy)
        if dist < 1e-12:
            return True
        n = max(1, math.ceil(dist / _SWEEP))
        ts = np.linspace(0.0, 1.0, n + 1)[1:]
        pts = np.stack([sx + ts * (gx - sx), sy + ts * (gy - sy)], axis=1)
        hit = self.sim.collides_many(pts)
        if not hit.any():
            t_ok = 1.0
        else:
            k = int(np.argmax(hit))
            lo, hi = (0.0 if k == 0 else float(ts[k - 1])), float(ts[k])
            while (hi - lo) * dist > 1e-3:  # bisection to 1 mm of the contact point
                mid = (lo + hi) / 2
                if self.sim.collides(sx + mid * (gx - sx), sy + mid * (gy - sy)):
                    hi = mid
                else:
                    lo = mid
            t_ok = lo
            self.collisions += 1
        self.x, self.y = sx + t_ok * (gx - sx), sy + t_ok * (gy - sy)
        self.path_length += t_ok * dist
        return not hit.any()


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi
