"""``roughwalk demo``: the end-to-end showcase."""

from __future__ import annotations

import argparse
from typing import Any

from roughwalk.cli.common import info


def register(sub: Any) -> None:
    """Add the ``demo`` command."""
    from roughwalk.demo import DEFAULT_DEMO_TERRAIN

    p = sub.add_parser("demo", help="run the end-to-end demo and write pictures")
    p.add_argument("--out-dir", default="demo-output", help="folder for the outputs")
    p.add_argument("--terrain", default=DEFAULT_DEMO_TERRAIN, help="terrain spec to use")
    p.set_defaults(func=cmd_demo)


def cmd_demo(args: argparse.Namespace) -> int:
    """Run :func:`roughwalk.demo.run_demo`."""
    from roughwalk.demo import run_demo

    run_demo(args.out_dir, args.terrain, progress=info)
    return 0
