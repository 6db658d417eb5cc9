"""``roughwalk robot list | info | show``."""

from __future__ import annotations

import argparse
from typing import Any

from roughwalk.cli.common import add_output_args, info, result_envelope, write_json


def register(sub: Any) -> None:
    """Add the ``robot`` command group."""
    p = sub.add_parser("robot", help="list, inspect and draw robot models")
    rsub = p.add_subparsers(dest="robot_command", metavar="SUBCOMMAND")

    pl = rsub.add_parser("list", help="the registered robots")
    pl.add_argument("--json", metavar="FILE", help="write the registry as JSON here")
    pl.set_defaults(func=cmd_list)

    pi = rsub.add_parser("info", help="mass, leg lengths, joint limits, nominal stance")
    pi.add_argument("robot", help="a registered name or an MJCF path")
    add_output_args(pi)
    pi.set_defaults(func=cmd_info)

    ps = rsub.add_parser(
        "show", help="draw the robot in its nominal stance with its collision model"
    )
    ps.add_argument("robot", help="a registered name or an MJCF path")
    add_output_args(ps, picture=True)
    ps.set_defaults(func=cmd_show)
    p.set_defaults(func=lambda args: (p.print_help(), 2)[1])


def cmd_list(args: argparse.Namespace) -> int:
    """Print the robot registry."""
    from roughwalk.robots import list_robots

    rows = list_robots()
    for r in rows:
        print(f"{r.name:<12} {r.description}")
        print(f"{'':<12} {r.mjcf_path}")
    if args.json:
        data = [
            {
                "name": r.name,
                "mjcf_path": str(r.mjcf_path),
                "description": r.description,
                "sources": r.sources,
            }
            for r in rows
        ]
        write_json(args.json, result_envelope("robot_list", robots=data))
    return 0


def _info_dict(name: str) -> tuple[Any, dict[str, Any]]:
    from roughwalk.robots import load_robot

    robot = load_robot(name)
    data = robot.info()
    stance = robot.nominal_stance
    data["nominal_stance"] = {
        "feet_base_frame": {leg: stance.feet[i].tolist() for i, leg in enumerate(robot.legs)},
        "base_height": stance.base_height,
    }
    return robot, data


def cmd_info(args: argparse.Namespace) -> int:
    """Print a robot's summary."""
    robot, data = _info_dict(args.robot)
    lengths = robot.leg_lengths
    print(
        f"{robot.name}: {robot.mass:.3f} kg, {len(robot.joint_names)} joints, "
        f"foot radius {robot.foot_radius * 1000:.1f} mm"
    )
    print(f"  MJCF: {robot.mjcf_path}")
    print(f"  nominal base height: {robot.nominal_stance.base_height:.4f} m")
    for i, leg in enumerate(robot.legs):
        print(
            f"  {leg}: hip at {robot.hip_positions[i].round(4).tolist()} m, "
            f"thigh {lengths[i, 0]:.4f} m, shank {lengths[i, 1]:.4f} m"
        )
    for j, name in enumerate(robot.joint_names):
        print(
            f"  {name:<14} [{robot.joint_lower[j]:+.3f}, {robot.joint_upper[j]:+.3f}] rad, "
            f"{robot.joint_velocity_limit[j]:.2f} rad/s, {robot.joint_torque_limit[j]:.2f} N·m"
        )
    if args.json:
        write_json(args.json, result_envelope("robot_info", robot=robot.name, info=data))
    return 0


def cmd_show(args: argparse.Namespace) -> int:
    """Draw a robot to a PNG."""
    from roughwalk.robots import load_robot
    from roughwalk.viz.robot_plot import save_robot_picture

    robot = load_robot(args.robot)
    out = args.output or f"{robot.name}.png"
    save_robot_picture(robot, out)
    info(f"wrote {out}")
    if args.json:
        write_json(args.json, result_envelope("robot_show", robot=robot.name, picture=out))
    return 0
