"""``capnav caption MAP --dataset DIR``: choose views, caption and embed every object of a map."""

from __future__ import annotations

from pathlib import Path

import typer

from capnav.cli.options import (
    check_input_path,
    check_map_matches_dataset,
    check_model_folder,
    check_output_file,
    on_interrupt,
)


def register(app: typer.Typer) -> None:
    @app.command("caption")
    def caption_cmd(
        map_path: Path = typer.Argument(..., help="map file written by `capnav map`"),
        dataset: Path | None = typer.Option(None, "--dataset", help="the dataset folder the map was built from "
                                            "(for the views); without it existing views are kept"),
        captioner: str = typer.Option("offline", help="offline | gemini | openai | hf-local"),
        model: str | None = typer.Option(None, help="model name for gemini / openai"),
        base_url: str | None = typer.Option(None, help="endpoint for gemini / openai (e.g. a local server)"),
        model_path: Path | None = typer.Option(None, help="local folder for hf-local"),
        embedder: str = typer.Option("minilm", help="minilm | onnx | sentence-transformers | bge-m3 | flag"),
        embedder_path: Path | None = typer.Option(None, help="local model folder for non-default embedders"),
        output: Path | None = typer.Option(None, "-o", "--output", help="write here instead of over MAP"),
        reselect_views: bool = typer.Option(False, help="choose views again for every object"),
        progress: bool = typer.Option(True, help="show progress bars"),
    ) -> None:
        """Fill captions and embeddings (paper 3.3); the caption cache makes reruns free."""
        from capnav.core.console import make_console
        from capnav.io.mapfile import load_map, save_map
        from capnav.language import create_captioner, create_embedder, describe_map
        from capnav.language.embedder import EMBEDDERS
        from capnav.language.vlm.base import VLMS

        check_input_path(map_path, "map file")
        out = output or map_path
        check_output_file(out, "-o" if output is not None else "MAP")
        check_model_folder("--embedder", embedder, embedder_path, "--embedder-path", EMBEDDERS.required(embedder))
        if captioner in VLMS:
            check_model_folder("--captioner", captioner, model_path, "--model-path", VLMS.required(captioner))
        kw: dict[str, object] = {}
        if model:
            kw["model"] = model
        if base_url:
            kw["base_url"] = base_url
        if model_path is not None:
            kw["path"] = model_path
        cap = create_captioner(captioner, **kw)
        emb = create_embedder(embedder, **({"path": embedder_path} if embedder_path is not None else {}))
        cmap = load_map(map_path)
        reader = None
        if dataset is not None:
            from capnav.io.dataset import DatasetReader

            reader = DatasetReader(dataset)
            check_map_matches_dataset(cmap.meta, map_path, dataset, reader)
        on_interrupt(f"{out} was not written (it is as it was); captions made so far are lost unless the "
                     "captioner caches them")
        rep = describe_map(cmap, reader, cap, emb, progress=progress, reselect_views=reselect_views)
        save_map(cmap, out)
        con = make_console(stderr=True)
        con.print(f"{out}: {rep.objects} objects, {rep.captions_new} new captions, {rep.captions_cached} cached, "
                  f"{rep.embeddings_new} embedded, "
                  f"{len(rep.fallbacks)} fallbacks; captioner {cap.model_id}, embedder {emb.model_id} "
                  f"({', '.join(f'{k} {v:.1f} s' for k, v in rep.seconds.items())})", highlight=False)
        for oid, why in rep.fallbacks[:10]:
            con.print(f"[yellow]object {oid}:[/] {why}", highlight=False)
