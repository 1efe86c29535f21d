"""Floor alignment: a recording in a tilted, shifted, y-down world comes back z up with the floor at 0."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.io.align import FloorConfig, fit_floor, floor_alignment, parse_up, rotation_between


@pytest.fixture(scope="module")
def frames(render_views) -> list[Frame]:  # type: ignore[no-untyped-def]
    return render_views(1, [25.0] * 8)


def _world(up: str, tilt_deg: float, yaw_deg: float, lift: float) -> np.ndarray:
    """A recording world: CapNav's +z becomes ``up``, tilted a few degrees, yawed, floor moved by ``lift``."""
    W = np.eye(4)
    R_up = rotation_between(np.array([0.0, 0.0, 1.0]), parse_up(up))  # type: ignore[arg-type]
    W[:3, :3] = Rotation.from_euler("xz", [tilt_deg, yaw_deg], degrees=True).as_matrix()
    W[:3, :3] = R_up @ W[:3, :3]
    W[:3, 3] = [0.4, -0.2, 0.7] + (-lift) * parse_up(up)  # type: ignore[operator]
    return W


@pytest.mark.parametrize("up,tilt", [("-y", 4.0), ("+z", -6.0), ("+x", 0.0)])
def test_alignment_recovers_gravity_and_floor(frames: list[Frame], up: str, tilt: float) -> None:
    W = _world(up, tilt, 30.0, 1.3)
    align = floor_alignment(((f.depth, W @ f.T_wc) for f in frames), frames[0].K, up)
    M = align.A @ W  # must be a rotation about z plus a horizontal shift (yaw and xy origin are free)
    assert np.degrees(np.arccos(np.clip(M[2, 2], -1, 1))) < 0.5
    assert abs(M[2, 3]) < 0.01
    for f in frames:
        T = align.A @ W @ f.T_wc
        assert abs(T[2, 3] - 1.25) < 0.01  # camera height above the floor survives
    assert align.info["method"] == "floor-ransac" and align.info["floor_rms_m"] < 0.01
    assert align.to_meta()["up"] == up and len(align.to_meta()["A"]) == 16


def test_floor_not_table_top() -> None:
    """A large table top above a smaller visible floor patch: the floor (lowest, enough support) wins."""
    rng = np.random.default_rng(0)
    floor = np.c_[rng.uniform(0, 4, (800, 2)), rng.normal(0, 0.003, 800)]
    table = np.c_[rng.uniform(0, 2, (2000, 2)), 0.75 + rng.normal(0, 0.003, 2000)]
    wall = np.c_[np.zeros(1500), rng.uniform(0, 4, 1500), rng.uniform(0, 2.5, 1500)]
    below = np.c_[rng.uniform(0, 4, (30, 2)), rng.uniform(-1.0, -0.2, 30)]  # stray points under the floor
    n, d, info = fit_floor(np.vstack([floor, table, wall, below]), np.array([0.0, 0.0, 1.0]))
    assert n[2] > 0.999 and abs(d) < 0.005 and info["floor_points"] >= 700


def test_up_none_keeps_frame_and_errors(frames: list[Frame]) -> None:
    assert np.array_equal(floor_alignment([], frames[0].K, "none").A, np.eye(4))
    with pytest.raises(InputError, match="--up must be one of"):
        parse_up("up")
    assert parse_up("none") is None and np.array_equal(parse_up("Y"), [0.0, 1.0, 0.0])  # type: ignore[arg-type]
    rng = np.random.default_rng(0)
    walls = np.c_[np.zeros(1000), rng.uniform(0, 4, 1000), rng.uniform(0, 2.5, 1000)]  # only vertical surfaces
    with pytest.raises(InputError, match=r"is --up right|no plane within"):
        fit_floor(np.vstack([walls, walls[:, [1, 0, 2]]]), np.array([0.0, 0.0, 1.0]), FloorConfig())
    with pytest.raises(InputError, match="only 0 depth points"):
        floor_alignment([], frames[0].K, "+z")


def test_rotation_between_opposites() -> None:
    for a in np.eye(3):
        for s in (1.0, -1.0):
            R = rotation_between(a, s * np.array([0.0, 0.0, 1.0]))
            assert np.allclose(R @ a, s * np.array([0.0, 0.0, 1.0])) and np.isclose(np.linalg.det(R), 1.0)
