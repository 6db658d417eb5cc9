"""The exception hierarchy of roughwalk.

Every error the library raises on purpose is a :class:`RoughwalkError`; the
Rust core's errors arrive as the same classes. Messages name the bad value and
what would have been valid.
"""

from __future__ import annotations

__all__ = [
    "RoughwalkError",
    "InvalidArgumentError",
    "TerrainError",
    "RobotModelError",
    "PlanningError",
    "ConfigError",
]


class RoughwalkError(Exception):
    """Root of every error roughwalk raises on purpose."""


class InvalidArgumentError(RoughwalkError, ValueError):
    """An argument has the wrong shape, type or value."""


class TerrainError(RoughwalkError, ValueError):
    """A terrain, its file, its generator or its signed distance field is unusable."""


class RobotModelError(RoughwalkError, ValueError):
    """A robot model is missing, malformed or not a supported quadruped."""


class PlanningError(RoughwalkError):
    """A planning problem is malformed or a planner failed unexpectedly."""


class ConfigError(RoughwalkError, ValueError):
    """A configuration file or override names an unknown field or a bad value."""
