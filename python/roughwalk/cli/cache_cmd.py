"""``roughwalk cache list|warm|clear``: the on-disk cache of built NLPs.

Solves with ``compiled`` set to "auto" or "on" store each NLP structure they
build (``$ROUGHWALK_CACHE/nlp``, else ``~/.cache/roughwalk/nlp``), so that
later processes read it instead of building it again. ``warm`` builds and
stores one structure ahead of time, ``list`` shows what is stored and
``clear`` removes it.
"""

from __future__ import annotations

import argparse
from typing import Any

from roughwalk.cli.common import add_output_args, info, result_envelope, write_json


def register(sub: Any) -> None:
    """Add the ``cache`` command and its subcommands."""
    p = sub.add_parser(
        "cache",
        help="list, warm or clear the on-disk cache of built trajectory-optimisation NLPs",
        description=__doc__.split("\n\n", 1)[1].strip() if __doc__ else None,
    )
    actions = p.add_subparsers(dest="action", metavar="ACTION", required=True)

    listing = actions.add_parser("list", help="show the stored NLPs")
    listing.add_argument("--json", metavar="FILE", help="write the listing here")
    listing.set_defaults(func=cmd_list)

    clear = actions.add_parser("clear", help="remove stored NLPs")
    clear.add_argument(
        "--kind",
        choices=("compiled", "serialized", "failed", "unreadable", "unfinished"),
        help="only entries of this kind (default: all)",
    )
    clear.set_defaults(func=cmd_clear)

    warm = actions.add_parser(
        "warm",
        help="build one NLP and store it (the flags of `roughwalk optimize`)",
        description=(
            "Build the NLP of one structure (robot, terrain, gait, steps, duration, config) "
            "and store it, so that later solves of any task on it skip the build."
        ),
    )
    warm.add_argument(
        "--preset", choices=("melon", "towr"), default="melon", help="base configuration"
    )
    warm.add_argument(
        "--robot",
        help="a registered robot or an MJCF path (default anymal_c; only where the "
        "config's body_model is 'robot': the towr preset's body is a fixed parameter set)",
    )
    warm.add_argument("--terrain", default="flat", help="a terrain spec")
    warm.add_argument("--gait", help="walk, trot, pace, bound or gallop")
    warm.add_argument("--steps", type=int, help="number of swings of all feet")
    warm.add_argument("--duration", type=float, help="total duration [s]")
    warm.add_argument(
        "--optimize-durations", action="store_true", help="phase durations are variables"
    )
    warm.add_argument(
        "--compiled",
        choices=("auto", "on"),
        default="auto",
        help="auto: CasADi's serialised form (no compiler); on: compiled with gcc",
    )
    add_output_args(warm)
    warm.set_defaults(func=cmd_warm)


def cmd_list(args: argparse.Namespace) -> int:
    """Print one line per stored NLP and the total size."""
    from roughwalk.trajopt import nlp_cache
    from roughwalk.trajopt.compiled_nlp import cache_dir

    entries = nlp_cache.entries()
    print(f"{cache_dir()}: {len(entries)} entries")
    for e in entries:
        variables = str(e.n_variables) if e.n_variables else "-"
        print(
            f"  {e.key[:16]}  {e.kind:<10} {e.size_bytes / 1e6:8.1f} MB  {variables:>6} variables"
        )
    total = sum(e.size_bytes for e in entries)
    print(f"  total {total / 1e6:.1f} MB")
    if args.json:
        rows = [
            {
                "key": e.key,
                "kind": e.kind,
                "size_bytes": e.size_bytes,
                "n_variables": e.n_variables,
                "path": str(e.path),
            }
            for e in entries
        ]
        write_json(
            args.json, result_envelope("nlp_cache", directory=str(cache_dir()), entries=rows)
        )
        info(f"wrote {args.json}")
    return 0


def cmd_clear(args: argparse.Namespace) -> int:
    """Remove entries; print how many and how much."""
    from roughwalk.trajopt import nlp_cache

    removed = nlp_cache.clear(kind=args.kind)
    total = sum(e.size_bytes for e in removed)
    print(f"removed {len(removed)} entries ({total / 1e6:.1f} MB)")
    return 0


def cmd_warm(args: argparse.Namespace) -> int:
    """Build and store one NLP structure (no iteration is taken)."""
    from roughwalk.config import configure
    from roughwalk.errors import InvalidArgumentError
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain
    from roughwalk.trajopt import Task, melon_config, optimize_motion, towr_config

    preset = melon_config() if args.preset == "melon" else towr_config()
    config = configure(preset, args.config, args.set)
    overrides: dict[str, Any] = {"compiled": args.compiled, "solver__max_iter": 0}
    for field in ("gait", "steps", "duration"):
        value = getattr(args, field)
        if value is not None:
            overrides[field] = value
    if args.optimize_durations:
        overrides["optimize_durations"] = True
    if config.body_model != "robot" and args.robot is not None:
        # The structure would be the named body's whatever robot was asked for:
        # storing it under the asker's belief would be a silent surprise.
        raise InvalidArgumentError(
            f"--robot {args.robot} has no effect: the config's body_model is "
            f"'{config.body_model}', a fixed parameter set; drop --robot, or add "
            "--set body_model=robot to take the body from the robot's model"
        )
    robot = load_robot(args.robot or "anymal_c") if config.body_model == "robot" else None
    terrain = load_terrain(args.terrain)
    # Any task will do: the structure does not depend on it.
    task = Task((0.0, 0.0, 0.0), (0.5, 0.0, 0.0))
    result = optimize_motion(robot, terrain, task, config=config, **overrides)
    if result.status.value == "invalid_input":
        print(f"not stored: {result.message}")
        return 1
    print(
        f"{result.build}: {result.n_variables} variables, "
        f"build {result.build_time_s:.2f} s ({terrain.spec})"
    )
    if args.json:
        write_json(
            args.json,
            result_envelope(
                "nlp_cache_warm",
                build=result.build,
                build_time_s=result.build_time_s,
                n_variables=result.n_variables,
                terrain=terrain.spec,
            ),
        )
    return 0
