"""``roughwalk sdf TERRAIN``: build a terrain's signed distance field."""

from __future__ import annotations

import argparse
from typing import Any

from roughwalk.cli.common import add_output_args, info, result_envelope, write_json
from roughwalk.terrain import load_terrain


def register(sub: Any) -> None:
    """Add the ``sdf`` command."""
    p = sub.add_parser("sdf", help="build the signed distance field of a terrain")
    p.add_argument("terrain", help="a file, a generator spec or a course")
    p.add_argument("--resolution", type=float, default=None, help="voxel size [m] (0.005)")
    add_output_args(p, picture=True, npz=True)
    p.set_defaults(func=cmd_sdf)


def cmd_sdf(args: argparse.Namespace) -> int:
    """Build the SDF, print its summary, write the requested outputs."""
    from roughwalk.config import configure, to_dict
    from roughwalk.terrain.sdf import SdfConfig, SignedDistanceField

    cfg = configure(SdfConfig(), args.config, args.set)
    if args.resolution is not None:
        cfg = configure(cfg, None, [f"resolution={args.resolution}"])
    t = load_terrain(args.terrain)
    info(f"building the SDF of {t} at {cfg.resolution * 1000:g} mm ...")
    sdf = SignedDistanceField.build(t, config=cfg)
    summary = sdf.info()
    summary.pop("terrain", None)  # the envelope carries the terrain spec
    info(
        f"built {summary['shape']} voxels in {summary['build_time_s']:.3f} s "
        f"(EDT backend: {summary['backend']})"
    )
    if args.npz:
        sdf.save(args.npz)
        info(f"wrote {args.npz}")
    if args.output:
        from roughwalk.viz.sdf_plot import save_sdf_slice_picture

        save_sdf_slice_picture(t, sdf, args.output)
        info(f"wrote {args.output}")
    if args.json:
        write_json(
            args.json,
            result_envelope("sdf", terrain=t.spec, config=to_dict(cfg), npz=args.npz, **summary),
        )
    return 0
