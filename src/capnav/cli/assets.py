"""``capnav assets``: fetch Sweet Home 3D furniture meshes into a cache (for ``--furniture sh3d``)."""

from __future__ import annotations

from pathlib import Path

import typer


def register(app: typer.Typer) -> None:
    @app.command("assets")
    def assets_cmd(
        dir: Path | None = typer.Option(None, "--dir", help="cache folder (default ~/.cache/capnav/assets)"),
        deb: Path | None = typer.Option(None, "--deb", help="use this sweethome3d-furniture .deb instead of apt-get"),
        catalog: list[str] | None = typer.Option(None, "--catalog", help="only these catalogs (e.g. BlendSwap-CC-0)"),
    ) -> None:
        """Run `apt-get download sweethome3d-furniture` + `dpkg-deb -x`, keep CapNav's categories, split
        multi-material OBJ files per material, and record each model's size, creator and licence."""

        from capnav.core.console import make_console
        from capnav.sim.sh3d import fetch_assets, load_catalog

        out = fetch_assets(dir, deb=deb, catalogs=catalog or None)
        models = load_catalog(out.parent)
        licences = sorted({m.license for m in models})
        cats = sorted({m.category for m in models})
        make_console().print(f"{len(models)} models in {len(cats)} categories written to {out} "
                        f"(licences: {', '.join(licences)}); use: capnav sim --furniture sh3d", markup=False)
