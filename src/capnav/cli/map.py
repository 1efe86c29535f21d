"""``capnav map DATASET -o MAP``: build a CapNav map from a posed RGB-D dataset folder."""

from __future__ import annotations

import json
import re
import time
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
        encoder: str = typer.Option("label-embedding", help="dense feature encoder backend"),
        embedder: str = typer.Option("minilm", help="text embedder of the label-embedding encoder"),
        max_frames: MaxFrames = None,
        strict: bool = typer.Option(False, help="stop at the first bad frame instead of skipping it"),
        progress: bool = typer.Option(True, help="show a progress bar"),
    ) -> None:
        """Detect, fuse the semantic voxel map, track objects and write the map file."""
        from rich.console import Console

        from capnav.core.errors import InputError
        from capnav.io.dataset import DatasetReader
        from capnav.io.mapfile import save_map
        from capnav.language import create_embedder
        from capnav.mapping import MapperConfig, map_dataset
        from capnav.perception import create_detector, create_encoder

        check_output_file(output, "-o")  # fail on an unwritable output and a bad folder before any model loads
        options = parse_detector_options(detector_option)
        reader = DatasetReader(dataset)
        kwargs = {"noise": noise, "seed": seed, **options} if detector == "sim" else options
        try:
            det = create_detector(detector, **kwargs)
        except TypeError as e:  # a backend whose factory does not check its kwargs itself
            raise InputError(f"detector {detector!r} rejected its options {sorted(options)}: {e}") from None
        enc = create_encoder(encoder, embedder=create_embedder(embedder))
        cfg = MapperConfig(on_bad_frame="raise" if strict else "skip")
        on_interrupt(f"no map was written ({output} is as it was)")
        t0 = time.perf_counter()
        cmap = map_dataset(reader, det, enc, cfg, max_frames=max_frames, progress=progress)
        seconds = time.perf_counter() - t0
        save_map(cmap, output)
        con = Console(stderr=True)
        m = cmap.meta
        speed = f" ({m['frames_used'] / seconds:.1f} frames/s)" if seconds > 0 and m["frames_used"] else ""
        con.print(f"{output}: {len(cmap.objects)} objects, {len(cmap.voxels)} voxels, "
                  f"{m['frames_used']} frames{speed}, detector {det.id}")
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


def _grouped(skips: list[dict[str, Any]]) -> list[tuple[str, list[Any]]]:
    """Skipped frames grouped by reason (numbers blanked), in first-seen order, with one example reason."""
    groups: dict[str, tuple[str, list[Any]]] = {}
    for s in skips:
        groups.setdefault(re.sub(r"[0-9]+", "#", str(s["reason"])), (str(s["reason"]), []))[1].append(s["frame"])
    return list(groups.values())


def _frames(frames: list[Any]) -> str:
    return f"frame {frames[0]}" if len(frames) == 1 else f"{len(frames)} frames (first: {frames[0]})"
