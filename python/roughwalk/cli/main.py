"""Entry point of the ``roughwalk`` command."""

from __future__ import annotations

import argparse
import importlib
import sys
from collections.abc import Sequence

from roughwalk import __version__
from roughwalk.errors import RoughwalkError

# Each module defines ``register(subparsers)`` and sets ``func`` on its parsers.
COMMAND_MODULES = [
    "roughwalk.cli.terrain_cmd",
    "roughwalk.cli.sdf_cmd",
    "roughwalk.cli.robot_cmd",
    "roughwalk.cli.demo_cmd",
    "roughwalk.cli.plan_cmd",
    "roughwalk.cli.optimize_cmd",
    "roughwalk.cli.cache_cmd",
    "roughwalk.cli.bench_cmd",
    "roughwalk.cli.cost_cmd",
    "roughwalk.cli.trajectory_cmd",
    "roughwalk.cli.run_cmd",
    "roughwalk.cli.replay_cmd",
    "roughwalk.cli.track_cmd",
    "roughwalk.cli.init_cmd",
]


def build_parser() -> argparse.ArgumentParser:
    """The full argument parser (all registered commands)."""
    parser = argparse.ArgumentParser(
        prog="roughwalk",
        description="Plan and execute quadruped locomotion over rough terrain.",
    )
    parser.add_argument("--version", action="version", version=f"roughwalk {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the process exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except RoughwalkError as e:
        print(f"roughwalk: error: {e}", file=sys.stderr)
        return 1
    except BrokenPipeError:
        # Output piped into `head` and the like: stop quietly, as Unix tools do.
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except KeyboardInterrupt:
        print("roughwalk: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    raise SystemExit(main())
