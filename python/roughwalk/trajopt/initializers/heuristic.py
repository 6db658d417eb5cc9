"""TOWR's heuristic initial guess (Melon 2020, §IV): a straight base, even footholds and timing.

The base moves on the straight line from start to goal at constant speed
while the feet step (it rests during the stand phases at both ends); each
foot's footholds are evenly spaced from its start foothold to its nominal
foothold at the goal, on the terrain, moved along the path off steep ground
and step edges when one falls there (our addition: on a step's smoothed edge
the friction pyramid lies on its side), and the base pitches and rolls with
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


class HeuristicInitializer:
    """TOWR's heuristic guess; registered as ``heuristic``."""

    name = "heuristic"

    def __init__(self, argument: str | None = None) -> None:
        if argument:
            raise ConfigError(f"the heuristic initialiser takes no argument, got {argument!r}")

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
        parts = base_guess(nlp, task, float(goal_feet[:, 2].mean() + nlp.body.nominal_height))
        for foot in range(nlp.n_feet):
            # Evenly spaced footholds from the start foothold to the goal's (Melon 2020, §IV).
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
            parts[nlp.feet[foot].name] = feet_guess(nlp, task, foot, durations[foot], footholds)
            parts[nlp.forces[foot].name] = forces_guess(nlp, foot, durations[foot], durations)
            parts[nlp.durations[foot].name] = nlp.durations[foot].pack(durations[foot])
        return nlp.join(parts)
