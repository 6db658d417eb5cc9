"""Task spaces: where a robot may start and where it must go, per environment.

Melon et al. sample the start base position 0.5–1.5 m back from the step
and ±0.75 m laterally, with yaw in ±30°, and a fixed goal on top (Melon
2020, §IV-B). A task's sample depends only on (seed, split, index), so that
asking for more tasks later extends a run without changing the first ones,
and the held-out "test" split is a separate random stream, never seen in
training.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from roughwalk.errors import ConfigError
from roughwalk.trajopt import Task

__all__ = ["TaskSpace", "task_space", "ENVIRONMENTS", "SPLITS"]

SPLITS = ("train", "test")
_SPLIT_STREAM = {"train": 0, "test": 1}


@dataclass(frozen=True)
class TaskSpace:
    """Starts drawn uniformly from a box; one fixed goal.

    Attributes
    ----------
    name:
        The environment's name.
    terrain:
        The terrain spec the tasks are on.
    start_low, start_high:
        Corners (x [m], y [m], yaw [rad]) of the start box.
    goal:
        (x [m], y [m], yaw [rad]) of the goal.

    """

    name: str
    terrain: str
    start_low: tuple[float, float, float]
    start_high: tuple[float, float, float]
    goal: tuple[float, float, float]

    def __post_init__(self) -> None:
        if any(lo > hi for lo, hi in zip(self.start_low, self.start_high, strict=True)):
            raise ConfigError(
                f"task space '{self.name}': start_low {self.start_low} exceeds "
                f"start_high {self.start_high}"
            )

    def task(self, index: int, *, seed: int = 0, split: str = "train") -> Task:
        """Task ``index`` of ``split`` ("train" or "test") for ``seed``."""
        if split not in _SPLIT_STREAM:
            raise ConfigError(f"unknown split {split!r}; known: {', '.join(SPLITS)}")
        if index < 0:
            raise ConfigError(f"task index must be ≥ 0, got {index}")
        rng = np.random.default_rng([seed, _SPLIT_STREAM[split], index])
        start = rng.uniform(self.start_low, self.start_high)
        return Task((float(start[0]), float(start[1]), float(start[2])), self.goal)

    def sample(self, n: int, *, seed: int = 0, split: str = "train") -> list[Task]:
        """Tasks 0..n−1 of ``split`` for ``seed``."""
        return [self.task(i, seed=seed, split=split) for i in range(n)]

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> TaskSpace:
        """The space written by :meth:`to_dict`."""
        try:
            return cls(
                str(data["name"]),
                str(data["terrain"]),
                _triple(data["start_low"]),
                _triple(data["start_high"]),
                _triple(data["goal"]),
            )
        except KeyError as e:
            raise ConfigError(f"task space lacks the field {e}; got {sorted(data)}") from None

    @classmethod
    def for_terrain(
        cls,
        terrain: str,
        goal: tuple[float, float, float],
        *,
        edge_x: float | None = None,
        back: tuple[float, float] = (0.5, 1.5),
        lateral: float = 0.75,
        yaw: float = math.radians(30.0),
        name: str | None = None,
    ) -> TaskSpace:
        """Melon's task space on any terrain: starts ``back`` [m] before ``edge_x``.

        Without ``edge_x`` the starts lie ``back`` before the goal's x. The
        lateral offset [m] is around the goal's y, the yaw [rad] around 0.
        """
        edge = goal[0] if edge_x is None else edge_x
        return cls(
            name or terrain,
            terrain,
            (edge - back[1], goal[1] - lateral, -yaw),
            (edge - back[0], goal[1] + lateral, yaw),
            goal,
        )


def _triple(value: Any) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in value)
    return (x, y, z)


# The pallets' near edge is at x = 1 m (terrain generators); flat ground's
# goal is 1.5 m ahead of the middle of the same start box.
ENVIRONMENTS: dict[str, TaskSpace] = {
    "single_pallet": TaskSpace.for_terrain("single_pallet", (1.6, 0.0, 0.0), edge_x=1.0),
    "double_pallet": TaskSpace.for_terrain("double_pallet", (1.8, 0.0, 0.0), edge_x=1.0),
    "flat": TaskSpace.for_terrain("flat", (1.5, 0.0, 0.0), edge_x=1.0),
}


def task_space(name: str) -> TaskSpace:
    """The named environment's task space ("flat", "single_pallet", "double_pallet")."""
    if name not in ENVIRONMENTS:
        raise ConfigError(f"unknown environment {name!r}; known: {', '.join(ENVIRONMENTS)}")
    return ENVIRONMENTS[name]
