"""ROS bag import: simulator frames written as real ROS1 and ROS2 bags by the rosbags library's own writers
and serialisers come back as the original z-up poses; association, skip reports and topic errors."""

from __future__ import annotations

import dataclasses
import io
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

from capnav.cli import app
from capnav.core.errors import InputError, PoseError
from capnav.core.frame import Frame
from capnav.io.dataset import DatasetReader
from capnav.io.importer import import_recording
from capnav.io.rosbag import RosbagReader, parse_extrinsic

pytest.importorskip("rosbags")
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore

T0 = 1_700_000_000.0
# camera optical frame in a robot body frame (x forward, z up): optical z = body x, x = -y, y = -z
T_BC = np.eye(4)
T_BC[:3, :3] = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
T_BC[:3, 3] = [0.12, 0.0, 1.05]
EXTRINSIC = ",".join(repr(float(v)) for v in (*T_BC[:3, 3], *Rotation.from_matrix(T_BC[:3, :3]).as_quat()))


def _world(up_y: bool) -> np.ndarray:
    """The recording's world: z up with the floor at z = -0.3 m, or y down with the floor at y = 1.3 m."""
    W = np.eye(4)
    if up_y:
        W[:3, :3] = Rotation.from_euler("x", 90, degrees=True).as_matrix()
        W[:3, 3] = [0.0, 1.3, 0.0]
    else:
        W[:3, 3] = [0.0, 0.0, -0.3]
    return W


@pytest.fixture(scope="module")
def frames(render_views) -> list[Frame]:  # type: ignore[no-untyped-def]
    return render_views(5, [22.0] * 5)


def _make(ts: Any, name: str, **kw: Any) -> Any:
    """A message of type ``name``; ROS1/ROS2 field spellings differ (K/k, seq), so pick what the type has."""
    cls = ts.types[name]
    fields = {f.name for f in dataclasses.fields(cls)}
    args = {}
    for k, v in kw.items():
        key = k if k in fields else k.lower()
        if key in fields:
            args[key] = v
    if "seq" in fields:
        args.setdefault("seq", 0)
    return cls(**args)


def _header(ts: Any, stamp: float, frame: str = "camera") -> Any:
    sec = int(stamp)
    t = _make(ts, "builtin_interfaces/msg/Time", sec=sec, nanosec=round((stamp - sec) * 1e9))
    return _make(ts, "std_msgs/msg/Header", stamp=t, frame_id=frame)


def _pose(ts: Any, T: np.ndarray) -> Any:
    q = Rotation.from_matrix(T[:3, :3]).as_quat()
    return _make(ts, "geometry_msgs/msg/Pose",
                 position=_make(ts, "geometry_msgs/msg/Point", x=T[0, 3], y=T[1, 3], z=T[2, 3]),
                 orientation=_make(ts, "geometry_msgs/msg/Quaternion", x=q[0], y=q[1], z=q[2], w=q[3]))


def _image(ts: Any, stamp: float, arr: np.ndarray, encoding: str, pad: int = 0) -> Any:
    h, w = arr.shape[:2]
    raw = np.ascontiguousarray(arr).view(np.uint8).reshape(h, -1)
    step = raw.shape[1] + pad
    data = np.zeros((h, step), dtype=np.uint8)
    data[:, :raw.shape[1]] = raw
    return _make(ts, "sensor_msgs/msg/Image", header=_header(ts, stamp), height=h, width=w, encoding=encoding,
                 is_bigendian=0, step=step, data=data.reshape(-1))


def write_bag(path: Path, frames: list[Frame], ros2: bool, drop_depth: tuple[int, ...] = (),
              extra_pose: np.ndarray | None = None) -> None:
    """ROS1: bgr8 Image (padded rows), 16UC1 depth, Odometry of the body frame in a z-up world.
    ROS2: png CompressedImage, 32FC1 depth (NaN = no reading), PoseStamped of the camera in a y-down world."""
    ts = get_typestore(Stores.LATEST if ros2 else Stores.ROS1_NOETIC)
    W = _world(ros2)
    K = frames[0].K
    msgs: list[tuple[float, str, str, Any]] = []
    info = _make(ts, "sensor_msgs/msg/CameraInfo", header=_header(ts, T0), height=K.height, width=K.width,
                 distortion_model="plumb_bob", D=np.zeros(5), K=K.K.reshape(-1), R=np.eye(3).reshape(-1),
                 P=np.c_[K.K, np.zeros(3)].reshape(-1), binning_x=0, binning_y=0,
                 roi=_make(ts, "sensor_msgs/msg/RegionOfInterest", x_offset=0, y_offset=0, height=0, width=0,
                           do_rectify=False))
    msgs.append((T0, "/camera/color/camera_info", "sensor_msgs/msg/CameraInfo", info))
    for i, f in enumerate(frames):
        t = T0 + 0.1 * i
        if ros2:
            buf = io.BytesIO()
            Image.fromarray(f.rgb).save(buf, format="PNG")
            rgb = _make(ts, "sensor_msgs/msg/CompressedImage", header=_header(ts, t), format="rgb8; png compressed",
                        data=np.frombuffer(buf.getvalue(), dtype=np.uint8))
            msgs.append((t, "/camera/color/image_raw/compressed", "sensor_msgs/msg/CompressedImage", rgb))
            depth = np.where(f.valid_depth(), f.depth, np.nan).astype("<f4")
            dmsg = _image(ts, t + 0.003, depth, "32FC1")
        else:
            msgs.append((t, "/camera/color/image_raw", "sensor_msgs/msg/Image",
                         _image(ts, t, f.rgb[..., ::-1], "bgr8", pad=4)))
            mm = np.where(f.valid_depth(), np.round(f.depth * 1000), 0).astype("<u2")
            dmsg = _image(ts, t + 0.003, mm, "16UC1")
        if i not in drop_depth:
            msgs.append((t + 0.003, "/camera/depth/image_raw", "sensor_msgs/msg/Image", dmsg))
        T = W @ f.T_wc
        for s in (-1.0, 1.0):  # two poses 20 ms either side, only interpolation gives the frame's pose
            D = np.eye(4)
            D[:3, :3] = Rotation.from_rotvec(s * np.radians(2.0) * np.array([0.0, 0.6, 0.8])).as_matrix()
            D[:3, 3] = s * np.array([0.01, 0.02, -0.01])
            Tp = T @ D
            if ros2:
                msgs.append((t + 0.02 * s, "/camera/pose", "geometry_msgs/msg/PoseStamped",
                             _make(ts, "geometry_msgs/msg/PoseStamped", header=_header(ts, t + 0.02 * s, "map"),
                                   pose=_pose(ts, Tp))))
            else:
                Tb = Tp @ np.linalg.inv(T_BC)
                cov = np.zeros(36)
                twist = _make(ts, "geometry_msgs/msg/Twist", linear=_make(ts, "geometry_msgs/msg/Vector3", x=0, y=0,
                                                                           z=0),
                              angular=_make(ts, "geometry_msgs/msg/Vector3", x=0, y=0, z=0))
                odo = _make(ts, "nav_msgs/msg/Odometry", header=_header(ts, t + 0.02 * s, "odom"),
                            child_frame_id="base_link",
                            pose=_make(ts, "geometry_msgs/msg/PoseWithCovariance", pose=_pose(ts, Tb), covariance=cov),
                            twist=_make(ts, "geometry_msgs/msg/TwistWithCovariance", twist=twist, covariance=cov))
                msgs.append((t + 0.02 * s, "/odom", "nav_msgs/msg/Odometry", odo))
    if extra_pose is not None:
        bad = _make(ts, "geometry_msgs/msg/Pose", position=_make(ts, "geometry_msgs/msg/Point", x=0.0, y=0.0, z=0.0),
                    orientation=_make(ts, "geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=0.0, w=float(extra_pose[0])))
        msgs.append((T0 + 10.0, "/camera/pose", "geometry_msgs/msg/PoseStamped",
                     _make(ts, "geometry_msgs/msg/PoseStamped", header=_header(ts, T0 + 10.0, "map"), pose=bad)))
    msgs.sort(key=lambda m: m[0])
    writer: Any = Writer2(path, version=9) if ros2 else Writer1(path)
    with writer:
        conns: dict[str, Any] = {}
        for t, topic, typ, msg in msgs:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, typ, typestore=ts)
            data = ts.serialize_cdr(msg, typ) if ros2 else ts.serialize_ros1(msg, typ)
            writer.write(conns[topic], round((t + 0.005) * 1e9), data)  # received 5 ms after the stamp


def _pose_err(A: np.ndarray, B: np.ndarray) -> tuple[float, float]:
    c = (np.trace(A[:3, :3].T @ B[:3, :3]) - 1) / 2
    return float(np.linalg.norm(A[:3, 3] - B[:3, 3])), float(np.degrees(np.arccos(np.clip(c, -1, 1))))


def _check(ds_path: Path, frames: list[Frame], skip: tuple[int, ...] = ()) -> None:
    ds = DatasetReader(ds_path)
    kept = [f for i, f in enumerate(frames) if i not in skip]
    assert len(ds) == len(kept) and ds.intrinsics == frames[0].K
    for g, orig in zip(ds, kept, strict=True):
        dt, dr = _pose_err(g.T_wc, orig.T_wc)
        assert dt < 0.01 and dr < 1.0, (g.index, dt, dr)
        assert np.array_equal(g.rgb, orig.rgb)
        ok = orig.valid_depth()
        assert np.array_equal(g.depth > 0, ok)
        assert np.abs(g.depth[ok] - orig.depth[ok]).max() < 0.0011
        assert abs(g.timestamp - (T0 + 0.1 * orig.index)) < 1e-6


def test_ros1_bag_body_pose_with_extrinsic(tmp_path: Path, frames: list[Frame]) -> None:
    bag = tmp_path / "run.bag"
    write_bag(bag, frames, ros2=False, drop_depth=(3,))
    rec = RosbagReader(bag, "/camera/color/image_raw", "/camera/depth/image_raw", "/camera/color/camera_info",
                       "/odom", camera_in_body=EXTRINSIC)
    assert rec.msgtypes["pose"] == "nav_msgs/msg/Odometry" and rec.K == frames[0].K
    assert rec.skipped.counts() == {"no depth within max-dt 0.02 s": 1}
    assert rec.skipped.skips[0].name.startswith("/camera/color/image_raw message 3 ")
    report = import_recording(rec, tmp_path / "ds", up="+z", progress=False)
    assert report.written == 4 and abs(report.alignment.A[2, 3] - 0.3) < 0.01
    _check(tmp_path / "ds", frames, skip=(3,))
    meta = DatasetReader(tmp_path / "ds").meta["meta"]
    assert meta["source"] == "rosbag" and meta["topics"]["pose"] == "/odom" and meta["camera_in_body"] is not None


def test_ros2_bag_camera_pose(tmp_path: Path, frames: list[Frame]) -> None:
    bag = tmp_path / "run2"
    write_bag(bag, frames, ros2=True)
    rec = RosbagReader(bag, "/camera/color/image_raw/compressed", "/camera/depth/image_raw",
                       "/camera/color/camera_info", "/camera/pose")
    assert len(rec.frames) == 5 and len(rec.skipped) == 0
    import_recording(rec, tmp_path / "ds", up="-y", progress=False)
    _check(tmp_path / "ds", frames)
    # max-dt tighter than the 3 ms colour-depth offset: every frame is reported, none is written
    rec = RosbagReader(bag, "/camera/color/image_raw/compressed", "/camera/depth/image_raw",
                       "/camera/color/camera_info", "/camera/pose", max_dt=0.001)
    assert rec.skipped.counts() == {"no depth within max-dt 0.001 s": 5}
    with pytest.raises(InputError, match=r"no frame to import .*5 no depth within max-dt"):
        import_recording(rec, tmp_path / "ds2", progress=False)
    assert not (tmp_path / "ds2").exists()


def test_topic_errors_list_the_bag(tmp_path: Path, frames: list[Frame]) -> None:
    bag = tmp_path / "run.bag"
    write_bag(bag, frames[:2], ros2=False)
    args = ("/camera/color/image_raw", "/camera/depth/image_raw", "/camera/color/camera_info")
    with pytest.raises(InputError, match=r"no topic '/camera/pose' \(--pose-topic\); its topics: "
                                         r"/camera/color/camera_info \(sensor_msgs/msg/CameraInfo, 1 msgs\), .*"
                                         r"/odom \(nav_msgs/msg/Odometry, 4 msgs\)"):
        RosbagReader(bag, *args, "/camera/pose")
    with pytest.raises(InputError, match=r"--pose-topic '/camera/color/image_raw' carries sensor_msgs/msg/Image"):
        RosbagReader(bag, *args, "/camera/color/image_raw")
    with pytest.raises(InputError, match="bag not found"):
        RosbagReader(tmp_path / "none.bag", *args, "/odom")
    with pytest.raises(InputError, match="--camera-in-body must be 7 numbers"):
        RosbagReader(bag, *args, "/odom", camera_in_body="1,2,3")
    with pytest.raises(PoseError, match="--camera-in-body: not a rigid pose"):
        parse_extrinsic("0,0,0,0,0,0,3")


def test_non_rigid_pose_is_named(tmp_path: Path, frames: list[Frame]) -> None:
    bag = tmp_path / "bad"
    write_bag(bag, frames[:2], ros2=True, extra_pose=np.array([5.0]))
    with pytest.raises(PoseError, match=r"/camera/pose message 4 \(stamp 1700000010.0+\): not a rigid pose: "
                                        r"quaternion norm 5"):
        RosbagReader(bag, "/camera/color/image_raw/compressed", "/camera/depth/image_raw",
                     "/camera/color/camera_info", "/camera/pose")


def test_cli(tmp_path: Path, frames: list[Frame]) -> None:
    bag = tmp_path / "run.bag"
    write_bag(bag, frames[:3], ros2=False)
    res = CliRunner().invoke(app, ["import", "rosbag", str(bag), "-o", str(tmp_path / "ds"),
                                   "--rgb-topic", "/camera/color/image_raw", "--depth-topic", "/camera/depth/image_raw",
                                   "--info-topic", "/camera/color/camera_info", "--pose-topic", "/odom",
                                   "--camera-in-body", EXTRINSIC, "--no-progress"])
    assert res.exit_code == 0, res.output
    assert "3 frames written from the rosbag recording" in res.output and "up found: the recording's" in res.output
    assert "deg from +z; confidence 1.00" in res.output  # the bag's world is z up: found without --up
    _check(tmp_path / "ds", frames[:3])


def test_missing_library_says_how_to_install(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "x.bag").write_bytes(b"")
    monkeypatch.setitem(sys.modules, "rosbags", None)
    with pytest.raises(InputError, match=r"python3? -m pip install .*\[ros\]'"):
        RosbagReader(tmp_path / "x.bag", "/a", "/b", "/c", "/d")


def test_corrupt_bag_is_named(tmp_path: Path) -> None:
    (tmp_path / "x.bag").write_bytes(b"#ROSBAG V2.0\n garbage")
    with pytest.raises(InputError, match=r"cannot open bag .*x.bag"):
        RosbagReader(tmp_path / "x.bag", "/a", "/b", "/c", "/d")


def test_damaged_ros2_metadata_says_how_to_rebuild_it(tmp_path: Path, frames: list[Frame]) -> None:
    """A ROS2 bag whose metadata.yaml was cut short (a copy interrupted) or edited by hand: one line
    naming the file and ``ros2 bag reindex``, not the YAML parser's multi-line message."""
    bag = tmp_path / "run2"
    write_bag(bag, frames[:2], ros2=True)
    meta = bag / "metadata.yaml"
    text = meta.read_text()
    for broken in (text[: len(text) // 3], "topics: []\n"):
        meta.write_text(broken)
        with pytest.raises(InputError, match=r"its metadata.yaml is damaged or incomplete .*ros2 bag reindex") as e:
            RosbagReader(bag, "/camera/color/image_raw/compressed", "/camera/depth/image_raw",
                         "/camera/color/camera_info", "/camera/pose")
        assert "\n" not in str(e.value)
