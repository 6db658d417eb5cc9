"""``roughwalk replay LOG --video out.mp4``: render a run's log again."""

from __future__ import annotations

import argparse
from typing import Any

from roughwalk.cli.common import info


def register(sub: Any) -> None:
    """Add the ``replay`` command."""
    p = sub.add_parser(
        "replay",
        help="re-render a run's log (run.json / run.npz) as a video",
        description="Rebuilds the run's world from the robot and terrain its log names and "
        "renders the logged states with a camera following the robot.",
    )
    p.add_argument("log", help="the run log: run.json or run.npz (both must be there)")
    p.add_argument("--video", default="replay.mp4", help="output video (.mp4, or .gif)")
    p.add_argument("--speed", type=float, default=1.0, help="playback speed")
    p.add_argument("--fps", type=float, default=30.0, help="frames per second")
    p.add_argument("--size", default="640x480", metavar="WxH", help="frame size [px]")
    p.add_argument("--shadows", action="store_true", help="cast shadows (slower)")
    p.set_defaults(func=cmd_replay)


def cmd_replay(args: argparse.Namespace) -> int:
    """Load the log, render, print the path written."""
    from roughwalk.errors import InvalidArgumentError
    from roughwalk.sim.run_log import RunLog
    from roughwalk.sim.video import render_run

    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
    except ValueError:
        raise InvalidArgumentError(f"--size must be WxH like 640x480, got {args.size!r}") from None
    log = RunLog.load(args.log)
    info(f"rendering {len(log)} states of {log.meta.get('robot')} on {log.meta.get('terrain')} ...")
    path = render_run(
        log,
        args.video,
        fps=args.fps,
        width=width,
        height=height,
        speed=args.speed,
        shadows=args.shadows,
    )
    print(path)
    return 0
