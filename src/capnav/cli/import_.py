"""``capnav import tum|rosbag SRC -o DATASET``: bring a recording into a ``capnav-rgbd`` folder.

The recording's world frame is aligned to CapNav's (z up, floor at z = 0) from the floor seen in
depth; every skipped frame is counted with its reason.
"""

from __future__ import annotations

from pathlib import Path

import typer

_UP_HELP = "the recording's approximate up axis (+z, -y, +y, ...) refined by a floor fit, or 'none' to keep its frame"


def _report(report: object) -> None:
    from rich.console import Console

    from capnav.io.importer import ImportReport

    assert isinstance(report, ImportReport)
    con = Console(stderr=True, soft_wrap=True)
    for line in report.lines():
        con.print(line, style="yellow" if line.startswith("skipped") else None, highlight=False, markup=False)


def register(app: typer.Typer) -> None:
    imp = typer.Typer(help="Import a recording (TUM RGB-D folder, ROS1/ROS2 bag) as a capnav-rgbd dataset folder.",
                      no_args_is_help=True)

    @imp.command("tum")
    def tum_cmd(
        src: Path = typer.Argument(..., help="TUM sequence folder (rgb.txt, depth.txt, groundtruth.txt)"),
        out: Path = typer.Option(..., "-o", "--out", help="dataset folder to create"),
        intrinsics: str | None = typer.Option(None, "--intrinsics",
                                              help="fr1 | fr2 | fr3 | JSON file {fx, fy, cx, cy[, width, height]} "
                                                   "(default: from a folder name like ..._freiburg2_...)"),
        depth_scale: float = typer.Option(5000.0, "--depth-scale", help="depth PNG units per metre"),
        max_dt: float = typer.Option(0.02, "--max-dt", help="max colour-depth time difference (s)"),
        max_pose_gap: float = typer.Option(0.5, "--max-pose-gap", help="max gap between the pose stamps around "
                                                                        "a frame (s)"),
        stride: int = typer.Option(1, "--stride", help="keep every k-th associated frame"),
        max_frames: int | None = typer.Option(None, "--max-frames", help="keep only the first N selected frames"),
        up: str = typer.Option("+z", "--up", help=_UP_HELP),
        overwrite: bool = typer.Option(False, "--overwrite", help="replace an existing dataset folder"),
        progress: bool = typer.Option(True, help="show progress"),
    ) -> None:
        """Import a TUM RGB-D benchmark sequence (ground truth: camera optical frame to the mocap world)."""
        from capnav.io.align import parse_up
        from capnav.io.importer import import_recording
        from capnav.io.tum import TumReader

        parse_up(up)
        rec = TumReader(src, intrinsics, depth_scale=depth_scale, max_dt=max_dt, max_pose_gap=max_pose_gap)
        _report(import_recording(rec, out, up=up, stride=stride, max_frames=max_frames, overwrite=overwrite,
                                 progress=progress))

    @imp.command("rosbag")
    def rosbag_cmd(
        bag: Path = typer.Argument(..., help="ROS1 .bag file or ROS2 bag folder"),
        out: Path = typer.Option(..., "-o", "--out", help="dataset folder to create"),
        rgb_topic: str = typer.Option(..., "--rgb-topic", help="sensor_msgs/Image or CompressedImage topic"),
        depth_topic: str = typer.Option(..., "--depth-topic", help="sensor_msgs/Image 16UC1 (mm) or 32FC1 (m)"),
        info_topic: str = typer.Option(..., "--info-topic", help="sensor_msgs/CameraInfo of the colour camera"),
        pose_topic: str = typer.Option(..., "--pose-topic", help="PoseStamped / PoseWithCovarianceStamped / "
                                                                 "Odometry of the camera optical frame (or body)"),
        camera_in_body: str | None = typer.Option(None, "--camera-in-body",
                                                  help="x,y,z,qx,qy,qz,qw of the camera optical frame in the "
                                                       "pose topic's body frame"),
        max_dt: float = typer.Option(0.02, "--max-dt", help="max colour-depth time difference (s)"),
        max_pose_gap: float = typer.Option(0.5, "--max-pose-gap", help="max gap between the pose stamps around "
                                                                        "a frame (s)"),
        stride: int = typer.Option(1, "--stride", help="keep every k-th associated frame"),
        max_frames: int | None = typer.Option(None, "--max-frames", help="keep only the first N selected frames"),
        up: str = typer.Option("+z", "--up", help=_UP_HELP),
        overwrite: bool = typer.Option(False, "--overwrite", help="replace an existing dataset folder"),
        progress: bool = typer.Option(True, help="show progress"),
    ) -> None:
        """Import a ROS1/ROS2 bag (read with the rosbags library; no ROS install needed)."""
        from capnav.io.align import parse_up
        from capnav.io.importer import import_recording
        from capnav.io.rosbag import RosbagReader

        parse_up(up)
        rec = RosbagReader(bag, rgb_topic, depth_topic, info_topic, pose_topic, camera_in_body=camera_in_body,
                           max_dt=max_dt, max_pose_gap=max_pose_gap)
        _report(import_recording(rec, out, up=up, stride=stride, max_frames=max_frames, overwrite=overwrite,
                                 progress=progress))

    app.add_typer(imp, name="import")
