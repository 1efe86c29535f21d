"""Reader for ROS1 ``.bag`` files and ROS2 bag folders through the ``rosbags`` library (no ROS install).

Topics: colour (``sensor_msgs/msg/Image`` rgb8/bgr8/rgba8/bgra8/mono8, or ``CompressedImage`` jpeg/png),
depth (``Image`` 16UC1 millimetres or 32FC1 metres, NaN/inf = no reading), ``CameraInfo`` for K, and
poses (``geometry_msgs/msg/PoseStamped``, ``PoseWithCovarianceStamped`` or ``nav_msgs/msg/Odometry``)
of the camera optical frame in the world, or of a body frame when the fixed body -> camera extrinsic
is given. Header stamps time every message (bag receive times only when a topic's stamps are all 0).

The bag is read twice: once for stamps, calibration and poses (cheap), once streaming the images
of the selected frames in bag order (a ROS1 bag has no cheap random access by message).
"""

from __future__ import annotations

import io
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from capnav.core.errors import InputError, pip_hint
from capnav.core.geometry import Intrinsics
from capnav.io.assoc import PoseTrack, SkipLog, check_gap, match_nearest, poses_from_quat
from capnav.io.importer import PlannedFrame

IMAGE = "sensor_msgs/msg/Image"
COMPRESSED = "sensor_msgs/msg/CompressedImage"
INFO = "sensor_msgs/msg/CameraInfo"
POSE_TYPES = ("geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/PoseWithCovarianceStamped",
              "nav_msgs/msg/Odometry")
ROLES: dict[str, tuple[str, tuple[str, ...]]] = {  # role -> (CLI option, accepted message types)
    "rgb": ("--rgb-topic", (IMAGE, COMPRESSED)),
    "depth": ("--depth-topic", (IMAGE,)),
    "info": ("--info-topic", (INFO,)),
    "pose": ("--pose-topic", POSE_TYPES),
}
_COLOUR = {"rgb8": (3, False), "bgr8": (3, True), "rgba8": (4, False), "bgra8": (4, True), "mono8": (1, False)}


def _rosbags() -> Any:
    try:
        from rosbags import highlevel
    except ImportError:
        raise InputError(f"reading ROS bags needs the rosbags library: {pip_hint('capnav[ros]')}") from None
    return highlevel


def _stamp(msg: Any) -> float:
    s = msg.header.stamp
    return float(s.sec) + 1e-9 * float(s.nanosec)


def parse_extrinsic(values: str | Sequence[float], what: str = "--camera-in-body") -> NDArray[np.float64]:
    """``x,y,z,qx,qy,qz,qw`` (camera optical frame in the body frame) as a 4x4 body->camera transform."""
    if isinstance(values, str):
        try:
            vals = [float(v) for v in values.replace(",", " ").split()]
        except ValueError:
            raise InputError(f"{what} must be 7 numbers x,y,z,qx,qy,qz,qw, got {values!r}") from None
    else:
        vals = [float(v) for v in values]
    if len(vals) != 7:
        raise InputError(f"{what} must be 7 numbers x,y,z,qx,qy,qz,qw, got {len(vals)}")
    return poses_from_quat(np.zeros(1), np.array(vals[:3]), np.array(vals[3:]), [what])[0]


def image_rgb(msg: Any, msgtype: str, where: str) -> NDArray[np.uint8]:
    """Colour image of an ``Image`` or ``CompressedImage`` message as uint8 (H, W, 3) RGB."""
    if msgtype == COMPRESSED:
        from PIL import Image

        fmt = str(msg.format).lower()
        if "jpeg" not in fmt and "jpg" not in fmt and "png" not in fmt:
            raise InputError(f"{where}: compressed format {msg.format!r} is not jpeg or png")
        try:
            with Image.open(io.BytesIO(np.asarray(msg.data, dtype=np.uint8).tobytes())) as im:
                return np.asarray(im.convert("RGB"), dtype=np.uint8)
        except (OSError, SyntaxError, ValueError) as e:
            raise InputError(f"{where}: corrupt compressed image: {e}") from None
    enc = str(msg.encoding).lower()
    if enc not in _COLOUR:
        raise InputError(f"{where}: colour encoding {msg.encoding!r} not supported (rgb8, bgr8, rgba8, bgra8, mono8)")
    ch, bgr = _COLOUR[enc]
    arr = _rows(msg, np.dtype(np.uint8), ch, where)
    if ch == 1:
        return np.repeat(arr, 3, axis=2)
    arr = arr[..., :3]
    return np.ascontiguousarray(arr[..., ::-1] if bgr else arr)


def image_depth(msg: Any, msgtype: str, where: str) -> NDArray[np.float32]:
    """Depth in metres from a 16UC1 (millimetres) or 32FC1 (metres) ``Image``; NaN/inf stay invalid."""
    enc = str(msg.encoding).upper()
    if msgtype != IMAGE:
        raise InputError(f"{where}: depth must be a raw sensor_msgs/msg/Image, got {msgtype}")
    order = ">" if msg.is_bigendian else "<"
    if enc in ("16UC1", "MONO16"):
        return (_rows(msg, np.dtype(order + "u2"), 1, where)[..., 0].astype(np.float32) / np.float32(1000.0))
    if enc == "32FC1":
        return _rows(msg, np.dtype(order + "f4"), 1, where)[..., 0].astype(np.float32)
    raise InputError(f"{where}: depth encoding {msg.encoding!r} not supported (16UC1 millimetres, 32FC1 metres)")


def _rows(msg: Any, dtype: np.dtype[Any], ch: int, where: str) -> NDArray[Any]:
    """Pixels of a raw image honouring ``step`` (rows may be padded)."""
    h, w, step = int(msg.height), int(msg.width), int(msg.step)
    data = np.asarray(msg.data, dtype=np.uint8)
    row = w * ch * dtype.itemsize
    if step < row or data.size < step * h:
        raise InputError(f"{where}: {w}x{h} {msg.encoding} image needs {row} bytes a row and {step * h} in all, "
                         f"message has step {step} and {data.size} bytes")
    rows = data[:step * h].reshape(h, step)[:, :row]
    return np.ascontiguousarray(rows).view(dtype).reshape(h, w, ch)


#: How each bag storage begins (ROS1 bag, ROS2 sqlite3 and MCAP storage files).
BAG_MAGIC = {b"#ROSBAG V2.0": "a ROS1 bag", b"SQLite format 3\x00": "a ROS2 sqlite3 file",
             b"\x89MCAP": "an MCAP file"}
OTHER_MAGIC = {b"\x89PNG": "a PNG image", b"\xff\xd8\xff": "a JPEG image", b"PK\x03\x04": "a zip archive",
               b"\x1f\x8b": "a gzip file", b"%PDF": "a PDF", b"\x00\x00\x00": "an MP4 / QuickTime video"}


def check_is_bag(path: Path) -> None:
    """Refuse, naming what it is instead, a file that is not a bag (the bag library would fail on it with a
    decoding error that says nothing) or a folder that is not a ROS2 bag."""
    if path.is_dir():
        if not (path / "metadata.yaml").is_file():
            raise InputError(f"{path} is a folder but not a ROS2 bag (no metadata.yaml); a ROS1 bag is one .bag file")
        return
    try:
        with path.open("rb") as fh:
            head = fh.read(64)
    except OSError as e:
        raise InputError(f"cannot read {path}: {e.strerror or e}") from None
    if any(head.startswith(m) for m in BAG_MAGIC):
        return
    what = next((v for m, v in OTHER_MAGIC.items() if head.startswith(m)), None)
    if what is None:
        if not head:
            what = "an empty file"
        else:
            try:
                head.decode("utf-8")
                what = f"text ({head[:30].decode('utf-8', 'replace')!r}...)"
            except UnicodeDecodeError:
                what = f"binary data starting {head[:8].hex(' ')}"
    raise InputError(f"{path} is not a ROS bag: it is {what}; a ROS1 bag begins with '#ROSBAG V2.0', a ROS2 bag "
                     "is a folder with metadata.yaml")


class RosbagReader:
    """A ROS1/ROS2 bag as associated frames (``frames``) plus the colour images dropped (``skipped``)."""

    kind = "rosbag"

    def __init__(self, bag: str | Path, rgb_topic: str, depth_topic: str, info_topic: str, pose_topic: str,
                 camera_in_body: str | Sequence[float] | None = None, max_dt: float = 0.02,
                 max_pose_gap: float = 0.5) -> None:
        self.path = Path(bag)
        if not self.path.exists():
            raise InputError(f"bag not found: {self.path}")
        if not max_dt > 0:
            raise InputError(f"--max-dt must be > 0 s, got {max_dt}")
        check_gap(max_pose_gap)
        self.topics = {"rgb": rgb_topic, "depth": depth_topic, "info": info_topic, "pose": pose_topic}
        if rgb_topic == depth_topic:
            raise InputError(f"--rgb-topic and --depth-topic are the same topic {rgb_topic!r}")
        T_bc = parse_extrinsic(camera_in_body) if camera_in_body is not None else None
        stamps: dict[str, list[float]] = {"rgb": [], "depth": [], "pose": []}
        bagtime: dict[str, list[int]] = {"rgb": [], "depth": [], "pose": []}
        pose_xyzq: list[list[float]] = []
        info: Any = None
        with self._open() as r:
            conns = self._connections(r)
            self.msgtypes = {role: cs[0].msgtype for role, cs in conns.items()}
            role_of = {c.id: role for role, cs in conns.items() for c in cs}
            by_conn = {c.id: c for cs in conns.values() for c in cs}
            for conn, t_ns, raw in r.messages(connections=list(by_conn.values())):
                role = role_of[conn.id]
                if role == "info" and info is not None:
                    continue
                msg = self._deserialize(r, raw, conn, t_ns)
                if role == "info":
                    info = msg
                    continue
                stamps[role].append(_stamp(msg))
                bagtime[role].append(int(t_ns))
                if role == "pose":
                    p = msg.pose if conn.msgtype == POSE_TYPES[0] else msg.pose.pose
                    pose_xyzq.append([p.position.x, p.position.y, p.position.z, p.orientation.x, p.orientation.y,
                                      p.orientation.z, p.orientation.w])
        self.K, self.info_meta = self._intrinsics(info)
        t: dict[str, NDArray[np.float64]] = {}
        self.stamp_source: dict[str, str] = {}
        for role in stamps:
            if not stamps[role]:
                raise InputError(f"{self.path}: topic {self.topics[role]!r} ({ROLES[role][0]}) has no messages")
            s = np.asarray(stamps[role])
            use_bag = bool(np.all(s == 0))
            t[role] = np.asarray(bagtime[role], dtype=np.float64) * 1e-9 if use_bag else s
            self.stamp_source[self.topics[role]] = "bag time (header stamps are 0)" if use_bag else "header"
        q = np.asarray(pose_xyzq, dtype=np.float64)
        names = [f"{pose_topic} message {k} (stamp {s:.6f})" for k, s in enumerate(t["pose"])]
        T = poses_from_quat(t["pose"], q[:, :3], q[:, 3:], names)
        if T_bc is not None:
            T = T @ T_bc
        track = PoseTrack(t["pose"], T, f"{self.path} {pose_topic}")
        j, dt = match_nearest(t["rgb"], t["depth"], max_dt)
        poses, has_pose, why = track.at(t["rgb"], max_dt, max_pose_gap)
        self.skipped = SkipLog()
        self.frames: list[PlannedFrame] = []
        for i in np.argsort(t["rgb"], kind="stable").tolist():
            name = f"{rgb_topic} message {i} (stamp {t['rgb'][i]:.6f})"
            if j[i] < 0:
                reason = (f"nearest depth {dt[i] * 1000:.0f} ms away" if dt[i] > max_dt
                          else "its nearest depth image is nearer to another colour image")
                self.skipped.add(name, t["rgb"][i], f"no depth within max-dt {max_dt} s", reason)
            elif not has_pose[i]:
                self.skipped.add(name, t["rgb"][i], "no pose", why[i])
            else:
                self.frames.append(PlannedFrame(name, float(t["rgb"][i]), poses[i], i, int(j[i]), i))
        self.meta: dict[str, Any] = {
            "topics": self.topics, "message_types": self.msgtypes, "stamps": self.stamp_source,
            "camera_in_body": None if T_bc is None else [float(v) for v in T_bc.reshape(-1)],
            "max_dt": max_dt, "colour_images": len(t["rgb"]), "depth_images": len(t["depth"]),
            "poses": len(track), **self.info_meta}

    # -- bag access ---------------------------------------------------------------------
    @contextmanager
    def _open(self) -> Iterator[Any]:
        """The opened ``AnyReader``; the library's errors (corrupt bag, missing types) become ``InputError``."""
        highlevel = _rosbags()
        check_is_bag(self.path)
        from rosbags.typesys import Stores, get_typestore

        path = self.path.parent if self.path.is_file() and self.path.suffix in (".db3", ".mcap") else self.path
        store = get_typestore(Stores.ROS1_NOETIC if path.suffix == ".bag" else Stores.LATEST)
        try:
            reader = highlevel.AnyReader([path], default_typestore=store)
            reader.open()
        except Exception as e:  # AnyReaderError, or the ROS1/ROS2 readers' own errors on a corrupt file
            why = " ".join(str(e).split())  # YAML errors span lines; the CLI shows one
            if path.is_dir() and ("metadata" in why.lower() or "yaml" in why.lower()):
                raise InputError(f"cannot open bag {self.path}: its metadata.yaml is damaged or incomplete ({why}); "
                                 f"ROS2 rebuilds it from the bag's files with `ros2 bag reindex {path}`") from None
            raise InputError(f"cannot open bag {self.path}: {type(e).__name__}: {why}") from None
        try:
            yield reader
        except Exception as e:
            if type(e).__module__.startswith("rosbags"):
                raise InputError(f"reading bag {self.path}: {type(e).__name__}: {e}") from None
            raise
        finally:
            reader.close()

    def _connections(self, r: Any) -> dict[str, list[Any]]:
        """Connections of each role's topic; an unknown topic lists what the bag has."""
        out = {}
        for role, topic in self.topics.items():
            option, types = ROLES[role]
            cs = [c for c in r.connections if c.topic == topic]
            if not cs:
                have = ", ".join(f"{name} ({info.msgtype}, {info.msgcount} msgs)"
                                 for name, info in sorted(r.topics.items()))
                raise InputError(f"{self.path} has no topic {topic!r} ({option}); its topics: {have or 'none'}")
            bad = [c.msgtype for c in cs if c.msgtype not in types]
            if bad:
                raise InputError(f"{self.path}: {option} {topic!r} carries {bad[0]}, expected {' or '.join(types)}")
            out[role] = cs
        return out

    def _deserialize(self, r: Any, raw: bytes, conn: Any, t_ns: int) -> Any:
        try:
            return r.deserialize(raw, conn.msgtype)
        except Exception as e:  # the library's own error types vary by version
            raise InputError(f"{self.path}: cannot decode a {conn.msgtype} message on {conn.topic} "
                             f"at bag time {t_ns * 1e-9:.6f}: {e}") from None

    def _intrinsics(self, info: Any) -> tuple[Intrinsics, dict[str, Any]]:
        where = f"{self.path} {self.topics['info']}"
        if info is None:
            raise InputError(f"{where}: no CameraInfo message")
        K = np.asarray(getattr(info, "k", getattr(info, "K", None)), dtype=np.float64)
        if K.size != 9 or not np.all(np.isfinite(K)) or K[0] <= 0 or K[4] <= 0:
            raise InputError(f"{where}: CameraInfo K is not a calibrated 3x3 matrix: {K.tolist()}")
        D = np.asarray(getattr(info, "d", getattr(info, "D", [])), dtype=np.float64)
        try:
            k = Intrinsics.from_matrix(K.reshape(3, 3), int(info.width), int(info.height))
        except InputError as e:
            raise InputError(f"{where}: {e}") from None
        return k, {"distortion_model": str(info.distortion_model), "distortion": D.tolist(),
                   "distortion_ignored": bool(np.any(D != 0))}

    def _stream(self, frames: list[PlannedFrame], roles: tuple[str, ...]) -> Iterator[tuple[int, str, Any, str]]:
        """Messages (frame position, role, message, message type) of ``frames`` in bag order."""
        want: dict[tuple[str, int], list[int]] = {}
        for k, f in enumerate(frames):
            for role in roles:
                want.setdefault((role, f.rgb if role == "rgb" else f.depth), []).append(k)
        if not want:
            return
        last = {role: max(o for ro, o in want if ro == role) for role in roles}
        with self._open() as r:
            conns = self._connections(r)
            role_of = {c.id: role for role in roles for c in conns[role]}
            count = dict.fromkeys(roles, 0)
            for conn, t_ns, raw in r.messages(connections=[c for role in roles for c in conns[role]]):
                role = role_of[conn.id]
                n = count[role]
                count[role] += 1
                if (role, n) in want:
                    msg = self._deserialize(r, raw, conn, t_ns)
                    for k in want[(role, n)]:
                        yield k, role, msg, conn.msgtype
                if all(count[ro] > last[ro] for ro in roles):
                    return

    def load_depths(self, frames: list[PlannedFrame]) -> Iterator[tuple[PlannedFrame, NDArray[np.float32]]]:
        got: dict[int, NDArray[np.float32]] = {}
        for k, _, msg, mt in self._stream(frames, ("depth",)):
            got[k] = image_depth(msg, mt, f"{self.topics['depth']} ({frames[k].name})")
        for k, f in enumerate(frames):
            if k in got:
                yield f, got[k]

    def load(self, frames: list[PlannedFrame]) -> Iterator[tuple[PlannedFrame, NDArray[np.uint8],
                                                                NDArray[np.float32]]]:
        """Frames in their order, each as soon as its colour and depth have streamed past (small buffer)."""
        pending: dict[int, dict[str, Any]] = {}
        nxt = 0
        for k, role, msg, mt in self._stream(frames, ("rgb", "depth")):
            where = f"{self.topics[role]} ({frames[k].name})"
            pending.setdefault(k, {})[role] = (image_rgb(msg, mt, where) if role == "rgb"
                                               else image_depth(msg, mt, where))
            while nxt in pending and len(pending[nxt]) == 2:
                p = pending.pop(nxt)
                yield frames[nxt], p["rgb"], p["depth"]
                nxt += 1
        if nxt < len(frames):
            raise InputError(f"{self.path}: images of {frames[nxt].name} were not found on the second read")
