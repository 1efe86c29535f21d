"""Floor alignment: a recording in a tilted, shifted world comes back z up with the floor at 0, with
up found from the recording itself or checked when named; weak or contradicting evidence refuses."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from capnav.core.errors import InputError
from capnav.core.frame import Frame
from capnav.core.geometry import backproject
from capnav.io.align import floor_alignment, parse_up, rotation_between
from capnav.io.up_axis import UpConfig, choose_up, find_up

# The TUM test's world: CapNav's +z is the recording's -y, floor at y = +1.3 m.
Y_DOWN = np.eye(4)
Y_DOWN[:3, :3] = Rotation.from_euler("x", 90, degrees=True).as_matrix()
Y_DOWN[:3, 3] = [0.0, 1.3, 0.0]


@pytest.fixture(scope="module")
def frames(render_views) -> list[Frame]:  # type: ignore[no-untyped-def]
    return render_views(1, [25.0] * 8)


def _world(up: str, tilt_deg: float, yaw_deg: float, lift: float) -> np.ndarray:
    """A recording world: CapNav's +z becomes ``up``, tilted by ``tilt_deg``, yawed, floor moved by ``lift``."""
    W = np.eye(4)
    R_up = rotation_between(np.array([0.0, 0.0, 1.0]), parse_up(up))  # type: ignore[arg-type]
    W[:3, :3] = Rotation.from_euler("xz", [tilt_deg, yaw_deg], degrees=True).as_matrix()
    W[:3, :3] = R_up @ W[:3, :3]
    W[:3, 3] = [0.4, -0.2, 0.7] + (-lift) * parse_up(up)  # type: ignore[operator]
    return W


def _check_aligned(A: np.ndarray, W: np.ndarray, frames: list[Frame]) -> None:
    M = A @ W  # must be a rotation about z plus a horizontal shift (yaw and xy origin are free)
    assert np.degrees(np.arccos(np.clip(M[2, 2], -1, 1))) < 0.5
    assert abs(M[2, 3]) < 0.01
    for f in frames:
        assert abs((A @ W @ f.T_wc)[2, 3] - f.T_wc[2, 3]) < 0.01  # camera height above the floor survives


# small tilts of every axis, and tilts far from any axis (35, 60 degrees), which no axis guess covers
@pytest.mark.parametrize("up,tilt", [("-y", 4.0), ("+z", -6.0), ("+x", 0.0), ("+z", 35.0), ("-x", 60.0)])
def test_auto_finds_up_in_tilted_worlds(frames: list[Frame], up: str, tilt: float) -> None:
    W = _world(up, tilt, 30.0, 1.3)
    align = floor_alignment(((f.depth, W @ f.T_wc) for f in frames), frames[0].K, "auto")
    _check_aligned(align.A, W, frames)
    info = align.info
    assert info["method"] == "floor-auto" and info["floor_rms_m"] < 0.01 and info["confidence"] >= 0.9
    assert abs(info["facts"]["camera_height_median_m"] - 1.25) < 0.01
    assert align.to_meta()["up"] == "auto" and len(align.to_meta()["A"]) == 16


@pytest.mark.parametrize("up,tilt", [("-y", 4.0), ("+z", -6.0), ("+x", 0.0)])
def test_named_axis_is_refined(frames: list[Frame], up: str, tilt: float) -> None:
    W = _world(up, tilt, 30.0, 1.3)
    align = floor_alignment(((f.depth, W @ f.T_wc) for f in frames), frames[0].K, up)
    _check_aligned(align.A, W, frames)
    assert align.info["method"] == "floor-named" and abs(align.info["tilt_from_up_deg"] - abs(tilt)) < 0.5


def test_named_axis_contradicted(frames: list[Frame]) -> None:
    """The floor is 35 degrees from +z: --up +z (or its opposite) is refused with what the depth says."""
    W = _world("+z", 35.0, 30.0, 1.3)
    views = [(f.depth, W @ f.T_wc) for f in frames]
    with pytest.raises(InputError, match=r"--up \+z contradicts the recording: the depth says up is .* 35 deg from it"):
        floor_alignment(views, frames[0].K, "+z")
    with pytest.raises(InputError, match=r"--up -z contradicts"):
        floor_alignment(views, frames[0].K, "-z")


def test_back_wall_is_not_the_floor(wall_views) -> None:  # type: ignore[no-untyped-def]
    """The real failure: a camera looking level at a wall, the floor a strip at the bottom. The wall
    is the biggest plane by far and the camera keeps its distance to it; the floor still wins."""
    frames = wall_views(0.0)
    pts = np.concatenate([backproject(f.depth, f.K, f.T_wc)[0] for f in frames])
    counts, _ = np.histogram(pts[:, 0], bins=np.arange(pts[:, 0].min(), pts[:, 0].max() + 0.03, 0.03))
    floor_share, wall_share = np.mean(pts[:, 2] < 0.03), counts.max() / len(pts)  # wall: the densest x slice
    assert floor_share < 0.1 and wall_share > 0.3  # the hard case: the wall dominates the depth
    views = [(f.depth, Y_DOWN @ f.T_wc) for f in frames]
    align = floor_alignment(views, frames[0].K, "auto")
    _check_aligned(align.A, Y_DOWN, frames)
    assert align.info["nearest_axis"] == "-y" and align.info["confidence"] >= 0.9
    rival = align.info["search"]["runner_up"]  # the wall, beaten only by how the camera is held
    assert rival["nearest_axis"] == "-x" and rival["cues"]["upright"] == 0.0 and rival["cues"]["support"] == 1.0
    # naming the axis the wall faces (the recording's -x here) is what took the wall for the floor: refused
    with pytest.raises(InputError, match=r"--up -x contradicts the recording: the depth says up is .* from -y"):
        floor_alignment(views, frames[0].K, "-x")
    _check_aligned(floor_alignment(views, frames[0].K, "-y").A, Y_DOWN, frames)  # the right axis is accepted


def test_weak_evidence_refuses(wall_views, frames: list[Frame]) -> None:  # type: ignore[no-untyped-def]
    close = wall_views(1.2)  # 1.1 m from the wall: no floor in view, the wall is the only plane
    views = [(f.depth, Y_DOWN @ f.T_wc) for f in close]
    with pytest.raises(InputError, match=r"cannot tell which way is up \(confidence 0.00 < 0.50\): no direction "
                                         r"looks like up.* fails on upright .* --up AXIS"):
        floor_alignment(views, close[0].K, "auto")
    with pytest.raises(InputError, match=r"no floor within 20 deg of --up -y"):
        floor_alignment(views, close[0].K, "-y")
    few = [(np.where(np.arange(f.depth.size).reshape(f.depth.shape) < 40, f.depth, 0.0), f.T_wc) for f in frames[:2]]
    with pytest.raises(InputError, match=r"only \d+ depth points"):
        floor_alignment(few, frames[0].K, "auto")
    with pytest.raises(InputError, match="no frame with depth"):
        floor_alignment([], frames[0].K, "auto")


def test_two_explanations_are_ambiguous(frames: list[Frame]) -> None:
    """Cameras looking straight down at a floor: a wall facing them would fit as well (image rows say
    nothing about gravity then), so the margin, not the fit, limits the confidence."""
    rng = np.random.default_rng(0)
    floor = np.c_[rng.uniform(-2, 2, (3000, 2)), np.zeros(3000)]
    poses = np.tile(np.eye(4), (6, 1, 1))
    poses[:, :3, :3] = np.diag([1.0, -1.0, -1.0])  # optical axis down (-z), image-down along -y
    poses[:, :3, 3] = np.c_[np.linspace(-1, 1, 6), np.zeros(6), np.full(6, 1.2)]
    res = choose_up(floor, np.tile([0.0, 0.0, 1.0], (3000, 1)), poses, UpConfig())
    assert not res.ok and res.chosen is not None and res.chosen.cues["upright"] == 0.0
    assert "fails on upright" in res.reason


def test_floor_not_table_top() -> None:
    """A large table top above a smaller visible floor patch: the floor (lowest, enough support) wins."""
    rng = np.random.default_rng(0)
    floor = np.c_[rng.uniform(0, 4, (800, 2)), rng.normal(0, 0.003, 800)]
    table = np.c_[rng.uniform(0, 2, (2000, 2)), 0.75 + rng.normal(0, 0.003, 2000)]
    wall = np.c_[np.zeros(1500), rng.uniform(0, 4, 1500), rng.uniform(0, 2.5, 1500)]
    below = np.c_[rng.uniform(0, 4, (30, 2)), rng.uniform(-1.0, -0.2, 30)]  # stray points under the floor
    P = np.vstack([floor, table, wall, below])
    N = np.vstack([np.tile([0.0, 0.0, 1.0], (2800, 1)), np.tile([1.0, 0.0, 0.0], (1500, 1)),
                   np.full((30, 3), np.nan)])
    poses = np.stack([np.asarray(np.block([[Rotation.from_euler("xz", [-110, 30 * k], degrees=True).as_matrix(),
                                            np.array([[1.0 + 0.4 * k], [1.0 + 0.3 * (k % 2)], [1.3]])],
                                           [np.zeros((1, 3)), np.ones((1, 1))]])) for k in range(5)])
    res = choose_up(P, N, poses, UpConfig())
    assert res.ok and res.chosen is not None
    assert res.chosen.up[2] > 0.999 and abs(res.chosen.offset) < 0.005 and res.chosen.floor_points >= 700
    assert res.chosen.cues["below"] > 0.9  # 30 of 4330 points below the floor: noise, not a contradiction


def test_up_none_keeps_frame_and_errors(frames: list[Frame]) -> None:
    assert np.array_equal(floor_alignment([], frames[0].K, "none").A, np.eye(4))
    with pytest.raises(InputError, match="--up must be one of auto"):
        parse_up("up")
    assert parse_up("none") is None and parse_up("auto") is None
    assert np.array_equal(parse_up("Y"), [0.0, 1.0, 0.0])  # type: ignore[arg-type]


def test_find_up_on_real_frame(shared_dir) -> None:  # type: ignore[no-untyped-def]
    """The real TUM desk frame (one frame, camera axes as recorded): the floor under the desk, about
    1.8 m below a camera pitched down about 30 degrees (looking at it: the desk's front edge and the
    floor fill the lower half)."""
    from PIL import Image

    from capnav.core.geometry import Intrinsics

    depth = np.asarray(Image.open(shared_dir / "realdata" / "TUM_depth.png"), dtype=np.float32) / 5000.0
    K = Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)
    res = find_up([(depth, np.eye(4))], K, np.eye(4)[None])
    assert res.ok and res.chosen is not None
    f = res.chosen.facts
    assert 15.0 < f["upright_deg"] < 45.0 and 1.0 < f["camera_height_median_m"] < 2.2 and f["floor_share"] > 0.1


def test_rotation_between_opposites() -> None:
    for a in np.eye(3):
        for s in (1.0, -1.0):
            R = rotation_between(a, s * np.array([0.0, 0.0, 1.0]))
            assert np.allclose(R @ a, s * np.array([0.0, 0.0, 1.0])) and np.isclose(np.linalg.det(R), 1.0)


def test_named_axis_leaving_the_world_on_its_side() -> None:
    """Cameras looking straight down (the depth cannot tell up by itself) over a floor with a third
    of the points scattered under it: a named +z is refused, naming the cue that fails."""
    from capnav.io.align import named_floor

    rng = np.random.default_rng(1)
    floor = np.c_[rng.uniform(-2, 2, (3000, 2)), np.zeros(3000)]
    under = np.c_[rng.uniform(-2, 2, (1500, 2)), rng.uniform(-2.0, -0.3, 1500)]
    N = np.vstack([np.tile([0.0, 0.0, 1.0], (3000, 1)), np.full((1500, 3), np.nan)])
    poses = np.tile(np.eye(4), (6, 1, 1))
    poses[:, :3, :3] = np.diag([1.0, -1.0, -1.0])
    poses[:, :3, 3] = np.c_[np.linspace(-1, 1, 6), np.zeros(6), np.full(6, 1.2)]
    cfg = UpConfig()
    res = choose_up(np.vstack([floor, under]), N, poses, cfg)
    assert not res.ok  # no confident auto choice to contradict: the named axis is judged on its own
    with pytest.raises(InputError, match=r"with --up \+z the world would be on its side: .* fails on below "
                                         r"\(33% of the depth points lie below that floor\)"):
        named_floor(res, np.array([0.0, 0.0, 1.0]), "+z", cfg)
    clean = choose_up(floor, N[:3000], poses, cfg)
    assert named_floor(clean, np.array([0.0, 0.0, 1.0]), "+z", cfg).up[2] > 0.999  # the same floor, nothing under
