"""TOWR's heuristic initial guess (Melon 2020, §IV): a straight base, even footholds and timing.

The base moves on the straight line from start to goal at constant speed
while the feet step (it rests during the stand phases at both ends); each
foot's footholds are evenly spaced from its start foothold to its nominal
foothold at the goal, on the terrain, moved along the path off steep ground
and step edges when one falls there (our addition: on a step's smoothed edge
the friction pyramid lies on its side) — on level ground each is instead the
nominal foothold under the base at the middle of its stance (our addition,
closer to TOWR's feet under its interpolated base; see
:class:`HeuristicInitializer`) —, and the base pitches and rolls with
the ground under its nominal feet; the goal footholds are moved within reach
until a level base can stand on them (our addition: TOWR's goal base is
level, and a nominal stance astride a step is not; see
:func:`~roughwalk.trajopt.initializers.guess.level_goal_stance`); the phase
durations are the gait's; the forces share the weight among the feet in stance.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from roughwalk.errors import ConfigError
from roughwalk.trajopt.formulation import Formulation
from roughwalk.trajopt.gaits import ContactSchedule
from roughwalk.trajopt.initializers.guess import (
    EDGE_COST,
    feet_guess,
    finite_difference,
    forces_guess,
    level_goal_stance,
    node_times,
    off_edges,
    straight_base,
)
from roughwalk.trajopt.task import ResolvedTask, nominal_feet

__all__ = ["HeuristicInitializer", "base_guess"]


def base_guess(
    nlp: Formulation, task: ResolvedTask, goal_z: float | None = None
) -> dict[str, NDArray[np.float64]]:
    """Base linear and angular variables on the straight line from start to goal.

    ``goal_z`` [m]: the CoM height at the goal (default: over the nominal stance).
    """
    times = node_times(nlp.base_lin, nlp.base_lin.durations)
    positions, euler = straight_base(nlp, task, times, goal_z)
    return {
        nlp.base_lin.name: nlp.base_lin.pack(positions, finite_difference(positions, times)),
        nlp.base_ang.name: nlp.base_ang.pack(euler, finite_difference(euler, times)),
    }


_LEVEL_TOLERANCE = 1e-3  # [m] of height and [-] of slope within which ground is level


def _even_footholds(
    nlp: Formulation,
    task: ResolvedTask,
    goal_feet: NDArray[np.float64],
    foot: int,
    direction: NDArray[np.float64],
) -> dict[int, NDArray[np.float64]]:
    """Foot ``foot``'s stance footholds, evenly spaced from start to goal (Melon 2020, §IV)."""
    stances = nlp.stance_phases(foot)
    start, goal = task.feet[foot], goal_feet[foot]
    footholds: dict[int, NDArray[np.float64]] = {}
    for j, phase in enumerate(stances):
        if nlp.fixed_foothold(foot, phase):
            footholds[phase] = start
        elif j == len(stances) - 1:
            footholds[phase] = goal
        else:
            p = start + (goal - start) * j / max(len(stances) - 1, 1)
            footholds[phase] = off_edges(nlp, p, direction)
    return footholds


def _under_base_footholds(
    nlp: Formulation,
    task: ResolvedTask,
    goal_z: float,
    foot: int,
    direction: NDArray[np.float64],
    even: dict[int, NDArray[np.float64]],
) -> dict[int, NDArray[np.float64]]:
    """Foot ``foot``'s stance footholds nominal under the guessed base at each stance's middle.

    The first and last stances keep ``even``'s footholds (the start's and the
    goal's). TOWR's flat trot from evenly spaced footholds: 38
    range-of-motion rows within 1 cm of their bound or beyond, against 8.
    """
    stances = nlp.stance_phases(foot)
    times = nlp.schedule.phase_times(foot)
    footholds = dict(even)
    for phase in stances[1:-1]:
        if nlp.fixed_foothold(foot, phase):
            continue
        middle = 0.5 * (times[phase] + times[phase + 1])
        position, euler = straight_base(nlp, task, np.array([0.0, middle]), goal_z)
        x, y, _ = (float(v) for v in position[1])
        nominal, _ = nominal_feet(nlp.body, nlp.terrain, x, y, float(euler[1, 2]))
        footholds[phase] = off_edges(nlp, nominal[foot], direction)
    return footholds


def _level(nlp: Formulation, footholds: list[dict[int, NDArray[np.float64]]]) -> bool:
    """Whether every foothold lies on one flat height, away from edges."""
    points = np.array([p for feet in footholds for p in feet.values()])
    values = nlp.terrain.evaluate(points[:, :2])
    return bool(
        np.ptp(points[:, 2]) <= _LEVEL_TOLERANCE
        and np.all(np.hypot(values[:, 1], values[:, 2]) <= _LEVEL_TOLERANCE)
        and np.all(values[:, 3] < EDGE_COST)
    )


class HeuristicInitializer:
    """TOWR's heuristic guess; registered as ``heuristic`` (``heuristic:even``).

    On level ground (every candidate foothold at one flat height, away from
    edges) each stance's foothold is the nominal one under the guessed base
    at the middle of that stance; with the argument "even" they are evenly
    spaced from start to goal there too (Melon 2020, §IV), as they are on
    uneven ground either way. Even footholds leave a trot's feet out of
    phase with the base and outside their range-of-motion box. Measured
    (session 11, iterations from the cold guess): TOWR's flat trot at goals
    1.4, 1.45, 1.5, 1.55, 1.6 m took 15, 11, 22, 21, 12 iterations from
    even footholds and 8, 11, 11, 8, 12 from level ones (TOWR: 13 at
    1.5 m); its flat walk at 1.3–1.7 m 83 in all against 77, with optimised
    durations 12 against 10 at 1.5 m; Melon's flat trot (14 steps, costs,
    1.3–1.7 m) 124 against 112, to the same costs. On uneven ground the
    footholds under the base fall into gaps and onto stairs' risers:
    applied there, TOWR's gap walk and bound stopped at the 40 s limit and
    its stairs 1.0 m with optimised durations took 235 iterations instead
    of 40, hence level ground only.
    """

    name = "heuristic"

    def __init__(self, argument: str | None = None) -> None:
        if argument not in (None, "even"):
            raise ConfigError(
                f"the heuristic initialiser takes no argument or 'even', got {argument!r}"
            )
        self.level_under_base = argument is None

    def schedule(self, gait: ContactSchedule) -> ContactSchedule:
        """The gait's schedule."""
        return gait

    def adjust_task(self, task: ResolvedTask) -> ResolvedTask:
        """The task as given."""
        return task

    def guess(self, nlp: Formulation, task: ResolvedTask) -> NDArray[np.float64]:
        """The initial variable vector for ``task``."""
        durations = [np.asarray(d.nominal) for d in nlp.durations]
        direction = task.goal_xy - task.base_position[:2]
        if np.linalg.norm(direction) < 1e-6:
            direction = np.array([np.cos(task.base_euler[2]), np.sin(task.base_euler[2])])
        gx, gy = (float(v) for v in task.goal_xy)
        goal_feet, _ = nominal_feet(nlp.body, nlp.terrain, gx, gy, float(task.goal_euler[2]))
        # Off edges like the other footholds: block 1.1 m's hind feet on the
        # edge's shoulder took 98 iterations, 21 off it.
        goal_feet = np.array([off_edges(nlp, f, direction) for f in goal_feet])
        goal_feet = level_goal_stance(nlp, goal_feet, direction)
        goal_z = float(goal_feet[:, 2].mean() + nlp.body.nominal_height)
        parts = base_guess(nlp, task, goal_z)
        feet = range(nlp.n_feet)
        chosen = [_even_footholds(nlp, task, goal_feet, foot, direction) for foot in feet]
        if self.level_under_base:
            under = [
                _under_base_footholds(nlp, task, goal_z, foot, direction, chosen[foot])
                for foot in feet
            ]
            if _level(nlp, [*chosen, *under]):
                chosen = under
        for foot in feet:
            parts[nlp.feet[foot].name] = feet_guess(nlp, task, foot, durations[foot], chosen[foot])
            parts[nlp.forces[foot].name] = forces_guess(nlp, foot, durations[foot], durations)
            parts[nlp.durations[foot].name] = nlp.durations[foot].pack(durations[foot])
        return nlp.join(parts)
