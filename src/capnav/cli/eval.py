"""``capnav eval``: the multi-object navigation benchmark (label-only and description protocols)."""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Annotated

import typer

from capnav.cli.options import Height, MaxFrames, Seed, Width, check_output_dir, on_interrupt

if TYPE_CHECKING:
    from capnav.eval.metrics import Summary


def register(app: typer.Typer) -> None:
    @app.command("eval")
    def eval_(
        scenes: Annotated[int, typer.Option(min=1, help="number of apartments (the paper: 10)")] = 10,
        episodes_per_scene: Annotated[int, typer.Option(min=1, help="episodes per apartment and protocol")] = 9,
        seed: Seed = 0,
        methods: Annotated[str, typer.Option(help="comma-separated method names, or 'all' (every registered one)")
                           ] = "all",
        protocols: Annotated[str, typer.Option(help="comma-separated: label, description")] = "label,description",
        workers: Annotated[int, typer.Option(min=1, help="local worker processes (one apartment per task)")] = 2,
        out: Annotated[Path, typer.Option("--out", "-o", help="run folder")] = Path("runs/eval"),
        ray: Annotated[str | None, typer.Option(
            "--ray", help="run the apartments on a Ray cluster at this address ('local' starts one)")] = None,
        episodes: Annotated[Path | None, typer.Option(
            help="folder with <protocol>.json episode files of an earlier run, to rerun exactly")] = None,
        width: Width = 320,
        height: Height = 240,
        max_frames: MaxFrames = None,
        pictures: Annotated[int, typer.Option(min=0, help="failure pictures per method, protocol and apartment")] = 1,
        max_steps: Annotated[int, typer.Option(min=1, help="action budget per subgoal of the exploring methods")
                             ] = 200,
        progress: Annotated[bool, typer.Option(help="show progress")] = True,
        size: Annotated[str, typer.Option(
            help="house size: default (3-7 rooms) or large (8-14 rooms, 60-150 objects, near Matterport scale)")
                        ] = "default",
        furniture: Annotated[str, typer.Option(
            help="apartment furniture: primitives, or sh3d (Sweet Home 3D meshes, after `capnav assets`)")
                             ] = "primitives",
        detector: Annotated[str, typer.Option(
            help="detector of every method: sim (with --noise), or a real one (yolo-fastest, centernet, owl)")
                            ] = "sim",
        noise: Annotated[str, typer.Option(help="sim detector noise: default, hard, oracle")] = "default",
        detector_option: Annotated[list[str] | None, typer.Option(
            "--detector-option", metavar="KEY=VALUE", help="setting of a real detector, repeatable")] = None,
        instructions: Annotated[Path | None, typer.Option(
            help="run the free-phrasing protocol from this JSONL file of hand-written instructions (seed, "
                 "instruction, robot, kind, accept_ids) instead of generated episodes")] = None,
        changes: Annotated[str | None, typer.Option(
            "--changes", metavar="moved=N,removed=N,added=N[,hidden=N]",
            help="the change track instead (docs/change.md): map visit 1, update with visit 2 after these "
                 "changes, score per change class for capnav (updated map), capnav-static, capnav-remap, "
                 "capnav-search (visit 1's map and --search, on moved and added objects) and "
                 "capnav-update-search (the updated map and --search, on hidden objects: carried into a "
                 "room visit 2 never entered)")] = None,
        per_class: Annotated[int, typer.Option(min=1, help="with --changes: subgoals per change class and "
                                                           "apartment")] = 8,
        reuse_maps: Annotated[bool, typer.Option(
            "--reuse-maps", help="with --changes: load the three maps an earlier run of the same -o saved instead "
                                 "of making them again (no CPU figures: they were measured by that run)")] = False,
    ) -> None:
        """Run every method on the same apartments, maps and episodes; write results.json and report.md."""
        from capnav.core.console import make_console

        if changes is not None:
            from capnav.eval.change_track import METHODS as METHODS_C
            from capnav.eval.change_track import ChangeTrackConfig, run_change_track, table
            from capnav.sim.changes import ChangeSpec

            check_output_dir(out, "--out")
            chosen = METHODS_C if methods == "all" else tuple(m.strip() for m in methods.split(",") if m.strip())
            ccfg = ChangeTrackConfig(scenes=scenes, seed=seed, changes=ChangeSpec.parse(changes), per_class=per_class,
                                     width=width, height=height, noise=noise, reuse_maps=reuse_maps, methods=chosen)
            on_interrupt(f"the change track stopped; recordings made so far are kept in {out}/scenes")
            res_c = run_change_track(ccfg, out, progress=progress)
            make_console().print(table(res_c), markup=False, highlight=False)
            return
        from capnav.eval.benchmark import run_benchmark
        from capnav.eval.episodes import parse_protocols
        from capnav.eval.method import load_methods
        from capnav.eval.scene_task import DEFAULT_METHODS, EvalConfig
        from capnav.pipeline import PipelineConfig

        if methods == "all":
            names = DEFAULT_METHODS + tuple(m for m in load_methods() if m not in DEFAULT_METHODS)
        else:
            names = tuple(m.strip() for m in methods.split(",") if m.strip())
        check_output_dir(out, "--out")  # a run folder may exist: finished apartments are reused
        from capnav.cli.map import parse_detector_options
        from capnav.perception import DETECTORS
        from capnav.sim.furniture import FURNITURE

        if detector not in DETECTORS.names():
            raise typer.BadParameter(f"unknown detector {detector!r}; available: {', '.join(DETECTORS.names())}",
                                     param_hint="--detector")
        if furniture not in FURNITURE.names():
            raise typer.BadParameter(f"unknown furniture {furniture!r}; available: {', '.join(FURNITURE.names())}",
                                     param_hint="--furniture")
        from capnav.sim.config import HOUSE_SIZES

        if size not in HOUSE_SIZES:
            raise typer.BadParameter(f"unknown house size {size!r}; choose from {', '.join(HOUSE_SIZES)}",
                                     param_hint="--size")
        opts = parse_detector_options(detector_option or [])
        sets = {}
        protos: tuple[str, ...]
        if instructions is not None:
            from capnav.eval.phrasings import load_phrasings

            sets = {"phrasing": load_phrasings(instructions, seed)}
            protos = ("phrasing",)
        else:
            protos = tuple(parse_protocols(protocols))
        cfg = EvalConfig(scenes=scenes, episodes_per_scene=episodes_per_scene, seed=seed, methods=names,
                         protocols=protos, pictures_per_scene=pictures, max_steps=max_steps,
                         pipeline=PipelineConfig(width=width, height=height, max_frames=max_frames,
                                                 detector=detector, detector_noise=noise, furniture=furniture,
                                                 size=size,
                                                 detector_options=tuple(sorted(opts.items()))))
        on_interrupt(f"workers stopped; finished apartments are kept in {out}/scenes (run the same command "
                     "again to resume from them)")
        res = run_benchmark(cfg, out, workers=workers, ray_address=ray, episodes_dir=episodes, progress=progress,
                            command=" ".join(["capnav", *map(shlex.quote, sys.argv[1:])]), episode_sets=sets)
        con = make_console()
        for s in res.summaries:
            con.print(summary_line(s))
        con.print(f"{len(res.records)} subgoals in {res.seconds:.0f} s; report: {res.out / 'report.md'}")


def summary_line(s: Summary) -> str:
    """One method and protocol on the console; a hand-written instruction is one subgoal, so its
    line has no in-a-row figures."""
    chain = "" if s.protocol == "phrasing" else f"in a row {' / '.join(f'{100 * v:.0f}' for v in s.in_a_row)}, "
    strict = f", strict indep. {100 * s.independent_strict:.1f}%" if s.independent_strict is not None else ""
    return f"{s.method:>20} {s.protocol:>11}: {chain}indep. {100 * s.independent:.1f}%, SPL {100 * s.spl:.1f}{strict}"
