"""``roughwalk trajectory --plan PLAN.json``: full-body trajectories of a footstep plan."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from roughwalk.cli.common import add_output_args, info, result_envelope, write_json


def register(sub: Any) -> None:
    """Add the ``trajectory`` command."""
    p = sub.add_parser(
        "trajectory",
        help="turn a footstep plan into full-body trajectories (ZMP preview + CHOMP)",
        description=(
            "Reads the JSON of `roughwalk plan` (it names its robot and terrain), builds each "
            "footstep's trajectory (Zucker 2011, §5) and reports per step whether it is valid."
        ),
    )
    p.add_argument("--plan", required=True, metavar="PLAN.json", help="the footstep plan")
    p.add_argument("--robot", help="override the plan's robot (a name or an MJCF path)")
    p.add_argument("--terrain", help="override the plan's terrain spec")
    p.add_argument(
        "--inline-samples",
        action="store_true",
        help="put the sampled trajectories into the JSON instead of an .npz beside it",
    )
    add_output_args(p, picture=True, npz=True)
    p.set_defaults(func=cmd_trajectory)


def cmd_trajectory(args: argparse.Namespace) -> int:
    """Generate, print a table, write the JSON, the samples and the picture."""
    from roughwalk.config import configure
    from roughwalk.errors import PlanningError
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain
    from roughwalk.trajectories import TrajectoryConfig, footstep_trajectories

    cfg = configure(TrajectoryConfig(), args.config, args.set)
    path = Path(args.plan)
    try:
        plan = json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as e:
        raise PlanningError(f"cannot read footstep plan '{path}': {e}") from None
    robot = load_robot(args.robot) if args.robot else None
    terrain = load_terrain(args.terrain) if args.terrain else None
    info(f"generating footstep trajectories for {path} ...")
    result = footstep_trajectories(plan, robot=robot, terrain=terrain, config=cfg)

    print(
        f"{'step':>4} {'leg':<3} {'dur[s]':>6} {'clear[mm]':>9} {'vel ok':>6} "
        f"{'zmp[mm]':>7} {'valid':>5} {'iters':>5} {'tries':>5} {'ms':>7}"
    )
    for s in result.steps:
        r = s.report
        print(
            f"{r.step:>4} {r.leg:<3} {r.duration_s:>6.2f} {r.min_clearance_m * 1000:>9.1f} "
            f"{'yes' if r.velocity_limits_ok else 'NO':>6} {r.zmp_margin_m * 1000:>7.1f} "
            f"{'yes' if r.valid else 'NO':>5} {r.iterations:>5} {r.attempts:>5} "
            f"{r.optimize_ms:>7.1f}"
        )
    print(
        f"valid {result.valid_fraction:.0%} of {len(result.steps)} footsteps, "
        f"{result.duration_s:.2f} s of motion, generated in {result.total_ms:.0f} ms"
    )

    npz = args.npz
    if npz is None and args.json and not args.inline_samples:
        npz = str(Path(args.json).with_suffix(".npz"))
    if npz:
        result.save_npz(npz)
        info(f"wrote {npz}")
    if args.output:
        from roughwalk.viz.trajectory_plot import save_trajectory_picture

        save_trajectory_picture(result, args.output)
        info(f"wrote {args.output}")
    if args.json:
        summary = result.summary()
        fields: dict[str, Any] = {
            "plan": str(path),
            "steps": summary["steps"],
            "valid_fraction": summary["valid_fraction"],
            "duration_s": summary["duration_s"],
            "total_ms": summary["total_ms"],
            "joint_names": summary["joint_names"],
            "config": summary["config"],
        }
        if args.inline_samples:
            # JSON has no NaN: the lifted-foot clearance is null while all feet are down.
            fields["samples"] = {
                k: [None if x != x else x for x in v.ravel().tolist()]
                if v.dtype.kind == "f" and np.isnan(v).any()
                else v
                for k, v in result.sampled().items()
            }
        else:
            fields["samples_npz"] = npz
        write_json(
            args.json,
            result_envelope(
                "footstep_trajectories", robot=result.robot, terrain=result.terrain, **fields
            ),
        )
        info(f"wrote {args.json}")
    return 0
