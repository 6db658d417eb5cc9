"""Helpers shared by every command: JSON results, progress, error printing."""

from __future__ import annotations

import json
import platform
import sys
from pathlib import Path
from typing import Any

import numpy as np

from roughwalk import __version__

__all__ = [
    "write_json",
    "result_envelope",
    "machine_description",
    "add_output_args",
    "info",
    "simulation_settings",
]

SCHEMA_VERSION = 1


def machine_description() -> dict[str, Any]:
    """What ran this: for benchmark and result JSON."""
    import os

    return {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "cpu_count": os.cpu_count(),
        "roughwalk": __version__,
        "numpy": np.__version__,
    }


def result_envelope(
    schema: str, *, robot: Any = None, terrain: Any = None, **fields: Any
) -> dict[str, Any]:
    """Every JSON result: its ``schema`` (kind), ``version`` and the context it was made with."""
    return {
        "schema": schema,
        "version": SCHEMA_VERSION,
        "roughwalk_version": __version__,
        "robot": robot,
        "terrain": terrain,
        **fields,
    }


def _default(o: Any) -> Any:
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, np.generic):
        return o.item()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"cannot write {type(o).__name__} to JSON")


def write_json(path: str | Path, data: dict[str, Any]) -> None:
    """Write ``data`` as indented JSON (atomically: a crash never leaves half a file)."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    tmp = p.with_name(p.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=2, default=_default, allow_nan=False) + "\n")
    tmp.replace(p)


def add_output_args(parser: Any, *, picture: bool = False, npz: bool = False) -> None:
    """The project-wide output flags: ``--json``, ``-o`` (PNG), ``--npz``, config overrides."""
    parser.add_argument("--json", metavar="FILE", help="write the machine-readable result here")
    if picture:
        parser.add_argument("-o", "--output", metavar="FILE.png", help="write a picture here")
    if npz:
        parser.add_argument("--npz", metavar="FILE", help="write arrays here (.npz)")
    parser.add_argument("--config", metavar="FILE.toml", help="config overrides from a TOML file")
    parser.add_argument(
        "--set",
        metavar="KEY=VALUE",
        action="append",
        default=[],
        help="override one config field (repeatable, dotted keys)",
    )


def info(message: str) -> None:
    """Print a progress or status line to stderr (stdout stays for results)."""
    print(message, file=sys.stderr, flush=True)


def simulation_settings(items: list[str]) -> tuple[dict[str, str], dict[str, str]]:
    """``--set KEY=VALUE`` items as (simulation, trajectory) settings, both checked.

    Keys prefixed ``trajectory.`` go, without the prefix, to
    :func:`roughwalk.trajectories.trajectory_config`; keys prefixed
    ``footstep.`` stay among the simulation settings, for
    :func:`roughwalk.sim.run` to give the footstep planner; the others go to
    :func:`roughwalk.sim.sim_config`. A malformed item or an unknown key or
    value raises :class:`~roughwalk.errors.ConfigError` before any run.
    """
    from roughwalk.config import override
    from roughwalk.errors import ConfigError
    from roughwalk.planning.footstep_config import FootstepConfig
    from roughwalk.robots import load_robot
    from roughwalk.sim import sim_config
    from roughwalk.sim.footstep_source import split_footstep_settings
    from roughwalk.trajectories import trajectory_config

    sim: dict[str, str] = {}
    trajectory: dict[str, str] = {}
    for item in items:
        key, eq, value = item.partition("=")
        key = key.strip()
        if not eq or not key:
            raise ConfigError(f"--set takes KEY=VALUE, got {item!r}")
        if key.startswith("trajectory."):
            trajectory[key.removeprefix("trajectory.")] = value.strip()
        else:
            sim[key] = value.strip()
    own, footstep = split_footstep_settings(sim)
    sim_config(None, **own)
    if footstep:
        # Field names and value types are the same for every robot's planner.
        override(FootstepConfig.for_robot(load_robot("littledog")), footstep)
    trajectory_config(None, **trajectory)
    return sim, trajectory
