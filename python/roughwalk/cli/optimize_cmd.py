"""``roughwalk optimize``: a dynamic motion with TOWR's NLP and Melon et al.'s costs."""

from __future__ import annotations

import argparse
from typing import Any

from roughwalk.cli.common import add_output_args, info, result_envelope, write_json


def register(sub: Any) -> None:
    """Add the ``optimize`` command."""
    p = sub.add_parser(
        "optimize",
        help="optimise a dynamic motion (base, footholds, timing, forces) with IPOPT",
        description=(
            "Optimise base motion, footholds and contact forces over a terrain with TOWR's "
            "single-rigid-body NLP and Melon et al.'s costs (roughwalk.trajopt). Unset flags "
            "keep the configuration's values (melon preset; change it with --config/--set)."
        ),
    )
    p.add_argument("--robot", default="anymal_c", help="a registered robot or an MJCF path")
    p.add_argument("--terrain", default="flat", help="a terrain spec (file, generator, course)")
    p.add_argument("--gait", help="walk, trot, pace, bound or gallop (default: walk)")
    p.add_argument("--steps", type=int, help="number of swings of all feet (default: 16)")
    p.add_argument("--duration", type=float, help="total duration [s] (default: 5.5)")
    p.add_argument(
        "--start", default="0,0,0", metavar="X,Y,YAW", help="start base pose [m, m, rad]"
    )
    p.add_argument(
        "--goal", default="1.5,0,0", metavar="X,Y,YAW", help="goal base pose [m, m, rad]"
    )
    p.add_argument(
        "--init",
        help="initial guess: heuristic, footsteps:PLAN.json or learned (default: heuristic)",
    )
    p.add_argument("--max-iter", type=int, metavar="N", help="IPOPT iteration limit")
    p.add_argument(
        "--fixed-durations",
        action="store_true",
        help="keep the gait's phase durations (the default; optimise them with "
        "--set optimize_durations=true)",
    )
    p.add_argument(
        "--leg-reach",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="keep every foot within its leg's real reach (a ball per leg; on by "
        "default, --no-leg-reach leaves TOWR's box alone)",
    )
    add_output_args(p, picture=True, npz=True)
    p.set_defaults(func=cmd_optimize)


def cmd_optimize(args: argparse.Namespace) -> int:
    """Run one optimisation; print its summary; write JSON and a picture when asked."""
    from roughwalk.config import configure
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain
    from roughwalk.trajopt import Task, melon_config, optimize_motion, parse_pose

    config = configure(melon_config(), args.config, args.set)
    overrides: dict[str, Any] = {}
    for flag, field in (
        ("gait", "gait"),
        ("steps", "steps"),
        ("duration", "duration"),
        ("init", "init"),
    ):
        value = getattr(args, flag)
        if value is not None:
            overrides[field] = value
    if args.fixed_durations:
        overrides["optimize_durations"] = False
    if args.max_iter is not None:
        overrides["solver__max_iter"] = args.max_iter
    if args.leg_reach and "leg_reach" not in config.constraints:
        overrides["constraints"] = (*config.constraints, "leg_reach")
    elif args.leg_reach is False:
        overrides["constraints"] = tuple(c for c in config.constraints if c != "leg_reach")
    robot = load_robot(args.robot) if config.body_model == "robot" else None
    terrain = load_terrain(args.terrain)
    task = Task(parse_pose(args.start, "--start"), parse_pose(args.goal, "--goal"))
    info(
        f"optimising {overrides.get('gait', config.gait)} with "
        f"{overrides.get('steps', config.steps)} steps over {terrain.spec} ..."
    )
    result = optimize_motion(robot, terrain, task, config=config, **overrides)
    print(
        f"{result.status.value}: {result.message}\n"
        f"  {result.iterations} iterations, {result.solve_time_s:.3f} s "
        f"(build {result.build_time_s:.3f} s, "
        f"{1000 * result.time_per_iteration_s:.1f} ms/iteration)\n"
        f"  objective {result.objective:.6g}, max violation {result.max_violation:.3g}, "
        f"max force {result.max_force_n:.1f} N, {result.n_variables} variables"
    )
    if args.json:
        data = result.to_dict(npz=args.npz)
        robot_name = data.pop("robot", None) or result.robot
        if config.body_model != "robot":
            # A named body model (towr_anymal) is not a robot: the JSON names the robot
            # that executes the motion (`roughwalk track` loads it) and the body separately.
            robot_name = args.robot
            data["body_model"] = config.body_model
        write_json(
            args.json,
            result_envelope("trajopt_result", robot=robot_name, terrain=terrain.spec, **data),
        )
        info(f"wrote {args.json}")
    elif args.npz and result.splines is not None:
        result.to_dict(npz=args.npz)
    if args.output and result.splines is not None:
        from roughwalk.viz.trajopt_plot import save_trajopt_picture

        save_trajopt_picture(result, args.output, terrain=terrain)
        info(f"wrote {args.output}")
    return 0 if result.solved else 1
