"""``capnav import auto|tum|open3d|3dmatch|scannet|stray|rosbag SRC -o DATASET``: bring a recording into a
``capnav-rgbd`` folder.

``auto`` recognises the layout from its files and says which it is. The recording's world frame is
aligned to CapNav's (z up, floor at z = 0) from the floor seen in depth; every skipped frame is
counted with its reason.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from capnav.cli.options import finite_float

if TYPE_CHECKING:
    from capnav.io.importer import Recording

# Options both commands take: declared once.
Out = Annotated[Path, typer.Option("-o", "--out", help="dataset folder to create")]
MaxDt = Annotated[float, typer.Option("--max-dt", parser=finite_float(0.0),
                                      help="max colour-depth time difference (s)")]
MaxPoseGap = Annotated[float, typer.Option("--max-pose-gap", parser=finite_float(0.0),
                                           help="max gap between the pose stamps around a frame (s)")]
Stride = Annotated[int, typer.Option("--stride", min=1, help="keep every k-th associated frame")]
MaxFrames = Annotated[int | None, typer.Option("--max-frames", min=1, help="keep only the first N selected frames")]
Up = Annotated[str, typer.Option("--up", help="'auto' finds up from the floor and the cameras (refuses when unsure); "
                                              "an axis (+z, -y, ...) or a direction x,y,z in the recording's frame "
                                              "is refined by the floor and checked; 'none' keeps the recorded frame")]
Overwrite = Annotated[bool, typer.Option("--overwrite", help="replace an existing dataset folder")]
Progress = Annotated[bool, typer.Option(help="show progress")]
Intrinsics = Annotated[str | None, typer.Option("--intrinsics", help="intrinsics file (default: the layout's own)")]
DepthScale = Annotated[float | None, typer.Option("--depth-scale", parser=finite_float(1.0),
                                                  help="depth PNG units per metre (default: the "
                                                                        "layout's: 5000 TUM, 1000 the others)")]


def _import(reader: Callable[[], Recording], out: Path, up: str, stride: int, max_frames: int | None,
            overwrite: bool, progress: bool, said: Callable[[Recording], str] | None = None) -> None:
    """Check ``--up`` before opening the recording, import it, print what was kept and skipped
    (``said``: a first line about the recording, e.g. which layout was recognised)."""
    from capnav.cli.options import check_output_dir, on_interrupt
    from capnav.core.console import make_console
    from capnav.io.align import parse_up
    from capnav.io.importer import import_recording

    check_output_dir(out, "--out", must_be_empty=True, overwrite=overwrite)
    parse_up(up)
    on_interrupt(f"{out} was left as it was (the dataset is built beside it and swapped in only when complete)")
    con = make_console(stderr=True)
    rec = reader()
    if said is not None:
        con.print(said(rec), highlight=False, markup=False)
    report = import_recording(rec, out, up=up, stride=stride, max_frames=max_frames, overwrite=overwrite,
                              progress=progress)
    for line in report.lines():
        con.print(line, style="yellow" if line.startswith("skipped") else None, highlight=False, markup=False)


def register(app: typer.Typer) -> None:
    imp = typer.Typer(help="Import a recording (TUM RGB-D, Open3D, 3DMatch, ScanNet, Stray Scanner, ROS1/ROS2 bag) "
                           "as a capnav-rgbd dataset folder; 'auto' recognises the layout.", no_args_is_help=True)

    @imp.command("auto")
    def auto_cmd(
        src: Annotated[Path, typer.Argument(help="recording folder of any known layout")],
        out: Out,
        intrinsics: Intrinsics = None, depth_scale: DepthScale = None, stride: Stride = 1,
        max_frames: MaxFrames = None, up: Up = "auto", overwrite: Overwrite = False, progress: Progress = True,
    ) -> None:
        """Recognise the layout of SRC (TUM, Open3D, 3DMatch, ScanNet, Stray Scanner) from its files and import it
        with that layout's defaults (its depth scale, its intrinsics file)."""
        from capnav.io.layouts import open_recording

        found: dict[str, str] = {}

        def open_it() -> Recording:
            rec, lay, ev = open_recording(src, intrinsics=intrinsics, depth_scale=depth_scale)
            found["line"] = (f"{src}: {lay.name} layout ({ev}); intrinsics {rec.meta.get('intrinsics_source')}, "
                             f"depth {rec.meta.get('depth_scale_in'):g} units per metre")
            return rec

        _import(open_it, out, up, stride, max_frames, overwrite, progress, said=lambda _: found["line"])

    @imp.command("open3d")
    def open3d_cmd(
        src: Annotated[Path, typer.Argument(help="folder with image/ (or color/), depth/, trajectory.log")],
        out: Out,
        intrinsics: Intrinsics = None, depth_scale: DepthScale = None,
        fps: float = typer.Option(30.0, "--fps", parser=finite_float(0.01),
                                  help="frame rate (the layout has no timestamps)"),
        trajectory: Path | None = typer.Option(None, "--trajectory", help="the trajectory log, if not SRC/*.log"),
        stride: Stride = 1, max_frames: MaxFrames = None, up: Up = "auto", overwrite: Overwrite = False,
        progress: Progress = True,
    ) -> None:
        """Import an Open3D / Redwood reconstruction-system folder (camera-to-world log, depth in mm)."""
        from capnav.io.open3d_log import DEPTH_SCALE, Open3dReader

        _import(lambda: Open3dReader(src, intrinsics, depth_scale=depth_scale or DEPTH_SCALE, fps=fps,
                                     trajectory=trajectory), out, up, stride, max_frames, overwrite, progress)

    @imp.command("3dmatch")
    def threedmatch_cmd(
        src: Annotated[Path, typer.Argument(help="scene folder (camera-intrinsics.txt, seq-*/) or one sequence")],
        out: Out,
        intrinsics: Intrinsics = None, depth_scale: DepthScale = None, stride: Stride = 1,
        max_frames: MaxFrames = None, up: Up = "auto", overwrite: Overwrite = False, progress: Progress = True,
    ) -> None:
        """Import a 3DMatch / 7-Scenes scene (frame-XXXXXX.color/.depth/.pose files, depth in mm)."""
        from capnav.io.threedmatch import DEPTH_SCALE, ThreeDMatchReader

        _import(lambda: ThreeDMatchReader(src, intrinsics, depth_scale=depth_scale or DEPTH_SCALE),
                out, up, stride, max_frames, overwrite, progress)

    @imp.command("stray")
    def stray_cmd(
        src: Annotated[Path, typer.Argument(help="Stray Scanner capture: rgb.mp4 (or rgb/), depth/, confidence/, "
                                                 "odometry.csv, camera_matrix.csv")],
        out: Out,
        intrinsics: Intrinsics = None, depth_scale: DepthScale = None,
        min_confidence: int = typer.Option(1, "--min-confidence", min=0, max=2,
                                           help="drop depth pixels of lower LiDAR confidence (0, 1, 2)"),
        camera_axes: str = typer.Option("opencv", "--camera-axes", help="opencv (x right, y down, z forward) or "
                                                                        "opengl (ARKit's y up, z backwards)"),
        max_width: int = typer.Option(640, "--max-width", min=32, help="write frames at most this wide"),
        stride: Stride = 1, max_frames: MaxFrames = None, up: Up = "auto", overwrite: Overwrite = False,
        progress: Progress = True,
    ) -> None:
        """Import a Stray Scanner iPhone capture (LiDAR depth upsampled to the colour's view, ARKit poses)."""
        from capnav.io.stray import DEPTH_SCALE, StrayReader

        _import(lambda: StrayReader(src, intrinsics, depth_scale=depth_scale or DEPTH_SCALE,
                                    min_confidence=min_confidence, camera_axes=camera_axes, max_width=max_width),
                out, up, stride, max_frames, overwrite, progress)

    @imp.command("scannet")
    def scannet_cmd(
        src: Annotated[Path, typer.Argument(help="exported frames: color/, depth/, pose/, intrinsic/")],
        out: Out,
        depth_scale: DepthScale = None, stride: Stride = 1,
        max_frames: MaxFrames = None, up: Up = "auto", overwrite: Overwrite = False, progress: Progress = True,
    ) -> None:
        """Import ScanNet's exported frames (written at the depth camera's resolution, colour resampled)."""
        from capnav.io.scannet import DEPTH_SCALE, ScannetReader

        _import(lambda: ScannetReader(src, depth_scale=depth_scale or DEPTH_SCALE),
                out, up, stride, max_frames, overwrite, progress)

    @imp.command("tum")
    def tum_cmd(
        src: Annotated[Path, typer.Argument(help="TUM sequence folder (rgb.txt, depth.txt, groundtruth.txt)")],
        out: Out,
        intrinsics: str | None = typer.Option(None, "--intrinsics",
                                              help="fr1 | fr2 | fr3 | JSON file {fx, fy, cx, cy[, width, height]} "
                                                   "(default: from a folder name like ..._freiburg2_...)"),
        depth_scale: float = typer.Option(5000.0, "--depth-scale", parser=finite_float(1.0),
                                          help="depth PNG units per metre"),
        max_dt: MaxDt = 0.02, max_pose_gap: MaxPoseGap = 0.5, stride: Stride = 1, max_frames: MaxFrames = None,
        up: Up = "auto", overwrite: Overwrite = False, progress: Progress = True,
    ) -> None:
        """Import a TUM RGB-D benchmark sequence (ground truth: camera optical frame to the mocap world)."""
        from capnav.io.tum import TumReader

        _import(lambda: TumReader(src, intrinsics, depth_scale=depth_scale, max_dt=max_dt, max_pose_gap=max_pose_gap),
                out, up, stride, max_frames, overwrite, progress)

    @imp.command("rosbag")
    def rosbag_cmd(
        bag: Annotated[Path, typer.Argument(help="ROS1 .bag file or ROS2 bag folder")],
        out: Out,
        rgb_topic: str = typer.Option(..., "--rgb-topic", help="sensor_msgs/Image or CompressedImage topic"),
        depth_topic: str = typer.Option(..., "--depth-topic", help="sensor_msgs/Image 16UC1 (mm) or 32FC1 (m)"),
        info_topic: str = typer.Option(..., "--info-topic", help="sensor_msgs/CameraInfo of the colour camera"),
        pose_topic: str = typer.Option(..., "--pose-topic", help="PoseStamped / PoseWithCovarianceStamped / "
                                                                 "Odometry of the camera optical frame (or body)"),
        camera_in_body: str | None = typer.Option(None, "--camera-in-body",
                                                  help="x,y,z,qx,qy,qz,qw of the camera optical frame in the "
                                                       "pose topic's body frame"),
        max_dt: MaxDt = 0.02, max_pose_gap: MaxPoseGap = 0.5, stride: Stride = 1, max_frames: MaxFrames = None,
        up: Up = "auto", overwrite: Overwrite = False, progress: Progress = True,
    ) -> None:
        """Import a ROS1/ROS2 bag (read with the rosbags library; no ROS install needed)."""
        from capnav.io.rosbag import RosbagReader

        _import(lambda: RosbagReader(bag, rgb_topic, depth_topic, info_topic, pose_topic,
                                     camera_in_body=camera_in_body, max_dt=max_dt, max_pose_gap=max_pose_gap),
                out, up, stride, max_frames, overwrite, progress)

    app.add_typer(imp, name="import")
