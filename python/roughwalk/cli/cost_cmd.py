"""``roughwalk cost label | learn | show``: a terrain cost learned from expert preferences."""

from __future__ import annotations

import argparse
import signal
from pathlib import Path
from types import FrameType
from typing import Any

from roughwalk.cli.common import info, result_envelope, write_json


def register(sub: Any) -> None:
    """Add the ``cost`` command group."""
    p = sub.add_parser("cost", help="label foothold preferences, learn and show the terrain cost")
    csub = p.add_subparsers(dest="cost_command", metavar="SUBCOMMAND")

    pl = csub.add_parser(
        "label",
        help="start the labelling web app (loopback only) and print its address",
        description="Show pairs of footholds in a browser; every judgement is saved to the "
        "store at once. Re-open the same store later to add more.",
    )
    pl.add_argument(
        "--terrain", action="append", required=True, metavar="TERRAIN", help="repeatable"
    )
    pl.add_argument("--store", required=True, metavar="FILE.sqlite", help="preference store")
    pl.add_argument("--port", type=int, default=0, help="TCP port (0: any free one)")
    pl.add_argument("--seed", type=int, default=0, help="seed of the pairs shown")
    pl.add_argument(
        "--terrain-dir", action="append", default=[], metavar="DIR", help=_TERRAIN_DIR_HELP
    )
    pl.add_argument("--verbose", action="store_true", help="log every HTTP request")
    _add_learning_args(pl)
    pl.set_defaults(func=cmd_label)

    pn = csub.add_parser("learn", help="learn a terrain cost from a preference store")
    pn.add_argument("store", metavar="FILE.sqlite", help="preference store")
    pn.add_argument("--save", required=True, metavar="COST.json", help="write the cost here")
    pn.add_argument(
        "--terrain-dir", action="append", default=[], metavar="DIR", help=_TERRAIN_DIR_HELP
    )
    _add_learning_args(pn)
    pn.add_argument("--json", metavar="FILE", help="write the learning report here")
    pn.set_defaults(func=cmd_learn)

    ps = csub.add_parser("show", help="draw a terrain's cost map (blue low, red high)")
    ps.add_argument("--terrain", required=True, metavar="TERRAIN", help="a file, spec or course")
    ps.add_argument("--cost", metavar="COST.json", help="a learned cost (default: the shipped one)")
    ps.add_argument("--leg", default="front", choices=("front", "hind"))
    ps.add_argument("--heading", type=float, default=None, help="robot heading [rad]")
    ps.add_argument("-o", "--output", metavar="FILE.png", help="write the picture here")
    ps.add_argument("--npz", metavar="FILE", help="write arrays x, y, cost here (.npz)")
    ps.add_argument("--json", metavar="FILE", help="write the machine-readable result here")
    ps.set_defaults(func=cmd_show)
    p.set_defaults(func=lambda args: (p.print_help(), 2)[1])


_TERRAIN_DIR_HELP = "folder to look for the store's terrain files in (repeatable)"


def _add_learning_args(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--separate-legs", action="store_true", help="learn front and hind feet apart"
    )
    parser.add_argument(
        "--oriented", action="store_true", help="features in the robot's heading frame"
    )
    parser.add_argument("--folds", type=int, default=None, help="cross-validation folds (5)")
    parser.add_argument("--learn-seed", type=int, default=None, help="seed of the learner (0)")
    parser.add_argument("--config", metavar="FILE.toml", help="learning config overrides")
    parser.add_argument(
        "--set",
        metavar="KEY=VALUE",
        action="append",
        default=[],
        help="override a learning field, e.g. svm.regularization=0.1 (repeatable)",
    )


def _learning_config(args: argparse.Namespace) -> Any:
    from roughwalk.config import configure
    from roughwalk.planning import CostLearningConfig

    sets = list(args.set)
    if args.separate_legs:
        sets.append("separate_legs=true")
    if args.oriented:
        sets.append("oriented=true")
    if args.folds is not None:
        sets.append(f"folds={args.folds}")
    if args.learn_seed is not None:
        sets.append(f"svm.seed={args.learn_seed}")
    return configure(CostLearningConfig(), args.config, sets)


def _stop_on_sigterm() -> None:
    """Let ``kill PID`` stop the server as Ctrl+C does, closing the store cleanly."""

    def handler(signum: int, frame: FrameType | None) -> None:
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, handler)


def cmd_label(args: argparse.Namespace) -> int:
    """Serve the labelling app until Ctrl+C (or SIGTERM)."""
    from roughwalk.planning import PreferenceStore, TerrainResolver
    from roughwalk.planning.labeling import LabelingServer, LabelingSession
    from roughwalk.terrain import load_terrain

    learning = _learning_config(args)
    terrains = [load_terrain(spec) for spec in args.terrain]
    store = PreferenceStore.open(args.store, create=True)
    try:
        resolver = TerrainResolver([store.path.parent, *args.terrain_dir])
        session = LabelingSession(
            store, terrains, learning=learning, seed=args.seed, resolver=resolver
        )
        try:
            server = LabelingServer(session, port=args.port, verbose=args.verbose)
            before = store.count()
            for problem in session.unusable:
                info(
                    f"note: earlier judgements on a terrain not found are kept, not learned from: "
                    f"{problem}"
                )
            print(
                f"labelling {len(terrains)} terrain(s) into {store.path} "
                f"({before} judgements so far)",
                flush=True,
            )
            print(f"open {server.url} in a browser (Ctrl+C to stop)", flush=True)
            _stop_on_sigterm()
            try:
                server.serve_forever()
            except KeyboardInterrupt:
                pass
            finally:
                server.shutdown()
            info(f"stopped: {store.count()} judgements in {store.path}")
        finally:
            session.close()
    finally:
        store.close()
    return 0


def cmd_learn(args: argparse.Namespace) -> int:
    """Learn a cost from a store, print the agreement, save the cost."""
    from roughwalk.planning import (
        PreferenceDataset,
        PreferenceStore,
        TerrainResolver,
        learn_cost,
    )

    learning = _learning_config(args)
    with PreferenceStore.open(args.store, readonly=True) as store:
        resolver = TerrainResolver([store.path.parent, *args.terrain_dir])
        data = PreferenceDataset.from_store(
            store, learning.radii, oriented=learning.oriented, resolver=resolver
        )
    for row, reason in data.skipped:
        info(f"skipped judgement #{row}: {reason}")
    from roughwalk.errors import PlanningError

    if data.n_strict == 0:
        raise PlanningError(
            f"preference store '{args.store}' holds no usable strict judgement "
            f"({len(data)} usable, {len(data.skipped)} skipped); "
            "label some with `roughwalk cost label`"
        )
    cost, report = learn_cost(
        data, learning, metadata={"preferences": str(Path(args.store).resolve())}
    )
    cost.save(args.save)
    cv = "n/a (too few)" if report.cv_agreement is None else f"{report.cv_agreement:.3f}"
    print(
        f"learned from {report.n_preferences} judgements ({report.n_strict} strict, "
        f"{report.n_equal} equal; front {report.by_leg['front']}, hind {report.by_leg['hind']}) "
        f"in {report.seconds:.2f} s"
    )
    print(
        f"agreement with the judgements: {report.train_agreement:.3f} trained on, "
        f"{cv} held out ({report.cv_folds}-fold cross-validation)"
    )
    print(f"wrote {args.save}")
    if args.json:
        write_json(
            args.json,
            result_envelope(
                "cost_learn",
                store=str(args.store),
                cost=str(args.save),
                config=_config_dict(learning),
                report=report.to_dict(),
            ),
        )
    return 0


def _config_dict(config: Any) -> dict[str, Any]:
    from roughwalk.config import to_dict

    return to_dict(config)


def cmd_show(args: argparse.Namespace) -> int:
    """Compute a terrain's cost map; write the picture and/or the arrays."""
    import numpy as np

    from roughwalk.planning import TerrainCost, default_cost_path
    from roughwalk.terrain import load_terrain

    cost = TerrainCost.load(args.cost)
    terrain = load_terrain(args.terrain)
    heading = args.heading
    if cost.oriented and heading is None:
        heading = 0.0
        info("this cost uses oriented features; drawing it for heading 0 rad (+x)")
    grid = cost.cost_map(terrain, heading=heading, leg=args.leg)
    finite = grid[np.isfinite(grid)]
    usable = finite.size / grid.size
    summary: dict[str, Any] = {"shape": list(grid.shape), "finite_fraction": usable}
    source = args.cost or f"{default_cost_path()} (shipped default)"
    if finite.size:
        lo, median, hi = (float(v) for v in np.percentile(finite, [0, 50, 100]))
        summary.update(min=lo, median=median, max=hi)
        print(
            f"cost of {terrain.name} ({args.leg} leg) from {source}: median {median:.3g}, "
            f"range {lo:.3g}–{hi:.3g}, {100 * (1 - usable):.1f}% of cells unusable (+inf)"
        )
    else:
        summary.update(min=None, median=None, max=None)
        print(f"no usable cell on {terrain.name}: every feature disc leaves the known ground")
    if args.npz:
        Path(args.npz).parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(args.npz, x=terrain.x, y=terrain.y, cost=grid)
        info(f"wrote {args.npz}")
    out = args.output
    if out is None and args.npz is None and args.json is None:
        out = f"{terrain.name.replace('/', '_')}_cost.png"
    if out:
        from roughwalk.viz.cost_plot import save_cost_picture

        save_cost_picture(terrain, grid, out, subtitle=f"{args.leg} leg · {Path(source).name}")
        info(f"wrote {out}")
    if args.json:
        write_json(
            args.json,
            result_envelope(
                "cost_show",
                terrain=terrain.spec,
                cost=args.cost,
                leg=args.leg,
                heading=heading,
                picture=out,
                npz=args.npz,
                summary=summary,
            ),
        )
    return 0
