"""``roughwalk terrain list | info | show``."""

from __future__ import annotations

import argparse
import json
from typing import Any

from roughwalk.cli.common import add_output_args, info, result_envelope, write_json
from roughwalk.terrain import load_terrain


def register(sub: Any) -> None:
    """Add the ``terrain`` command group."""
    p = sub.add_parser("terrain", help="list, inspect and draw terrains")
    tsub = p.add_subparsers(dest="terrain_command", metavar="SUBCOMMAND")

    pl = tsub.add_parser("list", help="the terrain generators with their parameters")
    pl.add_argument("--json", metavar="FILE", help="write the list as JSON here")
    pl.set_defaults(func=cmd_list)

    pi = tsub.add_parser("info", help="extent, resolution and unknown cells of a terrain")
    pi.add_argument("terrain", help="a file, a generator spec or a course (a.mat+b.mat@180)")
    add_output_args(pi)
    pi.set_defaults(func=cmd_info)

    ps = tsub.add_parser("show", help="draw a terrain as shaded relief")
    ps.add_argument("terrain", help="a file, a generator spec or a course")
    add_output_args(ps, picture=True)
    ps.set_defaults(func=cmd_show)
    p.set_defaults(func=lambda args: (p.print_help(), 2)[1])


def generator_table() -> list[dict[str, Any]]:
    """Every registered generator with its parameters, as plain data."""
    from roughwalk.terrain.generators import list_generators

    return [g.to_dict() for g in list_generators()]


def cmd_list(args: argparse.Namespace) -> int:
    """Print the generator registry."""
    table = generator_table()
    for g in table:
        print(f"{g['name']:<16} {g['description']}")
        for prm in g["params"]:
            unit = f" [{prm['unit']}]" if prm.get("unit") else ""
            print(f"    {prm['name']:<18} = {prm['default']!s:<10}{unit}  {prm.get('doc', '')}")
    if args.json:
        write_json(args.json, result_envelope("terrain_generators", generators=table))
    return 0


def cmd_info(args: argparse.Namespace) -> int:
    """Print a terrain's summary."""
    t = load_terrain(args.terrain)
    data = t.info()
    print(json.dumps(data, indent=2))
    if args.json:
        write_json(args.json, result_envelope("terrain_info", terrain=t.spec, info=data))
    return 0


def cmd_show(args: argparse.Namespace) -> int:
    """Draw a terrain to a PNG."""
    from roughwalk.viz.terrain_plot import save_terrain_picture

    t = load_terrain(args.terrain)
    out = args.output or f"{t.name.replace('/', '_')}.png"
    save_terrain_picture(t, out)
    info(f"wrote {out}")
    if args.json:
        write_json(
            args.json, result_envelope("terrain_show", terrain=t.spec, picture=out, info=t.info())
        )
    return 0
