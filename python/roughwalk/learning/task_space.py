"""Task spaces: where a robot may start and where it must go, per environment.

Melon et al. sample the start base position 0.5–1.5 m back from the step
and ±0.75 m laterally, with yaw in ±30°, and a fixed goal on top (Melon
2020, §IV-B). A task's sample depends only on (seed, split, index), so that
asking for more tasks later extends a run without changing the first ones,
and the held-out "test" split is a separate random stream, never seen in
training.

The walk a space's tasks are solved with is chosen per environment, as
Melon et al. choose the horizon (§V). Flat ground and the single pallet
walk 16 steps in 5.5 s, the double pallet 20 steps in 6.875 s, at the same
0.34 s a step.
Melon et al. kept the single pallet's parameters for the double pallet, but
walked "about the same" distance as on flat ground (up to 1.5 m). Our
double-pallet starts, 0.5–1.5 m back from the lower step, lie 1.3–2.3 m
from its goal on the upper one. Sixteen steps advance the base 2.30 m at
the very most (a stance foot stays put, so the base moves at most the
range-of-motion box's 0.31 m per stance), and no 16-step solve from farther
than 1.74 m converged, from any start (session 13). Session 15 reached
starts from converged neighbours' solutions: 20 steps in 5.5 s converged
up to 1.92 m, in 6.875 s up to 2.10 m (x = −0.30; farther starts have no
converged solve yet), 24 steps in 8.25 s no farther. A box
0.5–1.5 m back from the upper step instead would put front feet on the
lower pallet: 13 of the 30 held-out starts then have no level stance.

The double pallet's walk also lets the trunk come within 0.5 × its nominal
height of a swinging foot (``swing_base_clearance``; stance feet keep 0.7).
At 0.7 a front foot swinging onto the top holds the trunk 0.72 m up while
the hind feet stand on the ground, and no start behind x = −0.30 converged.
At 0.5 solves grown from converged neighbours converge across the whole box
(session 16: 516 of 539 starts at x ≤ 0.1, 125 of 143 behind x = −0.30,
down to x = −0.50).

The single pallet's walk sets 0.5 too (session 17). Its tracking failures
at 0.7 (a leg link touching the pallet top at 4.0–4.9 s) came after the
trunk had drifted 20–40 cm off its plan; converged plans of those tasks
track to about 1 cm once their forces cannot pull between nodes
(``unilateral_between_nodes``, which its 0.5 model is trained with), and the
plans ask less of the hips at 0.5.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from roughwalk.errors import ConfigError
from roughwalk.trajopt import Task

__all__ = ["TaskSpace", "task_space", "ENVIRONMENTS", "SPLITS"]

SPLITS = ("train", "test")
_STEPS, _DURATION = 16, 5.5  # the pallets' walk of Melon 2020, §V
_SPLIT_STREAM = {"train": 0, "test": 1}
_REDRAWS = 20  # draws of one task before its index is given up


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
    steps, duration:
        The walk its tasks are solved with: swings of all feet and the
        horizon T [s] (Melon 2020, §V: the horizon is chosen per
        environment). More steps reach farther starts (each stance advances
        the base at most the range-of-motion box's length), at more
        variables and CPU per solve; the time per step is what makes a walk
        dynamic. Left out of :meth:`to_dict` at 16 and 5.5 s, so that runs
        recorded before the fields existed still resume.
    swing_base_clearance:
        The walk's least height of the base above a swinging foot, as a
        fraction of the nominal base height
        (:class:`~roughwalk.trajopt.TrajoptConfig`'s field; None: as
        ``base_clearance``, 0.7). Lower lets the trunk stay low while a front
        foot swings up a step with the hind feet below, at the price of a
        swing foot nearer the trunk. Left out of :meth:`to_dict` when None.

    """

    name: str
    terrain: str
    start_low: tuple[float, float, float]
    start_high: tuple[float, float, float]
    goal: tuple[float, float, float]
    steps: int = _STEPS
    duration: float = _DURATION
    swing_base_clearance: float | None = None

    def __post_init__(self) -> None:
        if any(lo > hi for lo, hi in zip(self.start_low, self.start_high, strict=True)):
            raise ConfigError(
                f"task space '{self.name}': start_low {self.start_low} exceeds "
                f"start_high {self.start_high}"
            )
        if self.steps < 1 or not self.duration > 0:
            raise ConfigError(
                f"task space '{self.name}': steps must be ≥ 1 and duration > 0 s, got "
                f"{self.steps} and {self.duration}"
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

    def draw(
        self,
        index: int,
        *,
        seed: int = 0,
        split: str = "train",
        refuse: Callable[[Task], str | None],
        attempts: int = _REDRAWS,
    ) -> tuple[Task, list[tuple[Task, str]]]:
        """Task ``index``, drawn again while ``refuse`` says why it cannot be solved.

        The start box holds a few starts that no solve can begin from: a
        foot of the start stance on a pallet's edge, out of its range of
        motion under a level base (held-out double- and single-pallet seed 1,
        task 6). A benchmark of a controller counts them as failures of the
        task sampler, not of the controller, unless it draws them again.
        The first draw is :meth:`task`'s; the k-th redraw uses the stream
        (seed, split, index, k), so that a valid task never moves and a
        redrawn one is the same on every run. Returns the task and the
        refused draws with ``refuse``'s reasons.
        """
        task = self.task(index, seed=seed, split=split)
        refused: list[tuple[Task, str]] = []
        for attempt in range(1, attempts + 2):
            reason = refuse(task)
            if reason is None:
                return task, refused
            refused.append((task, reason))
            if attempt > attempts:
                break
            rng = np.random.default_rng([seed, _SPLIT_STREAM[split], index, attempt])
            start = rng.uniform(self.start_low, self.start_high)
            task = Task((float(start[0]), float(start[1]), float(start[2])), self.goal)
        raise ConfigError(
            f"task space '{self.name}': task {index} of seed {seed} ({split}) was refused "
            f"{len(refused)} times; the last reason: {refused[-1][1]}"
        )

    def sample(self, n: int, *, seed: int = 0, split: str = "train") -> list[Task]:
        """Tasks 0..n−1 of ``split`` for ``seed``."""
        return [self.task(i, seed=seed, split=split) for i in range(n)]

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON (``steps``, ``duration`` unless 16 and 5.5 s; a set clearance)."""
        data = asdict(self)
        if (self.steps, self.duration) == (_STEPS, _DURATION):
            del data["steps"], data["duration"]
        if self.swing_base_clearance is None:
            del data["swing_base_clearance"]
        return data

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
                int(data.get("steps", _STEPS)),
                float(data.get("duration", _DURATION)),
                None
                if data.get("swing_base_clearance") is None
                else float(data["swing_base_clearance"]),
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
        steps: int = _STEPS,
        duration: float = _DURATION,
        swing_base_clearance: float | None = None,
    ) -> TaskSpace:
        """Melon's task space on any terrain: starts ``back`` [m] before ``edge_x``.

        Without ``edge_x`` the starts lie ``back`` before the goal's x. The
        lateral offset [m] is around the goal's y, the yaw [rad] around 0;
        the tasks are walked in ``steps`` swings over ``duration`` [s] with
        the trunk ``swing_base_clearance`` over a swinging foot.
        """
        edge = goal[0] if edge_x is None else edge_x
        return cls(
            name or terrain,
            terrain,
            (edge - back[1], goal[1] - lateral, -yaw),
            (edge - back[0], goal[1] + lateral, yaw),
            goal,
            steps,
            duration,
            swing_base_clearance,
        )


def _triple(value: Any) -> tuple[float, float, float]:
    x, y, z = (float(v) for v in value)
    return (x, y, z)


# The pallets' near edge is at x = 1 m (terrain generators); flat ground's
# goal is 1.5 m ahead of the middle of the same start box. The double
# pallet's walk: the module docstring.
ENVIRONMENTS: dict[str, TaskSpace] = {
    "single_pallet": TaskSpace.for_terrain(
        "single_pallet", (1.6, 0.0, 0.0), edge_x=1.0, swing_base_clearance=0.5
    ),
    "double_pallet": TaskSpace.for_terrain(
        "double_pallet",
        (1.8, 0.0, 0.0),
        edge_x=1.0,
        steps=20,
        duration=6.875,
        swing_base_clearance=0.5,
    ),
    "flat": TaskSpace.for_terrain("flat", (1.5, 0.0, 0.0), edge_x=1.0),
}


def task_space(name: str) -> TaskSpace:
    """The named environment's task space ("flat", "single_pallet", "double_pallet")."""
    if name not in ENVIRONMENTS:
        raise ConfigError(f"unknown environment {name!r}; known: {', '.join(ENVIRONMENTS)}")
    return ENVIRONMENTS[name]
