"""``roughwalk plan``: plan footsteps across a terrain (Zucker 2011, §4)."""

from __future__ import annotations

import argparse
from typing import Any

from roughwalk.cli.common import add_output_args, info, result_envelope, write_json
from roughwalk.errors import InvalidArgumentError


def register(sub: Any) -> None:
    """Add the ``plan`` command."""
    p = sub.add_parser(
        "plan",
        help="plan footsteps with pose certificates (anytime ARA*)",
        description="Plan footsteps from a trunk pose to a goal point with the anytime "
        "ARA* footstep planner. Exits 0 when a plan reaches the goal, 1 otherwise "
        "(the JSON says why).",
    )
    p.add_argument("--robot", default="littledog", help="registered robot name (littledog)")
    p.add_argument("--terrain", required=True, help="a file, a generator spec or a course")
    p.add_argument(
        "--start",
        required=True,
        metavar="X,Y,YAW",
        help="trunk pose [m, m, rad] (--start=-0.2,0.3,0 when X is negative)",
    )
    p.add_argument("--goal", required=True, metavar="X,Y", help="goal point [m] (--goal=-1,0)")
    p.add_argument(
        "--time-limit", type=float, default=5.0, metavar="S", help="planning budget [s] (5)"
    )
    p.add_argument(
        "--expansions",
        type=int,
        default=None,
        metavar="N",
        help="budget of expanded states instead: deterministic (same inputs, same plan)",
    )
    p.add_argument(
        "--cost", metavar="FILE", help="terrain cost file (default: the learned cost shipped)"
    )
    add_output_args(p, picture=True)
    p.set_defaults(func=cmd_plan)


def _numbers(text: str, n: int, flag: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        raise InvalidArgumentError(
            f"{flag} expects {n} comma-separated numbers, got {text!r}"
        ) from None
    if len(values) != n:
        raise InvalidArgumentError(f"{flag} expects {n} comma-separated numbers, got {text!r}")
    return values


def cmd_plan(args: argparse.Namespace) -> int:
    """Plan, print a summary, write the JSON and the picture."""
    from roughwalk.config import configure, to_dict
    from roughwalk.planning.footstep_config import FootstepConfig
    from roughwalk.planning.footstep_cost import load_terrain_cost
    from roughwalk.planning.footstep_planner import FootstepPlanner
    from roughwalk.robots import load_robot
    from roughwalk.terrain import load_terrain

    start = _numbers(args.start, 3, "--start")
    goal = _numbers(args.goal, 2, "--goal")
    robot = load_robot(args.robot)
    config = configure(FootstepConfig.for_robot(robot), args.config, args.set)
    terrain = load_terrain(args.terrain)
    cost = load_terrain_cost(args.cost)
    info(f"precomputing {terrain} for {robot.name} (SDF, terrain cost) ...")
    planner = FootstepPlanner(robot, terrain, config, cost)
    budget = (
        f"{args.expansions} expansions" if args.expansions is not None else f"{args.time_limit} s"
    )
    info(f"planning from {start} to {goal} with the {config.heuristic} heuristic, {budget} ...")
    time_limit = None if args.expansions is not None else args.time_limit
    plan = planner.plan(start, goal, time_limit=time_limit, expansions=args.expansions)
    if plan.solved:
        print(
            f"{plan.status}: {plan.steps} steps, cost {plan.cost:.2f}, "
            f"bound ε′ {plan.epsilon_bound:.3f}"
            f"{'' if plan.bound_guaranteed else ' (not guaranteed)'}; first plan after "
            f"{plan.first_solution_s:.3f} s; {plan.states_expanded} states, "
            f"{plan.actions_evaluated} actions ({plan.actions_per_s:,.0f}/s)"
        )
    else:
        reason = f": {plan.reason}" if plan.reason else ""
        print(f"{plan.status}{reason} ({plan.states_expanded} states expanded)")
    if args.json:
        data = plan.to_json()
        data.pop("robot")
        data.pop("terrain")
        write_json(
            args.json,
            result_envelope(
                "footstep_plan",
                robot=robot.name,
                terrain=terrain.spec,
                cost_model=str(args.cost) if args.cost else "default",
                config=to_dict(config),
                precompute_s=planner.precompute_s,
                **data,
            ),
        )
        info(f"wrote {args.json}")
    if args.output:
        from roughwalk.viz.footstep_plot import save_footstep_plan_picture

        x0, x1, y0, y1 = terrain.extent
        save_footstep_plan_picture(
            plan, planner.cost_front, (x0, x1, y0, y1), args.output, goal_radius=config.goal_radius
        )
        info(f"wrote {args.output}")
    return 0 if plan.solved else 1
