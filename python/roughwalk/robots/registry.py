"""Robots registered by name: the MJCF models shipped inside the package.

Each entry is data: a name, the model file, a one-line description and where
its numbers come from (``models/README.md`` has the details). Everything
physical lives in the MJCF itself (limits, actuators, the ``home`` keyframe
used as the nominal pose, velocity limits as ``<custom>`` numerics), so that a
simulator loading :attr:`RobotInfo.mjcf_path` gets the very same robot.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from roughwalk.errors import RobotModelError

__all__ = ["RobotInfo", "list_robots", "robot_info", "register_robot", "MODELS_DIR"]

MODELS_DIR = Path(__file__).resolve().parent / "models"
"""Directory of the shipped MJCF files (inside the installed package)."""


@dataclass(frozen=True)
class RobotInfo:
    """A registered robot: its name, model file and provenance."""

    name: str
    """Registry name, lower case (``load_robot(name)``)."""
    mjcf_path: Path
    """The MJCF file [absolute path]."""
    description: str
    """One line: what the robot is."""
    sources: str
    """Where the model's numbers come from."""


_REGISTRY: dict[str, RobotInfo] = {}


def register_robot(
    name: str, mjcf_path: str | Path, description: str = "", sources: str = ""
) -> RobotInfo:
    """Register (or replace) a robot name for :func:`roughwalk.load_robot`.

    Raises :class:`RobotModelError` when the file does not exist.
    """
    path = Path(mjcf_path).expanduser().resolve()
    if not path.is_file():
        raise RobotModelError(f"cannot register robot '{name}': MJCF file '{path}' does not exist")
    info = RobotInfo(name=name.lower(), mjcf_path=path, description=description, sources=sources)
    _REGISTRY[info.name] = info
    return info


def list_robots() -> list[RobotInfo]:
    """All registered robots, sorted by name."""
    return [_REGISTRY[k] for k in sorted(_REGISTRY)]


def robot_info(name: str) -> RobotInfo:
    """Return the registered robot ``name`` (case-insensitive).

    Raises :class:`RobotModelError` listing the known names when there is none.
    """
    try:
        return _REGISTRY[name.lower()]
    except KeyError:
        known = ", ".join(sorted(_REGISTRY))
        raise RobotModelError(f"unknown robot '{name}'; known: {known}") from None


register_robot(
    "littledog",
    MODELS_DIR / "littledog.xml",
    "Boston Dynamics LittleDog, the 2.75 kg quadruped of the DARPA Learning Locomotion program",
    "MIT Robot Locomotion Group's LittleDog.urdf (masses, inertias, kinematics, limits, "
    "10.3 mm feet); Zucker et al. 2011 §5.2 (joint speed limits); actuators assumed",
)
register_robot(
    "anymal_c",
    MODELS_DIR / "anymal_c.xml",
    "ANYbotics ANYmal C, a 45 kg quadruped with series-elastic drives",
    "MuJoCo Menagerie's anymal_c.xml after ANYbotics' URDF (masses, inertias, kinematics, "
    "collision shapes, 80 N·m actuators); ANYbotics' URDF (7.5 rad/s joint speed)",
)
