import numpy as np
import pytest

from capnav.core.errors import InputError, PoseError
from capnav.core.geometry import Intrinsics, backproject, check_pose, look_at_pose, project


def test_backproject_then_project_roundtrip() -> None:
    K = Intrinsics.from_fov(64, 48, 60.0)
    rng = np.random.default_rng(0)
    depth = rng.uniform(0.5, 4.0, size=(48, 64)).astype(np.float32)
    depth[3, 5] = np.nan
    depth[10, 10] = 0.0
    T = look_at_pose([1.0, -2.0, 1.2], yaw=0.7, pitch=0.3)
    pts, flat = backproject(depth, K, T)
    assert len(pts) == 48 * 64 - 2  # the NaN and the zero are skipped
    uv, z = project(pts, K, T)
    v, u = np.divmod(flat, 64)
    np.testing.assert_allclose(uv[:, 0], u, atol=1e-3)
    np.testing.assert_allclose(uv[:, 1], v, atol=1e-3)
    np.testing.assert_allclose(z, depth.reshape(-1)[flat], rtol=1e-5)


def test_eq2_matches_direct_formula() -> None:
    K = Intrinsics(fx=100.0, fy=120.0, cx=30.0, cy=20.0, width=60, height=40)
    depth = np.zeros((40, 60), np.float32)
    depth[7, 11] = 2.0
    pts, _ = backproject(depth, K)
    np.testing.assert_allclose(pts[0], [(11 - 30) * 2.0 / 100.0, (7 - 20) * 2.0 / 120.0, 2.0], rtol=1e-6)


def test_look_at_is_opencv_and_z_up() -> None:
    T = look_at_pose([0, 0, 1.5], yaw=0.0)
    np.testing.assert_allclose(T[:3, 2], [1, 0, 0], atol=1e-12)  # camera z looks along world +x
    np.testing.assert_allclose(T[:3, 1], [0, 0, -1], atol=1e-12)  # camera y (down) is world -z
    check_pose(T)


@pytest.mark.parametrize(
    "bad, msg",
    [
        (np.eye(3), "4x4"),
        (np.diag([1.0, 1.0, -1.0, 1.0]), "det"),
        (np.diag([2.0, 1.0, 1.0, 1.0]), "orthonormal"),
        (np.full((4, 4), np.nan), "non-finite"),
    ],
)
def test_check_pose_rejects_non_rigid(bad: np.ndarray, msg: str) -> None:
    with pytest.raises(PoseError, match=msg) as e:
        check_pose(bad, frame=17)
    assert "frame 17" in str(e.value)


def test_intrinsics_validation() -> None:
    with pytest.raises(InputError):
        Intrinsics(fx=-1, fy=1, cx=0, cy=0, width=10, height=10)
    with pytest.raises(InputError, match="shape"):
        backproject(np.ones((5, 5), np.float32), Intrinsics.from_fov(10, 10, 60))
