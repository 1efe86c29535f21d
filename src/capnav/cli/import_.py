"""``capnav import tum|rosbag SRC -o DATASET``: bring a recording into a ``capnav-rgbd`` folder.

The recording's world frame is aligned to CapNav's (z up, floor at z = 0) from the floor seen in
depth; every skipped frame is counted with its reason.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

if TYPE_CHECKING:
    from capnav.io.importer import Recording

# Options both commands take: declared once.
Out = Annotated[Path, typer.Option("-o", "--out", help="dataset folder to create")]
MaxDt = Annotated[float, typer.Option("--max-dt", help="max colour-depth time difference (s)")]
MaxPoseGap = Annotated[float, typer.Option("--max-pose-gap", help="max gap between the pose stamps around a frame (s)")]
Stride = Annotated[int, typer.Option("--stride", min=1, help="keep every k-th associated frame")]
MaxFrames = Annotated[int | None, typer.Option("--max-frames", min=1, help="keep only the first N selected frames")]
Up = Annotated[str, typer.Option("--up", help="'auto' finds up from the floor and the cameras (refuses when unsure); "
                                              "an axis (+z, -y, ...) is refined by the floor and checked; 'none' "
                                              "keeps the recorded frame")]
Overwrite = Annotated[bool, typer.Option("--overwrite", help="replace an existing dataset folder")]
Progress = Annotated[bool, typer.Option(help="show progress")]


def _import(reader: Callable[[], Recording], out: Path, up: str, stride: int, max_frames: int | None,
            overwrite: bool, progress: bool) -> None:
    """Check ``--up`` before opening the recording, import it, print what was kept and skipped."""
    from rich.console import Console

    from capnav.cli.options import check_output_dir, on_interrupt
    from capnav.io.align import parse_up
    from capnav.io.importer import import_recording

    check_output_dir(out, "--out", must_be_empty=True, overwrite=overwrite)
    parse_up(up)
    on_interrupt(f"{out} was left as it was (the dataset is built beside it and swapped in only when complete)")
    report = import_recording(reader(), out, up=up, stride=stride, max_frames=max_frames, overwrite=overwrite,
                              progress=progress)
    con = Console(stderr=True, soft_wrap=True)
    for line in report.lines():
        con.print(line, style="yellow" if line.startswith("skipped") else None, highlight=False, markup=False)


def register(app: typer.Typer) -> None:
    imp = typer.Typer(help="Import a recording (TUM RGB-D folder, ROS1/ROS2 bag) as a capnav-rgbd dataset folder.",
                      no_args_is_help=True)

    @imp.command("tum")
    def tum_cmd(
        src: Annotated[Path, typer.Argument(help="TUM sequence folder (rgb.txt, depth.txt, groundtruth.txt)")],
        out: Out,
        intrinsics: str | None = typer.Option(None, "--intrinsics",
                                              help="fr1 | fr2 | fr3 | JSON file {fx, fy, cx, cy[, width, height]} "
                                                   "(default: from a folder name like ..._freiburg2_...)"),
        depth_scale: float = typer.Option(5000.0, "--depth-scale", help="depth PNG units per metre"),
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
