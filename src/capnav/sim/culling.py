"""Room-level portal culling: which rooms a camera can possibly see, through chains of doors.

pybullet's tiny renderer pays for every triangle whose screen box is on screen, even when a wall
hides it. A room is kept only when a chain of door openings leads to it from the camera's room
with a non-empty screen window: each opening's projected box is intersected with the window it
is seen through (classic portal culling with rectangles). The test is conservative, so culling
never changes a rendered pixel (tests/sim/test_render.py checks bit-equality).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from capnav.core.geometry import Intrinsics
from capnav.sim.layout import FloorPlan

Window = tuple[float, float, float, float]  # u0, u1, v0, v1 in pixels


class RoomCuller:
    """Precomputes door openings of an apartment; ``visible(T_wc, K)`` returns room indices."""

    def __init__(self, plan: FloorPlan, height: float, near: float, margin: float = 1e-6) -> None:
        self.plan = plan
        self.near = near
        self.margin = margin
        corners = []
        for d in plan.doors:
            ends = [(d.coord, d.lo), (d.coord, d.hi)] if d.axis == "x" else [(d.lo, d.coord), (d.hi, d.coord)]
            corners.append(np.array([[x, y, z] for (x, y) in ends for z in (0.0, height)]))
        self.corners = corners
        self.by_room: dict[int, list[tuple[int, int]]] = {i: [] for i in range(len(plan.rooms))}
        for k, d in enumerate(plan.doors):
            self.by_room[d.rooms[0]].append((k, d.rooms[1]))
            self.by_room[d.rooms[1]].append((k, d.rooms[0]))

    def _door_window(self, k: int, T_cw: NDArray[np.float64], K: Intrinsics) -> Window | None:
        """Screen box of door ``k``'s opening; None if behind the camera; full screen if it straddles."""
        pc = self.corners[k] @ T_cw[:3, :3].T + T_cw[:3, 3]
        front = pc[:, 2] > self.near
        if not front.any():
            return None
        if not front.all():  # crosses the camera plane: be conservative
            return (-np.inf, np.inf, -np.inf, np.inf)
        u = K.fx * pc[:, 0] / pc[:, 2] + K.cx
        v = K.fy * pc[:, 1] / pc[:, 2] + K.cy
        return (float(u.min()) - 1.0, float(u.max()) + 1.0, float(v.min()) - 1.0, float(v.max()) + 1.0)

    def visible(self, T_wc: NDArray[np.float64], K: Intrinsics) -> set[int]:
        eye = T_wc[:3, 3]
        T_cw = np.linalg.inv(np.asarray(T_wc, dtype=np.float64))
        start = [i for i, r in enumerate(self.plan.rooms)
                 if r.x0 - self.margin <= eye[0] <= r.x1 + self.margin
                 and r.y0 - self.margin <= eye[1] <= r.y1 + self.margin]
        screen: Window = (-0.5, K.width + 0.5, -0.5, K.height + 0.5)
        windows: dict[int, Window | None] = {}
        seen = set(start)
        stack: list[tuple[int, Window, frozenset[int]]] = [(r, screen, frozenset([r])) for r in start]
        while stack:
            room, win, path = stack.pop()
            for k, other in self.by_room[room]:
                if other in path:
                    continue
                if k not in windows:
                    windows[k] = self._door_window(k, T_cw, K)
                dw = windows[k]
                if dw is None:
                    continue
                clip = (max(win[0], dw[0]), min(win[1], dw[1]), max(win[2], dw[2]), min(win[3], dw[3]))
                if clip[0] >= clip[1] or clip[2] >= clip[3]:
                    continue
                seen.add(other)
                stack.append((other, clip, path | {other}))
        return seen
