"""``roughwalk track``: execute an optimised motion in MuJoCo with the whole-body controller."""

from __future__ import annotations

import argparse
from typing import Any

from roughwalk.cli.common import add_output_args, info, result_envelope, write_json


def register(sub: Any) -> None:
    """Add the ``track`` command."""
    p = sub.add_parser(
        "track",
        help="execute a `roughwalk optimize` result in MuJoCo with a whole-body QP controller",
        description=(
            "Track the motion of a `roughwalk optimize --json` result on its robot and terrain "
            "in MuJoCo (400 Hz whole-body QP, roughwalk.tracking) and judge it: success is no "
            "fall and the base within 10 cm of the planned final position after 1 s of standing."
        ),
    )
    p.add_argument("--trajectory", required=True, metavar="RESULT.json", help="optimize result")
    p.add_argument("--robot", help="override the robot the result names")
    p.add_argument("--terrain", help="override the terrain the result names")
    p.add_argument("--video", metavar="FILE.mp4", help="write a video of the run here")
    add_output_args(p, picture=True, npz=True)
    p.set_defaults(func=cmd_track)


def cmd_track(args: argparse.Namespace) -> int:
    """Track one motion; print the verdict; write JSON, video and picture when asked."""
    from roughwalk.config import configure
    from roughwalk.tracking import TrackingConfig
    from roughwalk.tracking.reference import load_trajectory
    from roughwalk.tracking.track import track

    config = configure(TrackingConfig(), args.config, args.set)
    result = load_trajectory(args.trajectory)
    info(f"tracking {args.trajectory} ({result.duration:.2f} s) ...")
    outcome = track(result, args.robot, args.terrain, config, video=args.video)
    print(
        f"{'success' if outcome.success else 'failure'}: {outcome.reason}\n"
        f"  mean position error {100 * outcome.mean_position_error_m:.1f} cm, "
        f"max orientation error {outcome.max_orientation_error_rad:.3f} rad, "
        f"{outcome.qp_failures} QP failures, {outcome.mean_qp_time_ms:.2f} ms per tick"
    )
    if args.json:
        write_json(
            args.json,
            result_envelope(
                "tracking_outcome",
                robot=args.robot or result.robot,
                terrain=args.terrain or result.terrain,
                trajectory=str(args.trajectory),
                **outcome.to_dict(),
            ),
        )
        info(f"wrote {args.json}")
    if args.npz and outcome.log is not None:
        outcome.log.to_npz(args.npz)
        info(f"wrote {args.npz}")
    if args.video and outcome.video:
        info(f"wrote {outcome.video}")
    if args.output:
        from roughwalk.viz.tracking import save_tracking_picture

        save_tracking_picture(outcome, args.output, title=str(args.trajectory))
        info(f"wrote {args.output}")
    return 0 if outcome.success else 1
