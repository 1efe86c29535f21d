"""``capnav map DATASET -o MAP``: build a CapNav map from a posed RGB-D dataset folder."""

from __future__ import annotations

import contextlib
import json
import re
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import typer

from capnav.cli.options import MaxFrames, Seed, check_output_file, on_interrupt


def parse_detector_options(items: list[str]) -> dict[str, Any]:
    """``KEY=VALUE`` strings to detector kwargs; a VALUE that parses as JSON is used as JSON
    (numbers, true/false, lists), anything else is the plain string."""
    out: dict[str, Any] = {}
    for item in items:
        key, sep, raw = item.partition("=")
        key = key.strip()
        if not sep or not key.isidentifier():
            raise typer.BadParameter(f"{item!r} is not KEY=VALUE (e.g. model_path=/models/owlv2)",
                                     param_hint="--detector-option")
        if key in out:
            raise typer.BadParameter(f"{key!r} is given twice", param_hint="--detector-option")
        try:
            out[key] = json.loads(raw)
        except ValueError:
            out[key] = raw
    return out


def _tracker(items: list[str]) -> Any:
    """``TrackerConfig`` with the ``--tracker-option`` settings (unknown keys refused by name)."""
    import dataclasses

    from capnav.core.errors import InputError
    from capnav.mapping.tracker import TrackerConfig

    opts = parse_detector_options(items)
    known = {f.name for f in dataclasses.fields(TrackerConfig)}
    unknown = sorted(set(opts) - known)
    if unknown:
        raise InputError(f"unknown --tracker-option {', '.join(unknown)}; known: {', '.join(sorted(known))}")
    try:
        return TrackerConfig(**opts)
    except TypeError as e:
        raise InputError(f"--tracker-option: {e}") from None


def register(app: typer.Typer) -> None:
    @app.command("map")
    def map_cmd(
        dataset: Path = typer.Argument(..., help="dataset folder (capnav-rgbd format)"),
        output: Path = typer.Option(..., "-o", "--output", help="map file to write (e.g. apt0.capnav)"),
        detector: str = typer.Option("sim", help="detector backend: sim (simulator recordings only), yolo-fastest "
                                                 "or centernet (COCO-80 on real pixels, CPU; capnav models install), "
                                                 "owl (OWL-ViT / OWLv2 from a local folder); docs/perception.md"),
        noise: str = typer.Option("default", help="sim detector noise: default, hard, oracle"),
        seed: Seed = 0,
        detector_option: list[str] = typer.Option(
            [], "--detector-option", metavar="KEY=VALUE",
            help="detector setting passed to the backend, repeatable; VALUE is JSON when it parses, else "
                 "text (yolo-fastest/centernet: model_dir=DIR, score_threshold=0.3, classes=indoor|all; owl: "
                 "model_path=DIR, mask=depth|sam|box, ...)"),
        tracker_option: list[str] = typer.Option(
            [], "--tracker-option", metavar="KEY=VALUE",
            help="tracker / confirmation setting (capnav.mapping.tracker.TrackerConfig), repeatable, VALUE as "
                 "for --detector-option: h_min=3, weak_h_min=5 (0: no low-score candidates), weak_score=1.0, "
                 "weak_agreement=0.667, weak_confident=1 (0: low-score sightings alone can confirm), "
                 "weak_shape=true (false: without a confident sighting, their 3D shape does not confirm them)"),
        encoder: str = typer.Option("label-embedding", help="dense feature encoder backend"),
        embedder: str = typer.Option("minilm", help="text embedder of the label-embedding encoder"),
        max_frames: MaxFrames = None,
        strict: bool = typer.Option(False, help="stop at the first bad frame instead of skipping it"),
        progress: bool = typer.Option(True, help="show a progress bar"),
        update: Path | None = typer.Option(
            None, "--update", metavar="MAP",
            help="fuse DATASET, a later recording of the same home, into MAP (objects keep their ids, moved "
                 "ones gain a pose history, ones whose place is observed empty retire, new ones are born) and "
                 "write the result to -o (docs/change.md)"),
        transform: str | None = typer.Option(
            None, "--transform", metavar="X,Y,YAW|FILE",
            help="with --update: DATASET's world frame in MAP's (x, y metres, yaw degrees, or a JSON file with "
                 "a 4x4 matrix); ICP refines it (default: identity)"),
        icp: bool = typer.Option(True, "--icp/--no-icp", help="with --update: refine the registration by ICP on "
                                                            "the depth (Open3D); --no-icp only checks it"),
    ) -> None:
        """Detect, fuse the semantic voxel map, track objects and write the map file."""
        from capnav.core.console import make_console
        from capnav.core.errors import InputError
        from capnav.io.dataset import DatasetReader
        from capnav.io.mapfile import save_map
        from capnav.language import create_embedder
        from capnav.mapping import MapperConfig, map_dataset
        from capnav.perception import create_detector, create_encoder

        check_output_file(output, "-o")  # fail on an unwritable output and a bad folder before any model loads
        options = parse_detector_options(detector_option)
        if update is None and (transform is not None or not icp):
            raise InputError("--transform and --no-icp belong to --update MAP")
        reader = DatasetReader(dataset)
        kwargs = {"noise": noise, "seed": seed, **options} if detector == "sim" else options
        try:
            det = create_detector(detector, **kwargs)
        except TypeError as e:  # a backend whose factory does not check its kwargs itself
            raise InputError(f"detector {detector!r} rejected its options {sorted(options)}: {e}") from None
        enc = create_encoder(encoder, embedder=create_embedder(embedder))
        cfg = MapperConfig(on_bad_frame="raise" if strict else "skip", tracker=_tracker(tracker_option))
        if update is not None:
            _update(update, reader, output, det, enc, cfg, transform, icp, progress)
            return
        on_interrupt(f"no map was written ({output} is as it was)")
        t0 = time.perf_counter()
        cmap = map_dataset(reader, det, enc, cfg, max_frames=max_frames, progress=progress)
        seconds = time.perf_counter() - t0
        save_map(cmap, output)
        con = make_console(stderr=True)
        m = cmap.meta
        speed = f" ({m['frames_used'] / seconds:.1f} frames/s)" if seconds > 0 and m["frames_used"] else ""
        con.print(f"{output}: {len(cmap.objects)} objects, {len(cmap.voxels)} voxels, "
                  f"{m['frames_used']} frames{speed}, detector {det.id}")
        default_h_min = cfg.tracker.h_min
        if m.get("h_min_used", default_h_min) < default_h_min:
            n_used = m["h_min_used"]
            con.print(f"note: a recording of {n_used} frame{'s' if n_used > 1 else ''}: an object is kept when seen in "
                      f"{n_used} frame{'s' if n_used > 1 else ''} (h_min {default_h_min} asks for more sightings "
                      "than there are frames); single detections are not confirmed by a second view",
                      highlight=False)
        if m.get("weak_confirmed_tracks"):
            t = cfg.tracker
            con.print(f"{m['weak_confirmed_tracks']} track(s) confirmed from low-score candidates ({t.weak_h_min} "
                      f"sightings, {t.weak_confident} confident, agreeing on the label)", highlight=False)
        if m.get("shape_confirmed_tracks"):
            con.print(f"{m['shape_confirmed_tracks']} of them without a confident sighting: their points have "
                      "the label's shape (a table's top at table height, open below) from 3 camera places",
                      highlight=False)
        for why in m.get("relabelled_by_size", []):
            con.print(f"label from the size: {why}", highlight=False)
        for reason, frames in _grouped(m["frames_skipped"]):
            con.print(f"[yellow]skipped {_frames(frames)}:[/] {reason}", highlight=False)
        for err in m.get("detector_errors", []):
            con.print(f"[yellow]detector failed on {err['count']} frame(s) (first: {err['first_frame']}), their depth "
                      f"still mapped:[/] {err['example']}", highlight=False)
        if not cmap.objects:
            failed = sum(e["count"] for e in m.get("detector_errors", []))
            h_min = m["config"]["tracker"]["h_min"]
            why = (f"the detector failed on {failed} of {m['frames_used']} frames" if failed else
                   "no frame could be used" if not m["frames_used"] else
                   f"none of {m['tracks']} tracks was seen in {h_min} frames (h_min)" if m["tracks"] else
                   "the detector found nothing it keeps in these frames (try a lower score_threshold, "
                   "or another --detector)")
            con.print(f"[yellow]warning:[/] the map has 0 objects: {why}", highlight=False)


def _parse_transform(text: str) -> Any:
    """``X,Y,YAW`` (metres, metres, degrees) or a JSON file holding a 4x4 matrix."""
    import numpy as np

    from capnav.core.errors import InputError
    from capnav.core.jsonfile import read_json_object

    p = Path(text)
    if p.is_file():
        data = read_json_object(p, "transform file")
        try:
            T = np.asarray(data.get("transform"), dtype=np.float64)
        except (TypeError, ValueError):
            T = np.zeros(0)
        if T.shape != (4, 4) or not np.isfinite(T).all() or not np.allclose(T[3], [0, 0, 0, 1]):
            raise InputError(f"--transform {p}: expected {{\"transform\": a 4x4 rigid matrix (4 rows)}}, got shape "
                             f"{T.shape}")
        return T
    try:
        x, y, yaw = (float(v) for v in text.split(","))
    except ValueError:
        raise InputError(f"--transform must be X,Y,YAW (metres, metres, degrees) or a JSON file, "
                         f"got {text!r}") from None
    c, s = np.cos(np.radians(yaw)), np.sin(np.radians(yaw))
    T = np.eye(4)
    T[:2, :2] = [[c, -s], [s, c]]
    T[0, 3], T[1, 3] = x, y
    return T


def _update(map_path: Path, reader: Any, output: Path, det: Any, enc: Any, cfg: Any, transform: str | None,
            icp: bool, progress: bool) -> None:
    """``capnav map --update MAP DATASET -o OUT``: register, fuse, write atomically under a lock."""
    from capnav.cli.options import check_input_path
    from capnav.core.console import make_console
    from capnav.io.mapfile import load_map, lock_map, save_map
    from capnav.mapping.update import check_same_home, register_recording, update_map

    check_input_path(map_path, "map file")
    init = _parse_transform(transform) if transform is not None else None
    con = make_console(stderr=True)
    with lock_map(map_path), (lock_map(output) if output.resolve() != map_path.resolve() else _nothing()):
        cmap = load_map(map_path)
        check_same_home(cmap, reader, str(map_path))
        reg = register_recording(cmap, reader, f"{reader.path} to {map_path}", init=init, icp=icp)
        con.print(f"registered {reader.path} to {map_path} by {reg.method}: {100 * reg.fitness:.0f}% of its depth on "
                  f"the map's surface, residual {reg.rmse:.3f} m", highlight=False)
        on_interrupt(f"{output} was not written ({map_path} is as it was)")
        new, rep = update_map(cmap, reader, det, enc, transform=reg.T, mapper_config=cfg, progress=progress,
                              registration=reg)
        save_map(new, output)
    con.print(f"{output}: {rep.summary()} ({rep.cpu_seconds:.1f} s CPU); run `capnav caption {output} --dataset "
              f"{reader.path}` for the views and captions of moved and new objects", highlight=False)


@contextlib.contextmanager
def _nothing() -> Iterator[None]:
    yield


def _grouped(skips: list[dict[str, Any]]) -> list[tuple[str, list[Any]]]:
    """Skipped frames grouped by reason (numbers blanked), in first-seen order, with one example reason."""
    groups: dict[str, tuple[str, list[Any]]] = {}
    for s in skips:
        groups.setdefault(re.sub(r"[0-9]+", "#", str(s["reason"])), (str(s["reason"]), []))[1].append(s["frame"])
    return list(groups.values())


def _frames(frames: list[Any]) -> str:
    return f"frame {frames[0]}" if len(frames) == 1 else f"{len(frames)} frames (first: {frames[0]})"
